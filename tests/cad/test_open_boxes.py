"""An open box (a tray, a case without its lid) is no hole: its cavity, floored and wider
than what rests in it by more than ``executor.cad.derive.CAVITY_ROOM``, locates nothing of
that size, so the part resting in it is in no hole, and an empty one is no hole for the
pegs of the product; a hole as wide as its peg, an empty one as wide as the product's pegs
and a wide opening through the base stay holes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import shapely
import trimesh

from executor.cad.cli import run_import
from executor.cad.derive import CAVITY_ROOM
from executor.cad.derive.cavities import room_at, roomy
from executor.cad.sections import Loop, classify


def _round(x: float, d: float, height: float, bottom: float) -> trimesh.Trimesh:
    """A cylinder of diameter ``d`` at (``x``, 0) from ``bottom`` up ``height`` [mm]."""
    solid = trimesh.creation.extrude_polygon(shapely.Point(x, 0.0).buffer(d / 2, quad_segs=16), height)
    solid.apply_translation((0.0, 0.0, bottom))
    return solid


def _box(size: tuple[float, float, float], centre: tuple[float, float, float]) -> trimesh.Trimesh:
    box = trimesh.creation.box(size)
    box.apply_translation(centre)
    return box


def _open_box(outside: tuple[float, float, float], floor: float, wall: float,
              at: tuple[float, float, float]) -> trimesh.Trimesh:
    """A box ``outside`` [mm] whose bottom's centre is ``at``, hollowed from its top down to a
    ``floor`` thick bottom, its walls ``wall`` thick."""
    x, y, z = outside
    cavity = _box((x - 2 * wall, y - 2 * wall, z), (at[0], at[1], at[2] + floor + z / 2))
    return _box(outside, (at[0], at[1], at[2] + z / 2)).difference(cavity)


def _case(folder: Path, *, peg: bool, block: tuple[float, float]) -> None:
    """A case 120 x 120 x 40 mm open at its top (floor 10 mm, walls 10 mm) as the base, a
    30 x 30 x 10 mm block resting on its floor at ``block`` (x, y) [mm] and, with ``peg``,
    a d 9.8 peg in a d 10 hole 7 mm deep in the floor at x -30 beside an empty d 10 hole at
    x -30, y 30, as STL [mm]."""
    folder.mkdir()
    case = _open_box((120.0, 120.0, 40.0), 10.0, 10.0, (0.0, 0.0, 0.0))
    if peg:
        for y in (0.0, 30.0):
            bore = _round(-30.0, 10.0, 9.0, 3.0)
            bore.apply_translation((0.0, y, 0.0))
            case = case.difference(bore)
        _round(-30.0, 9.8, 30.0, 3.0).export(folder / "peg.stl")
    case.export(folder / "case.stl")
    _box((30.0, 30.0, 10.0), (block[0], block[1], 15.0)).export(folder / "block.stl")


@pytest.mark.slow  # an import (2 s); a block in an open box in no hole: the L pocket's roomy leg (quick)
def test_a_block_resting_in_an_open_case_is_in_no_hole(tmp_path: Path) -> None:
    # The block lies 2 mm off two walls of the case's 100 mm cavity: the import took the
    # cavity for a square hole holding the block (35 mm all round), and the peg fitting it.
    _case(tmp_path / "meshes", peg=True, block=(33.0, 33.0))
    derived = run_import(tmp_path / "meshes", tmp_path / "out", "mm", None).derived
    assert derived.base == "case"
    assert {fit.part for fit in derived.holes.values()} == {"peg", None}  # the peg's hole and the empty one
    assert all(fit.hole.kind == "round" and abs(fit.hole.a - 0.010) < 1e-4 for fit in derived.holes.values())
    assert "block" not in derived.hole_of
    sizes = (tmp_path / "out" / "sizes.lp").read_text()
    assert "part(peg)." in sizes and "block" not in sizes and "hole(h3)" not in sizes


def test_an_empty_open_case_is_no_hole(tmp_path: Path) -> None:
    # Nothing stands in the case's floor: sliced at its middle, its empty cavity was a
    # 100 mm square hole that sizes.lp named with no part to go into it.
    _case(tmp_path / "meshes", peg=False, block=(0.0, 0.0))
    derived = run_import(tmp_path / "meshes", tmp_path / "out", "mm", None).derived
    assert not derived.holes and not derived.pins and not derived.part_holes


def test_a_cube_in_a_tray_on_the_base_is_in_no_hole_of_the_tray(tmp_path: Path) -> None:
    # A 10 mm cube 1 mm off two walls of a tray's 40 mm cavity: the import measured the
    # cavity as a hole of the tray holding it (a traceback, then a refused section).
    folder = tmp_path / "meshes"
    folder.mkdir()
    plate = _box((120.0, 120.0, 10.0), (0.0, 0.0, 5.0)).difference(_round(-30.0, 10.0, 9.0, 3.0))
    plate.export(folder / "plate.stl")
    _round(-30.0, 9.8, 30.0, 3.0).export(folder / "peg.stl")
    _open_box((50.0, 50.0, 20.0), 5.0, 5.0, (25.0, 0.0, 10.0)).export(folder / "tray.stl")
    _box((10.0, 10.0, 10.0), (39.0, 14.0, 20.0)).export(folder / "cube.stl")
    derived = run_import(folder, tmp_path / "out", "mm", None).derived
    assert derived.base == "plate" and not derived.part_holes
    assert {fit.part for fit in derived.holes.values()} == {"peg"}


def test_a_wide_opening_through_the_base_and_a_counterbored_hole_stay_holes(tmp_path: Path) -> None:
    # A d 30 opening through the plate: no floor, so no open box (a part may pass through it
    # to what lies beyond), though 20 mm wider than the peg. A d 20 counterbore 4 mm deep
    # over a d 10 blind hole, sliced in the counterbore at the peg's level: its section over
    # the stretch a part goes in is the d 10 hole's, so it is a spare hole for the peg.
    folder = tmp_path / "meshes"
    folder.mkdir()
    plate = _box((120.0, 120.0, 10.0), (0.0, 0.0, 5.0)).difference(_round(-30.0, 10.0, 9.0, 3.0))
    plate = plate.difference(_round(20.0, 30.0, 12.0, -1.0))
    plate = plate.difference(_round(-30.0, 20.0, 5.0, 6.0).union(_round(-30.0, 10.0, 8.0, 3.0)).apply_translation(
        (0.0, 40.0, 0.0)))
    plate.export(folder / "plate.stl")
    _round(-30.0, 9.8, 30.0, 3.0).export(folder / "peg.stl")
    derived = run_import(folder, tmp_path / "out", "mm", None).derived
    assert sorted((fit.part or "", round(fit.hole.a * 1000)) for fit in derived.holes.values()) == [
        ("", 10), ("", 30), ("peg", 10)]


def test_a_loop_on_one_line_is_a_polygon_of_no_width() -> None:
    # Four points on one line (a cavity's sliver): Qhull found no hull of them (QhullError).
    sliver = Loop(np.array([[0.565, -0.02], [0.565, 0.02], [0.565, -0.0067], [0.565, 0.01]]))
    shape = classify(sliver, hole=True)
    assert shape.kind == "polygon" and shape.b == 0.0 and abs(shape.a - 0.04) < 1e-9
    assert sliver.extent == (shape.a, 0.0)


def test_the_bound_that_skips_a_cavitys_rectangles_never_skips_a_cavity() -> None:
    # roomy bounds the hole's short side and the part's long side without their
    # minimum-area rectangles: wherever the rectangles leave more than CAVITY_ROOM across,
    # the bound says so; a shaft in its bore at zero clearance is skipped.
    rng = np.random.default_rng(3)
    turn = np.linspace(0, 2 * np.pi, 64, endpoint=False)
    for _ in range(300):
        hole = Loop(np.c_[rng.uniform(0.01, 0.12) * np.cos(turn), rng.uniform(0.01, 0.12) * np.sin(turn)]
                    @ np.array([[np.cos(a := rng.uniform(0, np.pi)), -np.sin(a)], [np.sin(a), np.cos(a)]]))
        part = Loop(np.array([[0, 0], [rng.uniform(0.002, 0.05), 0], [0, rng.uniform(0.002, 0.05)]]))
        if hole.extent[1] - part.extent[0] > CAVITY_ROOM:
            assert roomy(hole, part)
    shaft = Loop(np.c_[0.02 * np.cos(turn), 0.02 * np.sin(turn)])
    assert not roomy(Loop(shaft.points * 1.0001), shaft)
    assert roomy(Loop(np.array([[-0.05, -0.05], [0.05, -0.05], [0.05, 0.05], [-0.05, 0.05]])),
                  Loop(np.array([[0, 0], [0.03, 0], [0.03, 0.03], [0, 0.03]])))


def _l_pocket(folder: Path, block: tuple[float, float]) -> None:
    """A plate 120 x 120 x 20 mm as the base with an L-shaped pocket 10 mm deep (a leg 18 mm
    wide, x -50 to -20, y -40 to -22, joining one 50 x 80 mm: its minimum-area rectangle
    80 x 80 mm), a d 9.8 peg in a d 10 hole at (-40, 30) and a 14 x 14 x 10 mm block
    resting on the pocket's floor at ``block`` (x, y) [mm], as STL [mm]."""
    folder.mkdir()
    pocket = trimesh.creation.extrude_polygon(shapely.union(shapely.box(-50.0, -40.0, -20.0, -22.0),
                                                            shapely.box(-20.0, -40.0, 30.0, 40.0)), 11.0)
    plate = _box((120.0, 120.0, 20.0), (0.0, 0.0, 10.0)).difference(pocket.apply_translation((0.0, 0.0, 10.0)))
    plate.difference(_round(-40.0, 10.0, 9.0, 12.0).apply_translation((0.0, 30.0, 0.0))).export(folder / "plate.stl")
    _round(-40.0, 9.8, 30.0, 12.0).apply_translation((0.0, 30.0, 0.0)).export(folder / "peg.stl")
    _box((14.0, 14.0, 10.0), (block[0], block[1], 15.0)).export(folder / "block.stl")


@pytest.mark.slow  # an import (3 s); the narrow leg's room: the quick test of room_at below
def test_a_block_held_in_the_narrow_leg_of_an_l_pocket_is_in_a_hole(tmp_path: Path) -> None:
    # In the 18 mm leg the 14 mm block has 4 mm across: the pocket locates it. Its width was
    # its minimum-area rectangle's short side (80 mm), so the block lay in an open box.
    _l_pocket(tmp_path / "meshes", block=(-40.0, -31.0))
    derived = run_import(tmp_path / "meshes", tmp_path / "out", "mm", None).derived
    assert derived.base == "plate"
    assert {fit.part for fit in derived.holes.values()} == {"peg", "block"}
    assert "block" in derived.hole_of


def test_a_block_in_the_roomy_leg_of_an_l_pocket_is_in_no_hole(tmp_path: Path) -> None:
    # In the 50 mm leg the same block has 36 mm across every way: an open box, however
    # narrow the other leg.
    _l_pocket(tmp_path / "meshes", block=(10.0, 20.0))
    derived = run_import(tmp_path / "meshes", tmp_path / "out", "mm", None).derived
    assert derived.base == "plate"
    assert {fit.part for fit in derived.holes.values()} == {"peg"}
    assert "block" not in derived.hole_of


def test_the_room_in_a_rectangle_is_its_short_side_less_the_part_wherever_the_part_lies() -> None:
    # In a rectangle (turned any way) the room is the short side less the part's widest,
    # as the rule by the rectangle's sides had it, at every place the part may lie; in an L
    # it is the leg's where the part lies, and an empty L is roomy only if every leg is.
    rng = np.random.default_rng(5)
    for _ in range(200):
        a, b, turn = rng.uniform(0.02, 0.1), rng.uniform(0.02, 0.1), rng.uniform(0, np.pi)
        widest = rng.uniform(0.0, min(a, b))
        rotation = np.array([[np.cos(turn), -np.sin(turn)], [np.sin(turn), np.cos(turn)]])
        corners = np.array([[-a, -b], [a, -b], [a, b], [-a, b]]) / 2 @ rotation.T
        at = rng.uniform(-0.5, 0.5, 2) * (np.array([a, b]) - widest) @ rotation.T
        room = min(a, b) - widest
        if abs(room - CAVITY_ROOM) > 1e-6:
            assert room_at(corners, widest, at) == room_at(corners, widest, None) == (room > CAVITY_ROOM)
    leg = np.array(shapely.union(shapely.box(-0.050, -0.040, -0.020, -0.022),
                                 shapely.box(-0.020, -0.040, 0.030, 0.040)).exterior.coords)[:-1]
    assert not room_at(leg, 0.014, np.array([-0.040, -0.031]))
    assert room_at(leg, 0.014, np.array([0.010, 0.020]))
    assert not room_at(leg, 0.014, None) and room_at(leg, 0.011, None)
