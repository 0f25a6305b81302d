"""Cross-sections of real CAD: rects with rounded or chamfered corners are rects with
conservative sizes, splined, keyed and D-shaped outlines are polygons, never round."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from shapely import affinity

from assembly_constraints.executor.cad.sections import Loop, classify

MM = 1e-3


def rounded_rect(a: float, b: float, radius: float, yaw: float = 0.0) -> shapely.Polygon:
    """A centred a x b [m] rect with corner ``radius`` [m] (8 segments a quarter), turned by ``yaw`` [°]."""
    core = shapely.box(-a / 2 + radius, -b / 2 + radius, a / 2 - radius, b / 2 - radius)
    return affinity.rotate(core.buffer(radius, quad_segs=8), yaw, origin=(0, 0))


def loop_of(polygon: shapely.Polygon, at: tuple[float, float] = (0.1, -0.05)) -> Loop:
    return Loop(np.asarray(polygon.exterior.coords)[:-1] + at)


def splined(outer: float, root: float, teeth: int, tooth_angle: float, points: int = 8) -> shapely.Polygon:
    """A splined outline [m]: ``teeth`` teeth at radius ``outer`` each ``tooth_angle`` [rad]
    wide, the root at radius ``root`` between them; arcs sampled by ``points`` points."""
    ring = []
    pitch = 2 * math.pi / teeth
    for k in range(teeth):
        start = k * pitch - tooth_angle / 2
        ring += [(outer * math.cos(t), outer * math.sin(t)) for t in np.linspace(start, start + tooth_angle, points)]
        gap = np.linspace(start + tooth_angle, start + pitch, points)[1:-1]
        ring += [(root * math.cos(t), root * math.sin(t)) for t in gap]
    return shapely.Polygon(ring)


def test_a_rounded_rect_peg_is_a_rect_of_its_full_size() -> None:
    """Corner radius 1 mm on 10 x 6 mm fills 98.6 % of its rectangle: a rect 10 x 6 mm
    (the peg's circumscribed rectangle, which holds it) with its radius recorded; the
    classification before fell back to 'other' below 99.5 %."""
    peg = classify(loop_of(rounded_rect(10 * MM, 6 * MM, 1 * MM, yaw=20)), hole=False)
    assert peg.kind == "rect"
    assert (peg.a, peg.b) == pytest.approx((10 * MM, 6 * MM), abs=1e-9)
    assert peg.yaw == pytest.approx(20, abs=1e-6)
    assert peg.corner == pytest.approx(1 * MM, rel=0.02)  # the 8-segment arcs lack a little less area


def test_a_rounded_rect_hole_is_the_rect_inside_it() -> None:
    """The hole's rect is inset until it lies inside the rounded corners: 1 mm radius costs
    1 - 1/√2 mm a side; that rect fits, a wider one does not."""
    outline = rounded_rect(10 * MM, 6 * MM, 1 * MM)
    hole = classify(loop_of(outline, (0, 0)), hole=True)
    inset = 1 * MM * (1 - 1 / math.sqrt(2))
    assert hole.kind == "rect"
    assert (hole.a, hole.b) == pytest.approx((10 * MM - 2 * inset, 6 * MM - 2 * inset), abs=2e-7)
    assert outline.buffer(1e-9).covers(shapely.box(-hole.a / 2, -hole.b / 2, hole.a / 2, hole.b / 2))
    assert not outline.covers(shapely.box(-hole.a / 2 - 1e-6, -hole.b / 2 - 1e-6, hole.a / 2 + 1e-6, hole.b / 2 + 1e-6))


def test_a_chamfered_square_is_a_square() -> None:
    chamfered = shapely.box(-5 * MM, -5 * MM, 5 * MM, 5 * MM).buffer(-0.5 * MM, join_style="mitre").buffer(
        0.5 * MM, join_style="bevel")
    peg = classify(loop_of(chamfered), hole=False)
    assert peg.kind == "square" and peg.a == pytest.approx(10 * MM, abs=1e-9)


@pytest.mark.parametrize("name, outline", [
    ("corners too round", rounded_rect(10 * MM, 6 * MM, 2.5 * MM)),
    ("a rect with a deep notch", shapely.box(0, 0, 10 * MM, 6 * MM).difference(shapely.box(4 * MM, 4.5 * MM, 6 * MM,
                                                                                             6 * MM))),
    ("splined", splined(5 * MM, 4 * MM, 6, 0.5)),
    ("D-shaft", shapely.Point(0, 0).buffer(5 * MM, quad_segs=16).intersection(shapely.box(-6 * MM, -6 * MM, 4 * MM,
                                                                                          6 * MM))),
    ("keyed shaft", shapely.Point(0, 0).buffer(5 * MM, quad_segs=16).union(shapely.box(4 * MM, -1 * MM, 6 * MM,
                                                                                      1 * MM))),
])
def test_outlines_that_are_no_round_square_or_rect_are_polygons(name: str, outline: shapely.Polygon) -> None:
    for hole in (False, True):
        shape = classify(loop_of(outline), hole=hole)
        assert shape.kind == "polygon", name
        assert shapely.Polygon(shape.outline).area == pytest.approx(outline.area, rel=1e-9)


def test_a_tessellated_cylinder_stays_round() -> None:
    circle = shapely.Point(0, 0).buffer(5 * MM, quad_segs=6)  # a 24-gon
    assert classify(loop_of(circle), hole=False).kind == "round"
    assert classify(loop_of(circle), hole=True).a == pytest.approx(10 * MM * math.cos(math.pi / 24), rel=1e-9)
