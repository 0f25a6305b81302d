"""Open boxes: a floored loop that leaves a part more than :data:`CAVITY_ROOM` of room is
a cavity the part rests in (a tray's, a case's without its lid), no hole for it
(:func:`open_box`, its cheap bound :func:`roomy`, and the holes of the base left once such
cavities are taken out, :func:`without_cavities`)."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import shapely
import trimesh

from executor.cad.derive.derived import HoleFit
from executor.cad.derive.rays import roofed
from executor.cad.fits.faces import TOUCH
from executor.cad.locating import LOCATING_REACH
from executor.cad.sections import Loop

CAVITY_ROOM = 2 * LOCATING_REACH
"""[m] A hole that leaves the part in it more than this (6 mm) of room every way where it
lies (:func:`room_at`: a convex hole, as its narrowest width exceeds the part's widest)
leaves it free to move the locating rule's default reach one way or the other across:
with a floor under it, a cavity that locates nothing of that size (an open tray's, a
case's without its lid), no hole for it (:func:`open_box`)."""


def without_cavities(base: trimesh.Trimesh, fits: list[tuple[HoleFit, np.ndarray, np.ndarray]]) -> list[HoleFit]:
    """The holes of ``fits`` (each with its centre at the level sliced and its axis) that
    are no open box's cavity in ``base`` (:func:`open_box`): a part in a cavity is in no
    hole, and an empty cavity, or one so emptied, is no hole when it is one for the widest
    part left in a hole wherever such a part lies in it (every empty floored loop that
    leaves more than :data:`CAVITY_ROOM` across everywhere when none is)."""
    emptied = [(replace(fit, part=None, section=None)
                if fit.section is not None and open_box(_polygon(fit), fit.hole.b, fit.section.a, fit.section.centre,
                                                        base, centre, axis) else fit,
                centre, axis) for fit, centre, axis in fits]
    widest = max((fit.section.a for fit, _, _ in emptied if fit.section is not None), default=0.0)
    return [fit for fit, centre, axis in emptied
            if fit.part is not None or not open_box(_polygon(fit), fit.hole.b, widest, None, base, centre, axis)]


def _polygon(fit: HoleFit) -> np.ndarray:
    """The hole's section's loop (n, 2) [m] in the slice's frame."""
    return fit.hole.centre + fit.hole.outline


def open_box(cavity: np.ndarray, narrowest: float, widest: float, at: np.ndarray | None, mesh: trimesh.Trimesh,
             centre: np.ndarray, axis: np.ndarray) -> bool:
    """Whether the loop ``cavity`` (n, 2) [m] of ``mesh``, ``narrowest`` [m] across (the
    short side of its minimum-area rectangle or of its section), is an open box's cavity for a part
    ``widest`` [m] at its widest (its section's long side) whose centre is ``at`` (2,) [m]
    in the slice's frame (None: wherever such a part lies in it): it leaves the part more
    than :data:`CAVITY_ROOM` of room across every way there (:func:`room_at`), so it
    locates nothing of that size, and it has a floor (the ray from its ``centre`` [m] down
    the unit ``axis`` goes into the solid: no opening through). ``narrowest`` bounds
    that room from above (a loop that holds a disc is at least as wide as it every way), so
    a loop no wider than the part by more than CAVITY_ROOM is tried no further."""
    return (narrowest - widest > CAVITY_ROOM and room_at(cavity, widest, at) and roofed(mesh, centre, -axis))


def room_at(cavity: np.ndarray, widest: float, at: np.ndarray | None) -> bool:
    """Whether a part ``widest`` [m] across, its centre at ``at`` (2,) [m] (None: anywhere
    it fits), has more than :data:`CAVITY_ROOM` of room every way in the ``cavity``'s
    polygon (n, 2) [m]. The part stands for a disc that wide (it may lie turned any way, as
    the short side of a convex hole against the part's long side had it); where its centre
    may go is the cavity shrunk by half that width, and it has that room where its centre
    lies in what of that region a shrinking by CAVITY_ROOM / 2 and a growing back by as
    much keep (corners mitred: a rectangle more than CAVITY_ROOM wide every way is kept
    whole, a strip no wider is lost). So a rectangular or round cavity is roomy for the part
    when its short side is wider than the part by more than CAVITY_ROOM, wherever the part
    lies in it, while an L-, T- or U-shaped cavity, however wide its minimum-area rectangle,
    is only where the part lies in a leg that wide: a part held in a narrow leg is in a
    hole. Within :data:`executor.cad.fits.faces.TOUCH`: a part touching a wall is where
    it may go."""
    free = shapely.make_valid(shapely.Polygon(cavity)).buffer(-widest / 2)
    if free.is_empty:
        return False
    rooms = free.buffer(-CAVITY_ROOM / 2, join_style="mitre").buffer(CAVITY_ROOM / 2, join_style="mitre")
    if at is None:
        return bool(rooms.buffer(TOUCH).covers(free))
    return bool(rooms.distance(shapely.Point(float(at[0]), float(at[1]))) <= TOUCH)


def roomy(hole: Loop, part: Loop) -> bool:
    """Whether the ``hole`` loop may leave the ``part``'s loop in it more than
    :data:`CAVITY_ROOM` across (:func:`open_box`), by bounds that need no minimum-area
    rectangle (whose sides cost a turn per hull edge, a second on a fine round loop): the
    hole's short side is at most the square root of its axis-aligned box's area, the
    part's long side at least the square root of its own area. False: it does not."""
    box = np.ptp(hole.points, axis=0)
    return math.sqrt(float(box[0] * box[1])) - math.sqrt(part.area) > CAVITY_ROOM
