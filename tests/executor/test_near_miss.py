"""The near misses the simulated cell cannot resolve (executor/world/near_miss.py): a peg
whose collision shape lacks its corners (Bullet's 1 mm hull margin) passes a hole its
section misses by less than that, so such a pair is no experiment."""

from __future__ import annotations

import math

import pytest
import shapely

from executor.world import SIZE_RESOLUTION
from executor.world.geometry import Section, margin, outline_polygon
from executor.world.meshes import URDF_HULL_MARGIN
from executor.world.near_miss import collision_section, eroded_section, erosion, near_miss

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
