"""Screwed pairs: a screw's thread in a nut or a tapped hole, each a fit that slides along
its axis (:class:`executor.cad.fits.faces.Slide`, with the thread's pitch and lead).

**Modelled threads** (:func:`screwed_pairs`). A screw's outermost surface and a nut's
innermost, cut by half-planes about one axis (:func:`thread_profiles`), are each one
helical surface (:func:`helix`) of one pitch and one lead, the screw's crest outside the
nut's minor radius; or the nut's hole is plain and round at the thread's tap drill
(:func:`_tap_drill`). A modelled thread in a part that is no screwed pair with it is named
(:func:`lone_thread`). **Cosmetic threads** (:func:`cosmetic_pairs`): a plain cylinder of a
screw in a plain hole of another part, their diameters a standard thread's major and tap
drill (:data:`STANDARD_THREADS`, :func:`cosmetic_thread`).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, replace
from fractions import Fraction

import numpy as np
import trimesh

from executor.cad.fits.faces import COARSEST, TOUCH, CylinderFace, PrismFace, Slide, _seated, coaxial
from executor.cad.sweep import axis_name

THREAD_ANGLES = 8
"""Half-planes about a thread's axis its surface is cut with (:func:`thread_profiles`): a
turn in eighths, so a lead of up to four pitches (four starts) shifts the profile by less than half a pitch."""
THREAD_SAMPLES = 2048
"""Levels along the axis each half-plane's profile is sampled at, over the part's extent."""
THREAD_MATCH = 0.15
"""Two profiles are one (shifted) when their mean difference is at most this fraction of
the thread's depth (the profile's 5th to 95th percentile)."""


@dataclass(frozen=True)
class Thread:
    """A helical surface measured on a part (:func:`helix`): about the axis through
    ``point`` along the unit ``direction`` [m], its profile's period ``pitch`` [m] along the
    axis and its ``lead`` [m] (the advance per turn, counterclockwise about ``direction``:
    positive for a right-handed thread; a multiple of the pitch for several starts), its
    least and largest radii ``inner`` and ``outer`` [m] over ``span`` (along ``direction``
    from ``point``: the levels where every half-plane meets it within those radii)."""

    point: np.ndarray
    direction: np.ndarray
    pitch: float
    lead: float
    inner: float
    outer: float
    span: tuple[float, float]


def thread_profiles(mesh: trimesh.Trimesh, point: np.ndarray, direction: np.ndarray,
                    levels: np.ndarray, outermost: bool, rows: Iterable[int] = range(THREAD_ANGLES)) -> np.ndarray:
    """The radius [m] of ``mesh``'s surface about the axis through ``point`` along the unit
    ``direction``, in the half-planes ``rows`` of :data:`THREAD_ANGLES` bounded by the axis
    (row k at angle 0.1234 + 2πk/K rad, counterclockwise about ``direction``: off the
    frame's axes) at each of ``levels`` [m] along the axis: the surface crossing the
    half-plane's line at that level nearest the axis (a nut's thread) or, ``outermost``,
    farthest from it (a screw's); NaN where none crosses (and in the rows not asked)."""
    across = np.eye(3)[int(np.argmin(np.abs(direction)))]
    first = np.cross(direction, across)
    first /= np.linalg.norm(first)
    second = np.cross(direction, first)
    found = np.full((THREAD_ANGLES, len(levels)), np.nan)
    for k in rows:
        angle = 0.1234 + 2 * np.pi * k / THREAD_ANGLES
        out = np.cos(angle) * first + np.sin(angle) * second
        segments = trimesh.intersections.mesh_plane(mesh, np.cross(direction, out), point)
        if len(segments) == 0:
            continue
        z = (segments - point) @ direction
        r = (segments - point) @ out
        order = np.argsort(levels)
        best = np.full(len(levels), -np.inf if outermost else np.inf)
        for (z0, z1), (r0, r1) in zip(z, r):  # each segment over the levels it spans
            if z1 == z0:
                continue
            lo, hi = np.searchsorted(levels[order], [min(z0, z1), max(z0, z1)], side="left")
            at = order[lo:hi]
            radius = r0 + (levels[at] - z0) / (z1 - z0) * (r1 - r0)
            radius = np.where(radius > 0, radius, -np.inf if outermost else np.inf)
            best[at] = np.maximum(best[at], radius) if outermost else np.minimum(best[at], radius)
        found[k] = np.where(np.isfinite(best), best, np.nan)
    return found


def _mismatch(a: np.ndarray, b: np.ndarray) -> float:
    """The mean absolute difference of two profiles where both are measured, over the 90 %
    of levels where they differ least (a stretch's ends may reach a head, a chamfer or a
    run-out); inf where they share under half their levels."""
    both = np.isfinite(a) & np.isfinite(b)
    if both.sum() * 2 < min(len(a), len(b)):
        return math.inf
    differences = np.sort(np.abs(a[both] - b[both]))
    return float(np.mean(differences[:max(1, int(0.9 * len(differences)))]))


def period(profile: np.ndarray, levels: np.ndarray, within: tuple[float, float]) -> tuple[int, float] | None:
    """The period (in levels) and the depth [m] (5th to 95th percentile) of one
    :func:`thread_profiles` row at the evenly spaced ``levels`` [m], over the levels
    ``within``: its smallest shift, above a sixteenth of the stretch and under a half,
    under which it matches itself within :data:`THREAD_MATCH` of its depth, at a local
    minimum of the difference; None where it has none (or is measured on under half the stretch)."""
    base = profile[(levels >= within[0]) & (levels <= within[1])]
    if len(base) == 0 or np.isnan(base).mean() > 0.5:
        return None
    depth = float(np.nanpercentile(base, 95) - np.nanpercentile(base, 5))
    if depth <= 2 * TOUCH:
        return None
    shifts = np.arange(max(1, len(base) // 16), len(base) // 2)
    if len(shifts) < 3:
        return None
    differences = np.array([_mismatch(base[s:], base[:-s]) for s in shifts])
    minima = [i for i in range(1, len(shifts) - 1) if differences[i] <= THREAD_MATCH * depth
              and differences[i] <= differences[i - 1] and differences[i] <= differences[i + 1]]
    return (int(shifts[minima[0]]), depth) if minima else None


def helix(profiles: np.ndarray, levels: np.ndarray, within: tuple[float, float]) -> tuple[float, float] | None:
    """(pitch, lead) [m] of :func:`thread_profiles` ``profiles`` at the evenly spaced
    ``levels`` [m], over the levels ``within`` (along the axis), when they are one helical
    surface: the first profile periodic along the axis (:func:`period`: the pitch) and each half-plane's profile
    the first one shifted by k times one shift s (within :data:`THREAD_MATCH`), s at least a
    sixteenth of the pitch from 0 (a surface of revolution, rings or grooves, has s = 0);
    the lead is K·s, taken as the nearest whole number of pitches (the starts; K·s measured
    within K levels of it, else None). None otherwise."""
    inside = (levels >= within[0]) & (levels <= within[1])
    rows = profiles[:, inside]
    step = float(levels[1] - levels[0])
    base = rows[0]
    found = period(profiles[0], levels, within)
    if found is None:
        return None
    cycle, depth = found
    half = cycle // 2
    options = np.arange(-half, half + 1)

    def shifted(row: np.ndarray, s: int) -> float:
        return _mismatch(row[s:], base[:-s]) if s > 0 else _mismatch(row[:s or None], base[-s:])

    one = int(options[np.argmin([shifted(rows[1], int(s)) for s in options])])
    if abs(one) * 16 < cycle:
        return None
    for k in range(1, len(rows)):
        s = (k * one + half) % cycle - half
        if shifted(rows[k], s) > THREAD_MATCH * depth:
            return None
    # one is a whole number of levels (±0.5), K·one within ±K/2 of the lead: the lead is the
    # nearest whole number of pitches (the starts), where K·one lies within K levels of it
    starts = round(len(rows) * abs(one) / cycle)
    if starts < 1 or abs(len(rows) * abs(one) - starts * cycle) > len(rows):
        return None
    return cycle * step, float(np.sign(one)) * starts * cycle * step


def _thread(mesh: trimesh.Trimesh, point: np.ndarray, direction: np.ndarray, overlap: tuple[float, float],
            outermost: bool) -> Thread | None:
    """``mesh``'s helical surface about the axis (:func:`helix`) measured over ``overlap``
    (along the axis from ``point`` [m]), on its outermost crossings (a screw) or innermost
    (a nut), or None; its span the levels about ``overlap`` where every half-plane meets it
    within its radii."""
    along = (mesh.vertices - point) @ direction
    levels = np.linspace(float(along.min()), float(along.max()), THREAD_SAMPLES)
    profiles = thread_profiles(mesh, point, direction, levels, outermost, rows=[0])
    if period(profiles[0], levels, overlap) is None:  # the cheap reject: one half-plane
        return None
    profiles = thread_profiles(mesh, point, direction, levels, outermost)
    found = helix(profiles, levels, overlap)
    if found is None:
        return None
    inside = (levels >= overlap[0]) & (levels <= overlap[1])
    inner, outer = float(np.nanmin(profiles[:, inside])), float(np.nanmax(profiles[:, inside]))
    on = np.all((profiles >= inner - TOUCH) & (profiles <= outer + TOUCH), axis=0)
    middle = int(np.flatnonzero(inside)[np.sum(inside) // 2])
    if not on[middle]:
        return None
    low = middle
    while low > 0 and on[low - 1]:
        low -= 1
    high = middle
    while high < len(on) - 1 and on[high + 1]:
        high += 1
    return Thread(point, direction, found[0], found[1], inner, outer, (float(levels[low]), float(levels[high])))


def screwed_pairs(meshes: dict[str, trimesh.Trimesh], pairs: Iterable[tuple[str, str]] | None = None) -> list[Slide]:
    """The screwed pairs among ``meshes`` (of ``pairs``, either way round, where given: the
    import asks only of parts the disassembly leaves and their blockers): a part's outermost surface (a screw's) and
    another's innermost (a nut's, a tapped hole's), about one axis along an axis of the
    frame through the centre of the smaller part's box across it, over the stretch where
    both parts are, each a helical surface (:func:`helix`) of one pitch and one lead
    (within 2 %), the screw's crest outside the nut's minor radius (they interlock).
    Each is a :class:`executor.cad.fits.faces.Slide` along that axis: swept against its mate
    only, the screw's thread is taken in to under the nut's minor radius (its vertices
    from that radius out to twice its crest less it, on its thread's span, moved in by
    its crest less that radius plus :data:`executor.cad.fits.faces.TOUCH`), so
    the pair slides along the axis where nothing else (a head, a bottom) stops it."""
    found: list[Slide] = []
    ids = sorted(meshes)
    asked = None if pairs is None else {frozenset(pair) for pair in pairs}
    for a in ids:
        for b in ids:
            if a == b or (asked is not None and frozenset((a, b)) not in asked):
                continue
            low = np.maximum(meshes[a].bounds[0], meshes[b].bounds[0])
            high = np.minimum(meshes[a].bounds[1], meshes[b].bounds[1])
            if np.any(high - low <= TOUCH):
                continue
            for axis in range(3):
                slide = _screwed(meshes[a], meshes[b], axis, (float(low[axis]), float(high[axis])))
                if slide is not None:
                    found.append(replace(slide, shaft=a, bore=b))
    return found


def lone_thread(meshes: dict[str, trimesh.Trimesh]) -> str:
    """For two overlapping parts (``meshes``: id -> mesh [m]) that are no screwed pair, what
    the import says of a modelled thread among them: the part whose outermost surface is a
    helical thread (:func:`helix`) about an axis of the frame through the smaller part's box
    centre, over the stretch both share, in the other part, whose innermost surface there is
    none (a tapped hole drawn at its tap drill); "" where neither is such a thread."""
    (a, one), (b, other) = sorted(meshes.items())
    low, high = np.maximum(one.bounds[0], other.bounds[0]), np.minimum(one.bounds[1], other.bounds[1])
    for axis in range(3):
        direction = np.eye(3)[axis]
        across = [i for i in range(3) if i != axis]
        smaller = min((one, other), key=lambda m: float(np.prod(m.extents[across])))
        point = smaller.bounds.mean(axis=0) * (1 - direction)
        for screw, mesh, hole in ((a, one, b), (b, other, a)):
            thread = _thread(mesh, point, direction, (float(low[axis]), float(high[axis])), outermost=True)
            if thread is not None:
                return (f"; '{screw}' has a modelled thread (pitch {1000 * thread.pitch:.3f} mm, d "
                        f"{2000 * thread.outer:.3f} mm, along {axis_name(direction)[1:]}) in '{hole}', which has "
                        "no thread there (a tapped hole drawn at its tap drill?): the import takes a modelled "
                        "thread only screwed into another")
    return ""


def _plain_bore(male: Thread, screw: trimesh.Trimesh, nut: trimesh.Trimesh, overlap: tuple[float, float]
                ) -> Slide | None:
    """The thread ``male`` of ``screw`` in a plain bore of ``nut`` drawn at its crest
    diameter (a clearance or tapped hole drawn at the screw's nominal size), or None:
    ``nut``'s innermost surface about the thread's axis, over the thread's span within
    ``overlap`` [m] (where both parts are, along the axis from the thread's point), a ring
    whose crossings lie between its largest radius and that less :data:`COARSEST` of it (a
    tessellated cylinder's chords), and the crest's vertex circle there within the two
    tessellations' deflections (the ring's spread, the crest's vertices beyond its
    crossings) plus :data:`TOUCH` of that largest radius. A zero-clearance fit (pitch 0),
    no screwed pair: the screw's thread taken in to under the bore's least radius, it
    slides along the axis out of the bore."""
    low, high = max(male.span[0], overlap[0]) + TOUCH, min(male.span[1], overlap[1]) - TOUCH
    if high <= low:
        return None
    levels = np.linspace(low, high, THREAD_SAMPLES // 8)
    profiles = thread_profiles(nut, male.point, male.direction, levels, outermost=False)
    if np.isnan(profiles).any():
        return None
    least, largest = float(profiles.min()), float(profiles.max())
    relative = screw.vertices - male.point
    along = relative @ male.direction
    radii = np.linalg.norm(relative - np.outer(along, male.direction), axis=1)
    crest = float(radii[(along >= low) & (along <= high)].max(initial=male.outer))
    if (largest - least > COARSEST * largest
            or abs(crest - largest) > largest - least + crest - male.outer + TOUCH):
        return None
    reach = crest - least + TOUCH
    face = CylinderFace(male.point, male.direction, crest, male.span, True, 0.0)
    hole = CylinderFace(male.point, male.direction, largest, male.span, False, 0.0)
    return Slide("", "", face, hole, reach, reach + TOUCH, True)



def _screwed(screw: trimesh.Trimesh, nut: trimesh.Trimesh, axis: int, overlap: tuple[float, float]) -> Slide | None:
    """The screwed pair (:func:`screwed_pairs`) of ``screw`` in ``nut`` along the frame's
    ``axis`` (0, 1, 2) over the stretch ``overlap`` [m] along it where both are, or None:
    the nut's thread modelled, or a plain round hole at the screw's tap drill (:func:`_tap_drill`);
    a plain bore at its crest is a zero-clearance fit (:func:`_plain_bore`)."""
    direction = np.eye(3)[axis]
    across = [i for i in range(3) if i != axis]
    smaller = min((screw, nut), key=lambda m: float(np.prod(m.extents[across])))
    point = smaller.bounds.mean(axis=0) * (1 - direction)
    male = _thread(screw, point, direction, overlap, outermost=True)
    if male is None:
        return None
    face = CylinderFace(point, direction, male.outer, male.span, True, 0.0)
    female = _thread(nut, point, direction, overlap, outermost=False)
    if female is None:
        hole = _tap_drill(nut, male)
        if hole is None:
            return _plain_bore(male, screw, nut, overlap)
        reach = male.outer - hole.radius + hole.deflection + TOUCH
        return Slide("", "", face, hole, reach, reach + TOUCH, True, pitch=male.pitch, lead=male.lead,
                     thread="a modelled thread in a plain hole at its tap drill")
    if (abs(male.pitch - female.pitch) > 0.02 * male.pitch
            or abs(male.lead - female.lead) > 0.02 * abs(male.lead) or male.outer <= female.inner):
        return None
    reach = male.outer - female.inner + TOUCH
    hole = CylinderFace(point, direction, female.inner, female.span, False, 0.0)
    return Slide("", "", face, hole, reach, reach + TOUCH, True, pitch=male.pitch, lead=male.lead,
                 thread="a modelled thread")


TAP_LEVELS = 64
"""Levels along the stretch a modelled thread shares with a plain hole at which the hole's
radius is sampled (:func:`_tap_drill`), in every half-plane of :data:`THREAD_ANGLES`."""


def _tap_drill(nut: trimesh.Trimesh, male: Thread) -> CylinderFace | None:
    """The plain round hole of ``nut`` the modelled thread ``male`` lies in, drawn at its tap
    drill: over the stretch of the thread's span the nut covers (two pitches at least),
    inside its ends, the nut's innermost surface in each half-plane about the thread's axis
    (:func:`thread_profiles`, :data:`TAP_LEVELS` levels) met at every level, its radii
    within :data:`THREAD_MATCH` of the thread's depth of each other (a round hole, coaxial:
    an off-axis one varies by twice its offset) and between the thread's least and largest
    radii (the minor and the major), exclusive. Its face: the least radius [m], the spread
    as its deflection, that stretch as its span; None otherwise."""
    along = (nut.vertices - male.point) @ male.direction
    low, high = max(male.span[0], float(along.min())), min(male.span[1], float(along.max()))
    if high - low < 2 * male.pitch:
        return None
    levels = np.linspace(low, high, TAP_LEVELS + 2)[1:-1]
    radii = thread_profiles(nut, male.point, male.direction, levels, outermost=False)
    if not np.all(np.isfinite(radii)):
        return None
    least, largest = float(radii.min()), float(radii.max())
    if largest - least > THREAD_MATCH * (male.outer - male.inner) or not male.inner < least <= largest < male.outer:
        return None
    return CylinderFace(male.point, male.direction, least, (low, high), False, largest - least)


def _metric() -> list[tuple[str, float, float]]:
    """ISO metric threads (name, major diameter, pitch) [m] of :data:`STANDARD_THREADS`:
    every size of ISO 261:1998 (Table 1) from M1 to M64 with every pitch the table gives
    it, the first and second choice (M1.1, M2.2, M4.5 and M7 among them) and the third
    (coarse only for M9 and M11)."""
    coarse = {1: .25, 1.1: .25, 1.2: .25, 1.4: .3, 1.6: .35, 1.8: .35, 2: .4, 2.2: .45, 2.5: .45, 3: .5, 3.5: .6,
              4: .7, 4.5: .75, 5: .8, 6: 1, 7: 1, 8: 1.25, 10: 1.5, 12: 1.75, 14: 2, 16: 2, 18: 2.5, 20: 2.5,
              22: 2.5, 24: 3, 27: 3, 30: 3.5, 33: 3.5, 36: 4, 39: 4, 42: 4.5, 45: 4.5, 48: 5, 52: 5, 56: 5.5,
              60: 5.5, 64: 6, 9: 1.25, 11: 1.5}
    fine = {1: (.2,), 1.1: (.2,), 1.2: (.2,), 1.4: (.2,), 1.6: (.2,), 1.8: (.2,), 2: (.25,), 2.2: (.25,),
            2.5: (.35,), 3: (.35,), 3.5: (.35,), 4: (.5,), 4.5: (.5,), 5: (.5,), 6: (.75,), 7: (.75,),
            8: (1, .75), 10: (1.25, 1, .75), 12: (1.5, 1.25, 1), 14: (1.5, 1.25, 1), 16: (1.5, 1),
            18: (2, 1.5, 1), 20: (2, 1.5, 1), 22: (2, 1.5, 1), 24: (2, 1.5, 1), 27: (2, 1.5, 1),
            30: (3, 2, 1.5, 1), 33: (3, 2, 1.5), 36: (3, 2, 1.5), 39: (3, 2, 1.5)}
    fine |= {d: (4, 3, 2, 1.5) for d in (42, 45, 48, 52, 56, 60, 64)}
    third = {5.5: (.5,), 9: (1, .75), 11: (1, .75), 15: (1.5, 1), 17: (1.5, 1), 25: (2, 1.5, 1), 26: (1.5,),
             28: (2, 1.5, 1), 32: (2, 1.5), 35: (1.5,), 38: (1.5,), 40: (3, 2, 1.5), 50: (3, 2, 1.5),
             55: (4, 3, 2, 1.5), 58: (4, 3, 2, 1.5), 62: (4, 3, 2, 1.5)}
    found = [(f"M{d:g}", d * 1e-3, p * 1e-3) for d, p in coarse.items()]
    return found + [(f"M{d:g}x{p:g}", d * 1e-3, p * 1e-3)
                    for table in (fine, third) for d, pitches in table.items() for p in pitches]


def _unified() -> list[tuple[str, float, float]]:
    """Unified inch threads (name, major diameter, pitch) [m] of :data:`STANDARD_THREADS`
    (ASME B1.1): UNC #1 to 4 inch, UNF #0 to 1 1/2 inch, UNEF #12 to 1 11/16 inch and the
    8-thread series (8-UN) 1 1/8 to 6 inch."""
    sizes = [("#1", .073, 64, 72), ("#2", .086, 56, 64), ("#3", .099, 48, 56), ("#4", .112, 40, 48),
             ("#5", .125, 40, 44), ("#6", .138, 32, 40), ("#8", .164, 32, 36), ("#10", .190, 24, 32),
             ("#12", .216, 24, 28), ("1/4", .25, 20, 28), ("5/16", .3125, 18, 24), ("3/8", .375, 16, 24),
             ("7/16", .4375, 14, 20), ("1/2", .5, 13, 20), ("9/16", .5625, 12, 18), ("5/8", .625, 11, 18),
             ("3/4", .75, 10, 16), ("7/8", .875, 9, 14), ("1", 1.0, 8, 12), ("1 1/8", 1.125, 7, 12),
             ("1 1/4", 1.25, 7, 12), ("1 3/8", 1.375, 6, 12), ("1 1/2", 1.5, 6, 12)]
    series: list[tuple[str, float, float, str]] = [("#0", .06, 80, "UNF")]
    series += [(name, inch, tpi, kind) for name, inch, unc, unf in sizes for tpi, kind in ((unc, "UNC"), (unf, "UNF"))]
    series += [(_inches(inch), inch, tpi, "UNC") for inch, tpi in
               ((1.75, 5.0), (2.0, 4.5), (2.25, 4.5), (2.5, 4.0), (2.75, 4.0), (3.0, 4.0), (3.25, 4.0), (3.5, 4.0),
                (3.75, 4.0), (4.0, 4.0))]
    extra_fine = [("#12", .216, 32), ("1/4", .25, 32), ("5/16", .3125, 32), ("3/8", .375, 32), ("7/16", .4375, 28),
                  ("1/2", .5, 28), ("9/16", .5625, 24), ("5/8", .625, 24), ("11/16", .6875, 24), ("3/4", .75, 20),
                  ("13/16", .8125, 20), ("7/8", .875, 20), ("15/16", .9375, 20), ("1", 1.0, 20)]
    series += [(name, inch, tpi, "UNEF") for name, inch, tpi in extra_fine]
    series += [(_inches(1 + n / 16), 1 + n / 16, 18, "UNEF") for n in range(1, 12)]
    series += [(_inches(1 + n / 8), 1 + n / 8, 8, "UN") for n in range(1, 8)]
    series += [(_inches(2 + n / 4), 2 + n / 4, 8, "UN") for n in range(17)]
    return [(f"{name}-{tpi:g} {kind}", inch * 0.0254, 0.0254 / tpi) for name, inch, tpi, kind in series]


def _inches(inch: float) -> str:
    """A unified thread's size ``inch`` [inch] as its name: 1 1/16, 2, 3 3/4."""
    whole, part = int(inch), Fraction(inch - int(inch)).limit_denominator(64)
    return f"{whole} {part}" if part else f"{whole}"


STANDARD_THREADS = _metric() + _unified()
"""The standard threads a cosmetic thread is taken for (name, major diameter D, pitch P)
[m]: ISO 261's metric sizes M1 to M64, first, second and third choice, with every coarse
and fine pitch its table gives them (M12x1.5, M12x1.25, M12x1, ...), and the unified inch
series (ASME B1.1): UNC #1-64 to 4-4, UNF #0-80 to 1 1/2-12, UNEF #12-32 to 1 11/16-18
and 8-UN 1 1/8-8 to 6-8."""
TAP_DRILL = (1.0825, 0.85)
"""A tapped hole drawn at its tap drill has a diameter from D - 1.0825 P (the basic minor
diameter of the internal thread, ISO 68-1 and ASME B1.1: 5/4 of the fundamental
triangle's height 0.866 P) to D - 0.85 P (above the common drill D - P, a drill for
soft stock), in pitches P below the major diameter D."""
COSMETIC_MAJOR = 0.25
"""A screw drawn with a cosmetic thread has a diameter from D - 0.25 P to D (its major
diameter, nominal or at its class's least), in pitches P."""


def cosmetic_thread(shaft: float, hole: float, slack: float) -> tuple[str, float] | None:
    """(name, pitch [m]) of the standard thread (:data:`STANDARD_THREADS`) of which a plain
    shaft of diameter ``shaft`` [m] in a plain hole of diameter ``hole`` [m] is drawn
    with a cosmetic thread: the shaft within :data:`COSMETIC_MAJOR` of its major diameter,
    the hole within :data:`TAP_DRILL`, each widened by ``slack`` [m] (the faces'
    tessellation); of several, the one whose major diameter lies nearest the shaft's and, of
    those of one major diameter (pitches whose ranges overlap: M12x1.5 and M12x1.25,
    1/4-28 UNF and 1/4-32 UNEF), the one whose common tap drill D - P lies nearest the hole's."""
    found = [(abs(shaft - d), abs(hole - (d - p)), name, p) for name, d, p in STANDARD_THREADS
             if d - COSMETIC_MAJOR * p - slack <= shaft <= d + slack
             and d - TAP_DRILL[0] * p - slack <= hole <= d - TAP_DRILL[1] * p + slack]
    return (min(found)[2], min(found)[3]) if found else None


def cosmetic_pairs(faces: dict[str, list[CylinderFace | PrismFace]],
                   pairs: Iterable[tuple[str, str]] | None = None) -> list[Slide]:
    """The pairs among the parts' fitted ``faces`` (of ``pairs``, either way round, where
    given) drawn with a cosmetic thread: an outward cylinder of one part (the screw) and an
    inward one of another (the hole), parallel (within 1e-4 rad), coaxial within their
    larger deflection plus :data:`executor.cad.fits.faces.TOUCH`, meeting along the axis in the assembled pose,
    their diameters a standard thread's major and tap drill (:func:`cosmetic_thread`).
    Each is a screwed :class:`executor.cad.fits.faces.Slide` of that thread's pitch (its lead one pitch,
    right-handed: a cosmetic thread draws neither), swept as a modelled one (the screw's
    cylinder taken in to under the hole's radius)."""
    found: list[Slide] = []
    asked = None if pairs is None else {frozenset(pair) for pair in pairs}
    for shaft, outer in faces.items():
        for bore, inner in faces.items():
            if bore == shaft or (asked is not None and frozenset((shaft, bore)) not in asked):
                continue
            for a, b, slack, apart in coaxial(outer, inner):
                if not _seated(a, b, TOUCH):
                    continue
                match = cosmetic_thread(2 * a.radius, 2 * b.radius, 2 * slack)
                if match is None:
                    continue
                reach = a.radius - b.radius + b.deflection + apart + TOUCH
                found.append(Slide(shaft, bore, a, b, reach, reach + TOUCH, True, pitch=match[1], lead=match[1],
                                   thread=f"a cosmetic thread, {match[0]}: d {2000 * a.radius:.4g} in its "
                                          f"{2000 * b.radius:.4g} mm tap drill"))
    return found
