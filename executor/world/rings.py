"""Parts with a bore that go onto a pin (a nut, a washer, a gear, a pulley), as the cell
collides with them: their convex pieces, exact or with a bore smaller by a stated loss.

A moving part collides as convex pieces (:mod:`executor.world.meshes`). A decomposition
that approximates (CoACD) fills part of a bore, and the room between a pin and its bore is
what decides whether the part goes on. So a part with a bore is taken as what it is in
most products, a **prism**: its section across its axis (z of its part frame), at half
its height, swept over its height; it is one when the prism and the mesh differ by less
than :data:`PRISM_TOLERANCE` of the mesh's volume (exact booleans, manifold3d). The
section, a polygon with the bore as its hole (and the part's outline, a gear's teeth or
a nut's handle, as its shell), is cut into convex polygons whose union is that section
exactly: its constrained Delaunay triangles (shapely) merged across their diagonals,
longest first, while the union stays convex (Hertel and Mehlhorn: at most four times the
fewest convex pieces). Each convex polygon swept over the height is a piece. Every piece
touching the bore must have an eroded form (:func:`executor.world.meshes.eroded`: its
section inset by the cell's hull margin is something, and its height is more than twice
the margin), so the bore's faces are where the mesh has them and only edges are rounded
by the margin; a thinner piece of the outline away from the bore (the 0.2 mm notch where
two boxes of a nut meet) is left out, counted in the prism's difference from the mesh.

A convex piece holds at most one edge of a bore (its corners point into the piece), so a
finely tessellated round bore (128 edges of 0.26 mm) has no piece thick enough. Then the
bore is made coarser (:func:`coarser_bores`): a polygon of some of its corners, inscribed
in it, so the cell's bore is smaller by a ``loss`` (the largest distance of the bore from
it), never larger; the finest that works within the ``allowed`` loss is taken and the
loss reported.
"""

from __future__ import annotations

import hashlib

import numpy as np
import shapely
import trimesh

from executor.world.meshes import URDF_HULL_MARGIN

MIN_BORE_CORNERS = 6
"""A bore made coarser keeps at least this many corners."""
PRISM_TOLERANCE = 0.01
"""A part is the prism of its mid-height section when the two differ by less than this
fraction of its volume."""
_CONVEX = 1e-9
"""A union is convex when its hull is larger by less than this fraction of its area."""


def section_at(mesh: trimesh.Trimesh, z: float) -> shapely.MultiPolygon:
    """The closed mesh's section at height ``z`` [m] of its frame: its polygons, holes
    included (each loop's inside, even-odd: a loop within one other is a hole)."""
    cut = mesh.section(plane_origin=(0.0, 0.0, z), plane_normal=(0.0, 0.0, 1.0))
    found = shapely.MultiPolygon()
    for loop in [] if cut is None else cut.discrete:
        if len(loop) >= 4:
            found = shapely.symmetric_difference(found, shapely.Polygon(np.asarray(loop)[:, :2]))
    return found if isinstance(found, shapely.MultiPolygon) else shapely.MultiPolygon([found])


def convex_parts(section: shapely.Polygon) -> list[shapely.Polygon]:
    """Convex polygons whose union is ``section`` exactly (module docstring): each
    diagonal of its constrained Delaunay triangulation, longest first, joins the pieces on
    its two sides when their union is convex."""
    triangles = [np.asarray(t.exterior.coords)[:3] for t in shapely.constrained_delaunay_triangles(section).geoms
                 if t.area > 0]
    sides: dict[tuple[tuple[float, float], ...], list[int]] = {}
    for k, corners in enumerate(triangles):
        for i in range(3):
            edge = tuple(sorted((tuple(corners[i]), tuple(corners[(i + 1) % 3]))))
            sides.setdefault(edge, []).append(k)
    owner = list(range(len(triangles)))
    pieces: dict[int, shapely.Polygon] = {k: shapely.Polygon(c) for k, c in enumerate(triangles)}

    def root(k: int) -> int:
        while owner[k] != k:
            owner[k] = owner[owner[k]]
            k = owner[k]
        return k

    diagonals = sorted((edge for edge, on in sides.items() if len(on) == 2),
                       key=lambda e: -float(np.hypot(e[0][0] - e[1][0], e[0][1] - e[1][1])))
    for edge in diagonals:
        a, b = (root(k) for k in sides[edge])
        if a == b:
            continue
        union = shapely.union(pieces[a], pieces[b])
        if isinstance(union, shapely.Polygon) and union.convex_hull.area - union.area <= _CONVEX * union.area:
            owner[b] = a
            pieces[a] = shapely.simplify(union, 0.0)
            del pieces[b]
    return list(pieces.values())


Found = tuple[list[tuple[trimesh.Trimesh, float]], str] | str
"""A part's pieces, each with 0.0 (no vertex dropped), and how they were made; or why it has none."""
_FOUND: dict[bytes, Found] = {}
""":func:`ring_pieces` of each part and mesh asked for (an import asks for each more than once)."""


def ring_pieces(pid: str, mesh: trimesh.Trimesh, allowed: float = 0.0) -> Found:
    """The convex pieces of part ``pid`` with a bore, its closed ``mesh`` in its part frame
    [m] (z its axis; module docstring), each with 0.0 (no vertex dropped) and a line saying
    how they were made; or why the part has none: no prism of its section, or a piece at
    the bore too thin for the cell even with the bore made coarser by at most ``allowed``
    [m] (:func:`coarser_bores`)."""
    key = hashlib.sha256(pid.encode() + np.float64(allowed).tobytes() + np.ascontiguousarray(mesh.vertices).tobytes()
                         + np.ascontiguousarray(mesh.faces).tobytes()).digest()
    if key not in _FOUND:
        _FOUND[key] = _pieces(pid, mesh, allowed)
    return _FOUND[key]


def coarser_bores(section: shapely.Polygon, allowed: float) -> list[tuple[shapely.Polygon, float]]:
    """``section`` (loss 0.0) and, for one bore of more than :data:`MIN_BORE_CORNERS`
    corners, that bore made coarser: every k-th of its corners kept (k = 2, 3, ...), a
    polygon inscribed in it whose farthest point of the bore lies ``loss`` [m] outside it,
    while the loss is at most ``allowed`` [m] and :data:`MIN_BORE_CORNERS` corners are left;
    each with its loss, finest first. The material grows into the bore: the cell's bore
    is smaller, never larger."""
    found = [(section, 0.0)]
    if len(section.interiors) != 1:
        return found
    corners = np.asarray(section.interiors[0].coords)[:-1]
    step = 2
    while len(corners) // step >= MIN_BORE_CORNERS:
        kept = shapely.LinearRing(corners[::step])
        loss = float(shapely.hausdorff_distance(section.interiors[0], kept))
        if loss > allowed:
            break
        found.append((shapely.Polygon(section.exterior.coords, [kept.coords]), loss))
        step += 1
    return found


def _pieces(pid: str, mesh: trimesh.Trimesh, allowed: float) -> Found:
    """:func:`ring_pieces`, made."""
    low, high = (float(v) for v in mesh.bounds[:, 2])
    section = section_at(mesh, (low + high) / 2)
    if len(section.geoms) != 1 or not section.geoms[0].interiors:
        return f"part '{pid}' has no bore in one section at half its height"
    shape = section.geoms[0]
    prism = trimesh.creation.extrude_polygon(shape, high - low)
    prism.apply_translation((0.0, 0.0, low))
    common = trimesh.boolean.intersection([mesh, prism], engine="manifold")
    differ = mesh.volume + prism.volume - 2 * (float(common.volume) if len(common.faces) else 0.0)
    if differ >= PRISM_TOLERANCE * mesh.volume:
        return (f"part '{pid}' is no prism of its section at half its height (they differ by {differ / mesh.volume:.1%}"
                f" of its volume; the cell's exact pieces of a part with a bore are a prism's)")
    height = high - low
    candidates = coarser_bores(shape, allowed)
    # the exact section first, then the finest coarser bore that works, found by bisection
    # (a coarser bore has wider pieces at it); each one returned is checked whole
    order, low_k, high_k = [0], 1, len(candidates) - 1
    tried: dict[int, tuple[list[tuple[trimesh.Trimesh, float]], float] | None] = {}
    while order:
        k = order.pop()
        tried[k] = _cut(candidates[k][0], low, high)
        if k == 0 and tried[0] is None and low_k <= high_k:
            order.append((low_k + high_k) // 2)
        elif k > 0:
            low_k, high_k = (low_k, k - 1) if tried[k] is not None else (k + 1, high_k)
            if low_k <= high_k:
                order.append((low_k + high_k) // 2)
    working = {k: found for k, found in tried.items() if found is not None}
    if working:
        k = min(working)
        (pieces, dropped), (cut, loss) = working[k], candidates[k]
        if differ + dropped * height >= PRISM_TOLERANCE * mesh.volume:
            return (f"part '{pid}': the convex pieces of its section thick enough for the cell differ from its "
                    f"mesh by {(differ + dropped * height) / mesh.volume:.1%} of its volume")
        bore = ("exact at the bore" if loss == 0 else
                f"the bore {len(cut.interiors[0].coords) - 1}-cornered, inscribed in the mesh's, "
                f"{1e6 * loss:.1f} um smaller")
        return pieces, (f"{bore}: {len(pieces)} convex prism(s) of its section at half its height over its "
                        f"{1e3 * height:.3f} mm, {(differ + dropped * height) / mesh.volume:.2%} of its volume apart "
                        "from the mesh (slivers of the outline thinner than the cell's hull margin twice left out)")
    return (f"part '{pid}': a convex piece of its section at its bore is thinner than {2000 * URDF_HULL_MARGIN:g} mm "
            f"(the cell's hull margin twice; a coarser bore would lose more than {1e6 * allowed:.1f} um)")


def _cut(section: shapely.Polygon, low: float, high: float) -> tuple[list[tuple[trimesh.Trimesh, float]], float] | None:
    """The convex prisms from ``low`` to ``high`` [m] of ``section``'s convex parts and the
    area [m²] of the outline's slivers left out (parts away from the bore too thin for the
    cell); None when a part at the bore is too thin. A right prism's eroded form (the
    cell's, :func:`executor.world.meshes.eroded`) is its section's inset by the margin over
    its height less twice the margin: it has one when both are something."""
    bores = shapely.MultiLineString([ring.coords for ring in section.interiors])
    parts = convex_parts(section)
    tall = high - low > 2 * URDF_HULL_MARGIN
    thick = [tall and not shapely.buffer(part, -URDF_HULL_MARGIN).is_empty for part in parts]
    if any(not ok and part.distance(bores) == 0 for ok, part in zip(thick, parts)):
        return None
    pieces = []
    for part in (part for ok, part in zip(thick, parts) if ok):
        ring = np.asarray(part.exterior.coords)[:-1]
        pieces.append((trimesh.convex.convex_hull(np.vstack([np.column_stack([ring, np.full(len(ring), z)])
                                                              for z in (low, high)])), 0.0))
    return pieces, sum(part.area for ok, part in zip(thick, parts) if not ok)
