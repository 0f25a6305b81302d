"""The pegs' sections the cell's collision shapes lack, and the near misses it cannot resolve.

Bullet inflates every convex collision shape by its hull margin (:data:`URDF_HULL_MARGIN`,
1 mm): a box primitive is its box shrunk by the margin and added back, and a polygon
peg's prism pieces are eroded by it before it is added back
(:mod:`executor.world.meshes`). Either way a piece's vertical edges are rounded with the
margin's radius, so the cell's peg lies inside its section and falls short of it at each
corner of a piece: by r (1/sin(θ/2) - 1) at a corner of angle θ (0.41 mm at a right
angle), the points it lacks there lying at most r (1 - sin(θ/2)) inside the outline
(0.29 mm at a right angle); a notched polygon's pieces also leave slits where they meet
at a reflex corner. A cylinder's side is its circle (only its rims are rounded):
a round peg lacks nothing. A peg whose tightest contacts in a hole are its corners and
that misses the hole by less than that passes in physics (``vitac_shapes``' heptagon,
1.36 µm short of the rect hole, ``fit`` 2 of 2).

:func:`near_miss` is the sound test: the section eroded by :func:`erosion` (the largest
depth of a missing point, plus the :data:`SIZE_RESOLUTION` the physics resolves) lies
inside the cell's peg, so when that eroded section does not pass a hole the cell's peg
does not either and its no-fit is observed; when it passes while the section does not,
the cell cannot tell the pair from a fit, and it is no experiment (the import writes it
``near_miss`` in ``geometry.toml``: docs/cell.md#what-the-physics-resolves). Whether the
eroded section passes is :func:`executor.world.geometry.margin`'s decision, the same
polygon relation the import decides every pair by (for two polygons a search: a no-pass
is its finding).

A peg simulated from its own mesh collides as its convex pieces, each the asset's piece
eroded by the margin (:func:`executor.world.meshes.eroded`) that Bullet adds back: its
edges rounded alike (measured: a 10 mm square piece's vertical edge lies 0.414 mm inside
the CAD's corner, r (√2 - 1), its faces where the CAD has them). What such a peg covers
across its axis over the stretch that enters the hole holds, at least,
:func:`pieces_section`: each eroded piece clipped to that stretch, projected, and widened
by the margin. :func:`mesh_near_miss` decides its pairs by that section as
:func:`near_miss` decides a primitive peg's by the eroded one.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import shapely
import trimesh

from executor.world import SIZE_RESOLUTION
from executor.world.geometry import Section, margin, outline_polygon
from executor.world.meshes import URDF_HULL_MARGIN, eroded
from executor.world.outlines import convex_parts

ARC_SEGMENTS = 32
"""Chords per quarter of a rounded corner's arc (the chords lie inside it, so the peg
built from them is smaller than the cell's: its deficit is over-, never underestimated,
by at most r (1 - cos(π/128)), 0.3 µm at r = 1 mm)."""


def collision_section(part: Section) -> shapely.Polygon | None:
    """The section of the cell's collision peg built from ``part``'s section [m]: a box's
    rectangle (the cell's box has sharp sides a x b whatever the section's corner) or each
    convex piece of a polygon's prism opened by the hull margin (shrunk by it, then
    widened by it: nothing of a piece thinner than twice the margin, so a section of such
    pieces only, a Technic axle's cross, is empty); None for a round section (a
    cylinder's side is its circle)."""
    if part.kind == "round":
        return None
    if part.kind == "polygon":
        pieces = [shapely.Polygon(piece) for piece in convex_parts(outline_polygon(part, peg=True))]
    else:
        a, b = part.sides
        pieces = [shapely.box(-a / 2, -b / 2, a / 2, b / 2)]
    opened = [shapely.buffer(shapely.buffer(piece, -URDF_HULL_MARGIN, join_style="mitre"), URDF_HULL_MARGIN,
                             quad_segs=ARC_SEGMENTS) for piece in pieces]
    union = shapely.union_all(opened)  # empty where every piece is thinner than twice the margin
    shells = [shell for shell in getattr(union, "geoms", [union]) if isinstance(shell, shapely.Polygon)
              and not shell.is_empty]
    return shapely.union_all([shapely.Polygon(shell.exterior) for shell in shells])  # gaps between pieces filled


def erosion(part: Section) -> float:
    """How far [m] ``part``'s section must be eroded to lie inside the cell's collision peg
    (:func:`collision_section`: the largest distance from the section's outline of a point
    the peg lacks), plus :data:`SIZE_RESOLUTION`; that resolution alone for a round one."""
    cell = collision_section(part)
    if cell is None:
        return SIZE_RESOLUTION
    whole = outline_polygon(part, peg=True)
    if cell.is_empty:  # it lacks all of it: its deepest point, the centre of its largest inscribed circle
        return float(shapely.length(shapely.maximum_inscribed_circle(whole, 1e-7))) + SIZE_RESOLUTION
    lacking = shapely.segmentize(shapely.difference(whole, cell), URDF_HULL_MARGIN / 64)
    points = shapely.points(shapely.get_coordinates(lacking))
    deepest = float(shapely.distance(whole.exterior, points).max()) if len(points) else 0.0
    return deepest + SIZE_RESOLUTION


def eroded_section(part: Section, depth: float) -> Section:
    """``part``'s section eroded by ``depth`` [m] (every point of the result at least that
    far inside it): a round one's diameter less twice that, a rect's sides (its corner
    radius less that), a polygon's outline offset with mitred corners (its reflex corners
    cut further in than the exact erosion's arcs; where that cuts it in two, the larger part)."""
    if part.kind == "round":
        return Section(part.id, "round", part.size - 2 * depth)
    if part.kind != "polygon":
        a, b = part.sides
        return Section(part.id, part.kind, a - 2 * depth, width=b - 2 * depth if part.width > 0 else 0.0,
                       corner=max(part.corner - depth, 0.0))
    shrunk = shapely.buffer(outline_polygon(part, peg=True), -depth, join_style="mitre", mitre_limit=1e3)
    if isinstance(shrunk, shapely.MultiPolygon):  # a narrow waist cut through: its largest part is inside it too
        shrunk = max(shrunk.geoms, key=lambda piece: piece.area)
    (x0, y0, x1, y1), outline = shrunk.bounds, shapely.get_coordinates(shrunk.exterior)[:-1]
    return Section(part.id, "polygon", x1 - x0, width=y1 - y0, outline=tuple((float(x), float(y)) for x, y in outline))


def near_miss(part: Section, hole: Section, room: float) -> float | None:
    """The :func:`erosion` [m] of a peg ``part`` with ``room`` [m] (its :func:`margin`,
    negative: it does not pass) in ``hole`` when the cell cannot resolve that no-fit (the
    section eroded by it passes the hole), None when it can, or when the pair fits
    (``room`` >= 0: the cell's smaller peg passes too); a peg whose cell's section is
    empty (:func:`collision_section`) passes any hole in the cell: its no-fits are near misses."""
    if room >= 0:
        return None
    depth = erosion(part)
    cell = collision_section(part)
    if cell is not None and cell.is_empty:  # nothing of it in the cell's peg: no experiment decides the pair
        return depth
    return depth if margin(eroded_section(part, depth), hole) > 0 else None


def pieces_section(pieces: Sequence[np.ndarray], low: float, high: float) -> shapely.Polygon:
    """What the cell's peg made of convex ``pieces`` (vertices (n, 3) [m] each, in its part
    frame, z up its axis) covers across its axis between the levels ``low`` and ``high``
    [m], at least: each piece eroded by :data:`URDF_HULL_MARGIN` (the asset the cell
    loads), clipped to the levels, projected (the convex hull of its corners) and widened
    by the margin, which Bullet adds back all round (the arcs' chords lie inside them);
    where the pieces' shadows fall apart, the largest (a peg must pass as one piece)."""
    shadows = []
    for vertices in pieces:
        core = eroded(vertices, URDF_HULL_MARGIN)
        if core is None:
            continue
        clipped = trimesh.intersections.slice_mesh_plane(core, (0.0, 0.0, 1.0), (0.0, 0.0, low), cap=True)
        if clipped is None or clipped.is_empty:
            continue
        clipped = trimesh.intersections.slice_mesh_plane(clipped, (0.0, 0.0, -1.0), (0.0, 0.0, high), cap=True)
        if clipped is None or clipped.is_empty:
            continue
        shadow = shapely.MultiPoint(clipped.vertices[:, :2]).convex_hull
        shadows.append(shapely.buffer(shadow, URDF_HULL_MARGIN, quad_segs=ARC_SEGMENTS))
    union = shapely.union_all(shadows)
    if isinstance(union, shapely.Polygon):
        return union
    return max(shapely.get_parts(union), key=lambda piece: piece.area, default=shapely.Polygon())


def mesh_near_miss(part: Section, pieces: Sequence[np.ndarray], stretch: float, hole: Section,
                   room: float) -> float | None:
    """How deep [m] a peg simulated from its convex ``pieces`` (:func:`pieces_section`, its
    part frame's origin the centre of its section ``part``) lacks its section over the
    ``stretch`` [m] from its end that enters the hole, plus :data:`SIZE_RESOLUTION`, when
    the cell cannot resolve its no-fit in ``hole`` (``room`` [m] < 0, and what its pieces
    cover there, eroded by that resolution, passes the hole); None when it can or the pair
    fits (``room`` >= 0)."""
    if room >= 0:
        return None
    cell = pieces_section(pieces, 0.0, stretch)
    whole = outline_polygon(part, peg=True)
    lacking = shapely.segmentize(shapely.difference(whole, cell), URDF_HULL_MARGIN / 64)
    points = shapely.points(shapely.get_coordinates(lacking))
    depth = (float(shapely.distance(whole.exterior, points).max()) if len(points) else 0.0) + SIZE_RESOLUTION
    resolved = shapely.buffer(cell, -SIZE_RESOLUTION, join_style="mitre")
    if resolved.is_empty or not isinstance(resolved, shapely.Polygon):
        return depth  # nothing of it resolved: no pair of it is
    (x0, y0, x1, y1), outline = resolved.bounds, shapely.get_coordinates(resolved.exterior)[:-1]
    shrunk = Section(part.id, "polygon", x1 - x0, width=y1 - y0,
                     outline=tuple((float(x), float(y)) for x, y in outline))
    return depth if margin(shrunk, hole) > 0 else None
