"""Cross-sections of parts and holes from planar slices of their meshes.

A slice perpendicular to an insertion axis gives closed loops (trimesh's plane section).
A loop is classified as

- ``round`` when it has at least :data:`MIN_ROUND_POINTS` points, all within 2 % of one
  radius, and fills at least 98 % of that circle (a 24-gon fills 98.9 %); a splined,
  keyed or D-shaped outline spreads its radii further and is no round (a tessellation
  coarser than :data:`FACETED` is the polygon it is against a section that is no round:
  :func:`faceted`);
- ``rect`` (``square`` when both sides agree within :data:`SQUARE_TOLERANCE`) when it fills
  its minimum-area rectangle to :data:`RECT_FILL` and each side of that rectangle is
  covered by the loop's own edges over at least :data:`STRAIGHT_SIDES` of its length
  (rounded or chamfered corners: a 10 x 6 mm rect with 1 mm corner radii fills 98.6 % and
  its sides are straight over 80 % and 67 %), with the long side a, the short side b and
  the yaw of a from the slice's first axis;
- ``polygon`` otherwise: the loop itself, compared with
  :mod:`executor.world.fit` (``outline``).

Sizes are what a fit depends on, conservatively: a part's round section is its vertex
circle (its widest), a hole's its inscribed circle (its narrowest), so a polygonal hole's
size is its inradius and a tessellated cylinder's is within the tessellation's deflection;
the ``deflection`` kept is how far the loop's edges come in from its vertex circle (the
chords' sagitta, measured). Whether a tessellation's vertices or its edges lie on the true
cylinder the mesh does not say (a CAD kernel's vertices do, Cranfield's export's hole
edges do): a round peg at least as wide as a round hole's inscribed circle, whose vertex
circle's radius is the hole's within :data:`executor.cad.fits.faces.TOUCH`, is taken for the
same nominal diameter, a nominal zero-clearance fit (:func:`zero_clearance`), as the
disassembly's sliding cylinders are; so is a round section against a polygon whose
vertices lie on its vertex circle where they meet, each edge between them a short chord of
it (a hinge pin in a printed teardrop hole tangent to it). A part's rect is
its minimum-area rectangle (it holds the part, corners and all) with the largest corner
radius that still holds it; a hole's is the rounded rect that lies inside the loop: that
rectangle with the least corner radius that fits, inset evenly on every side only as far
as no rounded rect fits without (a tessellation's side tilted by a fraction of a µm costs
that fraction, its rounded corners nothing), so a rect peg that passes the recorded rect
passes the hole (``corner``, reported). The room of two rect or square sections is their
loops', not that of these readings (:func:`section_room`). Where the part's
B-rep has a cylinder on the loop's axis (a STEP part), :func:`exact_round` takes its
diameter instead.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from functools import cached_property

import networkx as nx
import numpy as np
import shapely
import trimesh
from matplotlib.path import Path as PolygonPath
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import depth_first_order
from scipy.spatial import ConvexHull, QhullError
from trimesh.constants import tol_path
from trimesh.grouping import unique_rows
from trimesh.path.entities import Line
from trimesh.path.exchange.misc import edges_to_path
from trimesh.path.traversal import discretize_path, vertex_to_entity_path

from executor.cad.fits.faces import SMOOTH, TOUCH
from executor.cad.parts import Cylinder
from executor.world.geometry import Section, section_fit
from executor.world.polygon_fit import OutlineError, PolygonFit, inscribed, polygon, round_fit, turned_fit

MIN_ROUND_POINTS = 12
SQUARE_TOLERANCE = 1e-5
"""Sides within this [m] make a square (10 µm)."""
RECT_FILL = 0.98
"""A rect fills at least this fraction of its minimum-area rectangle."""
STRAIGHT_SIDES = 0.5
"""Each side of a rect's rectangle is covered by the loop's edges over at least this fraction."""
ON_SIDE = 2e-6
"""A loop's point within this [m] (or 0.1 % of the short side, if more) of a side of its
rectangle lies on it (a flat face's slice is straight to the float)."""


@dataclass(frozen=True)
class Loop:
    """A closed loop of a slice: its ``points`` (n, 2) [m] in the slice's frame, and the
    loops cut out of what it bounds, ``inner`` (each (k, 2) [m]: a hole's islands, a
    part's bores; its measures are its outline's)."""

    points: np.ndarray
    inner: tuple[np.ndarray, ...] = ()

    @cached_property
    def area(self) -> float:
        x, y = self.points[:, 0], self.points[:, 1]
        return abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))) / 2

    @cached_property
    def length(self) -> float:
        """The perimeter [m]."""
        return float(np.sum(np.linalg.norm(self.points - np.roll(self.points, 1, axis=0), axis=1)))

    @cached_property
    def centre(self) -> np.ndarray:
        """The area centroid [m] (a mean of the points would lean towards denser edges)."""
        x, y = self.points[:, 0], self.points[:, 1]
        cross = x * np.roll(y, -1) - np.roll(x, -1) * y
        signed = cross.sum() / 2
        if abs(signed) < 1e-18:
            return self.points.mean(axis=0)
        return np.array([np.sum((x + np.roll(x, -1)) * cross), np.sum((y + np.roll(y, -1)) * cross)]) / (6 * signed)

    @cached_property
    def extent(self) -> tuple[float, float]:
        """The sides (a ≥ b) [m] of the minimum-area rectangle around the loop."""
        a, b, _ = _min_rectangle(self.points)
        return a, b

    def contains(self, point: np.ndarray) -> bool:
        return bool(PolygonPath(self.points).contains_point((float(point[0]), float(point[1]))))


@dataclass(frozen=True, eq=False)
class Shape2D:
    """A classified loop: ``kind`` (round, square, rect, polygon), ``a`` ≥ ``b`` [m] (a
    round section: its diameter twice; a polygon: its minimum-area rectangle's sides),
    ``deflection`` [m] a round section's sagitta (its loop's edges inside its vertex circle,
    whose diameter is a part's ``a`` and a hole's ``a`` + 2 ``deflection``; 0: exact),
    ``yaw`` [°] of side a in (-90, 90] (square: (-45, 45]; a polygon: 0, its outline
    holds its turn), ``centre`` (2,) [m] in the slice's frame, ``outline`` (n, 2) [m] the
    loop's points about the centre, ``corner`` [m] the corner radius a rect's missing
    area gives (0: sharp), ``inner`` the loop's inner rings about the centre (a hole's
    islands, a part's bores)."""

    kind: str
    a: float
    b: float
    yaw: float
    centre: np.ndarray
    outline: np.ndarray = field(repr=False, kw_only=True)
    corner: float = field(default=0.0, kw_only=True)
    deflection: float = field(default=0.0, kw_only=True)
    inner: tuple[np.ndarray, ...] = field(default=(), kw_only=True, repr=False)


def frame_of(axis: np.ndarray) -> np.ndarray:
    """(2, 3): the slice's axes u, v for an insertion ``axis``; for ±z they are the cell's x
    and y (so a yaw is measured from the cell's x axis)."""
    axis = np.asarray(axis, dtype=float)
    helper = np.array([1.0, 0.0, 0.0]) if abs(axis[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = helper - np.dot(helper, axis) * axis
    u /= np.linalg.norm(u)
    return np.array([u, np.cross(axis, u) if axis[2] >= 0 else np.cross(u, axis)])


_SECTION_SCALE = 1e6
"""The scale [1/m] a section's points are joined at (:func:`slice_loops`)."""


_kept: dict[tuple[int, bytes, float], tuple[trimesh.Trimesh, list[Loop]]] | None = None
"""The slices :func:`slice_loops` made within :func:`slices_kept`, by mesh (its id: the
mesh is held, so no other takes it), axis and level, with the mesh; None outside."""


@contextmanager
def slices_kept() -> Iterator[None]:
    """Within it, :func:`slice_loops` slices a mesh across an axis at a level once and
    answers again with the same loops (the import asks for many slices twice: a part's bore
    at its middle for its hole and for its pin). The meshes must not change within it;
    the loops returned are shared, never to be changed."""
    global _kept
    outer = _kept
    _kept = {} if outer is None else outer
    try:
        yield
    finally:
        _kept = outer


def slice_loops(mesh: trimesh.Trimesh, axis: np.ndarray, level: float) -> list[Loop]:
    """The closed loops of ``mesh`` cut by the plane ``dot(x, axis) = level`` [m] (made
    once within :func:`slices_kept`)."""
    axis = np.asarray(axis, dtype=float)
    if _kept is None:
        return _sliced(mesh, axis, level)
    key = (id(mesh), axis.tobytes(), float(level))
    if key not in _kept:
        _kept[key] = (mesh, _sliced(mesh, axis, level))
    return _kept[key][1]


def _sliced(mesh: trimesh.Trimesh, axis: np.ndarray, level: float) -> list[Loop]:
    """:func:`slice_loops`, made."""
    lines = trimesh.intersections.mesh_plane(mesh, plane_normal=axis, plane_origin=axis * level)
    if len(lines) == 0:
        return []
    # trimesh joins a section's points on a grid of 1e-5 of its units (its mesh.section, in
    # metres: 10 µm, which closed a tapered mortise's corner 4 µm from the next point): the
    # points are joined in µm [m × 1e6], on a grid of 10 pm, as only those of one edge are
    entities, vertices = _lines_to_path(lines * _SECTION_SCALE)
    section = trimesh.path.Path3D(entities=entities, vertices=vertices / _SECTION_SCALE)
    frame = frame_of(axis)
    loops = []
    # a plane section is made of straight lines, which need no scale to be discretised
    # (the section's ``discrete`` would measure every line's bounds for one)
    for polyline in _closed_polylines(section):
        points = np.asarray(polyline) @ frame.T
        if len(points) > 1 and np.allclose(points[0], points[-1]):
            points = points[:-1]
        if len(points) >= 3:
            loops.append(Loop(points))
    return loops


SPAN_TOLERANCE = 1e-8
"""A face lying within this [m] of an end of a span, beyond its inside, is no part of it
(:func:`shadow`): the faces across the axis that bound it there (a hole's floor a peg
stands on, a bolt head's face on the plate's) are taken as at that end's level; so is a
corner of a face crossing the span that lies within it of an end (the ends are vertex
levels rounded to 1 nm: cut a fraction of a nm from their corner, the faces sharing it
left cracks in their shadow, and a bore's section over a span in its edge radius a sliver)."""
SAME_OUTLINE = 1e-8
"""A section over a span whose outline lies within this [m] of the loop sliced in it
(Hausdorff) is that loop (the projected faces meet its edges to the float)."""
SLIVER = 1e-12
"""A face's shadow (:func:`shadow`) lying wholly within this [m] (1 pm) of the loop's
outline is left out of a section over a span (:func:`over_span`): a wall's faces along the
axis, tilted by the float, project to thousands of such slivers. The section is then made
conservative by twice this: a hole's eroded, a peg's dilated (:func:`_conservative`)."""


def shadow(mesh: trimesh.Trimesh, axis: np.ndarray, low: float, high: float,
           near: tuple[float, float, float, float], band: shapely.Geometry | None = None
           ) -> tuple[shapely.Geometry, bool]:
    """The union of the projections across ``axis`` (in :func:`frame_of`'s axes) of the
    pieces of ``mesh``'s triangles between the levels ``low`` and ``high`` [m] (not those
    within :data:`SPAN_TOLERANCE` of an end, beyond it), of those whose projection meets the box
    ``near`` (x0, y0, x1, y1) [m]. A triangle clipped to the span is convex, so its
    projection is the convex hull of its clipped corners; a wall along the axis projects
    to no area. Every point the solid covers at some level of the span, and not at a level
    inside it where it is sliced, lies under a face crossing the span: this is exactly the
    set that sections over the span gain or lose (:func:`over_span`). The projections
    ``band`` covers are left out; with the union, whether any was."""
    axis = np.asarray(axis, dtype=float)
    triangles = mesh.triangles
    heights = triangles @ axis
    flat = triangles @ frame_of(axis).T
    keep = ((heights.max(axis=1) > low + SPAN_TOLERANCE) & (heights.min(axis=1) < high - SPAN_TOLERANCE)
            & (flat[:, :, 0].max(axis=1) >= near[0]) & (flat[:, :, 0].min(axis=1) <= near[2])
            & (flat[:, :, 1].max(axis=1) >= near[1]) & (flat[:, :, 1].min(axis=1) <= near[3]))
    heights, flat = heights[keep], flat[keep]
    # a corner within SPAN_TOLERANCE of an end is at that end (SPAN_TOLERANCE)
    heights = np.where(np.abs(heights - low) <= SPAN_TOLERANCE, low,
                       np.where(np.abs(heights - high) <= SPAN_TOLERANCE, high, heights))
    if not len(heights):
        return shapely.Polygon(), False
    points, valid = [flat], [(heights >= low) & (heights <= high)]
    for i, j in ((0, 1), (1, 2), (2, 0)):
        for level in (low, high):
            crossing = (heights[:, i] - level) * (heights[:, j] - level) < 0
            step = np.where(crossing, heights[:, j] - heights[:, i], 1.0)
            t = np.where(crossing, (level - heights[:, i]) / step, 0.0)
            points.append((flat[:, i] + t[:, None] * (flat[:, j] - flat[:, i]))[:, None])
            valid.append(crossing[:, None])
    corners, mask = np.concatenate(points, axis=1), np.concatenate(valid, axis=1)
    spanning = mask.sum(axis=1) >= 3  # fewer corners span no area
    corners, mask = corners[spanning], mask[spanning]
    owner = np.nonzero(mask)[0]
    # a line string through the corners: GEOS hulls its coordinates in their order, as a
    # multipoint's (the same hull), without making a point of each
    hulls = shapely.convex_hull(shapely.linestrings(corners[mask], indices=owner))
    hulls = hulls[shapely.area(hulls) > 0]
    dropped = False
    if band is not None and len(hulls):
        shapely.prepare(band)
        inside = shapely.covers(band, hulls)
        hulls, dropped = hulls[~inside], bool(inside.any())
    return (shapely.union_all(hulls) if len(hulls) else shapely.Polygon()), dropped


def _conservative(section: shapely.Polygon, *, hole: bool) -> shapely.Geometry:
    """``section`` [m] made without shadows within :data:`SLIVER` of its loop's outline
    (:func:`shadow`'s ``band``), made no larger for a hole (eroded) and no smaller for a
    peg (dilated) than the exact one: each point it wrongly holds (a hole's) or misses (a
    peg's) lies within SLIVER of the loop's outline, outside the hole's section or inside
    the peg's. By twice SLIVER: a round buffer's arcs are chords, short of the disc by
    under a hundredth of its radius."""
    return section.buffer(-2 * SLIVER if hole else 2 * SLIVER)


def over_span(loop: Loop, mesh: trimesh.Trimesh, axis: np.ndarray, low: float, high: float, *, hole: bool,
              reach: float = math.inf) -> Loop:
    """The section of ``mesh`` over the span between the levels ``low`` and ``high`` [m]
    along ``axis``, from its ``loop`` sliced at a level inside it. A hole's: the points
    free at every level of the span, the loop less the :func:`shadow` of the faces within
    the loop's box (where that leaves several pieces, the largest). A part's: the points
    it covers at some level, the loop with the shadow of its faces within ``reach`` [m] of
    the loop's centre across the axis (the faces by their box, their shadow cut to a 64-gon
    about the circle of that radius: a pin's owner's other pins are not the pin, on a
    diagonal too), its outer outline (pieces apart joined by their convex hull, but slivers within
    :data:`SAME_OUTLINE` of it: a wall's faces along the axis, tilted by the float). Exact, whatever
    lies between the levels slices are taken at (a taper, a groove's edge, a slanted
    facet): a point free at one level of the span and covered at another lies under a
    face crossing the span; but for the shadows within :data:`SLIVER` of the loop's
    outline, left out, after which a hole's section is eroded and a peg's dilated by twice
    SLIVER (never larger, never smaller than the exact one). A hole's loop's ``inner`` rings
    (islands) are cut out of it first, and what the shadow cuts out inside it is kept as
    inner rings of the section (not filled: a stub standing on a pocket's floor into the
    span). ``loop`` itself when the section lies within
    :data:`SAME_OUTLINE` of it, or when it is no simple polygon; no points when nothing of
    the hole is free all along."""
    outline = shapely.make_valid(shapely.Polygon(loop.points, loop.inner if hole else ()))
    if not isinstance(outline, shapely.Polygon):
        return loop  # no simple polygon (faces that touch): the fit relation refuses it as sliced
    x0, y0, x1, y1 = outline.bounds
    if not hole:
        x, y = loop.centre
        x0, y0, x1, y1 = x - reach, y - reach, x + reach, y + reach
    cover, dropped = shadow(mesh, axis, low, high, (x0, y0, x1, y1),
                            (outline.boundary if hole and loop.inner else outline.exterior).buffer(SLIVER))
    if not hole and math.isfinite(reach):  # the box's corners reach farther: a plate's other pin on a diagonal
        cover = shapely.intersection(cover, shapely.Point(loop.centre).buffer(reach / math.cos(math.pi / 64),
                                                                              quad_segs=16))
    if cover.is_empty and not dropped:
        return loop
    if hole:
        free = shapely.difference(outline, cover)
        pieces = shapely.get_parts(_conservative(free, hole=True) if dropped else free)
        if not len(pieces):
            return Loop(np.zeros((0, 2)))
        found = max(pieces, key=lambda piece: piece.area)
    else:
        covered = shapely.union(outline, cover)
        pieces = list(shapely.get_parts(_conservative(covered, hole=False) if dropped else covered))
        main = max(pieces, key=lambda piece: piece.area)
        near = main.buffer(SAME_OUTLINE)
        apart = [piece for piece in pieces if piece is not main and not near.covers(piece)]
        found = shapely.Polygon((shapely.union_all([main, *apart]).convex_hull if apart else main).exterior)
    islands = tuple(np.asarray(ring.coords)[:-1] for ring in found.interiors) if hole else ()
    if _same_outline(outline.exterior, found.exterior) and len(islands) == len(loop.inner) and all(
            _same_outline(shapely.LinearRing(mine), shapely.LinearRing(kept))
            for mine, kept in zip(loop.inner, islands, strict=True)):
        return loop
    return Loop(np.asarray(found.exterior.coords)[:-1], islands)


SPIKE = 5e-8
"""A level's section in the sweep (:func:`passage`) loses its spikes and slivers narrower
than twice this [m] (50 nm, a tenth of :data:`OUTLINE_TOUCH`): a hole's is opened (buffered
in by it and out again: never wider), a peg's closed (out and in: never narrower), with
mitred joins that give a corner back where it was, so both stay conservative where the
faces of a tessellation meet at a hair's angle."""
SEAT = TOUCH
"""The sweep's stretch is taken this far [m] inside its ends: a peg's shoulder resting on
the entry face, or its tip on a hole's floor, overlaps that face by the tessellations'
touch (asap_beam's shoulders lie 27 nm below the top's face), which the disassembly takes
for touching up to :data:`executor.cad.fits.faces.TOUCH` (10 µm)."""
_SPLIT = 1e-8
"""Vertex levels closer than this [m] are one (the sweep's levels, :func:`passage`)."""
_INSIDE = 3e-9
"""The sweep slices this far [m] inside each span's ends (a section's limit from within the span)."""


class Slicer:
    """The loops of ``mesh``'s slices across ``axis``, each level sliced once."""

    def __init__(self, mesh: trimesh.Trimesh, axis: np.ndarray) -> None:
        self.mesh, self.axis = mesh, np.asarray(axis, dtype=float)
        self._done: dict[float, list[Loop]] = {}

    def at(self, level: float) -> list[Loop]:
        """The loops at ``level`` [m] along the axis."""
        key = round(level, 12)
        if key not in self._done:
            self._done[key] = slice_loops(self.mesh, self.axis, key)
        return self._done[key]

    def levels(self, line: np.ndarray, reach: float) -> np.ndarray:
        """The levels [m] along the axis of the mesh's vertices within ``reach`` [m] of the
        point ``line`` (2,) across it (in :func:`frame_of`'s axes)."""
        vertices = self.mesh.vertices
        near = np.linalg.norm(vertices @ frame_of(self.axis).T - line, axis=1) <= reach
        return vertices[near] @ self.axis


@dataclass(frozen=True)
class Passage:
    """A peg's way into a hole along an axis (:func:`passage`): ``room`` [m] twice the least
    clearance of the peg's section at a level to the hole's at a level it crosses on the way
    in (diametral, as :func:`executor.world.geometry.margin`; negative: an overlap), and the
    ``peg``'s and ``hole``'s loops at the pair of levels where it is least."""

    room: float
    peg: Loop
    hole: Loop


def _cleaned(loop: Loop, *, hole: bool) -> shapely.Geometry:
    """The ``loop`` as a region without its spikes (:data:`SPIKE`): a hole's largest piece
    (where the loop touches itself), a peg's every piece."""
    pieces = [piece for piece in shapely.get_parts(shapely.make_valid(shapely.Polygon(loop.points)))
              if isinstance(piece, shapely.Polygon)]
    if not pieces:
        return shapely.Polygon()
    if hole:
        opened = max(pieces, key=lambda piece: piece.area).buffer(-SPIKE, join_style="mitre").buffer(
            SPIKE, join_style="mitre")
        parts = [piece for piece in shapely.get_parts(opened) if isinstance(piece, shapely.Polygon)]
        return max(parts, key=lambda piece: piece.area) if parts else shapely.Polygon()
    return shapely.union_all(pieces).buffer(SPIKE, join_style="mitre").buffer(-SPIKE, join_style="mitre")


def _hole_around(loops: list[Loop], line: np.ndarray) -> Loop | None:
    """The smallest loop holding the point ``line`` that is a hole (inside an odd number of
    the others); None when none is (the point is in the solid)."""
    holding = [loop for loop in loops if loop.contains(line)]
    found = [loop for loop in holding if sum(1 for o in holding if o is not loop and o.area > loop.area) % 2 == 1]
    return min(found, key=lambda loop: loop.area) if found else None


def _peg_near(loops: list[Loop], line: np.ndarray, reach: float, shift: np.ndarray) -> list[Loop]:
    """The outlines (inside an even number of the others) of a peg's slice, moved by
    ``shift`` (2,) [m], that come within ``reach`` [m] of the point ``line``: every piece
    of it that could enter the hole, whole (a piece reaching beyond the hole's mouth does
    not pass it)."""
    moved = [Loop(loop.points + shift) for loop in loops
             if sum(1 for o in loops if o is not loop and o.area > loop.area and o.contains(loop.centre)) % 2 == 0]
    return [loop for loop in moved if shapely.distance(shapely.Polygon(loop.points), shapely.Point(line)) <= reach]


def sweep_levels(levels: np.ndarray, low: float, high: float) -> list[float]:
    """The levels [m] :func:`passage` slices at: just inside both ends of each span between
    the distinct ``levels`` clipped to [``low``, ``high``] (:data:`_INSIDE`; within a span
    every section's corners move in straight lines), the middle of a span too short for two."""
    bounds = [low]
    for level in np.unique(np.round(np.clip(levels, low, high), 9)):
        if level - bounds[-1] > _SPLIT and high - level > _SPLIT:
            bounds.append(float(level))
    bounds.append(high)
    found: list[float] = []
    for a, b in zip(bounds[:-1], bounds[1:], strict=True):
        found += [a + _INSIDE, b - _INSIDE] if b - a > 4 * _INSIDE else [(a + b) / 2]
    return found


def passage(peg: Slicer, owner: Slicer, line: np.ndarray, low: float, high: float,
            offset: np.ndarray | None = None) -> Passage | None:
    """The sweep of a peg leaving a hole along the slicers' common axis (``owner``'s the
    hole's, ``peg``'s the peg's, moved by ``offset`` (3,) [m]): the peg's sections at the
    levels between ``low`` and ``high`` [m] (its tip and the entry, :data:`SEAT` inside
    them) each against the hole's at that level and every level above it, the loops around
    the point ``line`` (2,) [m] across the axis. The stretch is split at the levels of the
    vertices of both within the hole's reach at the entry (its loop's farthest point from
    the line; :func:`sweep_levels`): a peg passing the entry lies within it, and there a
    section changes only at such a level (a face's vertex beyond it bends the face's trace
    beyond it). The peg passes when each of its
    sections lies in the hole's at every level it crosses on the way in: a taper in its own
    taper, whose narrow tip meets the hole's wide mouth; not a prism through a throat. The
    clearance of a pair is the least distance of the peg's corners to the hole's walls
    (negative outside it) and of the hole's corners inside the peg's sections below to
    their outline, each section in the pose the product has it (not centred). Exact at the
    levels sliced, and between them where the hole's section is convex (a corner's distance
    to a wall then moves in a straight line); None when the hole closes at a level."""
    offset = np.zeros(3) if offset is None else np.asarray(offset, dtype=float)
    across, along = frame_of(owner.axis) @ offset, float(owner.axis @ offset)
    mouth = _hole_around(owner.at(high - SEAT), line)
    if mouth is None:
        return None
    reach = float(np.linalg.norm(mouth.points - line, axis=1).max()) + SEAT
    levels = np.concatenate([owner.levels(line, reach), peg.levels(line - across, reach) + along])
    best: tuple[float, int, int] | None = None
    union = shapely.Polygon()  # the peg's sections at the levels so far
    sections: list[tuple[int, shapely.Polygon]] = []
    found: list[tuple[Loop | None, Loop]] = []
    for index, level in enumerate(sweep_levels(levels, low + SEAT, high - SEAT)):
        hole_loop = _hole_around(owner.at(level), line)
        hole = shapely.Polygon() if hole_loop is None else _cleaned(hole_loop, hole=True)
        if hole_loop is None or hole.is_empty:
            return None
        pieces = _peg_near(peg.at(level - along), line, reach, across)
        found.append((max(pieces, key=lambda loop: loop.area) if pieces else None, hole_loop))
        if pieces:
            section = shapely.union_all([_cleaned(loop, hole=False) for loop in pieces])
            sections.append((index, section))
            union = shapely.union(union, section)
        if union.is_empty:
            continue
        # the union's corners are the peg's farthest points from a wall (a corner of the
        # hole inside it is measured from its outline below)
        corners = shapely.get_coordinates(union)
        distance = shapely.distance(shapely.points(corners), hole.exterior)
        clearance = np.where(shapely.contains_xy(hole, corners[:, 0], corners[:, 1]), distance, -distance)
        least, nearest = float(clearance.min()), shapely.Point(corners[int(clearance.argmin())])
        walls = np.asarray(hole.exterior.coords)[:-1]
        poking = shapely.contains_xy(union, walls[:, 0], walls[:, 1])
        if poking.any():
            depths = shapely.distance(shapely.points(walls[poking]), union.boundary)
            if -float(depths.max()) < least:
                least, nearest = -float(depths.max()), shapely.Point(walls[poking][int(depths.argmax())])
        if best is None or least < best[0]:
            at = min(sections, key=lambda item: shapely.distance(item[1].boundary, nearest))[0]
            best = (least, at, index)
    if best is None:
        return None
    least, at, index = best
    peg_loop = found[at][0]
    assert peg_loop is not None  # a clearance is measured only from a section of the peg
    return Passage(2 * least, peg_loop, found[index][1])


def _same_outline(first: shapely.LinearRing, second: shapely.LinearRing) -> bool:
    """Whether the rings lie within :data:`SAME_OUTLINE` of each other: their discrete
    Hausdorff distance (``shapely.hausdorff_distance``, each one's vertices to the other's
    edges) is at most it, decided as that comparison decides (:func:`_vertices_near`, one
    way, then the other) without measuring every vertex against every edge."""
    return _vertices_near(shapely.get_coordinates(first), shapely.get_coordinates(second)) and _vertices_near(
        shapely.get_coordinates(second), shapely.get_coordinates(first))


def _vertices_near(points: np.ndarray, ring: np.ndarray) -> bool:
    """Whether each of ``points`` (n, 2) [m] lies within :data:`SAME_OUTLINE` of an edge of
    the closed polyline ``ring`` (m, 2) [m] (its first point repeated last), each distance
    computed as GEOS's discrete Hausdorff distance computes it, operation for operation (the
    edge's closest point: the projection where its factor lies strictly between 0 and 1,
    else the nearer end; then the squared distance), so the comparison decides alike to the
    last bit. Only the edges whose box,
    widened by twice :data:`SAME_OUTLINE`, holds the point are measured: any other edge and
    its closest point, rounded or not, lie farther than :data:`SAME_OUTLINE`."""
    if not len(points) or not len(ring):
        return False  # GEOS's distance to or from nothing is NaN, within no distance
    # GEOS walks the ring with one segment, replacing its ends in turn: every second edge
    # runs from its end back to its start (which the rounding of its projection follows)
    start, end = ring[:-1].copy(), ring[1:].copy()
    start[1::2], end[1::2] = ring[2::2], ring[1:-1:2]
    reach = 2 * SAME_OUTLINE
    low, high = np.minimum(start, end) - reach, np.maximum(start, end) + reach
    tree = shapely.STRtree(shapely.box(low[:, 0], low[:, 1], high[:, 0], high[:, 1]))
    which, edge = tree.query(shapely.points(points))  # the boxes holding each point
    if len(np.unique(which)) < len(points):
        return False
    p, a, b = points[which], start[edge], end[edge]
    dx, dy = b[:, 0] - a[:, 0], b[:, 1] - a[:, 1]
    with np.errstate(divide="ignore", invalid="ignore"):
        factor = ((p[:, 0] - a[:, 0]) * dx + (p[:, 1] - a[:, 1]) * dy) / (dx * dx + dy * dy)
    at_a, at_b = np.all(p == a, axis=1), np.all(p == b, axis=1)
    factor = np.where(at_a | (~at_b & np.all(a == b, axis=1)), 0.0, np.where(at_b, 1.0, factor))
    inside = (factor > 0) & (factor < 1)
    nearer_end = np.where((np.sqrt(_squared(a, p)) < np.sqrt(_squared(b, p)))[:, None], a, b)
    closest = np.where(inside[:, None], np.stack([a[:, 0] + factor * dx, a[:, 1] + factor * dy], axis=1), nearer_end)
    nearest = np.full(len(points), np.inf)
    np.minimum.at(nearest, which, _squared(closest, p))
    return bool(math.sqrt(float(nearest.max())) <= SAME_OUTLINE)


def _squared(first: np.ndarray, second: np.ndarray) -> np.ndarray:
    """The squared distances [m²] of the rows of two (n, 2) arrays, as GEOS sums them (dx² + dy²)."""
    dx, dy = first[:, 0] - second[:, 0], first[:, 1] - second[:, 1]
    return dx * dx + dy * dy


def _lines_to_path(lines: np.ndarray) -> tuple[list[Line], np.ndarray]:
    """The entities and vertices of trimesh's ``lines_to_path`` of the segments ``lines``
    (n, 2, 3), the same: the segments' ends joined where they agree to trimesh's digits, the
    lines of the graph of joined points' depth-first traversals. Where that graph is
    simple cycles (:func:`_cycles`: loops that touch nowhere, no segment shorter than the
    joining grid), its
    traversals are made in one search instead of trimesh's search per cycle and check of
    every segment against the traversals (most of a fine mesh's slice's time)."""
    points = np.asarray(lines, dtype=np.float64).reshape((-1, 3))
    unique, inverse = unique_rows(points, digits=tol_path.merge_digits)
    edges = inverse.reshape((-1, 2))
    cycles = _cycles(edges)
    if cycles is None:
        path = edges_to_path(edges=edges, vertices=points[unique])
        return path["entities"], path["vertices"]
    return [Line(cycle) for cycle in cycles], points[unique]


def _cycles(edges: np.ndarray) -> list[np.ndarray] | None:
    """The traversals trimesh's ``edges_to_path`` makes of the graph of ``edges`` (n, 2)
    (nodes 0 to n - 1) when it is simple cycles (each node on two edges, none twice, none
    from a node to itself), else None: each cycle from its least node towards the lesser
    of that node's neighbours and back to it, ordered by their least nodes, as a
    depth-first search (scipy's, trimesh's) from each node not yet reached, in order,
    walks them. Here one search, from a node joined to every other, walks them all."""
    count = len(edges)
    ordered = np.sort(edges, axis=1)
    if (int(edges.max()) + 1 != count or np.any(ordered[:, 0] == ordered[:, 1])
            or np.any(np.bincount(ordered.ravel(), minlength=count) != 2) or len(unique_rows(ordered)[0]) != count):
        return None
    rows = np.concatenate([ordered[:, 0], np.arange(count)])
    columns = np.concatenate([ordered[:, 1], np.full(count, count)])
    graph = csr_matrix((np.ones(len(rows), dtype=bool), (rows, columns)), shape=(count + 1, count + 1))
    walk, before = depth_first_order(graph, count, directed=False, return_predecessors=True)
    walk = walk[1:]
    starts = np.flatnonzero(before[walk] == count)
    return [np.append(cycle, cycle[0]) for cycle in np.split(walk, starts[1:])]


def _closed_polylines(section: trimesh.path.Path3D) -> list[np.ndarray]:
    """The points (n, 3) [m] of each closed path of a plane section, the first repeated
    last: those of :func:`_closed_paths` discretised, in the same order. Where the
    section's other entities all go from a vertex to itself they make no cycle, so its
    paths are its closed entities and no graph is built (most sections of a fine mesh in
    metres: thousands of such lines, whose graph took most of a slice's time)."""
    entities, vertices = section.entities, section.vertices
    closed = _only_closed(entities)
    paths = _closed_paths(section) if closed is None else [[index] for index in closed]
    return [discretize_path(entities, vertices, path) for path in paths]


def _only_closed(entities: list[trimesh.path.entities.Entity]) -> list[int] | None:
    """The indices of the closed entities when each other entity is a line of two points
    at one vertex (a self-loop, no cycle of :func:`_closed_paths`' graph), else None."""
    ends = [entity.points for entity in entities]
    sizes = np.fromiter(map(len, ends), dtype=np.int64, count=len(ends))
    others = np.flatnonzero(sizes != 2)
    closed = [int(index) for index in others if entities[index].closed]
    if len(closed) < len(others):
        return None
    lines = np.flatnonzero(sizes == 2)
    if len(lines) and np.any(np.diff(np.concatenate([ends[index] for index in lines]).reshape(-1, 2), axis=1)):
        return None
    return closed


def _closed_paths(section: trimesh.path.Path3D) -> list[list[int]]:
    """The closed paths of a plane section (lists of its entities' indices): trimesh's
    ``closed_paths``, the same paths in the same order (the cycles of one graph of the
    lines' vertices, built with the same edges in the same order), the graph built in one
    call instead of one per line (trimesh's per-line calls took most of a slice's time on
    meshes of 10⁵ triangles)."""
    graph = nx.Graph()
    paths: list[list[int]] = []
    edges: list[tuple[int, int, dict[str, int]]] = []
    for index, entity in enumerate(section.entities):
        if entity.closed:
            paths.append([index])
        else:
            points = entity.points.tolist()
            edges += [(a, b, {"entity_index": index}) for a, b in zip(points[:-1], points[1:], strict=True)]
    graph.add_edges_from(edges)
    for cycle in nx.cycle_basis(graph):
        if len(cycle) >= 2:
            paths.append(vertex_to_entity_path(cycle, graph, section.entities, section.vertices))
    return paths


def _min_rectangle(points: np.ndarray) -> tuple[float, float, float]:
    """Sides (a ≥ b) [m] and the angle of a [rad] of the minimum-area rectangle around
    ``points``; b is 0 when they lie on one line (Qhull finds no hull of them)."""
    flat = False
    try:
        hull = points[ConvexHull(points).vertices] if len(points) > 3 else points
    except QhullError:  # no area: the sliver two faces leave where they meet
        hull, flat = points, True
    best = (math.inf, 0.0, 0.0, 0.0)
    for i in range(len(hull)):
        edge = hull[(i + 1) % len(hull)] - hull[i]
        length = float(np.linalg.norm(edge))
        if length <= 0:
            continue
        angle = math.atan2(edge[1], edge[0])
        c, s = math.cos(angle), math.sin(angle)
        turned = hull @ np.array([[c, -s], [s, c]])
        extent = turned.max(axis=0) - turned.min(axis=0)
        if extent[0] * extent[1] < best[0]:
            best = (float(extent[0] * extent[1]), float(extent[0]), float(extent[1]), angle)
    _, w, h, angle = best
    if flat:
        w, h = max(w, h), 0.0
    return (w, h, angle) if w >= h else (h, w, angle + math.pi / 2)


def edge_distance(points: np.ndarray, centre: np.ndarray) -> float:
    """The smallest distance [m] from ``centre`` to the loop's edges."""
    start, end = points, np.roll(points, -1, axis=0)
    edge = end - start
    t = np.clip(np.einsum("ij,ij->i", centre - start, edge) / np.einsum("ij,ij->i", edge, edge), 0, 1)
    return float(np.min(np.linalg.norm(start + t[:, None] * edge - centre, axis=1)))


def _straight(points: np.ndarray, a: float, b: float, tolerance: float) -> float:
    """The least fraction of a side of the centred rectangle ``a`` x ``b`` [m] (``points``
    in its frame) covered by the loop's edges lying on that side (both ends within
    ``tolerance`` [m] of it)."""
    ends = np.roll(points, -1, axis=0)
    fractions = []
    for axis, half, length in ((0, a / 2, b), (0, -a / 2, b), (1, b / 2, a), (1, -b / 2, a)):
        on = (np.abs(points[:, axis] - half) <= tolerance) & (np.abs(ends[:, axis] - half) <= tolerance)
        fractions.append(float(np.abs(ends[on, 1 - axis] - points[on, 1 - axis]).sum()) / length)
    return min(fractions)


def _rounded(a: float, b: float, radius: float, inset: float = 0.0) -> shapely.Polygon:
    """The centred rect ``a`` x ``b`` [m] inset by ``inset`` [m] a side, with corners of
    ``radius`` [m] (at most half its inset short side)."""
    half_a, half_b = a / 2 - inset, b / 2 - inset
    radius = min(radius, half_b)
    core = shapely.box(radius - half_a, radius - half_b, half_a - radius, half_b - radius)
    return core.buffer(radius, quad_segs=16) if radius > 0 else core


def _bisect(low: float, high: float, ok_high: bool, test: Callable[[float], bool]) -> float:
    """The end of [``low``, ``high``] [m] at which ``test`` changes, to 0.1 µm, on its
    passing side (``ok_high``: it passes at high)."""
    while high - low > 1e-7:
        mid = (low + high) / 2
        if test(mid) == ok_high:
            high = mid
        else:
            low = mid
    return high if ok_high else low


def _corner_and_inset(points: np.ndarray, a: float, b: float, *, hole: bool) -> tuple[float, float]:
    """The corner radius and inset [m] of a rect section (``points`` in its centred frame):
    a peg's the largest radius whose rounded rect still holds the loop (inset 0); a hole's
    the least radius whose rounded rect lies inside the loop (inset 0). Where none does (a
    notch, or a side a tessellation tilts by a fraction of a µm), the least even inset any
    radius needs is that of radius b/2 (a rounded rect of a larger radius lies inside one
    of a smaller): the sharp rect at its least inset where that is within
    :data:`OUTLINE_TOUCH` of it, else the least radius whose rounded rect lies inside the
    loop inset by OUTLINE_TOUCH beyond it, at the least inset that radius needs. A tilt
    then costs a fraction of a µm of inset, not the corner (the sharp rect shrunk until
    it fits: 2.3 mm of a 42 mm rounded square with 4 mm corners)."""
    loop = shapely.make_valid(shapely.Polygon(points))
    shapely.prepare(loop)
    grown = loop.buffer(1e-9)  # the loop's own points on the rect's sides stay covered
    if not hole:
        return _bisect(0.0, b / 2, False, lambda r: bool(_rounded(a, b, r).buffer(1e-9).covers(loop))), 0.0
    if grown.covers(_rounded(a, b, b / 2)):
        return _bisect(0.0, b / 2, True, lambda r: bool(grown.covers(_rounded(a, b, r)))), 0.0
    least = _bisect(0.0, b / 2, True, lambda d: bool(grown.covers(_rounded(a, b, b / 2, d))))
    allowed = min(least + OUTLINE_TOUCH, b / 2)
    sharp = _bisect(0.0, b / 2, True, lambda d: bool(grown.covers(_rounded(a, b, 0.0, d))))
    if sharp <= allowed:
        return 0.0, sharp
    radius = _bisect(0.0, b / 2, True, lambda r: bool(grown.covers(_rounded(a, b, r, allowed))))
    return radius, _bisect(0.0, allowed, True, lambda d: bool(grown.covers(_rounded(a, b, radius, d))))


def classify(loop: Loop, *, hole: bool, round_ok: bool = True) -> Shape2D:
    """The loop's cross-section (the module docstring); ``hole`` picks the inscribed size;
    without ``round_ok``, a loop is never read as round (the rect or polygon it is). A loop
    with inner rings (a hole's islands, a part's bores) is a polygon that keeps them."""
    points, centre = loop.points, loop.centre
    outline = points - centre
    if loop.inner:
        a, b, _ = _min_rectangle(points)
        return Shape2D("polygon", a, b, 0.0, centre, outline=outline, inner=tuple(ring - centre for ring in loop.inner))
    radii = np.linalg.norm(outline, axis=1)
    outer = float(radii.max())
    if (round_ok and len(points) >= MIN_ROUND_POINTS and (outer - radii.min()) <= 0.02 * outer
            and loop.area >= 0.98 * math.pi * outer ** 2):
        inner = edge_distance(points, centre)
        d = 2 * (inner if hole else outer)
        return Shape2D("round", d, d, 0.0, centre, outline=outline, deflection=outer - inner)
    a, b, angle = _min_rectangle(points)
    if b <= 0:  # points on one line (two faces meeting): no rect to fit, a sliver of no area
        return Shape2D("polygon", a, b, 0.0, centre, outline=outline)
    c, s = math.cos(angle), math.sin(angle)
    turned = points @ np.array([[c, -s], [s, c]])  # side a along the first axis
    local = turned - (turned.max(axis=0) + turned.min(axis=0)) / 2
    if (loop.area >= RECT_FILL * a * b
            and _straight(local, a, b, max(ON_SIDE, 1e-3 * b)) >= STRAIGHT_SIDES):
        corner, inset = _corner_and_inset(local, a, b, hole=hole)
        a, b = a - 2 * inset, b - 2 * inset
        square = a - b <= SQUARE_TOLERANCE
        yaw = math.degrees(angle)
        period, upper = (90.0, 45.0) if square else (180.0, 90.0)
        yaw = (yaw + period - upper) % period - (period - upper)
        if yaw <= -upper + 1e-9:
            yaw += period
        if square:
            a = b = (a + b) / 2
        return Shape2D("square" if square else "rect", a, b, round(yaw, 6), centre, outline=outline,
                       corner=round(corner, 7) if corner > ON_SIDE else 0.0)
    return Shape2D("polygon", a, b, 0.0, centre, outline=outline)


FACETED = 0.005
"""A round section whose loop's edges come farther in from its vertex circle than this
fraction of its radius (a 24-gon's: 0.86 %; a 32-gon's 0.48 %, a 46-gon's 0.23 %) is a
polygon against a section that is no round (:func:`faceted`)."""


def faceted(shape: Shape2D, loop: Loop, other: Shape2D, *, hole: bool) -> Shape2D:
    """``shape``, the section read from ``loop`` (``hole``: a hole's), or the polygon its
    loop is when ``shape`` is a coarse tessellation's round reading (its ``deflection``
    beyond :data:`FACETED` of its vertex radius; a B-rep cylinder's, :func:`exact_round`,
    has none) and the section it meets, ``other``, is not round. A round peg's room in a
    round hole is the same whether a tessellated one is read as its circle (a hole's
    inscribed, a peg's vertex circle) or as its polygon, up to the deflection that a nominal
    zero-clearance fit allows for (:func:`zero_clearance`); a straight-sided or polygonal
    section's room depends on where its corners meet the polygon's vertices at its best
    yaw, which the circle gives away (a 12-spline shaft d 40 in a 24-gon bore d 41: 0.325
    mm all round read round, 0.346 mm as the polygon). A finer tessellation stays round: a
    fine-tessellated cylinder (a d 20 pin in a 20 mm slot, nominally zero clearance) is
    its circle, and its polygon would report the tessellation's room (12 µm) as the fit's."""
    if shape.kind != "round" or other.kind == "round":
        return shape
    vertex_radius = shape.a / 2 + (shape.deflection if hole else 0.0)  # a hole's a: its inscribed circle
    if shape.deflection <= FACETED * vertex_radius:
        return shape
    return classify(loop, hole=hole, round_ok=False)


ON_AXIS = 1e-6
"""A B-rep cylinder's axis within this [m] of a round loop's centre is the loop's."""


def exact_round(shape: Shape2D, cylinders: tuple[Cylinder, ...], axis: np.ndarray, level: float,
                tolerance: float) -> Shape2D:
    """``shape`` with the diameter of the B-rep cylinder it tessellates, if it is round and
    one of ``cylinders`` is parallel to ``axis``, on the loop's centre (``level`` [m] along
    the axis) and within ``tolerance`` [m] of its radius (deflection 0); else ``shape`` unchanged."""
    if shape.kind != "round":
        return shape
    axis = np.asarray(axis, dtype=float)
    centre = frame_of(axis).T @ shape.centre + axis * level
    for cylinder in cylinders:
        off = centre - cylinder.point
        if (abs(abs(float(cylinder.direction @ axis)) - 1.0) < 1e-9
                and np.linalg.norm(off - (off @ cylinder.direction) * cylinder.direction) < ON_AXIS
                and abs(2 * cylinder.radius - shape.a) <= 2 * tolerance):
            d = 2 * cylinder.radius
            return Shape2D("round", d, d, 0.0, shape.centre, outline=shape.outline)
    return shape


OUTLINE_TOUCH = 5e-7
"""A straight-sided section (rect, square, polygon) has no deflection: its sides are its
loop's own (a polygon's outline is the loop's vertices, written to 0.1 µm by
:func:`rounded`; a rect's sides are its minimum-area rectangle through them). A peg and
hole of which either is a polygon, or both rect or square, that pass only with an overlap
of at most this [m] all round (0.5 µm, five times that resolution) are taken for one
nominal section. More is a peg of another size or shape that does not pass (the ViTac
heptagon misses the rect hole by 1.36 µm all round at its best turn)."""


STRAIGHT = frozenset({"rect", "square"})
"""The section kinds measured as a rectangle (no deflection)."""


def zero_clearance(peg: Shape2D, hole: Shape2D, room: float) -> float | None:
    """How far apart [m] ``peg`` and ``hole`` are when they are a nominal zero-clearance
    fit, given the ``room`` [m] of the peg's section in the hole's
    (:func:`executor.world.geometry.margin`): both round, the peg not narrower than the
    hole's inscribed circle (else it passes with room), their vertex circles' radii within
    :data:`executor.cad.fits.faces.TOUCH` (their difference); a round section and a polygon
    that do not pass, the round side's vertex circle on the polygon's vertices where they
    meet (:func:`_round_and_polygon`); or a polygon on either side, or rect or square both
    (straight sides: no deflection), that pass only with an overlap of at most
    :data:`OUTLINE_TOUCH` all round (half the room, at most 0); None when they are no such
    pair."""
    if "polygon" in (peg.kind, hole.kind) or {peg.kind, hole.kind} <= STRAIGHT:
        if -2 * OUTLINE_TOUCH <= room <= 0:
            return room / 2
        return _round_and_polygon(peg, hole) if {peg.kind, hole.kind} == {"round", "polygon"} and room < 0 else None
    if peg.kind != "round" or hole.kind != "round" or peg.a < hole.a:
        return None
    apart = hole.a / 2 + hole.deflection - peg.a / 2
    return apart if abs(apart) < TOUCH else None


def _round_and_polygon(peg: Shape2D, hole: Shape2D) -> float | None:
    """How far apart [m] a round section's vertex circle (a tessellated cylinder's own
    circle) and a polygon are when they are a nominal zero-clearance fit, as two coaxial
    cylinders of one radius are (:func:`zero_clearance`): a polygon peg whose corners reach
    a round hole's vertex circle within :data:`executor.cad.fits.faces.TOUCH`; a round peg
    in a polygon hole, on the centre of the hole's largest inscribed circle, each edge of
    the hole that its circle crosses a chord of that circle (both its ends on it within
    TOUCH, spanning at most :data:`executor.cad.fits.faces.SMOOTH` about its centre): the
    tessellation of a wall the peg touches (NopSCADlib's hinge pin, d 4, in a teardrop
    hole whose two arcs are tangent to its circle; the chords beside the tangent vertices
    cut 3.2 µm into it on its meshes), not a straight side it goes into; the nearest vertex's distance
    from the circle, None when they are no such pair."""
    if hole.kind == "round":
        reach = -round_fit(polygon(peg.outline, "peg"), None).room
        apart = hole.a / 2 + hole.deflection - reach
        return apart if abs(apart) < TOUCH else None
    outline = polygon(hole.outline, "hole")
    centre = np.asarray(inscribed(outline).coords[0])
    ends = np.asarray(outline.exterior.coords) - centre
    radius = peg.a / 2
    distances = np.linalg.norm(ends, axis=1)
    for k in range(len(ends) - 1):
        if shapely.distance(shapely.LineString(ends[k:k + 2]), shapely.Point(0.0, 0.0)) >= radius:
            continue
        cosine = float(ends[k] @ ends[k + 1]) / (distances[k] * distances[k + 1])
        if np.any(np.abs(distances[k:k + 2] - radius) > TOUCH) or cosine < math.cos(SMOOTH):
            return None
    return float(distances.min() - radius)


def rounded(value: float) -> float:
    """Metres rounded to 0.1 µm (a printed tessellation is no finer), never -0.0."""
    return round(value, 7) + 0.0


def section(name: str, shape: Shape2D) -> Section:
    """The cell's section of a measured one (a polygon's outline about its centre, in the cell's axes)."""
    polygonal = shape.kind == "polygon"
    outline = tuple((rounded(x), rounded(y)) for x, y in shape.outline) if polygonal else ()
    inner = tuple(tuple((rounded(x), rounded(y)) for x, y in ring) for ring in shape.inner) if polygonal else ()
    return Section(name, shape.kind, shape.a, width=shape.b if shape.kind in ("rect", "polygon") else 0.0,
                   outline=outline, corner=shape.corner, inner=inner)


def section_room(peg: Shape2D, hole: Shape2D, peg_name: str = "peg", hole_name: str = "hole",
                 make: Callable[[str, Shape2D], Section] | None = None) -> PolygonFit:
    """How the measured ``peg`` passes the measured ``hole``: rect or square both (straight
    sides), the room of the peg's loop in the hole's at the turns that align the peg's
    side a with the hole's (:func:`aligned_turns`), each at its best shift, the least of
    them (:func:`executor.world.polygon_fit.turned_fit`): the room between the outlines
    the meshes have, corners and all, not that of the rounded rects read from them
    (a peg's holds its loop, a hole's lies inside its loop: each a fraction of the
    corners' tessellation conservative, which the room would add up); else
    :func:`executor.world.geometry.section_fit` of their sections (a polygon's relation,
    a round side's closed forms, the exact rules). A straight pair whose loops' extents
    along the hole's sides already keep the peg out by more than twice
    :data:`OUTLINE_TOUCH` at one of those turns (:func:`_extents_room`, a bound: no pass,
    no nominal zero-clearance fit) keeps the readings' room, a negative measure, without
    the search. OutlineError naming ``peg_name`` or ``hole_name`` when a loop is no
    simple polygon. ``make`` builds the cell's section of a measured one (default
    :func:`section`; a caller measuring one section against many holes passes a cache)."""
    turns = aligned_turns(peg, hole) if {peg.kind, hole.kind} <= STRAIGHT else []
    if not turns or _extents_room(peg, hole, turns) < -2 * OUTLINE_TOUCH:
        build = make or section
        return section_fit(build(peg_name, peg), build(hole_name, hole))
    try:
        return _outline_fit(peg.outline.tobytes(), hole.outline.tobytes(), tuple(turns))
    except OutlineError:  # the cached answer knows no names: name the loop that is no simple polygon
        polygon(peg.outline, peg_name)
        polygon(hole.outline, hole_name)
        raise


def aligned_turns(peg: Shape2D, hole: Shape2D) -> list[float]:
    """The turns [rad] of a rect or square ``peg`` that put its side a along the hole's
    side a (a rect's long side along the long side: two turns half a turn apart; with a
    square on either side, four a quarter turn apart); the skill turns the peg to the
    hole's yaw by one of them."""
    period = 90.0 if "square" in (peg.kind, hole.kind) else 180.0
    return [math.radians(hole.yaw - peg.yaw + k * period) for k in range(round(360.0 / period))]


def _extents_room(peg: Shape2D, hole: Shape2D, turns: list[float]) -> float:
    """A bound [m] on the least room of ``peg``'s loop in ``hole``'s over the ``turns``
    [rad]: at each, half the least difference of the loops' extents along the hole's
    sides (a peg that passes fits within the hole's extent along every direction)."""
    def extents(points: np.ndarray, angle: float) -> np.ndarray:
        c, s = math.cos(angle), math.sin(angle)
        turned = points @ np.array([[c, s], [-s, c]])
        return turned.max(axis=0) - turned.min(axis=0)

    frame = -math.radians(hole.yaw)
    room = extents(hole.outline, frame)
    return min(float(np.min(room - extents(peg.outline, turn + frame))) / 2 for turn in turns)


@functools.lru_cache(maxsize=4096)
def _outline_fit(peg: bytes, hole: bytes, turns: tuple[float, ...]) -> PolygonFit:
    """:func:`turned_fit` of the outlines (their points' float64 bytes, (n, 2) [m]) at the
    ``turns`` [rad], once for each (many pegs of one shape meet many holes of one shape)."""
    return turned_fit(polygon(np.frombuffer(peg).reshape(-1, 2), "peg"),
                      polygon(np.frombuffer(hole).reshape(-1, 2), "hole"), list(turns))


def passes(peg: Shape2D, hole: Shape2D) -> bool:
    """Whether ``peg`` passes ``hole`` as ``sizes.lp`` writes it: a positive room
    (:func:`section_room`) or a nominal zero-clearance fit (:func:`zero_clearance`);
    False when either outline is no simple polygon."""
    try:
        room = section_room(peg, hole).margin
    except OutlineError:
        return False
    return room > 0 or zero_clearance(peg, hole, room) is not None
