"""Cross-sections of real CAD: rects with rounded or chamfered corners are rects with
conservative sizes, splined, keyed and D-shaped outlines are polygons, never round."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
import trimesh
from shapely import affinity
from trimesh.path.exchange.misc import lines_to_path
from trimesh.path.traversal import discretize_path

from executor.cad import sections
from executor.cad.derive import derive
from executor.cad.operations.rooms import margins
from executor.cad.parts import CadPart
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


def test_a_rounded_square_hole_with_a_tilted_side_keeps_its_corner_radius() -> None:
    """gridfinity_bases' pocket 20 µm below its entry: a 41.96 mm square with corner
    radius 3.98 mm whose tessellation runs one side from a corner's tangent point to the
    next arc's first vertex 0.2 µm in, so no full-size rounded square lies inside it. The
    hole is the rounded square inset by that fraction of a µm, not a sharp square shrunk
    until it fits (39.63 mm), and it lies inside the loop."""
    side, radius = 41.96 * MM, 3.98 * MM
    ring = np.asarray(rounded_rect(side, side, radius, quad_segs=64).exterior.coords)[:-1]
    tangent = np.flatnonzero(np.isclose(ring[:, 1], -side / 2, atol=1e-12) & (ring[:, 0] > 0))
    assert len(tangent) == 1  # the bottom side's end at the right corner's arc
    step = np.array([[math.cos(0.01), -math.sin(0.01)], [math.sin(0.01), math.cos(0.01)]])
    first = np.array([side / 2 - radius, -side / 2 + radius]) + (ring[tangent[0]] - [side / 2 - radius,
                                                                                      -side / 2 + radius]) @ step.T
    points = np.insert(np.delete(ring, tangent[0], axis=0), tangent[0], first, axis=0)
    outline = shapely.Polygon(points)
    assert outline.is_valid and 0.1e-6 < side / 2 + first[1] < 0.3e-6  # the arc's first vertex 0.2 µm in
    hole = classify(Loop(points), hole=True)
    assert hole.kind == "square"
    assert side - 2 * (0.3e-6 + sections.OUTLINE_TOUCH) <= hole.a <= side  # inset by the tilt and the allowance
    assert hole.corner == pytest.approx(radius, abs=0.05 * MM)
    assert outline.buffer(1e-9).covers(affinity.rotate(rounded_rect(hole.a, hole.b, hole.corner, quad_segs=64),
                                                       hole.yaw, origin=(0, 0)))



def _arcs(a: float, b: float, radius: float, per_quarter: int) -> np.ndarray:
    """A centred a x b [m] rect with corner ``radius`` [m] whose arcs are ``per_quarter``
    chords with their vertices on the arc (as OpenSCAD and CAD kernels tessellate)."""
    points = []
    for k, (sx, sy) in enumerate(((1, 1), (-1, 1), (-1, -1), (1, -1))):
        centre = np.array([sx * (a / 2 - radius), sy * (b / 2 - radius)])
        angles = k * math.pi / 2 + np.linspace(0, math.pi / 2, per_quarter + 1)
        points += list(centre + radius * np.stack([np.cos(angles), np.sin(angles)], axis=1))
    return np.array(points)


@pytest.mark.parametrize("hole_of", ["mitred", "arcs", "one sharp corner"])
def test_the_room_of_a_rounded_rect_in_a_rounded_rect_is_that_of_their_outlines(hole_of: str) -> None:
    """A 20 x 12 mm peg with 2 mm corners tessellated coarsely (4 chords a quarter), in a
    hole 0.2 mm larger all round: each edge of the peg's moved out by 0.2 mm (mitred:
    the room is 0.2 mm exactly), or 20.4 x 12.4 mm with 2.2 mm corners tessellated alike
    (the room is the outlines' distance, 0.2 cos(π/16) mm, measured with shapely), or the
    mitred one with one corner sharp (no symmetry: the best shift is found). Read as
    rounded rects each corner is conservative (the peg's arc holds its chords, the hole's
    lies inside its own) and the errors add up (a room of 0.109 or 0.100 mm); the room is the
    outlines' at the aligning turn, both turned 30° and apart, and the peg placed where
    it is found is inside the hole with that room."""
    peg = shapely.Polygon(_arcs(20 * MM, 12 * MM, 2 * MM, 4))
    hole = shapely.Polygon(_arcs(20.4 * MM, 12.4 * MM, 2.2 * MM, 4)) if hole_of == "arcs" else \
        peg.buffer(0.2 * MM, join_style="mitre")
    if hole_of == "one sharp corner":  # no symmetry: its centroid moves off the best shift
        hole = shapely.union(hole, shapely.box(7 * MM, 3 * MM, 10.2 * MM, 6.2 * MM))
        centred = affinity.translate(peg, *np.asarray(hole.centroid.coords[0]))
        assert shapely.distance(hole.exterior, centred) < 0.199 * MM
    truth = shapely.distance(hole.exterior, peg)
    # the arcs': a peg's vertex faces a hole's, whose chords are 0.2 mm out at their normal, π/16 away
    assert truth == pytest.approx(0.2 * MM * (math.cos(math.pi / 16) if hole_of == "arcs" else 1.0), abs=1e-12)
    turned_peg, turned_hole = (affinity.rotate(shape, 30, origin=(0, 0)) for shape in (peg, hole))
    peg_section = classify(loop_of(turned_peg, (0.1, 0.02)), hole=False)
    hole_section = classify(loop_of(turned_hole, (-0.3, 0.05)), hole=True)
    assert (peg_section.kind, hole_section.kind) == ("rect", "rect")
    found = sections.section_room(peg_section, hole_section)
    assert truth - 1e-7 <= found.room <= truth + 1e-12  # the best shift to 0.1 µm, never more room than the truth
    placed = affinity.translate(affinity.rotate(shapely.Polygon(peg_section.outline), found.yaw, origin=(0, 0)),
                                *found.offset)
    assert shapely.Polygon(hole_section.outline).contains(placed.buffer(found.room - 1e-9))
    assert sections.passes(peg_section, hole_section)

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


@pytest.mark.parametrize("sides, other, kind", [
    (24, "polygon", "polygon"),  # flynn_clutch's outer plates' 24-gon bore against the 12-spline shaft
    (24, "round", "round"),
    (46, "polygon", "round"),  # asm4_disk_arm's fine d 20 tessellations, a nominal fit in its slot
    (64, "square", "round"),
])
def test_a_coarse_round_section_is_its_polygon_against_a_section_that_is_no_round(sides: int, other: str,
                                                                                   kind: str) -> None:
    """A tessellated round section deviating more than FACETED of its radius from its
    circle is read as the polygon it is against a non-round section (its room there
    depends on its vertices), and stays round against a round one or when finer."""
    turns = 2 * math.pi * np.arange(sides) / sides
    circle = shapely.Polygon(np.stack([20.5 * MM * np.cos(turns), 20.5 * MM * np.sin(turns)], axis=1))
    counterpart = {"polygon": splined(20 * MM, 17 * MM, 12, 0.26), "round": shapely.Point(0, 0).buffer(19 * MM, 32),
                   "square": shapely.box(-10 * MM, -10 * MM, 10 * MM, 10 * MM)}[other]
    for hole in (True, False):
        shape = classify(loop_of(circle), hole=hole)
        assert shape.kind == "round"
        against = classify(loop_of(counterpart), hole=not hole)
        assert against.kind == other
        found = sections.faceted(shape, loop_of(circle), against, hole=hole)
        assert found.kind == kind
        if kind == "polygon":
            assert shapely.Polygon(found.outline).equals_exact(circle, 1e-12)


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


def _plate_with_bores() -> trimesh.Trimesh:
    """A 40 x 30 x 10 mm plate [m] with a round bore and a turned square one, and a boss on
    top, tilted (its corners at levels of their own)."""
    plate = trimesh.creation.box((0.04, 0.03, 0.01))
    bore = trimesh.creation.cylinder(radius=0.004, height=0.02, sections=40)
    bore.apply_translation((-0.01, 0, 0))
    square = trimesh.creation.box((0.006, 0.006, 0.02))
    square.apply_transform(trimesh.transformations.rotation_matrix(0.4, (0, 0, 1)))
    square.apply_translation((0.01, 0, 0))
    boss = trimesh.creation.cylinder(radius=0.003, height=0.006, sections=24)
    boss.apply_translation((0.0, 0.01, 0.007))
    mesh = trimesh.boolean.union([trimesh.boolean.difference([plate, bore, square], engine="manifold"), boss],
                                 engine="manifold")
    mesh.apply_transform(trimesh.transformations.rotation_matrix(0.2, (1, 0.3, 0)))
    return mesh


def _touching_cubes() -> trimesh.Trimesh:
    """Two 10 mm cubes [m] meeting along a vertical edge: their slices' squares share a corner."""
    cubes = [trimesh.creation.box((0.01, 0.01, 0.01)) for _ in range(2)]
    cubes[1].apply_translation((0.01, 0.01, 0.0))
    return trimesh.util.concatenate(cubes)


def _sliced(mesh: trimesh.Trimesh, level: float, axis: tuple[float, float, float] = (0, 0, 1)) -> np.ndarray:
    """The segments [µm] of ``mesh``'s slice at ``level`` [m] across ``axis``, as
    :func:`sections.slice_loops` joins them."""
    normal = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    return trimesh.intersections.mesh_plane(mesh, plane_normal=normal, plane_origin=normal * level) * 1e6


@pytest.mark.parametrize("case, level, loops, simple", [
    ("the plate's outline and its two bores", 0.0, 3, True),
    ("through a corner of the plate", 2, 1, True),
    ("through the round bore's lowest corner, which the outline meets", 16, 2, False),
    ("through a corner of the round bore", 17, 2, True),
    ("through a corner, three loops", 46, 3, True),
    ("two squares that touch", 0.0, 2, False),
])
def test_slice_loops_are_joined_as_trimesh_joins_them(case: str, level: float, loops: int, simple: bool) -> None:
    """The segments of a slice are joined into the same lines, from the same point, the
    same way round and in the same order as trimesh's ``lines_to_path`` joins them, by one
    search where the loops are simple cycles, else by trimesh's (slices through a vertex,
    several loops, loops that touch). An int ``level`` is the rank of a vertex's level."""
    mesh = _touching_cubes() if case == "two squares that touch" else _plate_with_bores()
    if isinstance(level, int):
        level = float(np.sort(mesh.vertices[:, 2])[level])
    lines = _sliced(mesh, level)
    (entities, vertices), theirs = sections._lines_to_path(lines), lines_to_path(lines)
    assert np.array_equal(vertices, theirs["vertices"]), case
    assert [list(e.points) for e in entities] == [list(e.points) for e in theirs["entities"]], case
    edges = trimesh.grouping.unique_rows(lines.reshape(-1, 3), digits=5)[1].reshape(-1, 2)
    assert (sections._cycles(edges) is not None) == simple, case
    assert len(sections.slice_loops(mesh, np.array([0.0, 0.0, 1.0]), level)) == loops, case


def test_a_tilted_fine_slice_is_joined_as_trimesh_joins_it() -> None:
    """A fine ring cut aslant, through none of its vertices: two loops of thousands of points, joined alike."""
    ring = trimesh.creation.annulus(r_min=0.005, r_max=0.01, height=0.004, sections=3000)
    lines = _sliced(ring, 1e-4, (0.1, 0.2, 1.0))
    assert sections._cycles(trimesh.grouping.unique_rows(lines.reshape(-1, 3), digits=5)[1].reshape(-1, 2)) is not None
    (entities, vertices), theirs = sections._lines_to_path(lines), lines_to_path(lines)
    assert [list(e.points) for e in entities] == [list(e.points) for e in theirs["entities"]]
    assert len(entities) == 2 and np.array_equal(vertices, theirs["vertices"])


def _revolved(profile: list[tuple[float, float]], sections: int = 48) -> trimesh.Trimesh:
    """The solid of ``profile`` ((radius, z) [m], from the axis out and back) turned about z."""
    return trimesh.creation.revolve(np.array(profile), sections=sections)


def _narrowed(radius: float, narrow: float, levels: tuple[float, float, float], top: float) -> trimesh.Trimesh:
    """A bore of ``radius`` [m] from below 0 to above ``top`` [m] that narrows from the
    first of ``levels`` [m] to ``narrow`` at the second and widens again by the third."""
    low, throat, high = levels
    return _revolved([(0.0, -MM), (radius, -MM), (radius, low), (narrow, throat), (radius, high),
                      (radius, top + MM), (0.0, top + MM)])



@pytest.mark.slow  # the derivation: 4 to 7 s under load
@pytest.mark.parametrize(("narrow", "fits"), [(4.975 * MM, False), (5.1 * MM, True)])
def test_a_hole_narrowed_between_the_levels_sliced_is_measured_at_its_throat(narrow: float, fits: bool) -> None:
    # A 100 x 50 x 20 mm plate with two d 10.4 mm bores (48 corners on their circles), the
    # second narrowing from 12 mm up to a throat at 17 mm and widening again by 18 mm; a
    # d 10 mm peg stands through the first on the floor, a d 9.8 mm one through the second.
    # The plate is sliced in the middle of the pegs' depth in it (10 mm, d 10.4): a throat
    # of d 9.95 leaves the d 10 peg 0.05 mm too wide, one of d 10.2 leaves it room.
    box = trimesh.creation.box((0.1, 0.05, 0.02), trimesh.transformations.translation_matrix((0.02, 0, 0.01)))
    straight = _narrowed(5.2 * MM, 5.2 * MM, (12 * MM, 17 * MM, 18 * MM), 20 * MM)
    narrowed = _narrowed(5.2 * MM, narrow, (12 * MM, 17 * MM, 18 * MM), 20 * MM)
    narrowed.apply_translation((0.04, 0, 0))
    plate = trimesh.boolean.difference([box, straight, narrowed], engine="manifold")
    wide = _revolved([(0.0, 0.0), (5 * MM, 0.0), (5 * MM, 40 * MM), (0.0, 40 * MM)], sections=64)
    thin = _revolved([(0.0, 0.0), (4.9 * MM, 0.0), (4.9 * MM, 40 * MM), (0.0, 40 * MM)], sections=64)
    thin.apply_translation((0.04, 0, 0))
    derived = derive([CadPart("plate", "plate", plate, "plate.stl"), CadPart("wide", "wide", wide, "wide.stl"),
                      CadPart("thin", "thin", thin, "thin.stl")], "plate", {})
    hid = next(hid for hid, fit in derived.holes.items() if fit.part == "thin")
    assert derived.holes[hid].hole.a == pytest.approx(2 * narrow * math.cos(math.pi / 48), abs=1e-8)  # the throat's
    assert (margins(derived)["wide"][hid] > 0) == fits


@pytest.mark.slow  # the derivation: 4 to 7 s under load
@pytest.mark.parametrize(("narrow", "fits"), [(4.975 * MM, False), (5.1 * MM, True)])
def test_a_bore_narrowed_at_a_level_no_slice_is_taken_at_is_measured_at_its_throat(narrow: float, fits: bool) -> None:
    # A plate with a d 10 mm pin and a d 9.8 mm one 40 mm apart, standing 20 mm on it; on
    # each a nut 8 mm high with a d 10.4 mm bore, the second's narrowing from 5 mm up to a
    # throat at 6 mm (a vertex level, where no span's middle is, nor the nut's middle)
    # and widening again by 7 mm: a throat of d 9.95 does not pass the d 10 pin, one of
    # d 10.2 does.
    box = trimesh.creation.box((0.1, 0.05, 0.02), trimesh.transformations.translation_matrix((0.02, 0, 0.01)))
    pins = [_revolved([(0.0, 19 * MM), (radius, 19 * MM), (radius, 40 * MM), (0.0, 40 * MM)], sections=64)
            for radius in (5 * MM, 4.9 * MM)]
    pins[1].apply_translation((0.04, 0, 0))
    plate = trimesh.boolean.union([box, *pins], engine="manifold")
    nuts = [_revolved([(5.2 * MM, 20 * MM), (10 * MM, 20 * MM), (10 * MM, 28 * MM), (5.2 * MM, 28 * MM),
                       (5.2 * MM, 27 * MM), (throat, 26 * MM), (5.2 * MM, 25 * MM), (5.2 * MM, 20 * MM)])
            for throat in (5.2 * MM, narrow)]
    nuts[1].apply_translation((0.04, 0, 0))
    derived = derive([CadPart("plate", "plate", plate, "plate.stl"), CadPart("plain", "plain", nuts[0], "plain.stl"),
                      CadPart("narrowed", "narrowed", nuts[1], "narrowed.stl")], "plate", {})
    wide = next(pid for pid, pin in derived.pins.items() if pin.parts == ("plain",))
    assert derived.bores["narrowed"].a == pytest.approx(2 * narrow * math.cos(math.pi / 48), abs=1e-8)  # the throat's
    assert (margins(derived)["narrowed"][wide] > 0) == fits


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


def _frustum(low: float, high: float, bottom: float, top: float) -> trimesh.Trimesh:
    """A square frustum about z from ``low`` (side ``bottom``) to ``high`` (side ``top``) [m]."""
    corners = [(x * side / 2, y * side / 2, z) for z, side in ((low, bottom), (high, top))
               for x, y in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    return trimesh.convex.convex_hull(np.array(corners))


def _tapered_pair(narrower: float) -> tuple[trimesh.Trimesh, trimesh.Trimesh]:
    """A 30 x 30 x 10 mm plate with a square mortise tapered 0.05 mm per mm per side (5 mm
    at its foot, 6 mm at its mouth, less ``narrower`` [m]), and a tenon of that taper
    (5 to 6 mm, 0.1 mm a side short of its tip's chamfer-free foot) under a 12 mm square
    shoulder resting on the plate."""
    plate = trimesh.creation.box((0.03, 0.03, 0.01), trimesh.transformations.translation_matrix((0, 0, 0.005)))
    cut = _frustum(-MM, 11 * MM, 4.9 * MM - narrower, 6.1 * MM - narrower)
    tenon = trimesh.boolean.union([_frustum(0.0, 10 * MM, 5 * MM, 6 * MM), trimesh.creation.box(
        (0.012, 0.012, 0.01), trimesh.transformations.translation_matrix((0, 0, 0.015)))], engine="manifold")
    return trimesh.boolean.difference([plate, cut], engine="manifold"), tenon


@pytest.mark.parametrize(("narrower", "fits"), [(0.0, True), (0.01 * MM, False)])
def test_a_taper_passes_its_own_taper_and_not_a_narrower_one(narrower: float, fits: bool) -> None:
    # Over the whole stretch the tenon's widest section (6 mm, under the shoulder) meets the
    # mortise's narrowest (5 mm, at its foot): no fit, though the tenon's narrow tip meets
    # the mortise's wide mouth all the way in. The sweep compares each level of the tenon
    # with the levels of the mortise it crosses: room 0 in its own taper (a nominal
    # zero-clearance fit), and 0.01 mm short all round in a taper 0.01 mm narrower.
    plate, tenon = _tapered_pair(narrower)
    up = np.array([0.0, 0.0, 1.0])
    loop = next(o for o in sections.slice_loops(plate, up, 5 * MM) if o.area < 1e-4)
    spanned = classify(sections.over_span(loop, plate, up, 0.0, 10 * MM, hole=True), hole=True)
    peg = classify(sections.over_span(sections.slice_loops(tenon, up, 5 * MM)[0], tenon, up, 0.0, 10 * MM,
                                      hole=False, reach=0.006), hole=False)
    assert not sections.passes(peg, spanned)  # the sections over the stretch: no fit, either way
    way = sections.passage(sections.Slicer(tenon, up), sections.Slicer(plate, up), np.zeros(2), 0.0, 10 * MM)
    assert way is not None
    # diametral, twice the least distance of a corner to the walls: outside, a corner lies 0.005 mm out of
    # each of two walls, 0.007 mm from their corner
    assert way.room == pytest.approx(-math.sqrt(2) * narrower, abs=2e-8)
    shapes = classify(way.peg, hole=False), classify(way.hole, hole=True)
    assert (way.room > 0 or sections.zero_clearance(*shapes, way.room) is not None) == fits


def test_a_tenon_swept_into_its_own_taper_fits_alike_tapers_and_not_a_straight_hole_of_its_middle() -> None:
    # The tenon of _tapered_pair in its mortise, beside an empty mortise of the same taper
    # and an empty straight 5.5 mm square hole (the tenon's section half way in). Over the
    # stretch the tenon (6 mm under its shoulder) passes none; swept, it passes both tapers
    # at room 0 and not the straight hole, whose mouth its upper half does not pass.
    plate = trimesh.creation.box((0.07, 0.03, 0.01), trimesh.transformations.translation_matrix((0, 0, 0.005)))
    cuts = [_frustum(-MM, 11 * MM, 4.9 * MM, 6.1 * MM), _frustum(-MM, 11 * MM, 4.9 * MM, 6.1 * MM),
            trimesh.creation.box((0.0055, 0.0055, 0.012), trimesh.transformations.translation_matrix((0, 0, 0.005)))]
    for cut, x in zip(cuts, (0.0, 0.02, -0.02), strict=True):
        cut.apply_translation((x, 0.0, 0.0))
    plate = trimesh.boolean.difference([plate, *cuts], engine="manifold")
    tenon = _tapered_pair(0.0)[1]
    derived = derive([CadPart("plate", "plate", plate, "plate.stl"), CadPart("tenon", "tenon", tenon, "tenon.stl")],
                     "plate", {})
    at = {round(fit.position[0], 3): hid for hid, fit in derived.holes.items()}
    own, alike, straight = at[0.0], at[0.02], at[-0.02]
    assert derived.holes[own].part == "tenon"
    assert set(derived.swept) == {("tenon", own), ("tenon", alike)}
    assert derived.swept[("tenon", own)][2] == pytest.approx(0.0, abs=2e-8)
    rooms = margins(derived)["tenon"]
    assert rooms[own] == rooms[alike] == 0.0 and rooms[straight] < -0.0004


def _stacked(profile: list[tuple[float, float]]) -> trimesh.Trimesh:
    """A square solid about z whose side [m] at each level [m] of ``profile`` ((z, side),
    upwards) runs straight to the next: frustums stacked."""
    return trimesh.boolean.union([_frustum(z0, z1, s0, s1) for (z0, s0), (z1, s1) in zip(profile, profile[1:])],
                                 engine="manifold")


def test_alike_chamfered_through_pockets_are_measured_alike_occupied_or_not() -> None:
    # A 126 x 42 x 4.65 mm plate with two alike square through pockets 42 mm apart (a
    # Gridfinity baseplate's, with sharp corners): 36.3 mm at the floor, 45 deg out to 37.7
    # by 0.7 mm, straight up to 2.5 mm, 45 deg out to 42 at the top; a foot standing on the
    # floor in the first (35.6 at the floor, 37.2 from 0.8 to 2.6 mm, 41.5 at its top,
    # 4.75 mm). Each pocket's section is the narrowest a part passes on its way through it,
    # the 36.3 mm opening at the floor, and its chamfer from that; the empty one measured
    # only from the level sliced (2.325 mm, half the foot's depth) up would be its 37.7 mm
    # walls, with another chamfer. The sweep admits the foot into both with 0.5 mm of room
    # (37.2 in 37.7).
    plate = trimesh.creation.box((0.126, 0.042, 4.65 * MM), trimesh.transformations.translation_matrix(
        (0.021, 0.0, 2.325 * MM)))
    pocket = [(-MM, 34.3 * MM), (0.7 * MM, 37.7 * MM), (2.5 * MM, 37.7 * MM), (5.65 * MM, 44 * MM)]
    cuts = [_stacked(pocket), _stacked(pocket)]
    cuts[1].apply_translation((0.042, 0.0, 0.0))
    plate = trimesh.boolean.difference([plate, *cuts], engine="manifold")
    foot = _stacked([(0.0, 35.6 * MM), (0.8 * MM, 37.2 * MM), (2.6 * MM, 37.2 * MM), (4.75 * MM, 41.5 * MM)])
    derived = derive([CadPart("plate", "plate", plate, "plate.stl"), CadPart("foot", "foot", foot, "foot.stl")],
                     "plate", {})
    at = {round(fit.position[0], 3): fit for fit in derived.holes.values()}
    held, empty = at[0.0], at[0.042]
    assert held.part == "foot" and empty.part is None
    measured = [(fit.hole.kind, fit.hole.a, fit.hole.b, fit.chamfer, fit.depth) for fit in (held, empty)]
    assert measured[0] == pytest.approx(measured[1], abs=1e-9)
    assert held.hole.a == pytest.approx(36.3 * MM, abs=1e-8)
    assert held.chamfer == pytest.approx((41.96 - 36.3) / 2 * MM + 0.02 * MM, abs=1e-7)  # probed 20 um below the top
    for fit in (held, empty):
        assert derived.swept[("foot", fit.id)][2] == pytest.approx(0.5 * MM, abs=1e-7)


def _rings_near(rng: np.random.Generator) -> tuple[shapely.LinearRing, shapely.LinearRing]:
    """A random convex ring [m] and its copy with a point between each two of its corners,
    pushed off their edge by :data:`sections.SAME_OUTLINE` give or take a few ulps, or the
    copy shifted by that much (so the rings' Hausdorff distance lies on the tolerance)."""
    angles = np.sort(rng.uniform(0, 2 * math.pi, int(rng.integers(3, 30))))
    points = np.stack([np.cos(angles), np.sin(angles)], axis=1) * rng.uniform(0.001, 0.05) + rng.uniform(-0.3, 0.3, 2)
    off = sections.SAME_OUTLINE * (1 + rng.integers(-3, 4, (len(points), 1)) * 1e-16)
    if rng.integers(2):
        turn = rng.uniform(0, 2 * math.pi)
        return shapely.LinearRing(points), shapely.LinearRing(points + off * [math.cos(turn), math.sin(turn)])
    edges = np.roll(points, -1, axis=0) - points
    normals = edges[:, ::-1] * [1, -1] / np.linalg.norm(edges, axis=1)[:, None]
    between = (points + np.roll(points, -1, axis=0)) / 2 + normals * off
    return shapely.LinearRing(points), shapely.LinearRing(np.stack([points, between], axis=1).reshape(-1, 2))


def test_a_section_is_its_loop_exactly_as_their_hausdorff_distance_decides() -> None:
    # over_span keeps the loop sliced when the section over the span lies within
    # SAME_OUTLINE of it, as shapely's discrete Hausdorff distance (GEOS's) decides; the
    # check measures each vertex only against the edges near it, each as GEOS does, so it
    # decides alike on rings whose distance lies on the tolerance to the last bits. The
    # first pair is off by 1e-8 m and 9.1e-18 m as GEOS measures it: GEOS measures every
    # second edge from its end (from its start, the pair comes out 5.3e-18 m within).
    first = [(-0.17051113754895594, 0.07954860562642242), (-0.14556593338799292, 0.031272340684703574),
             (-0.11329761921450417, 0.04715225115214819), (-0.1092857903794663, 0.05776384061486611)]
    second = [first[0], (-0.15803854435254833, 0.0554104685650041), first[1],
              (-0.12943177188575766, 0.03921228694605495), first[2], (-0.11129169544314062, 0.052458042347182675),
              first[3], (-0.13989846061196257, 0.06865623254202577)]
    rng = np.random.default_rng(7)
    pairs = [(shapely.LinearRing(first), shapely.LinearRing(second))] + [_rings_near(rng) for _ in range(300)]
    expected = [bool(shapely.hausdorff_distance(a, b) <= sections.SAME_OUTLINE) for a, b in pairs]
    assert [sections._same_outline(a, b) for a, b in pairs] == expected
    assert expected[0] is False and 0 < sum(expected) < len(expected)  # both outcomes decided


def _sliver_and_ledge(lean: float) -> tuple[Loop, trimesh.Trimesh]:
    """A 10 mm square's loop (0 to 10 mm in x and y) and a soup of faces over the span
    0 to 10 mm along z: its wall at x = 0 leaning by ``lean`` [m] in x from foot to top
    (a sliver of that width in its shadow, within :data:`sections.SLIVER` of the loop),
    and a ledge across the corner at x, y = 10 mm, 1 mm each way (the section is not the loop)."""
    side, span, ledge = 10 * MM, 10 * MM, 1 * MM
    vertices = np.array([[0.0, 0.0, 0.0], [0.0, side, 0.0], [lean, side, span], [lean, 0.0, span],
                         [side - ledge, side, span / 2], [side, side - ledge, span / 2],
                         [side + ledge, side + ledge, span / 2]])
    mesh = trimesh.Trimesh(vertices, [[0, 1, 2], [0, 2, 3], [4, 5, 6]], process=False)
    return Loop(np.array([[0.0, 0.0], [side, 0.0], [side, side], [0.0, side]])), mesh


@pytest.mark.parametrize("hole", [True, False])
def test_a_section_over_a_span_without_its_slivers_is_conservative(hole: bool) -> None:
    # The wall leaning by 0.5 pm into the hole (out of the peg) projects to a sliver the
    # section over the span leaves out (SLIVER): the hole's section is eroded so it is no
    # larger than the exact one (the loop less every face's shadow), the peg's dilated so it
    # is no smaller (the loop with it). Without that, the hole would hold the sliver and
    # the peg miss it, by 0.5 pm: a peg could pass a hole it overlaps.
    lean = 0.5e-12 if hole else -0.5e-12
    loop, mesh = _sliver_and_ledge(lean)
    up = np.array([0.0, 0.0, 1.0])
    found = sections.over_span(loop, mesh, up, 0.0, 10 * MM, hole=hole)
    assert found is not loop  # the ledge's shadow: not the loop sliced
    outline = shapely.Polygon(loop.points)
    cover, dropped = sections.shadow(mesh, up, 0.0, 10 * MM, outline.bounds)
    assert not dropped
    exact = shapely.difference(outline, cover) if hole else shapely.union(outline, cover)
    result = shapely.Polygon(found.points)
    inner, outer = (result, exact) if hole else (exact, result)
    assert outer.covers(inner)
    assert inner.area < outer.area  # the ledge kept: the section changed by the tolerance only
    assert outer.area - inner.area < 4 * sections.SLIVER * 40 * MM


def test_an_empty_drilled_hole_is_measured_above_its_drill_point() -> None:
    # A 60 x 30 x 10 mm plate with a d 6 mm blind hole drilled 7 mm deep, its drill point's
    # cone (apex 7 mm down, the bore 5 mm down) the first face down its centre line, and a
    # d 6.4 mm through bore with a d 6 mm peg in it. The empty hole is measured as deep as a
    # part goes in, to its floor: where the floor is no face across the axis (nothing of the
    # hole is free down to the apex), from the level sliced, its bore (48 corners).
    box = trimesh.creation.box((0.06, 0.03, 0.01), trimesh.transformations.translation_matrix((0.015, 0.0, 0.005)))
    drilled = _revolved([(0.0, 3 * MM), (3 * MM, 5 * MM), (3 * MM, 11 * MM), (0.0, 11 * MM)])
    bore = _revolved([(0.0, -MM), (3.2 * MM, -MM), (3.2 * MM, 11 * MM), (0.0, 11 * MM)])
    bore.apply_translation((0.03, 0.0, 0.0))
    plate = trimesh.boolean.difference([box, drilled, bore], engine="manifold")
    peg = _revolved([(0.0, 0.0), (3 * MM, 0.0), (3 * MM, 20 * MM), (0.0, 20 * MM)], sections=64)
    peg.apply_translation((0.03, 0.0, 0.0))
    derived = derive([CadPart("plate", "plate", plate, "plate.stl"), CadPart("peg", "peg", peg, "peg.stl")],
                     "plate", {})
    empty = next(fit for fit in derived.holes.values() if fit.part is None)
    assert empty.hole.kind == "round"
    assert empty.hole.a == pytest.approx(6 * MM * math.cos(math.pi / 48), abs=1e-8)
    assert empty.depth == pytest.approx(7 * MM, abs=1e-8)


def test_a_slice_asked_again_within_slices_kept_is_made_once() -> None:
    """Within ``slices_kept`` a mesh's slice at an axis and level asked again is the one made
    before (the same loops), outside it is made again; another level or mesh is its own."""
    mesh, other = _plate_with_bores(), _touching_cubes()
    up = np.array([0.0, 0.0, 1.0])
    assert sections.slice_loops(mesh, up, 0.0) is not sections.slice_loops(mesh, up, 0.0)
    with sections.slices_kept():
        first = sections.slice_loops(mesh, up, 0.0)
        assert sections.slice_loops(mesh, (0, 0, 1), 0.0) is first
        assert sections.slice_loops(mesh, up, 1e-4) is not first
        assert len(sections.slice_loops(other, up, 0.0)) == 2
    again = sections.slice_loops(mesh, up, 0.0)
    assert again is not first and all(np.array_equal(a.points, b.points) for a, b in zip(again, first, strict=True))


def _ngon(radius: float, sides: int, start: float = 0.0, centre: tuple[float, float] = (0.0, 0.0)) -> np.ndarray:
    """(sides, 2) [m]: the vertices of a regular ``sides``-gon on a circle of ``radius``
    about ``centre``, the first at ``start`` [rad]."""
    turns = start + 2 * math.pi * np.arange(sides) / sides
    return np.stack([centre[0] + radius * np.cos(turns), centre[1] + radius * np.sin(turns)], axis=1)


def teardrop_plus(radius: float) -> shapely.Polygon:
    """NopSCADlib's ``teardrop_plus(r)`` as OpenSCAD draws it (layer height 0.25 mm): each
    side an arc of a 56-gon of r + 0.117 mm about a centre 0.117 mm across the axis from the
    far side, so the arcs are tangent inside to the circle of r at (±r, 0), the top a
    truncated point; a hinge pin's hole."""
    elongation = (0.125 - 1 / 128) * MM
    right = _ngon(radius + elongation, 56, centre=(-elongation, 0.0))
    right = right[right[:, 0] >= -1e-12]
    top = 1.2 * radius
    points = np.vstack([right, right * [-1.0, 1.0], [[0.3 * radius, top], [-0.3 * radius, top]]])
    return shapely.MultiPoint(points).convex_hull


@pytest.mark.parametrize("hole_of, peg_radius, zero", [
    ("teardrop", 2.0, True),  # nop_flat_hinge: its pin, a 51-gon d 4, in the male's teardrop_plus(r = 2)
    ("teardrop", 2.02, False),  # a pin 40 µm wider: an interference
    ("hexagon", 2.003, False),  # a pin 3 µm into a hexagon's flats: straight sides, no chords of its circle
])
def test_a_round_peg_whose_circle_the_polygon_holes_vertices_lie_on_is_a_zero_clearance_fit(
        hole_of: str, peg_radius: float, zero: bool) -> None:
    # The hole's edges that the peg's circle crosses are short chords of that circle (their
    # ends on it within TOUCH): the tessellation of a wall it touches, as two coaxial
    # cylinders of one radius are, whose measured overlap (2.5 µm here) is no interference.
    hole_outline = {"teardrop": teardrop_plus(2 * MM),
                    "hexagon": shapely.Polygon(_ngon(2 * MM / math.cos(math.pi / 6), 6))}[hole_of]
    hole = classify(loop_of(hole_outline), hole=True)
    peg = classify(Loop(_ngon(peg_radius * MM, 51, start=-math.pi / 2) + (0.1, -0.05)), hole=False)
    assert (hole.kind, peg.kind) == ("polygon", "round")
    margin = sections.section_room(peg, hole).margin
    assert margin < -2 * sections.OUTLINE_TOUCH  # more than a straight-sided pair's touch: no fit before
    assert (sections.zero_clearance(peg, hole, margin) is not None) == zero
    assert sections.passes(peg, hole) == zero


@pytest.mark.parametrize("reach, zero", [(1.0, True), (1.02, False)])
def test_a_polygon_peg_whose_corners_lie_on_a_round_holes_vertex_circle_is_a_zero_clearance_fit(
        reach: float, zero: bool) -> None:
    # A hexagonal peg whose corners touch a 48-gon bore's vertex circle (d 4): its inscribed
    # circle, the hole's measure, is 8.6 µm narrower than the corners reach.
    hole = classify(Loop(_ngon(2 * MM, 48) + (0.1, -0.05)), hole=True)
    peg = classify(loop_of(shapely.Polygon(_ngon(2 * reach * MM, 6, start=0.1))), hole=False)
    assert (hole.kind, peg.kind) == ("round", "polygon")
    margin = sections.section_room(peg, hole).margin
    assert margin < -2 * sections.OUTLINE_TOUCH
    assert (sections.zero_clearance(peg, hole, margin) is not None) == zero
