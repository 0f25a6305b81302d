"""The simulated cell claims neither fit nor no_fit for a pair whose room or interference
per side is below what its physics resolves (``SIZE_RESOLUTION``, docs/cell.md)."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest

from executor import ExecutorError
from executor.trial import Cell
from executor.world.geometry import load_geometry, margin
from executor.world.scene import SIZE_RESOLUTION

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
