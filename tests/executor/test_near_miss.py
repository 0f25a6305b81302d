"""The near misses the simulated cell cannot resolve (executor/world/near_miss.py): a peg
whose collision shape lacks its corners (Bullet's 1 mm hull margin) passes a hole its
section misses by less than that, so such a pair is no experiment."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pybullet as p
import pytest
import shapely
import trimesh

from executor.world import SIZE_RESOLUTION
from executor.world.geometry import Section, margin, outline_polygon
from executor.world.meshes import URDF_HULL_MARGIN
from executor.world.near_miss import (
    collision_section,
    eroded_section,
    erosion,
    mesh_near_miss,
    near_miss,
    pieces_section,
)
from tests.executor import load_piece

SQUARE = (( -0.005, -0.005), (0.005, -0.005), (0.005, 0.005), (-0.005, 0.005))
L_SHAPE = ((-0.01, -0.01), (0.01, -0.01), (0.01, -0.004), (-0.004, -0.004), (-0.004, 0.01), (-0.01, 0.01))


def _verdict(part: Section, hole: Section) -> float | None:
    return near_miss(part, hole, margin(part, hole))


@pytest.mark.parametrize("peg", [Section("box", "square", 0.01),
                                 Section("prism", "polygon", 0.01, width=0.01, outline=SQUARE)])
def test_a_square_peg_that_misses_a_round_hole_by_less_than_its_rounded_corners_is_not_observable(peg: Section) -> None:
    # a right-angled corner rounded by the 1 mm margin leaves out points up to r (1 - sin 45°) = 0.293 mm
    # from the outline; the cell resolves 0.025 mm more
    expected = URDF_HULL_MARGIN * (1 - math.sin(math.pi / 4)) + SIZE_RESOLUTION
    assert erosion(peg) == pytest.approx(expected, abs=2e-6)
    diagonal = 0.01 * math.sqrt(2)  # 14.142 mm
    assert _verdict(peg, Section("close", "round", diagonal - 0.0002)) == pytest.approx(expected, abs=2e-6)
    assert _verdict(peg, Section("far", "round", diagonal - 0.002)) is None  # misses by 1 mm: observed
    assert _verdict(peg, Section("fits", "round", diagonal + 0.0002)) is None  # a fit: the smaller cell peg passes


def test_a_round_peg_lacks_nothing_but_what_the_cell_resolves() -> None:
    peg = Section("round", "round", 0.01)
    assert collision_section(peg) is None and erosion(peg) == SIZE_RESOLUTION
    assert _verdict(peg, Section("close", "round", 0.00997)) == SIZE_RESOLUTION  # 0.015 mm short per side
    assert _verdict(peg, Section("far", "round", 0.0099)) is None  # 0.05 mm short per side


def test_the_eroded_section_of_a_notched_polygon_lies_inside_the_cells_peg() -> None:
    # the L's two convex pieces are each rounded, so the cell's peg also lacks a notch at
    # the reflex corner where they meet: the erosion covers it (more than a corner's 0.293 mm)
    peg = Section("l", "polygon", 0.02, width=0.02, outline=L_SHAPE)
    cell = collision_section(peg)
    assert cell is not None and cell.within(outline_polygon(peg, peg=True).buffer(1e-9))
    depth = erosion(peg)
    assert depth > URDF_HULL_MARGIN * (1 - math.sin(math.pi / 4)) + SIZE_RESOLUTION
    inner = outline_polygon(eroded_section(peg, depth), peg=True)
    assert shapely.difference(inner, cell).area < 1e-12
    assert shapely.difference(outline_polygon(eroded_section(peg, depth / 2), peg=True), cell).area > 1e-10


BOX = trimesh.creation.box((0.01, 0.01, 0.03)).vertices + (0.0, 0.0, 0.015)
"""A 10 x 10 x 30 mm peg's one convex piece [m], in its part frame (its bottom's centre at the origin)."""


def _outline_along(body: int, direction: tuple[float, float], level: float) -> float:
    """How far [m] from the z axis, along ``direction`` at ``level`` [m], PyBullet's collision
    shape of ``body`` reaches: where a probe sphere of 0.1 mm first touches it (bisected to 0.1 µm)."""
    probe_radius = 1e-4
    probe = p.createMultiBody(0, p.createCollisionShape(p.GEOM_SPHERE, radius=probe_radius))
    unit = np.array(direction) / np.linalg.norm(direction)
    low, high = 0.0, 0.02
    while high - low > 1e-7:
        mid = (low + high) / 2
        p.resetBasePositionAndOrientation(probe, (*(unit * (mid + probe_radius)), level), (0, 0, 0, 1))
        touching = p.getClosestPoints(body, probe, 0.0)
        low, high = (mid, high) if touching and min(contact[8] for contact in touching) <= 0 else (low, mid)
    return (low + high) / 2


def test_a_mesh_pegs_pieces_lack_their_edges_in_pybullet_as_the_rule_takes_them(tmp_path: Path) -> None:
    # The piece as the cell writes a mesh part's collision asset (eroded by the hull margin)
    # and loads it (a URDF link), probed at mid-height: its faces where the CAD has them,
    # its vertical edges r (sqrt 2 - 1) = 0.414 mm inside the CAD's corners along the
    # diagonal; what the rule takes it to cover reaches as far, never farther.
    client = p.connect(p.DIRECT)
    try:
        peg = load_piece(tmp_path, BOX, "peg", 0.05)
        face, corner = _outline_along(peg, (1, 0), 0.015), _outline_along(peg, (1, 1), 0.015)
    finally:
        p.disconnect(client)
    assert face == pytest.approx(0.005, abs=2e-6)
    assert 0.005 * math.sqrt(2) - corner == pytest.approx(URDF_HULL_MARGIN * (math.sqrt(2) - 1), abs=2e-6)
    covered = pieces_section([BOX], 0.0, 0.03)
    reach = max(float(np.dot(point, (1, 1))) / math.sqrt(2) for point in shapely.get_coordinates(covered))
    assert corner - 2e-6 <= reach <= corner + 1e-7  # the arcs' chords lie inside them


def test_a_mesh_peg_that_misses_a_round_hole_by_less_than_its_rounded_edges_is_not_observable() -> None:
    peg, diagonal = Section("mesh", "square", 0.01), 0.01 * math.sqrt(2)  # 14.142 mm
    close = Section("close", "round", diagonal - 0.0002)
    depth = mesh_near_miss(peg, [BOX], 0.02, close, margin(peg, close))
    assert depth == pytest.approx(URDF_HULL_MARGIN * (1 - math.sin(math.pi / 4)) + SIZE_RESOLUTION, abs=2e-6)
    for hole in (Section("far", "round", diagonal - 0.002), Section("fits", "round", diagonal + 0.0002)):
        assert mesh_near_miss(peg, [BOX], 0.02, hole, margin(peg, hole)) is None  # observed: a no-fit, a fit


CROSS = ((0.0008, 0.0008), (0.0024, 0.0008), (0.0024, -0.0008), (0.0008, -0.0008), (0.0008, -0.0024),
         (-0.0008, -0.0024), (-0.0008, -0.0008), (-0.0024, -0.0008), (-0.0024, 0.0008), (-0.0008, 0.0008),
         (-0.0008, 0.0024), (0.0008, 0.0024))
"""A Technic axle's cross [m]: arms 1.6 mm wide, 4.8 mm across, thinner than the hull margin twice."""


def test_a_peg_of_pieces_thinner_than_the_margin_twice_lacks_all_of_it_and_its_no_fits_are_near_misses() -> None:
    # ldraw_axles turned 90 deg about z set its axle against a hole it misses: the empty
    # collision section had no exterior, and the import stopped on a traceback
    peg = Section("axle", "polygon", 0.0048, width=0.0048, outline=CROSS)
    cell = collision_section(peg)
    assert cell is not None and cell.is_empty
    deepest = math.hypot(0.0008, 0.0008)  # the centre, from the cross's inner corners
    assert erosion(peg) == pytest.approx(deepest + SIZE_RESOLUTION, abs=1e-6)
    assert near_miss(peg, Section("small", "round", 0.004), -0.0004) == pytest.approx(erosion(peg))
    assert near_miss(peg, Section("wide", "round", 0.006), 0.0006) is None  # a fit
