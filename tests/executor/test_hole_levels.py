"""Holes at their own heights and depths (``top_z`` and ``depth`` in ``[hole_shapes.*]``):
Cranfield with r2 raised 10 mm and s2 5 mm deeper. Its plate mesh (bosses up to their
own entries, floors where a hole is shallower than its boss, the plate under the bosses
at the deepest bottom); in physics, with the skills taught at the plate's level (the
shipped ones, taught in r1 and s1), a fitting peg inserted to the bottom of each, a
too-big one refused on the raised boss, skills taught in the raised and the deeper hole
against the shipped ones, and the assembling cell's goals at each hole's bottom; the
assembled export, made for the plate's level only, refuses the product."""

from __future__ import annotations

import math
import shutil
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
import trimesh

from assembly_constraints.cli import main
from bridge.assembly import DATA_DIR
from executor.assembly.product import load_product
from executor.assembly.step import Assembler
from executor.cell_description import CellDescription
from executor.skills.dmp import load_skill, save_skill
from executor.skills.teach import DEMO_CLEARANCE, teach_shape
from executor.trial import Cell
from executor.world.assets import sources_digest
from executor.world.geometry import CellGeometry, load_geometry, plate_obj_text
from tests._tolerances import END_BOUND

RAISE = 0.010  # [m] r2's entry above the plate's
DEEPER = 0.005  # [m] s2's depth beyond the plate's
LEVELS = [
    ('[hole_shapes.round_small]\nholes = ["r1", "r2"]\nkind = "round"\nsize = 0.0133           # diameter [m]',
     '[hole_shapes.round_small]\nholes = ["r1"]\nkind = "round"\nsize = 0.0133\n\n'
     f'[hole_shapes.round_raised]\nholes = ["r2"]\nkind = "round"\nsize = 0.0133\ntop_z = {0.10 + RAISE:.3f}'),
    ('[hole_shapes.square]\nholes = ["s1", "s2"]\nkind = "square"\nsize = 0.0133           # side [m]',
     '[hole_shapes.square]\nholes = ["s1"]\nkind = "square"\nsize = 0.0133\n\n'
     f'[hole_shapes.square_deep]\nholes = ["s2"]\nkind = "square"\nsize = 0.0133\ndepth = {0.025 + DEEPER:.3f}'),
]
"""Edits of data/cranfield/geometry.toml (whose plate has top_z 0.10, tile_thickness 0.025)."""
ASSEMBLY_BOUND = 0.002  # [m] a placed part's pose error (docs/assembly.md)


def _levelled(folder: Path, *edits: tuple[str, str]) -> Path:
    """A copy of data/cranfield (its taught skills, no assets) with ``LEVELS`` and ``edits``."""
    shutil.copytree(DATA_DIR / "cranfield", folder, ignore=shutil.ignore_patterns("assets"))
    path = folder / "geometry.toml"
    text = path.read_text()
    for old, new in (*LEVELS, *edits):
        assert old in text, old
        text = text.replace(old, new, 1)
    path.write_text(text)
    return folder


@pytest.fixture(scope="module")
def product(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return _levelled(tmp_path_factory.mktemp("levels") / "asm")


@pytest.fixture(scope="module")
def cell(product: Path) -> Iterator[Cell]:
    c = Cell(str(product))
    yield c
    c.close()


def _boss(geometry: CellGeometry, hole: str) -> trimesh.Trimesh:
    """The mesh of ``o boss_<hole>`` in the plate OBJ (vertices merged)."""
    vertices: list[list[float]] = []
    inside = False
    for line in plate_obj_text(geometry).splitlines():
        if line.startswith("o "):
            inside = line == f"o boss_{hole}"
        elif inside and line.startswith("v "):
            vertices.append([float(v) for v in line.split()[1:]])
    return trimesh.Trimesh(np.array(vertices), np.arange(len(vertices)).reshape(-1, 3))


def test_each_hole_has_its_own_level_and_the_plate_lies_under_the_deepest(product: Path) -> None:
    geometry = load_geometry(str(product))
    plate, holes = geometry.plate, geometry.holes
    assert (holes["r2"].top_z, holes["r2"].depth) == (pytest.approx(plate.top_z + RAISE), plate.tile_thickness)
    assert (holes["s2"].top_z, holes["s2"].depth) == (plate.top_z, pytest.approx(plate.tile_thickness + DEEPER))
    for hid in ("r1", "s1", "br"):
        assert (holes[hid].top_z, holes[hid].depth) == (plate.top_z, plate.tile_thickness)
    assert geometry.base_top == holes["s2"].bottom_z
    assert sources_digest(geometry) != sources_digest(load_geometry("cranfield"))  # the levels make other assets


def test_the_bosses_stand_to_their_entries_with_a_floor_where_shallower(product: Path) -> None:
    """Measured on the mesh: each boss a closed solid from the plate under the bosses to
    its entry; the difference of volumes of two bosses of one hole kind is the raise
    (tile² × 10 mm) or the extra depth (hole area × 5 mm, the square hole exact)."""
    geometry = load_geometry(str(product))
    tile, base = geometry.plate.tile_size, geometry.base_top
    bosses = {hid: _boss(geometry, hid) for hid in geometry.holes}
    for hid, boss in bosses.items():
        assert boss.is_watertight and boss.is_winding_consistent and boss.volume > 0, hid
        assert boss.bounds[:, 2] == pytest.approx([base, geometry.holes[hid].top_z], abs=1e-6), hid
    assert bosses["r2"].volume - bosses["r1"].volume == pytest.approx(tile**2 * RAISE, rel=1e-4)
    side = geometry.holes["s2"].size
    assert bosses["s1"].volume - bosses["s2"].volume == pytest.approx(side**2 * DEEPER, rel=1e-4)
    for hid, hole in geometry.holes.items():  # faces up inside the hole: its floor, or none (through)
        boss = bosses[hid]
        inside = np.linalg.norm(boss.triangles_center[:, :2] - hole.position, axis=1) < hole.size / 2
        floor = boss.triangles_center[inside & (boss.face_normals[:, 2] > 1 - 1e-9), 2]
        if hid == "s2":
            assert floor.size == 0 and hole.bottom_z == base
        else:
            assert floor.size and floor == pytest.approx(hole.bottom_z, abs=1e-6), hid


def test_the_assembled_export_refuses_holes_at_their_own_levels(product: Path, tmp_path: Path,
                                                               capsys: pytest.CaptureFixture[str]) -> None:
    """``executor export --assembled`` builds the base's solid at the plate's level only:
    it refuses (one line, exit 2) rather than write a base without r2's raise and s2's depth."""
    assert main(["-q", "executor", "export", "--assembled", "--assembly", str(product), str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"error: {product / 'geometry.toml'}: holes r2, s2 have their own top_z or depth; the base's solid "
                   "is exported only for holes at the plate's level"]
    assert not list((tmp_path / "out").glob("*.obj"))


@pytest.mark.slow
@pytest.mark.parametrize(("part", "hole"), [("p1", "r2"), ("p3", "s2")])
def test_a_fitting_peg_is_inserted_to_the_bottom_of_a_raised_and_of_a_deeper_hole(cell: Cell, part: str,
                                                                                  hole: str) -> None:
    """The skills were taught in r1 and s1 at the plate's level: the raised entry moves the
    hole frame, the extra depth the skill's goal; the tip ends on that hole's own bottom
    (within the teaching's 0.5 mm clearance; the peg presses on it)."""
    result = cell.run_trial(part, hole, seed=0)
    assert result.outcome == "fit", result.to_json()
    tip = cell.motion_for(part).controller.arm.read().tip_pos
    spec = cell.geometry.holes[hole]
    assert abs(tip[2] - spec.bottom_z) < DEMO_CLEARANCE, (tip, spec)
    assert math.dist(tip[:2], spec.position) < (spec.size - cell.geometry.parts[part].size) / 2 + END_BOUND


@pytest.mark.slow
def test_a_too_big_peg_is_no_fit_on_the_raised_boss(cell: Cell) -> None:
    """One attempt, stopped by eq. (6) like any (a trial's two: tests/executor/test_executor_cell.py)."""
    result = cell.run_trial("sh", "r2", seed=0, max_attempts=1)
    assert result.outcome == "no_fit", result.to_json()
    tip = cell.motion_for("sh").controller.arm.read().tip_pos
    assert tip[2] > cell.geometry.holes["r2"].top_z - 0.001  # it stayed on r2's top, 10 mm above the plate's


@pytest.mark.slow
def test_skills_taught_in_a_raised_and_a_deeper_hole_are_relative_to_the_entry(tmp_path: Path) -> None:
    """Taught in r2 (raised), the round peg's skill is the one taught in r1 at the plate's
    level, in the hole frame; taught in s2 (deeper), the square peg's goal and end are 5 mm
    further down, and it inserts into the shallower s1 to s1's bottom."""
    folder = _levelled(tmp_path / "asm", ('demo_hole = "r1"      # where the demonstration is taught\n\n'
                                          '[part_shapes.square_peg]', 'demo_hole = "r2"\n\n[part_shapes.square_peg]'),
                       ('demo_hole = "s1"', 'demo_hole = "s2"'))
    cell = Cell(str(folder))
    try:
        for shape, deeper in (("round_peg", 0.0), ("square_peg", DEEPER)):
            taught, shipped = teach_shape(cell, shape), load_skill(DATA_DIR / "cranfield", shape)
            hole = cell.geometry.holes[next(p for p in cell.geometry.parts.values() if p.shape == shape).demo_hole]
            room = (hole.size - cell.geometry.parts["p1" if shape == "round_peg" else "p3"].size) / 2
            down = np.array([0.0, 0.0, deeper])
            assert np.abs(taught.demo_start[:3] - shipped.demo_start[:3]) == pytest.approx(np.zeros(3), abs=room)
            assert taught.demo_goal[2] == pytest.approx(shipped.demo_goal[2] - deeper, abs=END_BOUND)
            assert taught.end_position[2] == pytest.approx(shipped.end_position[2] - deeper, abs=END_BOUND)
            assert np.abs(taught.end_position - shipped.end_position + down) == pytest.approx(np.zeros(3), abs=room)
            save_skill(folder, taught)
        result = cell.run_trial("p3", "s1", seed=0)  # the skill taught in s2 in the shallower s1
        assert result.outcome == "fit", result.to_json()
        tip = cell.motion_for("p3").controller.arm.read().tip_pos
        assert abs(tip[2] - cell.geometry.holes["s1"].bottom_z) < DEMO_CLEARANCE
    finally:
        cell.close()


@pytest.mark.slow
def test_the_assembling_cell_places_pegs_on_the_bottoms_of_their_own_holes(product: Path) -> None:
    description = CellDescription()
    assembler = Assembler(load_product(str(product), description), description=description)
    try:
        steps = [assembler.run_step(part, hole, seed=0) for part, hole in (("bp", None), ("p1", "r2"), ("p3", "s2"))]
        assert [s.outcome for s in steps] == ["fit"] * 3, [s.to_json() for s in steps]
        for part, hole in (("p1", "r2"), ("p3", "s2")):
            goal = assembler.world.goals[part]
            assert goal[2] == assembler.product.geometry.holes[hole].bottom_z
            assert np.linalg.norm(assembler.world.position(part) - goal) < ASSEMBLY_BOUND
    finally:
        assembler.close()
