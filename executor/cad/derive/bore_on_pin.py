"""A part's bore on a pin of another part (:func:`pin_of`): where the bore holds the pin,
and the sections of both at the narrowest passage over the pin's stretch, the pin's
sections beyond each level joined into one outline."""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np
import shapely

from executor.cad.derive.derived import Derived
from executor.cad.derive.loops import HOLE_LEVELS, SAME_HOLE, bore_around, outer, spans
from executor.cad.sections import (
    OUTLINE_TOUCH,
    Loop,
    Shape2D,
    classify,
    faceted,
    frame_of,
    over_span,
    section_room,
    slice_loops,
)
from executor.world.polygon_fit import OutlineError

_GRID = 1e-8  # the grid [m] the union of a pin's sections is snapped to (far below a fit's room)
_JITTER = 5e-8  # [m] a vertex of that union this close to the line through its neighbours is dropped
_PIN_LEVELS = 64
"""How many spans :func:`pin_of` measures a part's bore and its pin over, split at the ends of the longest."""


def pin_of(derived: Derived, pid: str, name: str, owner: str, taken: Iterable[np.ndarray] = (),
           around: Iterable[str] = ()) -> tuple[Shape2D, Shape2D, np.ndarray, float] | None:
    """Part ``pid`` on a pin of ``owner`` along removal direction ``name``: the pin's
    section, the bore's, the pin's centre [m] and the level [m] along the direction they
    were measured at; None when no level tried has one of ``pid``'s inner loops (its bore)
    around exactly one outline of ``owner`` lying in it (within the bore's sagitta and
    :data:`executor.cad.fits.faces.TOUCH`, as a nominal zero-clearance fit lies; or the
    pieces of one, :func:`executor.cad.derive.loops.bore_around`), no bore around a point of
    ``taken`` (the centres [m] across the axis of pins the part is on already: it goes onto
    another pin only through another bore of its own), nor one where a part of ``around``
    (the other parts ``pid`` may go onto) lies round the pin in the bore. The pin is the owner's
    within the part's reach across the axis, short of the owner's outlines in the part's
    other bores by twice :data:`SAME_HOLE` (a plate's other dowel pin is not this one). The levels
    tried: the middle of the part's extent along the direction, then
    :data:`HOLE_LEVELS` middles of the spans between the owner's vertex levels where both
    reach, longest first (a pulley whose middle lies behind the hub's disc has its bore
    around the boss in front of it).

    The part leaves over the pin's stretch from its own trailing end to the pin's free end
    (the owner's farthest vertex along the direction near the line): its bore at each level
    passes every section of the pin beyond that level. The sections kept are those of the
    narrowest such passage (the least room, :func:`executor.cad.sections.section_room`): the
    bore over one span and the union of the pin's outlines beyond it, over spans end to end
    split at the vertex levels of both (:func:`_intervals`), each measured over its whole
    length (:func:`executor.cad.sections.over_span`: the bore free at every level of it,
    the pin covering at some level), so a bore narrowest at a vertex level is measured
    there (Meta-World's torus ring, d 74.569 mm at its middle, d 74.980 at the nearest
    span's middle); a gland's d 17 lips, not the d 28 recess between them; a pulley's
    d 26 web over the boss's d 26 collar, not the d 22 it sits on. Of the passages within
    :data:`executor.cad.sections.OUTLINE_TOUCH` of the narrowest (one nominal room), the
    one nearest the pin's free end: a taper passes at zero clearance at every level,
    and alike parts on alike pins are then measured at the same level (asap_beam's feet on
    their tapered tenons: at levels 0.7 mm apart their sections differed by 63 µm)."""
    axis = np.array(derived.directions[name])
    part, other = derived.parts[pid].mesh, derived.parts[owner].mesh
    along, other_along = part.vertices @ axis, other.vertices @ axis
    low, high = max(along.min(), other_along.min()), min(along.max(), other_along.max())
    if high - low <= 1e-6:
        return None
    middle = float(along.min() + along.max()) / 2
    meshes = [derived.parts[q].mesh for q in around if q not in (pid, owner)]
    hit = next((found for level in ([middle] if low < middle < high else [])
                + spans(other_along, low, high)[:HOLE_LEVELS]
                if (found := bore_around(part, other, axis, level, taken, meshes)) is not None), None)
    if hit is None:
        return None
    line, apart = hit
    frame = frame_of(axis)
    reach = min(float(np.linalg.norm(part.vertices @ frame.T - line, axis=1).max()), apart - 2 * SAME_HOLE)
    near = other_along[np.linalg.norm(other.vertices @ frame.T - line, axis=1) <= reach + SAME_HOLE]
    start, end = float(along.min()), float(near.max())
    stretch: list[tuple[float, Loop | None, shapely.Polygon | None]] = []
    for low, high in _intervals(np.concatenate([along, near]), start, end, _PIN_LEVELS):
        level = (low + high) / 2
        own, theirs = slice_loops(part, axis, level), slice_loops(other, axis, level)
        bores = [o for o in own if o.contains(line) and not outer(o, own)]
        pins = [o for o in theirs if o.contains(line) and float(np.linalg.norm(o.points - line, axis=1).max()) <= reach
                and outer(o, theirs)]  # the base's plate is no pin
        narrowest = over_span(min(bores, key=lambda o: o.area), part, axis, low, high, hole=True) if bores else None
        widest = over_span(min(pins, key=lambda o: o.area), other, axis, low, high, hole=False,
                           reach=reach) if pins else None
        stretch.append((level, narrowest if narrowest is not None and len(narrowest.points) >= 3 else None,
                        None if widest is None else shapely.Polygon(widest.points)))
    beyond: shapely.Polygon | None = None
    passages: list[tuple[float, Shape2D, Shape2D, float]] = []
    rooms: dict[tuple[bytes, bytes], float] = {}
    for level, bore, pin in reversed(stretch):
        if pin is not None:
            beyond = _joined(beyond, pin)
        if bore is None or beyond is None:
            continue
        outline = _outline(beyond)
        union, hole = classify(outline, hole=False), classify(bore, hole=True)
        hole = faceted(hole, bore, union, hole=True)  # a tessellated round one against no round: its polygon
        union = faceted(union, outline, hole, hole=False)
        key = (np.round(union.outline + union.centre, 8).tobytes(), np.round(bore.points, 8).tobytes())
        if key not in rooms:
            try:
                rooms[key] = section_room(union, hole, "pin", "bore").margin
            except OutlineError:
                continue
        passages.append((rooms[key], union, hole, level))
    if not passages:
        return None
    least = min(room for room, *_ in passages)
    _, pin, hole, level = max((p for p in passages if p[0] <= least + OUTLINE_TOUCH), key=lambda p: p[3])
    return pin, hole, frame.T @ pin.centre + axis * level, level


def _intervals(levels: np.ndarray, low: float, high: float, count: int) -> list[tuple[float, float]]:
    """Spans [m] that cover [``low``, ``high``] end to end, split at the distinct
    ``levels`` [m] within it (a slice changes only at its mesh's vertex levels, so within
    a span each section's corners move in straight lines), spans of 1 µm or less joined to
    the next; where that makes more than ``count`` spans, split only at the ends of the
    ``count`` longest (a joined span is measured over its whole length: never less
    narrow, only coarser)."""
    bounds = [low]
    for level in np.unique(np.round(np.clip(levels, low, high), 9)):
        if level - bounds[-1] > 1e-6 and high - level > 1e-6:
            bounds.append(float(level))
    bounds.append(high)
    pieces = list(zip(bounds[:-1], bounds[1:], strict=True))
    if len(pieces) > count:
        kept = sorted({low, high} | {end for span in sorted(pieces, key=lambda s: s[0] - s[1])[:count] for end in span})
        pieces = list(zip(kept[:-1], kept[1:], strict=True))
    return pieces


def _joined(beyond: shapely.Polygon | None, pin: shapely.Polygon) -> shapely.Polygon:
    """The union of a pin's sections ``beyond`` a level (None: none yet) and ``pin``, its
    section at the level, its vertices on a grid of :data:`_GRID` [m]: the sections of a
    straight pin differ by the mesh's noise (under 1 µm), and GEOS takes seconds over the
    slivers between two alike many-sided outlines unless their vertices snap together.
    A union with more than 4 times the section's vertices has gathered the sections' noise
    (25 000 vertices over 64 levels of a 300-sided pin, each union slower than the last):
    its vertices within the grid of the line through their neighbours are left out
    (Douglas-Peucker, topology kept), which moves it less than the grid (64 noisy sections
    of a round pin: within 3 grid steps of their union taken at once, about one section's
    vertices). A union that stays smaller is kept as it is. On ldraw_axles' cross axle
    (45 vertices a section, its union 239) the simplified union gives the bush and the
    gear on it 0.1 µm more room than the union kept whole (+0.0 µm, not -0.1 µm: the same
    nominal fits)."""
    if beyond is None:
        return pin
    union = shapely.union(beyond, pin, grid_size=_GRID)
    if not isinstance(union, shapely.Polygon):  # snapped apart, or with lines of no area: what holds them all
        polygons = [part for part in shapely.get_parts(union) if isinstance(part, shapely.Polygon)]
        union = polygons[0] if len(polygons) == 1 else shapely.union_all(polygons).convex_hull
    if len(union.exterior.coords) > 4 * len(pin.exterior.coords):
        return shapely.simplify(union, _GRID)
    return union


def _outline(union: shapely.Polygon) -> Loop:
    """The outer loop of the ``union`` of a pin's sections (:func:`_joined`) without its
    jitter: its vertices within :data:`_JITTER` of the line through their neighbours
    dropped (Douglas-Peucker). Where two alike outlines cross at a small angle the union
    alternates between them in edges of a few tens of nm, which the cell's chamfer
    offsets into spikes (``ldraw_axles``' cross axle: 630 vertices for its 16 corners)."""
    return Loop(np.asarray(shapely.simplify(shapely.Polygon(union.exterior), _JITTER).exterior.coords)[:-1])
