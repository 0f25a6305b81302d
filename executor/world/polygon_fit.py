"""Whether a peg's cross-section passes a hole's, for sections of any shape (shapely).

A section is a simple polygon in its own frame [m] (a peg's about its section's centre, a
hole's about the hole's position, x along the part's or hole's x axis), or one with inner
rings: a hole's islands (a pocket around a standing core), a part's bores (a ring). The
peg passes the hole when some turn ``yaw`` about the peg's origin and some shift
``offset`` put the peg's polygon inside the hole's (its bores over the hole's islands; a
peg's bores count only against a hole with islands, where they change nothing else); its
**room** is the largest uniform offset (shapely's buffer) of the peg that still passes,
negative when none does (the peg must shrink by that much), so the room of a round peg of
diameter d in a round hole of D is (D - d) / 2.

:func:`polygon_fit` searches the turn and the shift. Turns one period of the pair's
rotational symmetry apart are the same (a 6-tooth spline in a 6-tooth hub: 60°); the
period is sampled every period / :data:`COARSE_TURNS` (yaw 0 among the samples, the pose
an assembled CAD holds), each turn from two starts (the peg's smallest enclosing circle's
centre on the hole's largest inscribed circle's, and the area centroids together). The
:data:`CANDIDATES` best are refined by zooming in on the best of 9 turns until the peg's
farthest corner moves less than :data:`FINE_SHIFT`, then (unless both outlines share a
rotational symmetry, which keeps their centres together) the shift. Where a shift passes
at that turn, the best shift at a turn is exact (:func:`_free_shift`: the centre of the
largest circle in the shifts that pass, the regions ∂hole ⊕ (−peg) leaves, to
:data:`FINE_SHIFT`), and the turn is climbed once more with each turn at its best shift
(one coarse step either side, down to 1/64 of a coarse step, then by golden section to
1/4096: :func:`_golden_turn`), then at the shift found down to the resolution. Where none
passes, or for two non-convex outlines of more than :data:`SWEEP_PIECES` edge pairs, the
shift by zooming in on the best of a 3 x 3 grid down to :data:`FINE_SHIFT`, and the turn
once more. About a hole's islands neither start need lie where the peg passes (the
centre on an island, a bar passing beside it): every coarse turn is tried at its best shift
too, and no shared symmetry keeps the centres together. The turn's search climbs a
continuous score: the room where the peg is inside, else minus its deepest overlap (a
peg corner outside the hole, a hole corner inside the peg; the farthest such corner of
each peg is found through a k-d tree of points along the outline's edges, which bounds
every corner's distance, and only the corners that may be the farthest are measured, each
against the edges that may be nearest: the numbers ``shapely.distance`` gives against the
whole outline, for a fraction of its pairs); the room of a peg inside the hole, and a
corner's distance to an outline (the symmetry's test), are measured by GEOS on the runs
of edges whose boxes may hold the nearest pair (:meth:`_Pair.clearances`,
:meth:`_Edges.distances`; outlines without inner rings): the same numbers again. The room reported is
measured at the turn and shift found (inside: the peg's distance to the hole's boundary,
exact; outside: a bisection on the buffer to :data:`FINE_SHIFT`), so a pass it reports
is one the peg can make; a pass whose window of turns the search never samples near can
be missed (a no-pass is the search's finding, not a proof; it is searched in four frames
a quarter turn apart, so that it, and the lack it reports, do not follow how the product
is turned about its axis by quarter turns). A peg whose largest
inscribed circle is wider than the hole's does not pass whatever its turn: its room is
then given as the difference of those radii, a bound (it lacks at least that much),
without a search. A round side has closed
forms: a polygon peg in a round hole has the room R - (the radius of its smallest
enclosing circle), a round peg in a polygon hole (the radius of the hole's largest
inscribed circle) - r, at any turn. :func:`turned_fit` measures a pair at given turns
only, each at its best shift (two rect or square sections at the turns the skill aligns
them by: :func:`executor.cad.sections.section_room`).
Deterministic: the same outlines give the same answer, so :func:`polygon_fit` searches
a pair of outlines once (the pair's exact WKB bytes its key: the same peg and hole
polygons of sections that differ elsewhere meet many times in an import), and a polygon's
largest inscribed circle and its symmetry, a peg's best shift at a turn, are found once for each.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
import shapely
from scipy.spatial import cKDTree

COARSE_TURNS = 72
"""Samples of the turn over one period of the pair's symmetry."""
CANDIDATES = 2
"""The best coarse turns refined."""
FINE_SHIFT = 1e-7
"""The shift's, the turn's (at the peg's farthest corner) and a negative room's resolution [m]."""
SWEEP_PIECES = 1024
"""The most edge pairs of two non-convex outlines whose free shifts are built (more: the shift climbed)."""
MAX_ORDER = 64
"""The highest rotational symmetry looked for (a 64-tooth spline)."""
SYMMETRY_TOLERANCE = 1e-6
"""An outline turned by 2π/n onto itself within this [m] has n-fold symmetry."""


class OutlineError(ValueError):
    """An outline that is no simple polygon of positive area (the message says why)."""


@dataclass(frozen=True)
class PolygonFit:
    """How a peg's section sits in a hole's: ``room`` [m] (the largest uniform offset of
    the peg that passes; negative: it does not pass), the peg's ``yaw`` [°] and ``offset``
    (x, y) [m] in the hole's frame where that room was found."""

    room: float
    yaw: float
    offset: tuple[float, float]

    @property
    def margin(self) -> float:
        """Twice the room [m]: the diametral clearance, as D - d of round in round."""
        return 2 * self.room


def polygon(points: np.ndarray | list[list[float]], what: str,
            inner: tuple[np.ndarray, ...] | list[np.ndarray] = ()) -> shapely.Polygon:
    """The polygon of an outline (n, 2) [m] with the ``inner`` rings (each (k, 2) [m]) cut
    out of it (a hole's islands, a part's bores); OutlineError naming ``what`` when a ring
    has fewer than 3 points or a non-finite one, or the polygon is no valid one of positive
    area (crossing edges, an inner ring outside the outline or across another)."""
    rings = [np.asarray(ring, dtype=float) for ring in (points, *inner)]
    for array in rings:
        if array.ndim != 2 or array.shape[0] < 3 or array.shape[1] != 2:
            raise OutlineError(f"{what}: expected an outline of at least 3 points [x, y], got shape {array.shape}")
        if not np.all(np.isfinite(array)):
            raise OutlineError(f"{what}: expected finite coordinates in its outline")
    shape = shapely.Polygon(rings[0], rings[1:])
    if not shape.is_valid or shape.area <= 0:
        raise OutlineError(f"{what}: expected a simple outline (no crossing edges, positive area), got "
                           f"{shapely.is_valid_reason(shape)}")
    return shapely.orient_polygons(shape)


def _edges_of(shape: shapely.Polygon) -> np.ndarray:
    """The edges (n, 2, 2) [m] of every ring of ``shape`` (its outline's, then its inner rings')."""
    rings = [np.asarray(ring.coords)[:-1] for ring in (shape.exterior, *shape.interiors)]
    return np.concatenate([np.stack([ring, np.roll(ring, -1, axis=0)], axis=1) for ring in rings])


def _boundary(shape: shapely.Polygon) -> shapely.Geometry:
    """The rings of ``shape`` as one geometry (its outline alone where it has no inner ring)."""
    if not shape.interiors:
        return shape.exterior
    return shape.boundary


def circle(radius: float, *, outside: bool) -> shapely.Polygon:
    """A 256-gon of a circle of ``radius`` [m]: around it (``outside``, a peg's: it holds
    the circle) or inside it (a hole's); either is within 0.008 % of the radius."""
    sides = 256
    scale = 1 / math.cos(math.pi / sides) if outside else 1.0
    angles = 2 * math.pi * np.arange(sides) / sides
    return shapely.Polygon(np.stack([np.cos(angles), np.sin(angles)], axis=1) * radius * scale)


def symmetry(shape: shapely.Polygon) -> int:
    """The largest n <= :data:`MAX_ORDER` such that turning ``shape`` by 2π/n about the
    origin puts each of its corners (its inner rings' too) on its boundary within :data:`SYMMETRY_TOLERANCE`
    (eight spread corners tried for every n at once, then all for the likely ones), once
    for each polygon (its WKB bytes)."""
    return _symmetry(shapely.to_wkb(shape))


@functools.lru_cache(maxsize=4096)
def _symmetry(wkb: bytes) -> int:
    shape = shapely.from_wkb(wkb)
    edge = _Edges(shape)
    corners = _edges_of(shape)[:, 0]
    few = corners[:: max(1, len(corners) // 8)]
    orders = np.arange(MAX_ORDER, 1, -1)
    turned = np.concatenate([_turn(few, 2 * math.pi / order) for order in orders])
    off = edge.distances(turned).reshape(len(orders), len(few)).max(axis=1)
    for order in orders[off <= SYMMETRY_TOLERANCE]:
        if float(np.max(edge.distances(_turn(corners, 2 * math.pi / order)))) <= SYMMETRY_TOLERANCE:
            return int(order)
    return 1


def _turn(points: np.ndarray, angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return points @ np.array([[c, s], [-s, c]])


_SAMPLES = 4096
"""Points along a ring's edges that :class:`_Edges` indexes, evenly by length (and its corners)."""
_INDEXED = 256
"""A ring of more corners than this is indexed (:class:`_Edges`); GEOS measures a smaller one
whole faster (the corpus's outlines: ``vitac_shapes``' 4 to 48 corners, ``flynn_clutch``'s
splines 634 to 1192)."""
_SLACK = 1e-12
"""[m] added to the bounds :class:`_Edges` compares (their rounding)."""
_CHUNK = 32
"""Edges of a ring's runs whose boxes :meth:`_Pair.clearances` compares."""


def _runs(rings: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Closed rings (k, n + 1, 2) [m] cut into runs of :data:`_CHUNK` edges in a row (the
    last shorter): their line strings (k, runs), each the ring's corners in its order, and
    their boxes' lowest and highest corners (k, runs, 2) [m]."""
    count, ends = rings.shape[0], rings.shape[1] - 1
    starts = np.arange(0, ends, _CHUNK)
    sizes = np.minimum(starts + _CHUNK, ends) - starts + 1
    index = np.repeat(starts - np.cumsum(sizes) + sizes, sizes) + np.arange(int(sizes.sum()))
    corners = rings[:, index]
    lines = shapely.linestrings(corners.reshape(-1, 2), indices=np.repeat(np.arange(count * len(starts)),
                                                                          np.tile(sizes, count)))
    first = np.cumsum(sizes) - sizes
    return (lines.reshape(count, len(starts)), np.minimum.reduceat(corners, first, axis=1),
            np.maximum.reduceat(corners, first, axis=1))


def _largest(values: np.ndarray, groups: np.ndarray, count: int) -> np.ndarray:
    """The largest of ``values`` in each of ``count`` groups (``groups``: each value's); -inf without one."""
    found = np.full(count, -np.inf)
    np.maximum.at(found, groups, values)
    return found


class _Edges:
    """A polygon's rings, and the largest distance of a group of points to them as ``shapely.distance``
    gives each (GEOS: the least of the point's distances to every edge, brute force), for
    far fewer pairs: a k-d tree of points along the edges at most ``step`` apart bounds each
    point's distance (between its nearest indexed point's distance less ``step`` / 2 and
    that distance), and only the points whose bound reaches the best lower bound of their
    group are measured, each against the edges with an indexed point within its bound plus
    ``step`` / 2 (which hold its nearest edges), by GEOS as it measures the whole ring: the
    same number, which the deepest overlap of a peg needs. An outline without inner rings
    has runs of :data:`_CHUNK` edges (:func:`_runs`) that answer each point's own distance
    (:meth:`distances`)."""

    runs: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
    """An indexed outline's runs of edges without inner rings (:func:`_runs`): line strings,
    boxes' lowest and highest corners; None otherwise."""

    def __init__(self, shape: shapely.Polygon) -> None:
        self.ring = _boundary(shape)
        shapely.prepare(self.ring)
        edges = _edges_of(shape)
        self.indexed = len(edges) > _INDEXED
        if not self.indexed:
            return
        corners, ends = edges[:, 0], edges[:, 1]
        if not shape.interiors:
            self.runs = _runs(np.asarray(shape.exterior.coords)[None])
            self.run_starts = corners[::_CHUNK]
            """Each run's first corner [m]."""
        lengths = np.hypot(*(ends - corners).T)
        self.step = float(lengths.sum()) / _SAMPLES
        pieces = np.maximum(1, np.ceil(lengths / self.step)).astype(int)
        self.owner = np.repeat(np.arange(len(corners)), pieces + 1)
        starts = np.cumsum(pieces + 1) - (pieces + 1)
        along = (np.arange(len(self.owner)) - starts[self.owner]) / pieces[self.owner]  # 0 to 1 on each edge
        self.tree = cKDTree(corners[self.owner] + along[:, None] * (ends - corners)[self.owner])
        self.lines = shapely.linestrings(np.stack([corners, ends], axis=1))

    def distances(self, points: np.ndarray) -> np.ndarray:
        """The distance [m] of each of ``points`` (k, 2) [m] to the rings as
        ``shapely.distance`` gives it (the least of its distances to every edge): for an
        outline with runs, measured against only the runs of edges whose boxes lie within its
        distance to the nearest run's first corner, each as GEOS measures the whole ring."""
        if self.runs is None:
            return shapely.distance(self.ring, shapely.points(points))
        lines, low, high = (run[0] for run in self.runs)
        offset = points[:, None] - low[None]  # (k, runs, 2): from each box's lowest corner
        gap = np.maximum(np.maximum(-offset, points[:, None] - high[None]), 0.0)
        bound = np.min(np.hypot(*(points[:, None] - self.run_starts[None]).transpose(2, 0, 1)), axis=1)
        point, run = np.nonzero(np.hypot(gap[..., 0], gap[..., 1]) <= bound[:, None] + _SLACK)
        found = np.full(len(points), np.inf)
        np.minimum.at(found, point, shapely.distance(lines[run], shapely.points(points[point])))
        return found

    def largest(self, points: np.ndarray, groups: np.ndarray, count: int) -> np.ndarray:
        """The largest distance [m] to the ring of ``points`` (k, 2) [m] in each of ``count``
        groups (``groups``: each point's), -inf in a group without one."""
        if not len(points):
            return np.full(count, -np.inf)
        if not self.indexed:
            return _largest(shapely.distance(self.ring, shapely.points(points)), groups, count)
        bound = self.tree.query(points)[0]
        best = _largest(bound - self.step / 2 - _SLACK, groups, count)
        chosen = np.flatnonzero(bound + _SLACK >= best[groups])
        balls = self.tree.query_ball_point(points[chosen], bound[chosen] + self.step / 2 + _SLACK)
        counts = np.fromiter(map(len, balls), int, len(balls))
        point, edge = np.divmod(np.unique(np.repeat(chosen, counts) * len(self.lines)
                                          + self.owner[np.concatenate(balls).astype(int)]), len(self.lines))
        measured = np.full(len(points), np.inf)
        np.minimum.at(measured, point, shapely.distance(shapely.points(points[point]), self.lines[edge]))
        return _largest(measured[chosen], groups[chosen], count)


class _Pair:
    """A peg and a hole about their centres (the peg's smallest enclosing circle's, the
    hole's largest inscribed circle's), scored at a turn [rad] and shift [m]."""

    def __init__(self, peg: shapely.Polygon, hole: shapely.Polygon) -> None:
        self.hole = hole
        self.hole_edge = _Edges(hole)
        shapely.prepare(hole)
        self.peg_points = np.asarray(peg.exterior.coords)[:-1]
        self.hole_points = np.asarray(hole.exterior.coords)[:-1]
        self.peg_edges, self.hole_edges = _edges_of(peg), _edges_of(hole)
        """Every ring's edges (n, 2, 2) [m]: a peg's bores, a hole's islands too."""
        self.peg_rings = [len(ring.coords) - 1 for ring in (peg.exterior, *peg.interiors)]
        """How many corners each ring of the peg has (its outline's first)."""
        self.peg = peg
        shapely.prepare(peg)
        self.peg_edge = _Edges(peg)
        hull = shapely.convex_hull(peg)
        self.peg_hull = np.asarray(hull.exterior.coords)[:-1]
        self.sweep_convex = hull.area <= peg.area * (1 + 1e-12) or \
            shapely.convex_hull(hole).area <= hole.area * (1 + 1e-12)
        """Whether :func:`_free_shift` sweeps the peg's convex hull (either outline convex)."""
        self.best_shifts: dict[str, np.ndarray | None] = {}
        """:func:`_best_shift`'s answers, by the turn's float in hex."""

    def pegs(self, angles: np.ndarray, shifts: np.ndarray) -> np.ndarray:
        """The peg polygons turned by ``angles`` (k,) and shifted by ``shifts`` (k, 2)
        (with their bores, where the peg has any)."""
        c, s = np.cos(angles)[:, None], np.sin(angles)[:, None]
        x, y = self.peg_edges[:, 0, 0], self.peg_edges[:, 0, 1]
        coords = np.stack([c * x - s * y + shifts[:, :1], s * x + c * y + shifts[:, 1:]], axis=2)
        if len(self.peg_rings) == 1:
            return shapely.polygons(coords)
        count, rings = len(angles), len(self.peg_rings)
        ring_of = np.repeat(np.arange(rings), self.peg_rings)
        made = shapely.linearrings(coords.reshape(-1, 2),
                                   indices=(np.arange(count)[:, None] * rings + ring_of[None, :]).ravel())
        return shapely.polygons(made, indices=np.repeat(np.arange(count), rings))

    def scores(self, angles: np.ndarray, shifts: np.ndarray) -> np.ndarray:
        """The room [m] of the peg at each turn and shift where it is inside the hole, else
        minus its deepest overlap: the farthest of its corners outside the hole or of the
        hole's corners inside it."""
        pegs = self.pegs(angles, shifts)
        inside = shapely.contains(self.hole, pegs)
        result = np.empty(len(angles))
        if np.any(inside):
            result[inside] = self.clearances(pegs[inside])
        out = ~inside
        if np.any(out):
            count = int(out.sum())
            corners = shapely.get_coordinates(pegs[out])
            groups = np.repeat(np.arange(count), len(self.peg_edges) + len(self.peg_rings))
            outside = ~shapely.contains_xy(self.hole, corners[:, 0], corners[:, 1])
            deepest = self.hole_edge.largest(corners[outside], groups[outside], count)
            # the hole's corners, brought into each peg's frame, inside the peg
            back = self.hole_edges[None, :, 0, :] - shifts[out][:, None, :]
            c, s = np.cos(-angles[out])[:, None], np.sin(-angles[out])[:, None]
            local = np.stack([c * back[..., 0] - s * back[..., 1], s * back[..., 0] + c * back[..., 1]],
                             axis=2).reshape(-1, 2)
            groups = np.repeat(np.arange(count), len(self.hole_edges))
            within = shapely.contains_xy(self.peg, local[:, 0], local[:, 1])
            poke = self.peg_edge.largest(local[within], groups[within], count)
            result[out] = -np.maximum(np.maximum(deepest, poke), 0.0)  # 0: no corner out
        return result

    def clearances(self, pegs: np.ndarray) -> np.ndarray:
        """The distance [m] from the hole's boundary to each of ``pegs`` (inside the hole)
        as ``shapely.distance`` gives it: GEOS takes the least of every pair of edges' (the
        hole's, the peg's) distances. For two outlines of more than :data:`_INDEXED` corners
        and no inner rings, GEOS measures only the runs of edges (:func:`_runs`) whose boxes
        lie within a bound of that least (the least distance of a few of the peg's corners
        to the hole), each pair of runs as the whole outlines' pairs of edges are measured:
        the same number."""
        hole_runs = self.hole_edge.runs
        if len(self.peg_points) <= _INDEXED or hole_runs is None or len(self.peg_rings) > 1:
            return shapely.distance(self.hole_edge.ring, pegs)
        count = len(pegs)
        placed = shapely.get_coordinates(pegs).reshape(count, -1, 2)  # each ring closed
        few = placed[:, :: max(1, len(self.peg_points) // 8)]
        bound = self.hole_edge.distances(few.reshape(-1, 2)).reshape(count, -1).min(axis=1)
        lines, low, high = _runs(placed)
        hole_lines, hole_low, hole_high = hole_runs
        gap = np.maximum(np.maximum(low[:, :, None] - hole_high[:, None], hole_low[:, None] - high[:, :, None]), 0.0)
        peg, run, hole_run = np.nonzero(np.hypot(gap[..., 0], gap[..., 1]) <= bound[:, None, None] + _SLACK)
        found = np.full(count, np.inf)
        np.minimum.at(found, peg, shapely.distance(hole_lines[0, hole_run], lines[peg, run]))
        return found

    def score(self, angle: float, shift: np.ndarray) -> float:
        return float(self.scores(np.array([angle]), shift[None, :])[0])

    def room(self, angle: float, shift: np.ndarray) -> float:
        """The exact room [m] at a turn and shift: the peg's distance to the hole's boundary
        when inside, else the buffer (bisection to :data:`FINE_SHIFT`) that brings it in."""
        found = self.score(angle, shift)
        peg = self.pegs(np.array([angle]), shift[None, :])[0]
        if found >= 0 and shapely.contains(self.hole, peg):
            return found
        # out, or across the hole's boundary with no corner beyond it (a bar across an island)
        found = min(found, -FINE_SHIFT)

        def inside(buffer: float) -> bool:
            """Whether the peg offset by ``buffer`` [m] is inside (shrunk to nothing: it is)."""
            offset = peg.buffer(buffer, join_style="mitre")
            return bool(offset.is_empty or shapely.contains(self.hole, offset))

        low, high = found, 0.0  # high never passes (the peg overlaps the hole's boundary)
        while not inside(low):
            high, low = low, 2 * low
        while high - low > FINE_SHIFT:
            mid = (low + high) / 2
            low, high = (mid, high) if inside(mid) else (low, mid)
        return low


def polygon_fit(peg: shapely.Polygon, hole: shapely.Polygon) -> PolygonFit:
    """The best turn and shift of ``peg`` in ``hole`` and the room there (the module
    docstring); both simple polygons in their own frames [m] (:func:`polygon`). Where the
    search finds no pass, it searches the pair again turned together by one, two and
    three quarter turns (exactly: a permutation of the coordinates with signs) and keeps
    the most room (the first frame's on a tie), its offset turned back: the search's start
    (the hole's largest inscribed circle's centre, which slides where that circle is not
    unique) and its steps (a grid along the frame's axes) follow the frame, so one frame's
    least lack, a local best, changed with a quarter turn of the product (``vitac_shapes``'
    hourglass peg in the convex hole: 1.773, 1.681, 1.773, 2.104 mm lacking per side); the
    four frames searched are the same four however the product is turned by quarter turns
    (but for a hole with islands, searched once: its search tries every coarse turn at its
    best shift, which no frame changes, so the answer whether it passes follows no frame;
    the lack it reports where none does may).
    Once for each pair of outlines (their WKB bytes, which hold the coordinates exactly)."""
    if not hole.interiors:  # a peg's bores meet nothing of a hole without islands
        peg = shapely.Polygon(peg.exterior)
    return _polygon_fit(shapely.to_wkb(peg), shapely.to_wkb(hole))


@functools.lru_cache(maxsize=4096)
def _polygon_fit(peg_wkb: bytes, hole_wkb: bytes) -> PolygonFit:
    """:func:`polygon_fit` of the polygons of these WKB bytes."""
    peg, hole = shapely.from_wkb(peg_wkb), shapely.from_wkb(hole_wkb)
    bound = _room_bound(peg, hole)
    found = _searched(peg, hole, bound)
    if found.room >= 0 or bound < 0 or hole.interiors:  # about islands every coarse turn's best shift was tried
        return found
    for quarter in (1, 2, 3):
        turned_peg, turned_hole = (shapely.transform(shape, lambda xy, k=quarter: _quarters(xy, k))
                                   for shape in (peg, hole))
        fit = _searched(turned_peg, turned_hole, bound)
        if fit.room > found.room:
            x, y = _quarters(np.array([fit.offset]), -quarter)[0]
            found = PolygonFit(fit.room, fit.yaw, (float(x), float(y)))
    return found


def _quarters(points: np.ndarray, quarter: int) -> np.ndarray:
    """``points`` (n, 2) turned by ``quarter`` × 90° about the origin (negative: clockwise),
    exactly (the coordinates swapped and negated)."""
    for _ in range(quarter % 4):
        points = np.column_stack([-points[:, 1], points[:, 0]])
    return points


def _searched(peg: shapely.Polygon, hole: shapely.Polygon, bound: float) -> PolygonFit:
    """:func:`polygon_fit`'s search in the frame the polygons are given in; ``bound`` [m]
    the room's (:func:`_room_bound`: negative, the answer without a search)."""
    peg_centre = np.asarray(shapely.minimum_bounding_circle(peg).centroid.coords[0])
    hole_centre = np.asarray(inscribed(hole).coords[0])
    if bound < 0:
        return PolygonFit(bound, 0.0, (float(hole_centre[0] - peg_centre[0]), float(hole_centre[1] - peg_centre[1])))
    pair = _Pair(shapely.affinity.translate(peg, *-peg_centre), shapely.affinity.translate(hole, *-hole_centre))
    orders = symmetry(pair.peg), symmetry(pair.hole)
    period = 2 * math.pi / math.lcm(*orders)
    reach = float(np.max(np.linalg.norm(pair.peg_points, axis=1)))
    fine = FINE_SHIFT / reach  # the turn that moves the peg's farthest corner by FINE_SHIFT
    coarse = period / COARSE_TURNS
    turns = np.arange(COARSE_TURNS) * coarse - period / 2  # yaw 0 among them: the pose the CAD may hold
    # two starts at every turn: the centres together, the area centroids together (one
    # where they are the centres, as for outlines symmetric about them)
    peg_mid, hole_mid = np.asarray(pair.peg.centroid.coords[0]), np.asarray(pair.hole.centroid.coords[0])
    angles, starts = turns, np.zeros((COARSE_TURNS, 2))
    if max(float(np.linalg.norm(peg_mid)), float(np.linalg.norm(hole_mid))) > FINE_SHIFT:
        angles = np.concatenate([turns, turns])
        starts = np.concatenate([starts, hole_mid - np.stack([_turn(peg_mid[None, :], t)[0] for t in turns])])
    sweep = pair.sweep_convex or len(pair.peg_edges) * len(pair.hole_edges) <= SWEEP_PIECES
    if pair.hole.interiors and sweep:
        # about islands neither start need lie where the peg passes (the centre is on an
        # island; a bar passes beside it): a third start at every turn, its best shift
        best_shifts = [_best_shift(pair, float(turn)) for turn in turns]
        angles = np.concatenate([angles, turns])
        starts = np.concatenate([starts, [np.zeros(2) if free is None else free for free in best_shifts]])
    scores = pair.scores(angles, starts)
    best = (-math.inf, 0.0, np.zeros(2))
    for index in np.argsort(-scores, kind="stable")[:CANDIDATES]:
        angle, shift = _refine_turn(pair, float(angles[index]), starts[index], coarse, fine)
        # no shared symmetry to keep the centres together, or islands where they would meet
        if math.gcd(*orders) == 1 or pair.hole.interiors:
            if sweep and (free := _best_shift(pair, angle)) is not None:
                angle, shift = _refine_turn_shifted(pair, angle, free, coarse)
                angle, shift = _golden_turn(pair, angle, shift, coarse / _SHIFTED_ZOOM)
                angle, shift = _refine_turn(pair, angle, shift, coarse / _SHIFTED_ZOOM, fine)
                free = _best_shift(pair, angle)
                shift = shift if free is None else free
            else:
                shift = _refine_shift(pair, angle, shift, reach)
                angle, shift = _refine_turn(pair, angle, shift, coarse / 8, fine)
        found = pair.score(angle, shift)
        if found > best[0] + FINE_SHIFT:
            best = (found, angle, shift)
    _, angle, shift = best
    room = pair.room(angle, shift)
    # the peg's origin where the turned peg's centre sits at the hole's centre plus the shift
    origin = hole_centre + shift - _turn(peg_centre[None, :], angle)[0]
    yaw = math.degrees(math.remainder(angle, period))
    return PolygonFit(room, round(yaw, 9) + 0.0, (float(origin[0]), float(origin[1])))



def turned_fit(peg: shapely.Polygon, hole: shapely.Polygon, turns: list[float]) -> PolygonFit:
    """The room of ``peg`` in ``hole`` (both simple polygons in their own frames [m],
    :func:`polygon`) at each of the ``turns`` [rad] of the peg about its origin, each at
    its best shift, and the least of them with that turn and shift: the best shift as in
    :func:`polygon_fit` (the centroids together where the outlines share a rotational
    symmetry, a rounded rect's half turn; else exact where a shift passes and the free
    shifts are built, else climbed from the centroids together), the room measured there
    (a pose the peg can take: never more room than the outlines have). The shift being free, the outlines
    are taken about their area centroids (a hole's largest inscribed circle to 0.1 µm took
    0.1 s on a beam's 100 mm slot)."""
    peg_centre, hole_centre = (np.asarray(shape.centroid.coords[0]) for shape in (peg, hole))
    pair = _Pair(shapely.affinity.translate(peg, *-peg_centre), shapely.affinity.translate(hole, *-hole_centre))
    reach = float(np.max(np.linalg.norm(pair.peg_points, axis=1)))
    sweep = pair.sweep_convex or len(pair.peg_edges) * len(pair.hole_edges) <= SWEEP_PIECES
    # a shared symmetry keeps them together (not about an island)
    together = math.gcd(symmetry(pair.peg), symmetry(pair.hole)) > 1 and not pair.hole.interiors
    found = []
    for angle in turns:
        free = None if together or not sweep else _best_shift(pair, angle)
        shift = free if free is not None else np.zeros(2) if together else \
            _refine_shift(pair, angle, np.zeros(2), reach)  # from the centroids together
        found.append((pair.room(angle, shift), angle, shift))
    least = min(room for room, _, _ in found)
    # the pose: the first turn within the float's noise (1 pm) of the least room (alike turns of symmetric outlines)
    _, angle, shift = next(pose for pose in found if pose[0] <= least + _NOISE)
    origin = hole_centre + shift - _turn(peg_centre[None, :], angle)[0]
    return PolygonFit(least, round(math.degrees(angle), 9) + 0.0, (float(origin[0]), float(origin[1])))


_NOISE = 1e-12
"""Rooms [m] of :func:`turned_fit`'s turns this close are alike (the float's noise)."""


_TURNS = np.linspace(-1.0, 1.0, 9)
_SHIFTS = np.array([[x, y] for x in (-1.0, 0.0, 1.0) for y in (-1.0, 0.0, 1.0)])
_ROUNDS = 64
"""A refinement stops after this many rounds whatever its step (a score that keeps climbing)."""
_SHIFTED_ZOOM = 64
"""The turn climbed at its best shift from one coarse step either side down to this many times narrower."""


def _room_bound(peg: shapely.Polygon, hole: shapely.Polygon) -> float:
    """A bound [m] the room cannot exceed: the peg offset by r has a largest inscribed
    circle r wider (narrower for r < 0), which must fit the hole's."""
    return float(shapely.length(inscribed(hole)) - shapely.length(inscribed(peg))) + FINE_SHIFT


def inscribed(shape: shapely.Polygon) -> shapely.LineString:
    """The largest inscribed circle of ``shape`` to :data:`FINE_SHIFT` as shapely gives it
    (its centre, then the nearest boundary point [m]), once for each polygon (its WKB bytes)."""
    return _inscribed(shapely.to_wkb(shape))


@functools.lru_cache(maxsize=4096)
def _inscribed(wkb: bytes) -> shapely.LineString:
    return shapely.maximum_inscribed_circle(shapely.from_wkb(wkb), FINE_SHIFT)


def _refine_turn(pair: _Pair, angle: float, shift: np.ndarray, step: float, fine: float) -> tuple[float, np.ndarray]:
    """Climb the score along the turn from ``angle`` [rad]: 9 turns within ``step`` [rad]
    either side at once, the window a quarter as wide when the best is inside it, until it
    is narrower than ``fine`` [rad]."""
    for _ in range(_ROUNDS):
        if step <= fine:
            break
        tried = angle + step * _TURNS
        scores = pair.scores(tried, np.tile(shift, (len(tried), 1)))
        k = int(np.argmax(scores))
        angle = float(tried[k])
        if 0 < k < len(tried) - 1:
            step /= 4
    return angle, shift


def _refine_turn_shifted(pair: _Pair, angle: float, shift: np.ndarray, step: float) -> tuple[float, np.ndarray]:
    """Climb the room along the turn from ``angle`` [rad], each turn at its best shift
    (:func:`_best_shift`, else ``shift``): 9 turns within ``step`` [rad] either side, the window a quarter
    as wide when the best is inside it, until it is :data:`_SHIFTED_ZOOM` times narrower."""
    stop = step / _SHIFTED_ZOOM
    for _ in range(_ROUNDS):
        if step <= stop:
            break
        tried = angle + step * _TURNS
        shifts = [shift if (free := _best_shift(pair, float(turn))) is None else free for turn in tried]
        scores = pair.scores(tried, np.array(shifts))
        k = int(np.argmax(scores))
        angle, shift = float(tried[k]), shifts[k]
        if 0 < k < len(tried) - 1:
            step /= 4
    return angle, shift


_GOLDEN_ZOOM = 64
""":func:`_golden_turn` narrows its window this many times."""


def _golden_turn(pair: _Pair, angle: float, shift: np.ndarray, step: float) -> tuple[float, np.ndarray]:
    """The turn [rad] within ``step`` [rad] of ``angle`` with the most room at its best shift
    (:func:`_best_shift`, else ``shift``), by golden section down to a window
    :data:`_GOLDEN_ZOOM` times narrower, and that shift; ``angle`` and ``shift`` when none
    tried has more. The climb of :func:`_refine_turn_shifted` stops a fraction of its step
    from the best turn, and the room at the best shift changes along the turn as fast as
    the peg's corners move (PEARL's digit 2 in its pocket: 1.3 µm less room per side 0.014°
    off its best turn, at 0.389° for 0.375°)."""
    def room(turn: float) -> tuple[float, np.ndarray]:
        free = _best_shift(pair, turn)
        at = shift if free is None else free
        return pair.score(turn, at), at

    best = (pair.score(angle, shift), angle, shift)
    ratio = (math.sqrt(5.0) - 1.0) / 2.0
    low, high = angle - step, angle + step
    left, right = high - ratio * (high - low), low + ratio * (high - low)
    (f_left, at_left), (f_right, at_right) = room(left), room(right)
    while high - low > 2 * step / _GOLDEN_ZOOM:
        for found, turn, at in ((f_left, left, at_left), (f_right, right, at_right)):
            if found > best[0]:
                best = (found, turn, at)
        if f_left >= f_right:
            high, right, f_right, at_right = right, left, f_left, at_left
            left = high - ratio * (high - low)
            f_left, at_left = room(left)
        else:
            low, left, f_left, at_left = left, right, f_right, at_right
            right = low + ratio * (high - low)
            f_right, at_right = room(right)
    for found, turn, at in ((f_left, left, at_left), (f_right, right, at_right)):
        if found > best[0]:
            best = (found, turn, at)
    return best[1], best[2]


def _best_shift(pair: _Pair, angle: float) -> np.ndarray | None:
    """:func:`_free_shift` of the pair at the turn ``angle`` [rad], once for each turn (the
    float exactly: -0.0 is not 0.0; a refinement tries the best turn of a round again)."""
    key = float(angle).hex()
    if key not in pair.best_shifts:
        pair.best_shifts[key] = _free_shift(pair, angle)
    found = pair.best_shifts[key]
    return None if found is None else found.copy()


def _free_shift(pair: _Pair, angle: float) -> np.ndarray | None:
    """The shift [m] with the most room at the turn ``angle`` [rad], from the free shifts:
    the peg at shift t meets the hole's boundary where t lies in ∂hole ⊕ (−peg), and its
    room there is t's distance to that set (the distance from peg + t to ∂hole). With a
    convex peg, or a convex hole (where the peg's convex hull passes as the peg does, with
    the same room), that set is the union of the convex hulls of each hole edge's ends
    minus the (hull's) corners; else ∂hole ⊕ (−∂peg), the union of the parallelograms of
    each hole edge minus each peg edge. The regions that set leaves, whose peg is inside
    the hole, are the shifts that pass; the centre of the largest circle in them (to
    :data:`FINE_SHIFT`) is the best shift (a parallelogram of two parallel edges is flat and
    left out, covered by its neighbours' sides unless an outline has two collinear edges in
    a row: the room is measured at the shift found, never taken from the circle); None
    where no shift passes."""
    hole_edges = pair.hole_edges
    if pair.sweep_convex:
        peg = _turn(pair.peg_hull, angle)
        corners = (hole_edges[:, :, None, :] - peg[None, None, :, :]).reshape(-1, 2)
        size = 2 * len(peg)
    else:
        peg = _turn(pair.peg_points, angle)
        peg_edges = _turn(pair.peg_edges.reshape(-1, 2), angle).reshape(-1, 2, 2)
        corners = (hole_edges[:, None, :, None, :] - peg_edges[None, :, None, :, :]).reshape(-1, 2)
        size = 4
    hulls = shapely.convex_hull(shapely.multipoints(corners, indices=np.repeat(np.arange(len(corners) // size), size)))
    touching = shapely.union_all(hulls[shapely.get_type_id(hulls) == shapely.GeometryType.POLYGON])
    reach = float(np.max(np.linalg.norm(peg, axis=1)))  # the shifts that pass lie within it of the hole
    low, high = pair.hole_points.min(axis=0) - 2 * reach, pair.hole_points.max(axis=0) + 2 * reach
    free = shapely.get_parts(shapely.difference(shapely.box(*low, *high), touching))
    free = free[shapely.get_type_id(free) == shapely.GeometryType.POLYGON]
    if not len(free):
        return None
    points = shapely.get_coordinates(shapely.point_on_surface(free))  # a point of each region, scored at once
    inside = free[pair.scores(np.full(len(free), angle), points) > 0]
    if not len(inside):
        return None
    circles = shapely.maximum_inscribed_circle(inside, FINE_SHIFT)
    return np.asarray(circles[int(np.argmax(shapely.length(circles)))].coords[0])


def _refine_shift(pair: _Pair, angle: float, shift: np.ndarray, reach: float) -> np.ndarray:
    """Climb the score over the shift [m] from ``shift``: a 3 x 3 grid at once, from twice
    the score's size (at most a tenth of the peg's ``reach`` [m]) either side, the grid half
    as wide when its centre is the best, down to :data:`FINE_SHIFT`."""
    step = min(reach / 10, max(2 * abs(pair.score(angle, shift)), 100 * FINE_SHIFT))
    for _ in range(_ROUNDS):
        if step <= FINE_SHIFT:
            break
        moves = shift + step * _SHIFTS
        scores = pair.scores(np.full(len(moves), angle), moves)
        k = int(np.argmax(scores))
        shift = moves[k]
        if not np.any(_SHIFTS[k]):
            step /= 2
    return shift


def round_fit(peg: shapely.Polygon | None, hole: shapely.Polygon | None, peg_diameter: float = 0.0,
              hole_diameter: float = 0.0) -> PolygonFit:
    """The closed forms of a round side (one of ``peg`` and ``hole`` None: round of that
    diameter [m]): a polygon peg in a round hole, a round peg in a polygon hole, any turn,
    the peg's centre on the circle's (the room the largest, the yaw 0)."""
    if hole is None:
        assert peg is not None
        mbc = shapely.minimum_bounding_circle(peg)
        centre = np.asarray(mbc.centroid.coords[0])
        reach = float(np.max(np.linalg.norm(np.asarray(peg.exterior.coords) - centre, axis=1)))
        return PolygonFit(hole_diameter / 2 - reach, 0.0, (float(-centre[0]), float(-centre[1])))
    centre = np.asarray(inscribed(hole).coords[0])
    inner = float(shapely.distance(_boundary(hole), shapely.Point(centre)))
    return PolygonFit(inner - peg_diameter / 2, 0.0, (float(centre[0]), float(centre[1])))
