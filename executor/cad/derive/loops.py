"""The loops of parts' slices, as the finders of holes and pins read them: which are
outlines (:func:`outer`), the levels a slice changes between (:func:`spans`), where one
part has a hole around another (:func:`hole_around`) and where a part's bore holds
another part's outline (:func:`bore_around`)."""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence

import numpy as np
import shapely
import trimesh

from executor.cad.derive.cavities import open_box, roomy
from executor.cad.fits.faces import TOUCH
from executor.cad.parts import CadPart
from executor.cad.sections import Loop, classify, frame_of, slice_loops

SAME_HOLE = 1e-4  # hole centres closer than this [m] across the axis are one hole
HOLE_LEVELS = 8
"""How many levels :func:`hole_around` slices an owner at, and
:func:`executor.cad.derive.bore_on_pin.pin_of` a part on a pin, at most, to find the hole
or the pin."""


def outer(loop: Loop, loops: list[Loop]) -> bool:
    """Whether ``loop`` is an outline of its slice (inside an even number of the others)."""
    return sum(1 for o in loops if o is not loop and o.area > loop.area and o.contains(loop.centre)) % 2 == 0


def touching_gap(area: float, length: float) -> bool:
    """Whether a loop of ``area`` [m²] and perimeter ``length`` [m] is a gap between faces
    that touch: its mean width (twice its area over its perimeter) at most
    :data:`executor.cad.fits.faces.TOUCH`, too narrow for any part (the crack two boxes of one
    part leave where their faces meet not quite flat, a Technic pin's slit)."""
    return 2 * area <= TOUCH * length


def in_loop(outline: Loop, hole: Loop) -> bool:
    """Whether a part's ``outline`` lies in the ``hole`` loop of another part's slice: at
    most the hole's sagitta (a round one's) plus :data:`executor.cad.fits.faces.TOUCH` beyond
    it, as a shaft tessellated at a nominal zero-clearance fit is (its vertices on the
    circle the bore's chords cut inside); a ring around a tube is not in the tube's bore."""
    margin = classify(hole, hole=True).deflection + TOUCH
    return bool(shapely.Polygon(hole.points).buffer(margin).covers(shapely.Polygon(outline.points)))


def spans(levels: np.ndarray, low: float, high: float) -> list[float]:
    """The middles [m] of the spans between the distinct ``levels`` [m] clipped to
    [``low``, ``high``], longest first, spans of 1 µm or less left out: a slice changes only
    at its mesh's vertex levels."""
    bounds = np.unique(np.concatenate([[low, high], np.unique(np.round(np.clip(levels, low, high), 9))]))
    spans = sorted(zip(bounds[:-1], bounds[1:], strict=True), key=lambda span: span[0] - span[1])
    return [float(a + b) / 2 for a, b in spans if b - a > 1e-6]


def hole_around(owner: CadPart, part: CadPart, axis: np.ndarray) -> tuple[float, Loop, Loop | None, Loop] | None:
    """Where ``owner`` has a hole around ``part`` across ``axis``: the level [m], the
    hole's loop, the loop around it (None: none) and the part's loop in it; None when no
    level tried has one. The levels tried are the middles of the spans between the owner's
    vertices near the part's centre line (within twice the part's reach across it) along
    the axis, where both reach, :data:`HOLE_LEVELS` longest first: an owner's slice changes
    only at its vertices' levels. Of the owner's holes holding the part, the smallest."""
    along, owner_along = part.mesh.vertices @ axis, owner.mesh.vertices @ axis
    low, high = max(along.min(), owner_along.min()), min(along.max(), owner_along.max())
    if high - low <= 1e-6:
        return None
    frame = frame_of(axis)
    middle = slice_loops(part.mesh, axis, float(along.min() + along.max()) / 2)
    outlines = [loop for loop in middle if outer(loop, middle)]
    if len(outlines) != 1:
        return None
    line = outlines[0].centre
    reach = 2 * float(np.linalg.norm(part.mesh.vertices @ frame.T - line, axis=1).max())
    near = np.linalg.norm(owner.mesh.vertices @ frame.T - line, axis=1) <= reach
    if not near.any():  # nothing of the owner around the part: no slice needed
        return None
    for level in spans(owner_along[near], low, high)[:HOLE_LEVELS]:
        loops = slice_loops(owner.mesh, axis, level)
        cut = slice_loops(part.mesh, axis, level)
        own = [o for o in cut if outer(o, cut)]
        # smallest first: of a part of several shells (a bearing's rings and balls) the
        # innermost hole around the part (the inner ring's bore, not the outer ring's inside)
        for loop in sorted((o for o in loops if not outer(o, loops)), key=lambda o: o.area):
            inside = [o for o in own if loop.contains(o.centre) and in_loop(o, loop)]
            if len(inside) == 1 and not (roomy(loop, inside[0]) and open_box(
                    loop.points, loop.extent[1], inside[0].extent[0], inside[0].centre, owner.mesh,
                    frame.T @ loop.centre + axis * level, axis)):
                around = sorted((o for o in loops if o is not loop and o.area > loop.area
                                 and o.contains(loop.centre)), key=lambda o: o.area)
                return level, loop, around[0] if around else None, inside[0]
    return None


def bore_around(part: trimesh.Trimesh, other: trimesh.Trimesh, axis: np.ndarray, level: float,
                taken: Iterable[np.ndarray] = (), around: Sequence[trimesh.Trimesh] = ()
                ) -> tuple[np.ndarray, float] | None:
    """The centre line (2,) [m] of the pin of ``other`` that lies in an inner loop (a bore)
    of ``part`` on their slices at ``level`` [m] along removal direction ``axis``
    (:func:`_pin_in`: one outline of ``other``, or the pieces of one, a slit sleeve's
    halves), of the bores around none of the points ``taken`` (2,) [m], and how far [m]
    from it the nearest outline of ``other`` in another inner loop of ``part`` lies (a
    plate's other dowel pin: inf when there is none); None when no bore holds such a pin.
    A bore where a part of ``around`` (the other parts it may go onto) lies round that pin
    is not on it (a collar round a sleeve on a shaft is on the sleeve, not on the shaft):
    the outlines of that part in the bore, taken together (their convex hull), cover it."""
    own = slice_loops(part, axis, level)
    bores = [o for o in own if not outer(o, own) and not any(o.contains(point) for point in taken)]
    frame = frame_of(axis)
    if not any(_in_box(other, frame, bore) for bore in bores):
        return None  # nothing of the other part in a bore's box across the axis, at any level: no slice needed
    theirs = slice_loops(other, axis, level)
    outlines = [o for o in theirs if outer(o, theirs)]
    for bore in bores:
        inside = _pin_in(bore, other, axis, level, outlines)
        if inside is None:
            continue
        pin = _hull(inside)
        if any(_hull(loops).buffer(TOUCH).covers(pin) for mesh in around if _in_box(mesh, frame, bore)
               and (loops := _outlines_in(bore, mesh, axis, level))):
            continue
        centre = inside[0].centre if len(inside) == 1 else np.array(pin.centroid.coords[0])
        apart = [float(np.linalg.norm(o.points - centre, axis=1).min()) for o in outlines
                 if all(o is not i for i in inside) and any(h is not bore and h.contains(o.centre) for h in own
                                                             if not outer(h, own))]
        return centre, min(apart, default=math.inf)
    return None


def _in_box(mesh: trimesh.Trimesh, frame: np.ndarray, bore: Loop) -> bool:
    """Whether a vertex of ``mesh`` lies in the box of ``bore`` across the axis of
    ``frame`` (:func:`executor.cad.sections.frame_of`) at any level: else no outline of
    the mesh lies in the bore."""
    across = mesh.vertices @ frame.T
    return bool(np.all((across >= bore.points.min(axis=0)) & (across <= bore.points.max(axis=0)), axis=1).any())


def _outlines_in(bore: Loop, mesh: trimesh.Trimesh, axis: np.ndarray, level: float) -> list[Loop]:
    """The outlines of ``mesh``'s slice at ``level`` [m] along ``axis`` that lie in ``bore``."""
    loops = slice_loops(mesh, axis, level)
    return [o for o in loops if outer(o, loops) and bore.contains(o.centre) and in_loop(o, bore)]


def _pin_in(bore: Loop, other: trimesh.Trimesh, axis: np.ndarray, level: float, outlines: list[Loop]
            ) -> list[Loop] | None:
    """The outlines of ``other`` (its slice's ``outlines`` at ``level`` [m] along removal
    direction ``axis``) that lie in ``bore`` when they are one pin: one outline, or several
    side by side that one outline of ``other`` holds beyond the level along the axis,
    towards the pin's free end, which a part going off passes (a sleeve slit into halves at
    one end and whole at its other, :data:`HOLE_LEVELS` levels tried, longest spans first);
    None otherwise (two dowel pins in one slot; a bearing's rings and balls, one inside
    another: which of them the bore holds is not measured)."""
    inside = [o for o in outlines if bore.contains(o.centre) and in_loop(o, bore)]
    if len(inside) <= 1:
        return inside or None
    if any(o is not i and o.contains(i.centre) for o in inside for i in inside):
        return None
    along = other.vertices @ axis
    for beyond in spans(along, level, float(along.max()))[:HOLE_LEVELS]:
        loops = slice_loops(other, axis, beyond)
        if any(outer(whole, loops) and all(in_loop(piece, whole) for piece in inside) for whole in loops):
            return inside
    return None


def _hull(loops: list[Loop]) -> shapely.Polygon:
    """The convex hull of ``loops`` across the axis: what a convex bore must hold to pass them all."""
    return shapely.MultiPoint(np.concatenate([loop.points for loop in loops])).convex_hull
