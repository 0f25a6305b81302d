"""Parts with a bore that go onto a pin (a nut, a washer, a gear, a pulley), as the cell
collides with them: their convex pieces, exact or with a bore smaller by a stated loss.

A moving part collides as convex pieces (:mod:`executor.world.meshes`). A decomposition
that approximates (CoACD) fills part of a bore, and the room between a pin and its bore is
what decides whether the part goes on. So a part with a bore is taken as what it is in
most products, a **stack of prisms** (:func:`stack`): it is cut across its axis (z of its
part frame) at the levels of its faces across that axis (within :data:`LEVEL`), each
layer's section the union of its sections near its ends and at its middle (a chamfer or a
set-screw hole adds material, never removes it: the bore is the layer's narrowest), and
adjacent layers are joined while that adds less than :data:`PRISM_TOLERANCE` of the
part's volume (a gear: its teeth, then its hub). It is such a stack when the layers'
prisms and the mesh differ by less than that (exact booleans, manifold3d). Each section,
a polygon with the bore as its hole (and the part's outline, a gear's teeth or a nut's
handle, as its shell), is cut into convex polygons whose union is that section exactly:
its constrained Delaunay triangles (shapely) merged across their diagonals, longest
first, while the union stays convex (Hertel and Mehlhorn: at most four times the fewest
convex pieces). Each convex polygon swept over its layer is a piece. Every piece touching
the bore must have an eroded form (:func:`executor.world.meshes.eroded`: its section inset
by the cell's hull margin is something, and its height is more than twice the margin), so
the bore's faces are where the mesh has them and only edges are rounded by the margin; the
thinner parts away from the bore (a gear's teeth, the 0.2 mm notch where two boxes of a
nut meet) are left out, up to :data:`THIN_TOLERANCE` of the part's volume.

A convex piece holds at most one edge of a bore (its corners point into the piece), so a
finely tessellated round bore (128 edges of 0.26 mm) has no piece thick enough. Then the
bore is made coarser (:func:`coarser_bores`): a polygon of some of its corners, inscribed
in it, so the cell's bore is smaller by a ``loss`` (the largest distance of the bore from
it), never larger; the finest that works within the ``allowed`` loss is taken and the
loss reported. A round bore of a part that goes onto round pins only is made a regular
polygon about its inscribed circle instead (:func:`round_bores`, :func:`sector_parts`): a
round pin passes it exactly when it passes the bore; for a fit whose room the cell does not
resolve, about that circle grown by the room the cell gives such a fit (``widen``), so a
round pin passes it as it passes the bore widened by that room.

A part on pins not all round that is no such stack (a knob on a D shaft: its top a wall
across the bore, its recess tapering to the bore in a layer thinner than the cell
collides as, its outside tapered) may be a stack of layers of which some have no bore,
thin ones joined to the next (:func:`_joined`), and those that are no prisms the hulls of
the mesh within their section's convex parts (:func:`_cut`); and its bore, where no
coarser one gives pieces (faces narrower than the hull margin twice), its round part a
regular polygon cut by its flats that leaves each pin the room the bore does
(:func:`flat_bores`).
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
from collections.abc import Callable

import numpy as np
import shapely
import trimesh

from executor.world import SIZE_RESOLUTION
from executor.world.meshes import MIN_THICKNESS, URDF_HULL_MARGIN, eroded

ROUND_BORE_CORNERS = (64, 48, 32, 24, 16, 12, 8)
"""The corners of the regular polygons a round bore on round pins is tried as (:func:`round_bores`)."""
MIN_BORE_CORNERS = 6
"""A bore made coarser keeps at least this many corners."""
THIN_TOLERANCE = 0.2
"""The parts of a part's sections away from its bore that are too thin for the cell (a
gear's teeth) are left out up to this fraction of its volume."""
PRISM_TOLERANCE = 0.01
"""A part is the prism of its mid-height section when the two differ by less than this
fraction of its volume."""
LEVEL = 1e-5
"""Faces across the axis within this height [m] of each other are at one level."""
_ACROSS = 1e-6
"""A face is across the axis when its normal is within this of it (1 - |n_z|)."""
_INSET = 0.01
"""A layer's sections are taken this fraction of its height inside its ends, and at its middle."""
_GRID = 1e-8
"""A layer's section is snapped to this grid [m] (a union of sections has corners closer
than a mesh can be made of)."""
_KEPT = 1e-9
"""[m] a piece at a bore, eroded and grown back by the hull margin, still touches the bore within this."""
_CONVEX = 1e-9
"""A union is convex when its hull is larger by less than this fraction of its area."""


def section_at(mesh: trimesh.Trimesh, z: float) -> shapely.MultiPolygon:
    """The closed mesh's section at height ``z`` [m] of its frame: its polygons, holes
    included (each loop's inside, even-odd: a loop within one other is a hole). What the
    overlay leaves of no area (a line of a few um where two loops nearly meet) is dropped."""
    cut = mesh.section(plane_origin=(0.0, 0.0, z), plane_normal=(0.0, 0.0, 1.0))
    found = shapely.MultiPolygon()
    for loop in [] if cut is None else cut.discrete:
        if len(loop) >= 4:
            found = shapely.symmetric_difference(found, shapely.Polygon(np.asarray(loop)[:, :2]))
    return shapely.MultiPolygon([part for part in shapely.get_parts(found) if isinstance(part, shapely.Polygon)])


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


class NoStack(str):
    """Why a part is no stack of prisms of its sections (its pieces are then made otherwise:
    :func:`executor.cad.convex.pin_pieces`)."""


Found = tuple[list[tuple[trimesh.Trimesh, float]], str] | str
"""A part's pieces, each with 0.0 (no vertex dropped), and how they were made; or why it has none."""
_FOUND: dict[bytes, Found] = {}
""":func:`ring_pieces` of each part and mesh asked for (an import asks for each more than once)."""


def ring_pieces(pid: str, mesh: trimesh.Trimesh, allowed: float = 0.0, round_pins: bool = False,
                bores: int = 1, widen: float = 0.0, pins: tuple[shapely.Polygon, ...] = ()) -> Found:
    """The convex pieces of part ``pid`` with ``bores`` bores (one per pin it goes onto: a
    plate over two dowel pins has two), its closed ``mesh`` in its part frame [m] (z its
    axis; module docstring), each with 0.0 (no vertex dropped) and a line saying how they
    were made; or why the part has none: no prism of its sections with that many bores, a
    layer no thicker than the cell's hull margin twice (a 1.2 mm clutch plate: none of its
    pieces has an eroded form), or
    a piece at a bore too thin for the cell even with the bore made coarser by at most
    ``allowed`` [m] (:func:`coarser_bores`, one bore only), or, when it goes onto
    ``round_pins`` only, circumscribing each bore's inscribed circle grown by ``widen`` [m]
    (:func:`round_bores`: the cell's room of a fit it does not resolve; 0 elsewhere), or,
    where no coarser bore within ``allowed`` keeps it, with its round part a regular polygon
    cut by its flats that leaves each of ``pins`` (their sections in the part frame, axes
    together with the bore) the room the bore does (:func:`flat_bores`)."""
    assert round_pins or not widen  # a bore is widened about its inscribed circle only
    key = hashlib.sha256(pid.encode() + np.float64(allowed).tobytes() + np.float64(widen).tobytes()
                         + bytes([round_pins, bores]) + np.ascontiguousarray(mesh.vertices).tobytes()
                         + b"".join(shapely.to_wkb(pin) for pin in pins)
                         + np.ascontiguousarray(mesh.faces).tobytes()).digest()
    if key not in _FOUND:
        _FOUND[key] = _pieces(pid, mesh, allowed, round_pins, bores, widen, pins)
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


def _discs(section: shapely.Polygon, centres: list[np.ndarray]) -> list[float]:
    """The radius [m] of each bore's disc: the largest circle about its centre (``centres``,
    one per bore of ``section``) within the section's outline and at most half way to the
    other bores' centres (the discs of two bores do not overlap)."""
    outline = shapely.Polygon(section.exterior).exterior
    return [min([float(shapely.distance(shapely.Point(*centre), outline)),
                 *(float(np.linalg.norm(centre - other)) / 2 for other in centres if other is not centre)])
            for centre in centres]


def sector_parts(section: shapely.Polygon, centres: list[np.ndarray] | None = None) -> list[shapely.Polygon]:
    """Convex polygons whose union is ``section``, whose bores are regular polygons
    (:func:`round_bores`): for each edge of a bore, the sector between the rays from the
    bore's centre through its ends, out to the bore's disc (:func:`_discs`: the largest
    circle about the centre within the section's outline, half way to the other bores at
    most; a polygon inscribed in it; of a section with several bores, the polygon of those
    rays inscribed in it); and the convex parts (:func:`convex_parts`) of what lies beyond
    those discs (a gear's teeth, a handle, the plate between two bores). Each bore's centre
    is the mean of its corners, or as given (``centres``: a bore cut by a flat, about its
    round part's, :func:`flat_bores`)."""
    outline = shapely.Polygon(section.exterior)
    cores, discs = [], []
    rings = [np.asarray(ring.coords)[:-1] for ring in section.interiors]
    centres = centres or [np.round(corners.mean(axis=0) / _GRID) * _GRID for corners in rings]  # one disc a bore
    for corners, centre, inner in zip(rings, centres, _discs(section, centres)):
        far = 2 * float(np.max(np.linalg.norm(np.asarray(outline.exterior.coords) - centre, axis=1)))
        if len(section.interiors) == 1:
            disc = shapely.Point(*centre).buffer(inner, quad_segs=32)
        else:  # what lies between the bores has straight sides, not arcs that only slivers fill
            rays = (corners - centre) / np.linalg.norm(corners - centre, axis=1)[:, None]
            disc = shapely.Polygon(centre + inner * rays)
        discs.append(disc)
        for a, b in zip(corners, np.roll(corners, -1, axis=0)):
            wedge = shapely.Polygon([a, b, centre + far * (b - centre) / np.linalg.norm(b - centre),
                                     centre + far * (a - centre) / np.linalg.norm(a - centre)])
            cores.append(shapely.intersection(wedge, disc))
    return cores + list(_beyond(outline, shapely.union_all(discs)))


@functools.lru_cache(maxsize=16)
def _beyond(outline: shapely.Polygon, discs: shapely.Geometry) -> tuple[shapely.Polygon, ...]:
    """The convex parts of ``outline`` beyond ``discs`` (the same for every bore tried)."""
    beyond = shapely.difference(outline, discs)
    return tuple(part for polygon in getattr(beyond, "geoms", [beyond]) if isinstance(polygon, shapely.Polygon)
                 and polygon.area > 0 for part in convex_parts(shapely.set_precision(polygon, _GRID)))


def round_bores(section: shapely.Polygon, allowed: float, widen: float = 0.0) -> list[tuple[shapely.Polygon, float]]:
    """``section`` with each bore made a regular polygon of :data:`ROUND_BORE_CORNERS`
    corners (most first) whose inscribed circle is the bore's (about its centroid) grown by
    ``widen`` [m] (0: the bore's own), within the bore's disc (:func:`_discs`); each with
    loss 0.0 (``allowed`` is not needed): a round pin passes such a polygon exactly when it
    passes that circle, as it passes the bore (``widen`` 0). The polygon's corners reach
    beyond the bore, so it is for parts that go onto round pins only."""
    found: list[tuple[shapely.Polygon, float]] = []
    centres = [np.array(shapely.Polygon(ring).centroid.coords[0]) for ring in section.interiors]
    discs = _discs(section, centres)
    radii = [float(shapely.distance(shapely.Point(*centre), ring)) + widen
             for ring, centre in zip(section.interiors, centres)]
    for corners in ROUND_BORE_CORNERS:
        turn = np.linspace(0.0, 2 * np.pi, corners, endpoint=False)
        reach = [radius / np.cos(np.pi / corners) for radius in radii]
        if any(far >= inner for far, inner in zip(reach, discs)):
            continue
        rings = [np.column_stack([centre[0] + far * np.cos(turn), centre[1] + far * np.sin(turn)])
                 for far, centre in zip(reach, centres)]
        found.append((shapely.Polygon(section.exterior.coords, rings), 0.0))
    return found


FLAT = 4 * URDF_HULL_MARGIN
"""[m] an edge of a bore at least this long is a flat of it (a D bore's), which the cell's
pieces keep (:func:`flat_bores`): a face that long keeps its middle under the hull margin."""
ROOM_KEPT = SIZE_RESOLUTION / 5
"""[m] the cell's bore of :func:`flat_bores` leaves each pin the room the bore does within
this, a fifth of what the cell resolves (a tessellated round pin's room in a polygon
changes by a few um with the polygon's corners: a 60-gon of d 6 in an 8-gon about d 6.4,
0.201 mm, in the 13-gon it replaces 0.200)."""


def room_in(pin: shapely.Polygon, bore: shapely.Polygon) -> float:
    """The room [m] of a ``pin``'s section in a ``bore``'s, axes as placed (no shift or turn):
    the distance from the pin to the bore's outline where the pin lies within it, else minus
    the farthest its corners reach outside it."""
    if bore.contains(pin):
        return float(shapely.distance(bore.exterior, pin))
    return -max(float(shapely.distance(shapely.Point(corner), bore)) for corner in pin.exterior.coords)


def flat_bores(section: shapely.Polygon, pins: tuple[shapely.Polygon, ...], widen: float = 0.0
               ) -> list[tuple[shapely.Polygon, float]]:
    """``section`` with its one bore made a regular polygon of :data:`ROUND_BORE_CORNERS`
    corners (most first) about the largest circle within its edges shorter than
    :data:`FLAT` (its round part: a knob's 13-gon), grown by ``widen`` [m], cut by its
    flats (edges at least that long: a D's), within the bore's disc (:func:`_discs`); each
    with loss 0.0, kept only where every pin of ``pins`` (their sections in the part frame,
    axes together with the bore) has the room in it that it has in the bore
    (:func:`room_in`, within :data:`ROOM_KEPT`, grown by ``widen``): the fits and no-fits and
    the rooms the cell sees are the mesh's. For a bore whose faces are narrower than the
    cell's hull margin twice (a 13-gon of 1.6 mm faces), which no convex pieces keep."""
    if len(section.interiors) != 1 or not pins:
        return []
    bore = shapely.simplify(shapely.Polygon(section.interiors[0]), _GRID)
    corners = np.asarray(bore.exterior.coords)[:-1]
    edges = list(zip(corners, np.roll(corners, -1, axis=0)))
    flats = [_side(bore, a, b) for a, b in edges if np.linalg.norm(b - a) >= FLAT]
    rounds = [(a, b) for a, b in edges if np.linalg.norm(b - a) < FLAT]
    if not rounds:
        return []
    centre, radius = _inscribed(bore, rounds)
    radius += widen
    disc = _discs(section, [centre])[0]
    found = []
    for count in ROUND_BORE_CORNERS:
        turn = np.linspace(0.0, 2 * np.pi, count, endpoint=False)
        reach = radius / np.cos(np.pi / count)
        if reach >= disc:
            continue
        made = shapely.Polygon(centre + reach * np.column_stack([np.cos(turn), np.sin(turn)]))
        made = shapely.intersection_all([made, *flats])
        if not isinstance(made, shapely.Polygon) or made.is_empty:
            continue
        made = shapely.set_precision(_whole_edges(made, 2 * reach * np.sin(np.pi / count)), _GRID)
        if not isinstance(made, shapely.Polygon) or any(
                abs(room_in(pin, made) - room_in(pin, bore) - (widen if room_in(pin, bore) >= 0 else 0.0)) > ROOM_KEPT
                for pin in pins):
            continue
        found.append((shapely.Polygon(section.exterior.coords, [made.exterior.coords]), 0.0))
    return found


def _side(bore: shapely.Polygon, a: np.ndarray, b: np.ndarray) -> shapely.Polygon:
    """The bore's side of its edge ``a`` -> ``b`` [m], a half-plane as far as matters (a
    polygon four times the bore's size beyond it)."""
    far = 4 * float(np.max(np.ptp(np.asarray(bore.exterior.coords), axis=0)))
    along = (b - a) / np.linalg.norm(b - a)
    into = np.array([-along[1], along[0]]) * (1.0 if bore.exterior.is_ccw else -1.0)
    return shapely.Polygon([a - far * along, b + far * along, b + far * along + far * into,
                            a - far * along + far * into])


def _inscribed(bore: shapely.Polygon, edges: list[tuple[np.ndarray, np.ndarray]]) -> tuple[np.ndarray, float]:
    """The centre and radius [m] of the largest circle on the bore's side of each of its ``edges``."""
    circle = shapely.maximum_inscribed_circle(shapely.intersection_all([_side(bore, a, b) for a, b in edges]), _GRID)
    return np.round(np.array(circle.coords[0]) / _GRID) * _GRID, float(circle.length)


def _centre_of(section: shapely.Polygon) -> np.ndarray:
    """The centre [m] of the regular polygon the bore of ``section`` was made of by
    :func:`flat_bores`: the point as far from each of its whole edges (the shortest: its
    flats and the edges extended to them are longer) along their normals through their
    middles (least squares)."""
    bore = shapely.orient_polygons(shapely.Polygon(section.interiors[0]))
    corners = np.asarray(bore.exterior.coords)[:-1]
    ends = np.roll(corners, -1, axis=0)
    lengths = np.linalg.norm(ends - corners, axis=1)
    whole = lengths <= np.min(lengths) * (1 + 1e-6)
    along = (ends - corners)[whole] / lengths[whole][:, None]
    inward = np.column_stack([-along[:, 1], along[:, 0]])  # counter-clockwise: the bore to the left
    middles = ((corners + ends) / 2)[whole]
    # centre - r * inward = middle: two equations an edge, in (x, y, r)
    rows = np.vstack([np.column_stack([np.ones(len(middles)), np.zeros(len(middles)), -inward[:, 0]]),
                      np.column_stack([np.zeros(len(middles)), np.ones(len(middles)), -inward[:, 1]])])
    solved = np.linalg.lstsq(rows, np.concatenate([middles[:, 0], middles[:, 1]]), rcond=None)[0]
    return np.round(solved[:2] / _GRID) * _GRID


def _flat_parts(section: shapely.Polygon) -> list[shapely.Polygon]:
    """:func:`sector_parts` of a section whose bore :func:`flat_bores` made, about its
    regular polygon's centre (:func:`_centre_of`); of a section with no bore, its convex parts."""
    return sector_parts(section, [_centre_of(section)]) if section.interiors else convex_parts(section)


def _whole_edges(polygon: shapely.Polygon, edge: float) -> shapely.Polygon:
    """The convex ``polygon`` with each edge shorter than ``edge`` [m] (a regular polygon's
    edge cut short by a flat) taken out by extending the edges on either side of it to
    where they meet (the polygon grows there), while they meet beyond it and more than
    three corners are left: a convex piece of a bore holds one edge, which must be wide
    enough for the cell's hull margin."""
    corners = [np.asarray(c) for c in np.asarray(shapely.orient_polygons(polygon).exterior.coords)[:-1]]
    k = 0
    while k < len(corners) and len(corners) > 3:
        n = len(corners)
        a, b = corners[k], corners[(k + 1) % n]
        if float(np.linalg.norm(b - a)) >= (1 - 1e-6) * edge:
            k += 1
            continue
        before, after = corners[k - 1], corners[(k + 2) % n]
        u, v = a - before, after - b
        cross = u[0] * v[1] - u[1] * v[0]
        if cross <= 0:  # the edges on either side do not meet beyond it
            k += 1
            continue
        t = ((b - before)[0] * v[1] - (b - before)[1] * v[0]) / cross
        corners[k] = before + t * u
        del corners[(k + 1) % n]
        k = 0
    return shapely.Polygon(corners)


def layers_of(mesh: trimesh.Trimesh) -> list[tuple[shapely.Geometry, float, float]]:
    """The layers of a closed ``mesh`` in its part frame [m] (module docstring), each as (its
    section, its bottom, its top) [m], the section the union of its sections near its ends
    and at its middle (polygons, holes included), adjacent layers joined while that adds
    less than :data:`PRISM_TOLERANCE` of the part's volume."""
    low, high = (float(v) for v in mesh.bounds[:, 2])
    levels = [low]
    for z in np.sort(mesh.triangles_center[np.abs(mesh.face_normals[:, 2]) > 1 - _ACROSS, 2]):
        if z - levels[-1] > LEVEL and high - z > LEVEL:
            levels.append(float(z))
    levels.append(high)
    layers: list[tuple[shapely.Geometry, float, float]] = []
    for bottom, top in zip(levels, levels[1:]):
        inset = _INSET * (top - bottom)
        section = shapely.set_precision(shapely.union_all(
            [section_at(mesh, z) for z in (bottom + inset, (bottom + top) / 2, top - inset)]), _GRID)
        if layers:
            below, start, _ = layers[-1]
            union = shapely.set_precision(shapely.union(below, section), _GRID)
            if (union.area * (top - start) - below.area * (bottom - start) - section.area * (top - bottom)
                    < PRISM_TOLERANCE * mesh.volume):
                layers[-1] = (union, start, top)
                continue
        layers.append((section, bottom, top))
    return layers


def stack(pid: str, mesh: trimesh.Trimesh, bores: int = 1, caps: bool = False
          ) -> list[tuple[shapely.Polygon, float, float]] | str:
    """The layers of part ``pid`` with ``bores`` bores, its closed ``mesh`` in its part
    frame [m] (:func:`layers_of`), each as (its section, its bottom, its top) [m], the
    section one polygon with that many bores, or, with ``caps``, with none (a wall across
    them: a knob's top over the shaft's end); or why it has none."""
    low = float(mesh.bounds[0][2])
    found = []
    for section, bottom, top in layers_of(mesh):
        polygons = list(getattr(section, "geoms", [section]))
        if len(polygons) != 1 or len(polygons[0].interiors) not in ((0, bores) if caps else (bores,)):
            many = "one bore" if bores == 1 else f"{bores} bores"
            return NoStack(f"part '{pid}' has no {many} in its section from {1e3 * (bottom - low):.3f} to "
                           f"{1e3 * (top - low):.3f} mm of its height")
        found.append((polygons[0], bottom, top))
    return found


def _pieces(pid: str, mesh: trimesh.Trimesh, allowed: float, round_pins: bool, bores: int, widen: float,
            pins: tuple[shapely.Polygon, ...]) -> Found:
    """:func:`ring_pieces`, made: a stack of prisms; where it has none and its pins are not
    all round (``pins``), the stack with the further layers and bores of :func:`_stacked`
    (its reason when that has none either)."""
    found = _stacked(pid, mesh, allowed, round_pins, bores, widen, ())
    if not isinstance(found, str) or round_pins or not pins:
        return found
    other = _stacked(pid, mesh, allowed, round_pins, bores, widen, pins)
    return found if isinstance(other, str) else other


def _stacked(pid: str, mesh: trimesh.Trimesh, allowed: float, round_pins: bool, bores: int, widen: float,
             pins: tuple[shapely.Polygon, ...]) -> Found:
    """The pieces of :func:`ring_pieces` as a stack of prisms of its sections; with ``pins``
    (their sections, for :func:`flat_bores`) also a stack whose layers may have no bore
    (a wall across it, at an end), whose layers at a bore thinner than the cell's hull
    margin twice are joined to the next (:func:`_joined`), whose layers that are no prisms
    are hulls within their section's parts (:func:`_cut`), and whose bores may be made of
    their round part and flats (:func:`flat_bores`); or why there is none."""
    if not mesh.is_volume:  # as written, a mesh can lose a sliver face to rounding
        return NoStack(f"part '{pid}': its mesh as written is no closed volume to compare with prisms of its sections")
    layers = stack(pid, mesh, bores, caps=bool(pins))
    if isinstance(layers, str):
        return layers
    low = float(mesh.bounds[0][2])
    if not any(section.interiors for section, _, _ in layers):
        return NoStack(f"part '{pid}' has no bore in its sections")
    layers, joined = _joined(layers, bores) if pins else (layers, set())
    centre, size = mesh.bounds.mean(axis=0), 2 * mesh.extents
    differ = excess = 0.0
    insides: list[trimesh.Trimesh | None] = []
    for section, bottom, top in layers:
        prism = trimesh.creation.extrude_polygon(section, top - bottom)
        prism.apply_translation((0.0, 0.0, bottom))
        common = trimesh.boolean.intersection([mesh, prism], engine="manifold")
        slab = trimesh.creation.box((size[0], size[1], top - bottom))
        slab.apply_translation((centre[0], centre[1], (bottom + top) / 2))
        inside = trimesh.boolean.intersection([mesh, slab], engine="manifold")
        volume = float(inside.volume) if len(inside.faces) else 0.0
        here = prism.volume + volume - 2 * (float(common.volume) if len(common.faces) else 0.0)
        flat = not pins or ((bottom, top) not in joined and differ + here < PRISM_TOLERANCE * mesh.volume)
        differ += here if flat else 0.0
        insides.append(None if flat else inside)
    if differ >= PRISM_TOLERANCE * mesh.volume:
        return NoStack(f"part '{pid}' is no stack of prisms of its sections (they differ by "
                       f"{differ / mesh.volume:.1%} of its volume over {len(layers)} layer(s); the cell's exact "
                       "pieces of a part with a bore are prisms')")
    thin = next(((bottom, top) for section, bottom, top in layers
                 if top - bottom < MIN_THICKNESS and section.interiors), None)
    if thin is not None:  # no piece of this layer at its bore has an eroded form, whatever its bore
        return (f"part '{pid}': its layer from {1e3 * (thin[0] - low):.3f} to {1e3 * (thin[1] - low):.3f} mm of its "
                f"height, at its bore, is thinner than the cell's hull margin twice less what it resolves "
                f"({1e3 * MIN_THICKNESS:g} mm)")
    # the exact sections first, then the finest coarser bores that work, found by bisection
    # (a coarser bore has wider pieces at it); each one returned is checked whole; then, for
    # a bore that none keeps, its round part a regular polygon cut by its flats
    searches: list[tuple[Callable[[shapely.Polygon], list[tuple[shapely.Polygon, float]]],
                         Callable[[shapely.Polygon], list[shapely.Polygon]]]] = (
        [(lambda section: round_bores(section, allowed, widen), sector_parts)] if round_pins
        else [(lambda section: coarser_bores(section, allowed), convex_parts)]
        + ([(lambda section: flat_bores(section, pins), _flat_parts)] if pins else []))
    tried: dict[int, tuple[list[tuple[trimesh.Trimesh, float]], float, float] | None] = {}
    for search, (make, partition) in enumerate(searches):
        made = {k: make(section) for k, (section, _, _) in enumerate(layers) if section.interiors}
        padded = max(len(c) for c in made.values())  # a layer with no bore is the same whatever its bore (none)
        candidates = [made.get(k, [(section, 0.0)] * padded) for k, (section, _, _) in enumerate(layers)]
        order, low_k, high_k = [0], 1, min(len(c) for c in candidates) - 1
        if high_k < 0:
            if search:  # no polygon of the round part within the outline: the coarser bores' why
                break
            return f"part '{pid}': no regular polygon about its bore lies within its outline"
        tried = {}
        while order:
            k = order.pop()
            tried[k] = _cut([(c[k][0], bottom, top) for c, (_, bottom, top) in zip(candidates, layers)],
                            partition, insides)
            if k == 0 and tried[0] is None and low_k <= high_k:
                order.append((low_k + high_k) // 2)
            elif k > 0:
                low_k, high_k = (low_k, k - 1) if tried[k] is not None else (k + 1, high_k)
                if low_k <= high_k:
                    order.append((low_k + high_k) // 2)
        if any(found is not None for found in tried.values()):
            break
    working = {k: found for k, found in tried.items() if found is not None}
    if working:
        k = min(working)
        (pieces, dropped, excess), loss = working[k], max(c[k][1] for c in candidates)
        if dropped >= THIN_TOLERANCE * mesh.volume:
            return (f"part '{pid}': the parts of its sections thinner than the cell's hull margin twice are "
                    f"{dropped / mesh.volume:.1%} of its volume (at most {THIN_TOLERANCE:.0%} are left out)")
        if excess >= HULL_TOLERANCE * mesh.volume:
            return NoStack(f"part '{pid}' is no stack of prisms of its sections, nor of hulls within them (its layers "
                           f"that are no prisms differ from their hulls by {excess / mesh.volume:.1%} of its volume, "
                           f"at most {HULL_TOLERANCE:.0%})")
        corners = "/".join(map(str, sorted({len(ring.coords) - 1 for c in candidates for ring in c[k][0].interiors})))
        grown = (f" grown by {1e3 * widen:g} mm (a fit whose room the cell does not resolve: round pins pass it as "
                 "they pass the mesh's widened by that per side)" if widen else "")
        bore = (f"the bore a regular {corners}-gon about its inscribed circle" + (grown or " (round pins pass it as "
                "they pass the mesh's)") if round_pins and bores == 1 else
                f"each of its {bores} bores a regular {corners}-gon about its inscribed circle" + (grown or
                " (round pins pass them as they pass the mesh's)") if round_pins else
                f"the bore's round part a regular polygon about its inscribed circle, cut by its flats, {corners} "
                f"corners (each pin's room in it the bore's within {1e3 * ROOM_KEPT:g} mm)" if search else
                "exact at the bore" if k == 0 else
                f"the bore {corners}-cornered, inscribed in the mesh's, {1e6 * loss:.1f} um smaller")
        heights = ", ".join(f"{1e3 * (top - bottom):.3f}{'' if inside is None else ' (hulls)'}"
                            for (_, bottom, top), inside in zip(layers, insides))
        hulls = "" if all(inside is None for inside in insides) else (
            f", the hulls within them {excess / mesh.volume:.2%} beyond it")
        return pieces, (f"{bore}: {len(pieces)} convex prism(s) of its section(s) over its {len(layers)} layer(s) of "
                        f"{heights} mm, {differ / mesh.volume:.2%} of its volume apart from the mesh{hulls}; "
                        f"the parts of its outline thinner than the cell's hull margin twice (a gear's teeth), "
                        f"{dropped / mesh.volume:.2%} of its volume, left out")
    return (f"part '{pid}': a convex piece of its section at its bore is thinner than {2000 * URDF_HULL_MARGIN:g} mm "
            f"(the cell's hull margin twice; a coarser bore would lose more than {1e6 * allowed:.1f} um)")


def _joined(layers: list[tuple[shapely.Polygon, float, float]], bores: int
            ) -> tuple[list[tuple[shapely.Polygon, float, float]], set[tuple[float, float]]]:
    """``layers`` with each layer at a bore thinner than
    :data:`executor.world.meshes.MIN_THICKNESS` (a knob's recess tapering to its bore, a
    washer under a nut) joined to the layer above it (the one below at the top), the
    section their union within that layer's outline (what of the thin layer lies beyond it,
    a washer's rim, is left out: :func:`_cut`), while that union is one polygon with
    ``bores`` bores; and the spans (bottom, top) [m] of the joined layers, which are taken
    as hulls within their section's parts (:func:`_cut`)."""
    layers, joined = list(layers), set()
    k = 0
    while k < len(layers) and len(layers) > 1:
        section, bottom, top = layers[k]
        if top - bottom >= MIN_THICKNESS or not section.interiors:
            k += 1
            continue
        other = k + 1 if k + 1 < len(layers) else k - 1
        within = shapely.intersection(section, shapely.Polygon(layers[other][0].exterior))
        union = shapely.set_precision(shapely.union(within, layers[other][0]), _GRID)
        if not isinstance(union, shapely.Polygon) or len(union.interiors) != bores:
            k += 1
            continue
        span = (min(bottom, layers[other][1]), max(top, layers[other][2]))
        layers[min(k, other)] = (union, *span)
        del layers[max(k, other)]
        joined.add(span)
        k = min(k, other)
    return layers, joined


def _cut(layers: list[tuple[shapely.Polygon, float, float]],
         partition: Callable[[shapely.Polygon], list[shapely.Polygon]],
         insides: list[trimesh.Trimesh | None]
         ) -> tuple[list[tuple[trimesh.Trimesh, float]], float, float] | None:
    """The convex prisms of each layer's section's convex parts (``partition``: :func:`convex_parts`,
    or :func:`sector_parts` about a regular bore), from its bottom to its top [m]; of a
    layer that is no prism of its section (``insides``: the mesh between its levels, None
    for a prism layer; a knob's tapered outside), the convex hull of the mesh within each
    part's prism instead (within the prism: it reaches no farther into the bore); the
    volume [m³] of the outline's slivers left out (parts away from the bore too thin for
    the cell, a wall across the bore thinner than that); and the volume [m³] by which the
    hulls exceed the mesh. None when a part at a bore is too thin. A right prism's eroded
    form (the cell's, :func:`executor.world.meshes.eroded`) is its section's inset by the
    margin over its height less twice the margin (near its middle when it is under twice the
    margin but at least :data:`executor.world.meshes.MIN_THICKNESS`): it has one when both are
    something; a hull has one when :func:`executor.world.meshes.eroded` finds it. A
    part with a face along a bore must keep that face: its inset grown back by the margin
    (what the cell collides as, its corners rounded) still reaches the bore (a sector of a
    32-gon about a d 10.2 bore, its face 1 mm wide, ends 4.1 mm out from it: a pin across
    it hung the part that low)."""
    pieces, dropped, excess = [], 0.0, 0.0
    for (section, low, high), inside in zip(layers, insides):
        bores = shapely.MultiLineString([ring.coords for ring in section.interiors])
        parts = [part for part in partition(section) if isinstance(part, shapely.Polygon) and part.area > 0]
        if abs(sum(part.area for part in parts) - section.area) > _CONVEX * 1e3 * section.area:
            return None  # the parts are no partition of the section (one over its bore)
        tall = high - low >= MIN_THICKNESS
        inset = [shapely.buffer(part, -URDF_HULL_MARGIN) for part in parts]
        if inside is None:  # a prism is swept only where it is thick enough to be kept (a gear's teeth are not)
            thick = [tall and not core.is_empty for core in inset]
            made = [_swept(part, low, high) if ok else None for ok, part in zip(thick, parts)]
            within: list[tuple[trimesh.Trimesh | None, float]] = []
        else:
            within = [_hull_within(inside, part, low, high) for part in parts]
            made = [piece for piece, _ in within]
            thick = [piece is not None and eroded(piece.vertices, URDF_HULL_MARGIN) is not None for piece in made]
        if any(not ok and section.interiors and part.distance(bores) == 0 for ok, part in zip(thick, parts)):
            return None
        faces = [shapely.intersection(part.exterior, bores).length > _KEPT for part in parts]  # along the bore
        if any(face and shapely.buffer(core, URDF_HULL_MARGIN).distance(bores) > _KEPT
               for face, core in zip(faces, inset)):
            return None
        for ok, part, piece in zip(thick, parts, made):
            if ok and piece is not None:
                pieces.append((piece, 0.0))
            else:
                dropped += (high - low) * part.area if piece is None or inside is None else float(piece.volume)
        if inside is not None:  # the hulls beyond the mesh; the mesh beyond the section's parts left out
            excess += sum(float(piece.volume) - common for piece, common in within if piece is not None)
            dropped += float(inside.volume) - sum(common for _, common in within)
    return pieces, dropped, excess


def _hull_within(inside: trimesh.Trimesh, part: shapely.Polygon, low: float, high: float
                 ) -> tuple[trimesh.Trimesh | None, float]:
    """The convex hull of the mesh ``inside`` (a layer's, from ``low`` to ``high`` [m])
    within the prism of the convex polygon ``part`` (None where it has none there), and the
    volume [m³] of the mesh there."""
    prism = trimesh.creation.extrude_polygon(shapely.set_precision(part, _GRID), high - low + 2 * LEVEL)
    prism.apply_translation((0.0, 0.0, low - LEVEL))
    if not prism.is_volume:  # a sliver the grid leaves no volume of
        return None, 0.0
    common = trimesh.boolean.intersection([inside, prism], engine="manifold")
    if not len(common.faces) or common.volume <= 0:
        return None, 0.0
    return common.convex_hull, float(common.volume)


HULL_TOLERANCE = 0.05
"""The layers of a part with no bore that are no prisms of their sections (a rocker
switch's tilted rocker) are taken as the convex hulls of the mesh between their levels
(:func:`prism_pieces`) when these hulls exceed the mesh by less than this fraction of the
part's volume (the rocker's: 2.3 %)."""
_FILLED = 0.99
"""A hole of a section's polygon is filled when the section's other polygons cover this
share of it (a lens in its flange: the mesh's two shells overlap, and the even-odd section
leaves their overlap out)."""


@dataclasses.dataclass(frozen=True)
class Prisms:
    """The convex ``pieces`` of a part with no bore made from its sections (each with 0.0: no
    vertex dropped), a line on how (``made``), and the volume [m³] added where its layers
    thinner than the cell collides as are filled to the section next to them (``filled``)."""

    pieces: list[tuple[trimesh.Trimesh, float]]
    made: str
    filled: float


def _filled(section: shapely.Geometry) -> list[shapely.Polygon]:
    """The polygons of ``section``, each hole the others cover (:data:`_FILLED`) filled, joined."""
    polygons = [p for p in getattr(section, "geoms", [section]) if isinstance(p, shapely.Polygon) and p.area > 0]
    kept = []
    for k, polygon in enumerate(polygons):
        others = shapely.union_all(polygons[:k] + polygons[k + 1:])
        holes = [ring for ring in polygon.interiors
                 if shapely.intersection(shapely.Polygon(ring), others).area < _FILLED * shapely.Polygon(ring).area]
        kept.append(shapely.Polygon(polygon.exterior, holes))
    joined = shapely.set_precision(shapely.union_all(kept), _GRID)
    return [p for p in getattr(joined, "geoms", [joined]) if isinstance(p, shapely.Polygon) and p.area > 0]


def _swept(polygon: shapely.Polygon, low: float, high: float) -> trimesh.Trimesh:
    """The convex prism of a convex ``polygon`` from ``low`` to ``high`` [m]."""
    ring = np.asarray(polygon.exterior.coords)[:-1]
    return trimesh.convex.convex_hull(np.vstack([np.column_stack([ring, np.full(len(ring), z)]) for z in (low, high)]))


def _layer_pieces(polygons: list[shapely.Polygon], bottom: float, top: float, inside: trimesh.Trimesh | None
                  ) -> list[trimesh.Trimesh]:
    """A layer's convex pieces from ``bottom`` to ``top`` [m]: the prisms of its ``polygons``'
    convex parts (:func:`convex_parts`), or, for a layer that is no prism (``inside``: the
    mesh between its levels), the convex hull of each body of that (none flatter than :data:`LEVEL`)."""
    if inside is not None:
        return [body.convex_hull for body in inside.split(only_watertight=True) if min(body.extents) > LEVEL]
    return [_swept(part, bottom, top) for polygon in polygons for part in convex_parts(polygon)]


def prism_pieces(pid: str, mesh: trimesh.Trimesh) -> Prisms | str:
    """The convex pieces of part ``pid`` with no bore (a peg), its closed ``mesh`` in its part
    frame [m] (z its axis), made from its sections (:func:`layers_of`): a layer whose prism
    and the mesh between its levels differ by little (these differences summed, less than
    :data:`PRISM_TOLERANCE` of the part's volume) is the prisms of its section's convex parts
    (:func:`convex_parts`, each polygon's holes that its other polygons fill filled), so its
    faces are the mesh's own: the section a fit was measured on goes through its hole as it
    is; any other layer is the convex hull of each body of the mesh between its levels, these
    hulls exceeding the mesh by less than :data:`HULL_TOLERANCE` of its volume. A layer at
    least :data:`executor.world.meshes.MIN_THICKNESS` tall whose pieces have no eroded form
    (:func:`executor.world.meshes.eroded`: thinner than that across a face) whose section lies
    within the thick pieces of the prism layer next to it (above first) is filled to that
    layer's section (a switch's 0.5 mm spade terminals under its body, inside its outline:
    the body's prism goes down to their ends, so the part's end, where the cell believes its
    tip, is where it collides, and it passes wherever the body does; not a chamfer, thin only
    along the axis); any other such piece is left out, up to
    :data:`THIN_TOLERANCE` of the part's volume. Returns them, or why there are none."""
    if not mesh.is_volume:
        return f"part '{pid}': its mesh as written is no closed volume to compare with prisms of its sections"
    centre, size = mesh.bounds.mean(axis=0), 2 * mesh.extents
    layers: list[tuple[list[shapely.Polygon], float, float, trimesh.Trimesh | None, float]] = []
    differ = 0.0
    for section, bottom, top in layers_of(mesh):
        slab = trimesh.creation.box((size[0], size[1], top - bottom))
        slab.apply_translation((centre[0], centre[1], (bottom + top) / 2))
        inside = trimesh.boolean.intersection([mesh, slab], engine="manifold")
        volume = float(inside.volume) if len(inside.faces) else 0.0
        polygons = _filled(section)
        common = 0.0
        for polygon in polygons:
            prism = trimesh.creation.extrude_polygon(polygon, top - bottom)
            prism.apply_translation((0.0, 0.0, bottom))
            both = trimesh.boolean.intersection([mesh, prism], engine="manifold")
            common += float(both.volume) if len(both.faces) else 0.0
        here = sum(polygon.area for polygon in polygons) * (top - bottom) + volume - 2 * common
        flat = differ + here < PRISM_TOLERANCE * mesh.volume
        differ += here if flat else 0.0
        layers.append((polygons, bottom, top, None if flat else inside, volume))
    def thick(layer: tuple[list[shapely.Polygon], float, float, trimesh.Trimesh | None, float]) -> list[bool]:
        return [eroded(piece.vertices, URDF_HULL_MARGIN) is not None for piece in _layer_pieces(*layer[:4])]

    def covers(layer: tuple[list[shapely.Polygon], float, float, trimesh.Trimesh | None, float],
               outline: shapely.Geometry) -> bool:  # a prism layer's thick pieces cover the outline
        parts = [part for polygon in layer[0] for part in convex_parts(polygon)]
        kept = [part for part, ok in zip(parts, thick(layer)) if ok]
        return layer[3] is None and shapely.union_all(kept).buffer(LEVEL).contains(outline)

    filled = 0.0
    k = 0
    while k < len(layers):
        polygons, bottom, top, inside, volume = layers[k]
        outline = shapely.union_all(polygons)
        tall = top - bottom >= MIN_THICKNESS  # thin across its section, not only along the axis (a chamfer)
        into = next((j for j in (k + 1, k - 1) if 0 <= j < len(layers) and covers(layers[j], outline)),
                    None) if tall and not any(thick(layers[k])) else None
        if into is None:
            k += 1
            continue
        other, low, high, _, more = layers[into]
        filled += sum(polygon.area for polygon in other) * (top - bottom) - volume
        layers[into] = (other, min(low, bottom), max(high, top), None, more + volume)
        del layers[k]
        k = min(k, into)
    pieces: list[tuple[trimesh.Trimesh, float]] = []
    excess = dropped = 0.0
    for polygons, bottom, top, inside, volume in layers:
        layer = _layer_pieces(polygons, bottom, top, inside)
        excess += 0.0 if inside is None else sum(hull.volume for hull in layer) - volume
        for piece in layer:
            if eroded(piece.vertices, URDF_HULL_MARGIN) is None:
                dropped += piece.volume
            else:
                pieces.append((piece, 0.0))
    if excess >= HULL_TOLERANCE * mesh.volume:
        return (f"part '{pid}': the convex hulls of its layers that are no prisms of their sections exceed its mesh "
                f"by {excess / mesh.volume:.1%} of its volume (at most {HULL_TOLERANCE:.0%})")
    if dropped >= THIN_TOLERANCE * mesh.volume or not pieces:
        return (f"part '{pid}': the parts of its layers thinner than the cell's hull margin twice are "
                f"{dropped / mesh.volume:.1%} of its volume (at most {THIN_TOLERANCE:.0%} are left out)")
    heights = ", ".join(f"{1e3 * (top - bottom):.3f}{'' if inside is None else ' (hulls)'}"
                        for _, bottom, top, inside, _ in layers)
    made = (f"{len(pieces)} convex piece(s) over its {len(layers)} layer(s) of {heights} mm, the prisms "
            f"{differ / mesh.volume:.2%} of its volume apart from the mesh, the hulls {excess / mesh.volume:.2%} "
            f"beyond it; its parts thinner than the cell's hull margin twice filled to the section next to them, "
            f"{filled / mesh.volume:.2%} of its volume added, or left out, {dropped / mesh.volume:.2%}")
    return Prisms(pieces, made, filled)
