"""The simulated cell claims neither fit nor no_fit for a pair whose room or interference
per side is below what its physics resolves (``SIZE_RESOLUTION``, docs/cell.md), and builds
a stated nominal zero-clearance fit with room (``NOMINAL_FIT_ROOM``) when that changes no
other pair's answer."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest
import shapely

from bridge.product.nominal import NOMINAL_FIT_ROOM
from executor import ExecutorError
from executor.trial import Cell
from executor.world import SIZE_RESOLUTION
from executor.world.geometry import HoleSpec, load_geometry, margin, widened

ROOT = Path(__file__).resolve().parents[2]


def _graded_with(tmp_path: Path, sizes: dict[str, float]) -> Path:
    """The graded board with the diameters [m] of some of its hole shapes changed."""
    folder = tmp_path / "graded"
    shutil.copytree(ROOT / "data" / "graded", folder, ignore=shutil.ignore_patterns("assets"))
    text = (folder / "geometry.toml").read_text(encoding="utf-8")
    for shape, size in sizes.items():
        text, count = re.subn(rf"(\[hole_shapes\.{shape}\]\nholes = [^\n]*\nkind = \"round\"\nsize = )[0-9.]+",
                              rf"\g<1>{size}", text)
        assert count == 1, shape
    (folder / "geometry.toml").write_text(text, encoding="utf-8")
    return folder


def test_a_pair_within_the_resolution_is_refused_and_one_outside_it_is_not(tmp_path: Path) -> None:
    # p2 is d 11 mm: h6 0.01 mm per side too small (PyBullet measured `fit`), h5 0.01 mm per
    # side of room (measured `no_fit` once), h4 0.05 mm per side too small (measured no_fit).
    folder = _graded_with(tmp_path, {"d15_8": 0.01098, "d14_8": 0.01102, "d13_8": 0.0109})
    cell = Cell(str(folder))
    try:
        for hole, says in (("h6", "-0.010 mm per side (an interference)"), ("h5", "+0.010 mm per side (room)")):
            with pytest.raises(ExecutorError, match=re.escape(says) + ".*claims neither fit nor no_fit"):
                cell.run_trial("p2", hole, seed=0)
        cell.check_pair("p2", "h4")
    finally:
        cell.close()


@pytest.mark.parametrize("assembly", ["cranfield", "spare", "graded", "taskboard"])
def test_no_pair_of_a_shipped_product_is_within_the_resolution(assembly: str) -> None:
    geometry = load_geometry(assembly)
    rooms = [(margin(hole, part) if hole.pin else margin(part, hole)) / 2
             for part in geometry.parts.values() for hole in geometry.holes.values() if part.bore == hole.pin]
    assert rooms and min(map(abs, rooms)) > SIZE_RESOLUTION


def _graded_stating(tmp_path: Path, p3_size: float) -> Path:
    """The graded board with its d 10.8 hole h1 made p2's nominal section (d 11 mm, stated
    a zero-clearance fit with p2) and p3 made ``p3_size`` [m]."""
    folder = _graded_with(tmp_path, {"d10_8": 0.011})
    text = (folder / "geometry.toml").read_text(encoding="utf-8")
    stated = '[hole_shapes.d10_8]\nholes = ["h1"]\n'
    text = text.replace(stated, stated + 'zero_clearance = ["p2"]\n')
    text, count = re.subn(r"(\[part_shapes\.peg_d12\]\nparts = [^\n]*\nkind = \"round\"\nsize = )[0-9.]+",
                          rf"\g<1>{p3_size}", text)
    assert count == 1
    (folder / "geometry.toml").write_text(text, encoding="utf-8")
    return folder


def test_a_nominal_zero_clearance_fit_is_built_with_the_stated_room_and_changes_no_other_answer(
        tmp_path: Path) -> None:
    geometry = load_geometry(str(_graded_stating(tmp_path, 0.012)))
    hole = geometry.holes["h1"]
    assert hole.size == pytest.approx(0.011 + 2 * NOMINAL_FIT_ROOM, abs=1e-12)
    assert margin(geometry.parts["p2"], hole) / 2 >= SIZE_RESOLUTION  # a pair the cell tries
    assert geometry.holes["h2"].size == pytest.approx(0.0118, abs=1e-12)  # states none: as written
    cell = Cell(str(tmp_path / "graded"))
    try:
        cell.check_pair("p2", "h1")
    finally:
        cell.close()
    # p3 0.02 mm wider than h1's nominal section: no fit, a fit in the widened hole
    with pytest.raises(ExecutorError, match=r"hole 'h1': .* part 'p3' \(-0\.0100 mm per side\) would then fit"):
        load_geometry(str(_graded_stating(tmp_path / "wider", 0.01102)))


@pytest.mark.slow  # one insertion in physics (about 10 s)
def test_a_nominal_zero_clearance_fit_goes_in_in_physics(tmp_path: Path) -> None:
    # p2 (d 11 mm) in h1 stated d 11 mm, room 0: refused at room 0, built with room it goes in
    cell = Cell(str(_graded_stating(tmp_path, 0.012)))
    try:
        result = cell.run_trial("p2", "h1", seed=0)
    finally:
        cell.close()
    assert result.outcome == "fit", result


def test_a_widened_hole_has_the_room_all_round_whatever_its_section() -> None:
    square = ((-0.005, -0.005), (0.005, -0.005), (0.005, 0.005), (-0.005, 0.005))
    polygon = HoleSpec("h", "polygon", 0.01, (0.0, 0.0), width=0.01, outline=square, top_z=0.1, depth=0.02)
    rect = HoleSpec("r", "rect", 0.012, (0.0, 0.0), width=0.008, corner=0.001, top_z=0.1, depth=0.02)
    for hole in (polygon, rect):
        built = widened(hole, 1e-4)
        assert built.sides == pytest.approx((hole.sides[0] + 2e-4, hole.sides[1] + 2e-4), abs=1e-12)
    grown = shapely.Polygon(widened(polygon, 1e-4).outline)
    assert grown.symmetric_difference(shapely.box(-0.0051, -0.0051, 0.0051, 0.0051)).area < 1e-15  # mitred: sharp
    assert widened(rect, 1e-4).corner == pytest.approx(0.0011, abs=1e-12)
