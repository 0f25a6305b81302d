"""Cross-sections of real CAD: rects with rounded or chamfered corners are rects with
conservative sizes, splined, keyed and D-shaped outlines are polygons, never round."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
import trimesh
from shapely import affinity
from trimesh.path.traversal import discretize_path

from executor.cad import sections
from executor.cad.sections import Loop, classify

MM = 1e-3


def rounded_rect(a: float, b: float, radius: float, yaw: float = 0.0, quad_segs: int = 8) -> shapely.Polygon:
    """A centred a x b [m] rect with corner ``radius`` [m] (``quad_segs`` segments a quarter), turned by ``yaw`` [°]."""
    core = shapely.box(-a / 2 + radius, -b / 2 + radius, a / 2 - radius, b / 2 - radius)
    return affinity.rotate(core.buffer(radius, quad_segs=quad_segs), yaw, origin=(0, 0))


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
    with the largest corner radius whose rounded rect still holds the loop; the
    classification before fell back to 'other' below 99.5 %."""
    peg = classify(loop_of(rounded_rect(10 * MM, 6 * MM, 1 * MM, yaw=20)), hole=False)
    assert peg.kind == "rect"
    assert (peg.a, peg.b) == pytest.approx((10 * MM, 6 * MM), abs=1e-9)
    assert peg.yaw == pytest.approx(20, abs=1e-6)
    assert peg.corner == pytest.approx(1 * MM, rel=1e-3)


def test_a_rounded_rect_hole_is_its_rect_with_a_corner_radius_inside_it() -> None:
    """The hole's rect is its full 10 x 6 mm with the least corner radius whose rounded
    rect lies inside the loop: about its 1 mm (the loop's chords lie inside the arcs, so a
    little more), never less."""
    outline = rounded_rect(10 * MM, 6 * MM, 1 * MM)
    hole = classify(loop_of(outline, (0, 0)), hole=True)
    assert hole.kind == "rect" and (hole.a, hole.b) == pytest.approx((10 * MM, 6 * MM), abs=1e-9)
    assert 1 * MM <= hole.corner <= 1.06 * MM
    assert outline.buffer(1e-9).covers(rounded_rect(10 * MM, 6 * MM, hole.corner, quad_segs=16))
    assert not outline.covers(rounded_rect(10 * MM, 6 * MM, 0.9 * MM, quad_segs=16))


def test_a_notched_rect_hole_is_the_sharp_rect_inset_inside_it() -> None:
    """A small bump into a rect hole leaves a rect; no rounded rect fits its loop, so the
    sharp rect is inset evenly until it does: a fit stays what the hole passes."""
    outline = shapely.box(-5 * MM, -3 * MM, 5 * MM, 3 * MM).difference(shapely.box(-1 * MM, 2.7 * MM, 1 * MM, 3 * MM))
    hole = classify(loop_of(outline, (0, 0)), hole=True)
    assert (hole.kind, hole.corner) == ("rect", 0.0)
    assert (hole.a, hole.b) == pytest.approx((9.4 * MM, 5.4 * MM), abs=2e-7)


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
    hole = classify(loop_of(circle), hole=True)
    assert hole.a == pytest.approx(10 * MM * math.cos(math.pi / 24), rel=1e-9)
    assert hole.deflection == pytest.approx(5 * MM * (1 - math.cos(math.pi / 24)), rel=1e-6)


def test_a_fine_section_takes_its_closed_entities_as_the_graph_would() -> None:
    """A fine ring in metres: its section's open entities are lines from a vertex to itself,
    and its loops, taken without the graph, are the graph's point for point."""
    ring = trimesh.creation.annulus(r_min=0.005, r_max=0.01, height=0.004, sections=3000)
    ring.apply_transform(trimesh.transformations.rotation_matrix(0.3, (1, 1, 0)))
    fast, graph = (ring.section(plane_origin=(0, 0, 3e-4), plane_normal=(0, 0, 1)) for _ in range(2))
    assert fast is not None and graph is not None
    assert any(len(entity.points) == 2 for entity in fast.entities)
    assert sections._only_closed(fast.entities) is not None
    loops = sections._closed_polylines(fast)
    expected = [discretize_path(graph.entities, graph.vertices, path) for path in sections._closed_paths(graph)]
    assert len(loops) == len(expected) == 2
    assert all(np.array_equal(a, b) for a, b in zip(loops, expected, strict=True))


def test_a_slice_in_metres_keeps_a_corner_4_um_from_its_neighbour() -> None:
    # trimesh's section joins points on a grid of 1e-5 of the mesh's units: in metres, 10 µm.
    # asap_beam's foot has a mortise corner 4 µm from the next point of its slice; joined,
    # the corner was cut off and the 6.286 mm mortise measured 6.280 mm.
    outline = shapely.Polygon([(0.0, 0.0), (0.006, 0.0), (0.006, 0.006 - 4e-6), (0.006, 0.006), (0.006 - 4e-6, 0.006),
                               (0.0, 0.006)])
    prism = trimesh.creation.extrude_polygon(outline, 0.01)
    loops = sections.slice_loops(prism, np.array([0.0, 0.0, 1.0]), 0.005)
    assert len(loops) == 1 and loops[0].area == pytest.approx(0.006 ** 2, rel=1e-9)
    assert classify(loops[0], hole=True).a == pytest.approx(0.006, abs=1e-9)
