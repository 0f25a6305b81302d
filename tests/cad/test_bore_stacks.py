"""Parts with a bore that are no prism of one section: a gear whose hub stands above its
teeth is a stack of prisms of its sections, each layer cut into convex pieces the cell
collides as; a round bore on round pins is a regular polygon about its inscribed circle
(a round pin passes it exactly as it passes the bore)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import shapely
import trimesh

from executor.cad.convex import APART, CONCAVITY_REACH, _shape_key, apart, pin_pieces
from executor.world.rings import NoStack, ring_pieces, room_in, section_at

BORE = 5.0e-3
"""The bore's radius [m] (a 64-gon's vertex circle)."""


def _stepped() -> trimesh.Trimesh:
    """A disc of radius 20 mm and 6 mm under a hub of radius 10 mm and 8 mm, through both
    a round bore (64 corners on the circle of :data:`BORE`), in its part frame [m]."""
    bore = shapely.Point(0, 0).buffer(BORE, quad_segs=16)
    disc = trimesh.creation.extrude_polygon(shapely.Point(0, 0).buffer(0.02, quad_segs=8).difference(bore), 0.006)
    hub = trimesh.creation.extrude_polygon(shapely.Point(0, 0).buffer(0.01, quad_segs=8).difference(bore), 0.008)
    hub.apply_translation((0.0, 0.0, 0.006))
    return trimesh.boolean.union([disc, hub], engine="manifold")


@pytest.mark.slow  # about 3 s on a loaded machine (the sections' convex parts)
def test_a_hub_over_a_disc_is_a_stack_of_two_prisms_whose_bore_is_the_inscribed_circle() -> None:
    found = ring_pieces("stepped", _stepped(), 0.0, round_pins=True)
    assert not isinstance(found, str), found
    pieces, made = [piece for piece, _ in found[0]], found[1]
    assert "2 layer(s) of 6.000, 8.000 mm" in made
    # each layer is covered up to its own outline, and nothing of it reaches into the bore's
    # inscribed circle (the mesh's, as trimesh cuts it), which every layer's bore touches
    # (within 1 um: its sections are snapped and joined)
    cut = _stepped().section(plane_origin=(0, 0, 0.003), plane_normal=(0, 0, 1))
    assert cut is not None
    inner = min(cut.discrete, key=lambda loop: float(np.ptp(loop[:, 0])))
    inscribed = shapely.distance(shapely.Point(0, 0), shapely.LinearRing(inner[:, :2]))
    assert inscribed == pytest.approx(BORE * np.cos(np.pi / 64), abs=1e-6)
    for low, high, outer in ((0.0, 0.006, 0.02), (0.006, 0.014, 0.01)):
        layer = [p for p in pieces if abs(p.bounds[0][2] - low) < 1e-9 and abs(p.bounds[1][2] - high) < 1e-9]
        rings = shapely.union_all([shapely.MultiPoint(p.vertices[:, :2]).convex_hull for p in layer])
        assert abs(rings.area - (np.pi * outer**2 - np.pi * inscribed**2)) < 0.03 * rings.area
        assert inscribed - 1e-6 < shapely.distance(shapely.Point(0, 0), rings.boundary) <= inscribed


def test_a_part_that_is_no_stack_of_prisms_says_so() -> None:
    # a cone with a bore: every height its own section
    cone = trimesh.creation.cone(radius=0.02, height=0.02, sections=32)
    bore = trimesh.creation.cylinder(radius=BORE, height=0.05, sections=32)
    found = ring_pieces("cone", trimesh.boolean.difference([cone, bore], engine="manifold"), 0.0, round_pins=True)
    assert isinstance(found, NoStack) and "is no stack of prisms of its sections" in found


def test_a_plate_thinner_than_the_hull_margin_twice_is_refused_saying_so() -> None:
    # flynn_clutch's plates: 1.2 mm thick, no piece of them has an eroded form (its height
    # less the margin twice is nothing), whatever its bore
    bore = shapely.Point(0, 0).buffer(BORE, quad_segs=16)
    plate = trimesh.creation.extrude_polygon(shapely.Point(0, 0).buffer(0.02, quad_segs=8).difference(bore), 0.0012)
    found = ring_pieces("plate", plate, 1e-4)
    assert isinstance(found, str) and not isinstance(found, NoStack)
    assert found == ("part 'plate': its layer from 0.000 to 1.200 mm of its height, at its bore, is thinner than "
                     "the cell's hull margin twice less what it resolves (1.952 mm)")


def test_a_large_part_whose_bore_coacd_cannot_keep_is_refused_without_decomposing() -> None:
    # asm4_disk_arm's disk: a d 240 disk with a d 21 bore and a nipple off its axis (no
    # stack of prisms), on a d 20 pin; its pieces may take 0.238 mm of the pin's room, and
    # CoACD's finest threshold allows them 2.4 mm of concavity on a part that size
    bore = shapely.Point(0, 0).buffer(0.0105, quad_segs=16)
    disc = trimesh.creation.extrude_polygon(shapely.Point(0, 0).buffer(0.12, quad_segs=16).difference(bore), 0.01)
    nipple = trimesh.creation.cylinder(radius=0.01, height=0.02, sections=32)
    nipple.apply_translation((0.0766, 0.0643, 0.02))
    disk = trimesh.boolean.union([disc, nipple], engine="manifold")
    pin = trimesh.creation.cylinder(radius=0.01, height=0.05, sections=64)
    found = pin_pieces("disk", disk, pin, 0.000238)
    assert isinstance(found, str)
    assert f"allows pieces 2.400 mm concave, over {CONCAVITY_REACH:g} times the 0.238 mm" in found, found
    assert "(not sought)" in found


def test_vertices_closer_than_a_written_file_keeps_are_moved_apart() -> None:
    points = np.array([[0.1, 0.0, 0.0], [0.1 + 4e-9, 0.0, 0.0], [0.2, 0.0, 0.0]])
    moved = apart(points)
    assert np.linalg.norm(moved[1] - moved[0]) == pytest.approx(APART, abs=1e-12)
    assert np.allclose(moved[:2].mean(axis=0), points[:2].mean(axis=0)) and np.array_equal(moved[2], points[2])


def test_a_pin_pieces_key_tells_apart_the_same_vertices_joined_by_other_triangles() -> None:
    # the cache of CoACD's pieces serves a mesh alike within the file's grid, never another
    # shape: a square's two triangulations share their four vertices, not their faces
    square = trimesh.creation.box((0.01, 0.01, 0.01))
    turned = square.copy()
    turned.faces = turned.faces[::-1][:, [1, 2, 0]]  # the same triangles, listed otherwise
    flipped = square.copy()
    quad = flipped.faces[:2]  # two triangles sharing a diagonal: the other diagonal
    shared = np.intersect1d(quad[0], quad[1])
    rim = [int(v) for v in np.union1d(quad[0], quad[1]) if v not in shared]
    flipped.faces[:2] = [[rim[0], shared[0], rim[1]], [rim[1], shared[1], rim[0]]]
    assert _shape_key(square) == _shape_key(turned)
    assert _shape_key(square) != _shape_key(flipped)


def test_a_section_whose_overlay_leaves_a_line_is_its_polygons() -> None:
    # flynn_clutch's outer plate (a ring with 20 splines outside, a round bore) cut at
    # 0.6 mm above its bottom: the even-odd overlay of its two loops leaves, beside the
    # ring, a line 2.5 um long, which made the section no MultiPolygon (a traceback).
    plate = trimesh.load(Path(__file__).parent / "corpus" / "flynn_clutch" / "meshes" / "outer_plate_a.stl")
    plate.apply_scale(1e-3)
    found = section_at(plate, 0.0036)
    assert len(found.geoms) == 1 and len(found.geoms[0].interiors) == 1
    assert found.area == pytest.approx(plate.volume / 0.0012, rel=1e-4)  # a prism 1.2 mm thick


def _knob() -> tuple[trimesh.Trimesh, shapely.Polygon, shapely.Polygon]:
    """A knob [m]: a d 16 cylinder 14 mm tall, a D bore 12 mm deep from its bottom (a
    13-gon whose flats are 3.2 mm from the axis, its faces 1.6 mm wide, cut flat 1.76 mm
    from it) under a 2 mm top; and the D shaft (d 6, a 60-gon, flat 1.5 mm from the axis)
    and the d 7 thread it may be tried on, in its frame."""
    turn = np.linspace(0.0, 2 * np.pi, 13, endpoint=False)
    gon = shapely.Polygon(3.2e-3 / np.cos(np.pi / 13) * np.column_stack([np.cos(turn), np.sin(turn)]))
    bore = gon.intersection(shapely.box(-0.01, -0.01, 0.01, 1.76e-3))
    body = trimesh.creation.cylinder(radius=0.008, height=0.014, sections=64)
    body.apply_translation((0.0, 0.0, 0.007))
    hole = trimesh.creation.extrude_polygon(bore, 0.013)
    hole.apply_translation((0.0, 0.0, -0.001))
    shaft = shapely.Point(0, 0).buffer(3e-3, quad_segs=15).intersection(shapely.box(-0.01, -0.01, 0.01, 1.5e-3))
    return trimesh.boolean.difference([body, hole], engine="manifold"), shaft, shapely.Point(0, 0).buffer(3.5e-3, 15)


@pytest.mark.slow  # about 3 s on a loaded machine
def test_a_d_bore_of_faces_narrower_than_the_hull_margin_twice_keeps_each_pins_room() -> None:
    mesh, shaft, thread = _knob()
    # no convex piece keeps a 1.6 mm face under the cell's 1 mm hull margin, nor does a
    # coarser bore within 0.1 mm
    assert isinstance(ring_pieces("knob", mesh, 1e-4), str)
    found = ring_pieces("knob", mesh, 1e-4, pins=(shaft, thread))
    assert not isinstance(found, str), found
    pieces, made = [piece for piece, _ in found[0]], found[1]
    assert "the bore's round part a regular polygon about its inscribed circle, cut by its flats" in made, made
    # the cell's bore, half way up: the shaft's room the mesh's 0.2 mm (within 0.005), the thread none
    cut = shapely.union_all([shapely.MultiPoint(p.vertices[:, :2]).convex_hull for p in pieces
                             if p.bounds[0][2] < 0.006 < p.bounds[1][2]])
    holes = [shapely.Polygon(ring) for ring in cut.interiors]
    assert len(holes) == 1
    assert abs(room_in(shaft, holes[0]) - 2e-4) <= 5e-6 and room_in(thread, holes[0]) < 0
    assert any(p.bounds[0][2] >= 0.012 - 1e-9 and shapely.MultiPoint(p.vertices[:, :2]).convex_hull.contains(
        shapely.Point(0, 0)) for p in pieces)  # its top, over the bore
