"""Solids of polygon sections, exact to their outline: a peg's convex pieces and a hole's boss.

A polygon peg collides as the prism of its outline over its length, cut into convex pieces
(:func:`convex_parts`: the outline's constrained Delaunay triangles merged greedily,
longest shared edge first, while the union stays convex; Hertel and Mehlhorn's bound: at
most four times the fewest pieces), each piece one convex hull of the part's URDF link, so
the union of the pieces is the outline's prism itself (no hull bridges a notch, as a
decomposition of the mesh may). A polygon hole's boss (:func:`boss_triangles`) is a
static triangle mesh like the other holes' bosses: the top of the square boss, the 45°
entry chamfer (each edge of the outline moved out by the chamfer, its corners where the
moved edges meet: :func:`mitre_offset`), the wall and the bottom (open onto the plate or
a floor). For an engine that collides convex solids only (MuJoCo), the same boss is cut
into convex pieces (:func:`boss_solids`).
"""

from __future__ import annotations

import math

import numpy as np
import shapely

CONVEX_TOLERANCE = 1e-7
"""A union of pieces is convex when its hull lies within this [m] of it (0.1 µm, the
resolution an outline is written to)."""


def corners(shape: shapely.Polygon) -> np.ndarray:
    """The exterior corners (n, 2) [m] of a polygon, counter-clockwise, collinear ones dropped."""
    clean = shapely.orient_polygons(shapely.simplify(shape, 0.0))
    return np.asarray(clean.exterior.coords)[:-1]


def convex_parts(outline: shapely.Polygon) -> list[np.ndarray]:
    """Convex polygons (each its corners (k, 2) [m], counter-clockwise) whose union is
    ``outline`` (a simple polygon) and whose interiors do not overlap (module docstring)."""
    if shapely.hausdorff_distance(outline.convex_hull, outline) <= CONVEX_TOLERANCE:
        return [corners(outline)]
    triangles = list(shapely.constrained_delaunay_triangles(outline).geoms)
    owner = list(range(len(triangles)))  # piece of each triangle (the index of its first triangle)
    pieces: dict[int, shapely.Polygon] = dict(enumerate(triangles))
    edges: dict[tuple[tuple[float, float], tuple[float, float]], list[int]] = {}
    for k, triangle in enumerate(triangles):
        points = [tuple(c) for c in np.asarray(triangle.exterior.coords)[:3]]
        for start, end in ((points[0], points[1]), (points[1], points[2]), (points[2], points[0])):
            edges.setdefault((min(start, end), max(start, end)), []).append(k)
    shared = sorted((pair for pair in edges.items() if len(pair[1]) == 2),
                    key=lambda pair: -math.dist(*pair[0]))
    for _, (first, second) in shared:
        a, b = owner[first], owner[second]
        if a == b:
            continue
        union = shapely.union(pieces[a], pieces[b])
        if not isinstance(union, shapely.Polygon) or (
                shapely.hausdorff_distance(union.convex_hull, union) > CONVEX_TOLERANCE):
            continue
        pieces[a] = union
        del pieces[b]
        owner = [a if o == b else o for o in owner]
    return [corners(piece) for _, piece in sorted(pieces.items())]


def prism_pieces(outline: shapely.Polygon, length: float) -> list[np.ndarray]:
    """The vertices (2k, 3) [m] of each convex piece of the prism of ``outline`` from z = 0
    to ``length`` [m] (:func:`convex_parts`)."""
    return [np.vstack([np.column_stack([part, np.full(len(part), z)]) for z in (0.0, length)])
            for part in convex_parts(outline)]


def mitre_offset(ring: np.ndarray, distance: float) -> np.ndarray | None:
    """Where each corner of the counter-clockwise ``ring`` (n, 2) [m] goes when every edge
    moves outwards by ``distance`` [m]: where the moved edges meet. An edge that the move
    turns over (a short edge between two inward corners) is dropped, the one turned
    furthest first, and its two corners go to where its neighbours' moved edges meet (its
    chamfer face is then a triangle). None when the moved ring crosses itself or differs
    from the ring's mitred buffer by more than :data:`CONVEX_TOLERANCE` (an offset no
    dropping of edges describes)."""
    n = len(ring)
    direction = np.roll(ring, -1, axis=0) - ring
    direction /= np.linalg.norm(direction, axis=1)[:, None]
    normal = np.column_stack([direction[:, 1], -direction[:, 0]])  # outwards of a counter-clockwise ring
    kept = list(range(n))
    while len(kept) >= 3:
        corners = {edge: _meet(ring, direction, normal, distance, kept[k - 1], edge) for k, edge in enumerate(kept)}
        lengths = [float((corners[kept[(k + 1) % len(kept)]] - corners[edge]) @ direction[edge])
                   for k, edge in enumerate(kept)]
        worst = int(np.argmin(lengths))
        if lengths[worst] > 0:
            break
        del kept[worst]
    else:
        return None
    # corner i (between edges i - 1 and i) goes where the kept edges around it meet
    moved = np.array([corners[_next_kept(kept, i)] for i in range(n)])
    shape = shapely.Polygon(_distinct(moved))
    expected = shapely.Polygon(ring).buffer(distance, join_style="mitre", mitre_limit=1e6)
    if not shape.is_valid or shapely.hausdorff_distance(shape, expected) > CONVEX_TOLERANCE:
        return None
    return moved


def _next_kept(kept: list[int], corner: int) -> int:
    """The first kept edge at or after ``corner``, round the ring."""
    return next((e for e in kept if e >= corner), kept[0])


def _meet(ring: np.ndarray, direction: np.ndarray, normal: np.ndarray, distance: float, before: int,
          after: int) -> np.ndarray:
    """Where edges ``before`` and ``after``, moved outwards by ``distance`` [m], meet (on
    one line: the moved start of ``after``)."""
    start = ring[after] + distance * normal[after]
    other = ring[before] + distance * normal[before]
    cross = direction[before, 0] * direction[after, 1] - direction[before, 1] * direction[after, 0]
    if abs(cross) < 1e-12:
        return start
    offset = other - start
    t = (offset[0] * direction[before, 1] - offset[1] * direction[before, 0]) / -cross
    return start + t * direction[after]


def _distinct(points: np.ndarray) -> np.ndarray:
    """The ring's points without a repeat of the one before (round the ring)."""
    keep = np.linalg.norm(points - np.roll(points, 1, axis=0), axis=1) > 1e-12
    return points[keep]


def _flat(shape: shapely.Polygon, z: float) -> list[np.ndarray]:
    """The constrained Delaunay triangles (3 × 3 [m]) of a polygon (holes allowed) at height ``z``."""
    return [np.column_stack([np.asarray(t.exterior.coords)[:3], np.full(3, z)])
            for t in shapely.constrained_delaunay_triangles(shape).geoms]


def _band(upper: np.ndarray, lower: np.ndarray) -> list[tuple[int, np.ndarray]]:
    """The triangles between two rings (n, 3) [m] of corresponding corners, each with the
    index of its edge: two for an edge, one where the upper ring's corners are one point."""
    out = []
    for k in range(len(upper)):
        j = (k + 1) % len(upper)
        if np.linalg.norm(upper[j] - upper[k]) > 1e-12:
            out.append((k, np.array([upper[k], upper[j], lower[j]])))
        out.append((k, np.array([upper[k], lower[j], lower[k]])))
    return out


def _lift(ring: np.ndarray, z: float) -> np.ndarray:
    return np.column_stack([ring, np.full(len(ring), z)])


def boss_triangles(hole: np.ndarray, tile: np.ndarray, chamfer: float, top: float, bottom: float,
                   base: float) -> list[tuple[np.ndarray, np.ndarray]] | str:
    """The boss of a polygon hole as ``(triangle 3 × 3, wanted normal)`` pairs [m]: the
    counter-clockwise ``hole`` ring and the boss's square ``tile`` (4, 2) in the cell
    frame, the entry at ``top``, the chamfer ``chamfer`` deep, the hole's bottom at
    ``bottom``, the plate under the bosses at ``base`` (a bottom at it opens onto the plate;
    above it, a floor). Or why none can be made: the chamfered mouth is no simple polygon
    inside the tile."""
    mouth = _mouth(hole, tile, chamfer)
    if isinstance(mouth, str):
        return mouth
    up, down = np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, -1.0])
    tris = [(t, up) for t in _flat(shapely.Polygon(tile, [_distinct(mouth)]), top)]
    edge = np.roll(hole, -1, axis=0) - hole
    inwards = np.column_stack([-edge[:, 1], edge[:, 0]]) / np.linalg.norm(edge, axis=1)[:, None]
    mouth3, wall_top, wall_bottom = _lift(mouth, top), _lift(hole, top - chamfer), _lift(hole, bottom)
    for faces, normal_xy, slope in ((_band(mouth3, wall_top), inwards, 1.0),
                                    (_band(wall_top, wall_bottom), inwards, 0.0)):
        tris += [(t, np.array([*normal_xy[k], slope])) for k, t in faces]
    tile_edge = np.roll(tile, -1, axis=0) - tile
    outwards = np.column_stack([tile_edge[:, 1], -tile_edge[:, 0]])
    tris += [(t, np.array([*outwards[k], 0.0])) for k, t in _band(_lift(tile, top), _lift(tile, base))]
    if bottom - base <= 0:  # an open ring on the plate, which is the hole's bottom
        tris += [(t, down) for t in _flat(shapely.Polygon(tile, [hole]), base)]
    else:  # the boss's floor inside the hole, its solid bottom on the plate
        tris += [(t, up) for t in _flat(shapely.Polygon(hole), bottom)]
        tris += [(t, down) for t in _flat(shapely.Polygon(tile), base)]
    return tris


def _mouth(hole: np.ndarray, tile: np.ndarray, chamfer: float) -> np.ndarray | str:
    """The ``hole`` ring's corners moved out by ``chamfer`` (:func:`mitre_offset`), or why
    none can be made: the chamfered mouth is no simple polygon inside the ``tile``."""
    mouth = mitre_offset(hole, chamfer)
    if mouth is None or not shapely.Polygon(tile).contains(shapely.Polygon(_distinct(mouth))):
        return (f"its outline offset by the chamfer ({1e3 * chamfer:g} mm, each edge moved out) is no simple polygon "
                "inside its boss")
    return mouth


def boss_solids(hole: np.ndarray, tile: np.ndarray, chamfer: float, top: float, bottom: float,
                base: float) -> list[np.ndarray] | str:
    """The boss of :func:`boss_triangles` (same arguments) as convex solids, each its
    vertices (k, 3) [m], whose union is that boss and whose interiors do not overlap: the
    ring between the tile and the hole (:func:`convex_parts` of the tile with the hole cut
    out) from ``base`` up to the chamfer; above it the ring between the tile and the
    chamfered mouth, and per edge of the hole the wedge under its chamfer face (the edge,
    its moved edge on the mouth and the vertical through that, a triangular prism, or a
    tetrahedron for an edge the offset dropped); the hole's floor (the prism of its
    outline's pieces from ``base`` to ``bottom``) when ``bottom`` is above ``base``. Or
    why none can be made (as :func:`boss_triangles`)."""
    mouth = _mouth(hole, tile, chamfer)
    if isinstance(mouth, str):
        return mouth
    wall_top = top - chamfer

    def prisms(outline: shapely.Polygon, low: float, high: float) -> list[np.ndarray]:
        return [np.vstack([_lift(part, low), _lift(part, high)]) for part in convex_parts(outline)]

    solids = prisms(shapely.Polygon(tile, [hole]), base, wall_top)
    if chamfer > 0:
        solids += prisms(shapely.Polygon(tile, [_distinct(mouth)]), wall_top, top)
    for k in range(len(hole) if chamfer > 0 else 0):
        j = (k + 1) % len(hole)
        points = np.array([[*hole[k], wall_top], [*hole[j], wall_top], *(
            [*mouth[i], z] for i in (k, j) for z in (wall_top, top))])
        solids.append(np.unique(points.round(12), axis=0))
    if bottom > base:
        solids += prisms(shapely.Polygon(hole), base, bottom)
    return solids
