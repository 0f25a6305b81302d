"""Open boxes: a floored loop that leaves a part more than :data:`CAVITY_ROOM` of room is
a cavity the part rests in (a tray's, a case's without its lid), no hole for it
(:func:`open_box`, its cheap bound :func:`roomy`, and the holes of the base left once such
cavities are taken out, :func:`without_cavities`)."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import trimesh

from executor.cad.derive.derived import HoleFit
from executor.cad.derive.rays import roofed
from executor.cad.locating import LOCATING_REACH
from executor.cad.sections import Loop

CAVITY_ROOM = 2 * LOCATING_REACH
"""[m] A hole whose narrowest width exceeds a part's widest by more than this (6 mm)
leaves that part, wherever it lies in it, free to move the locating rule's default reach
one way or the other across: with a floor under it, a cavity that locates nothing of that
size (an open tray's, a case's without its lid), no hole for it (:func:`open_box`)."""


def without_cavities(base: trimesh.Trimesh, fits: list[tuple[HoleFit, np.ndarray, np.ndarray]]) -> list[HoleFit]:
    """The holes of ``fits`` (each with its centre at the level sliced and its axis) that
    are no open box's cavity in ``base`` (:func:`open_box`): a part in a cavity is in no
    hole, and an empty cavity, or one so emptied, is no hole when it is one for the widest
    part left in a hole (every empty floored loop wider than :data:`CAVITY_ROOM` when none is)."""
    emptied = [(replace(fit, part=None, section=None)
                if fit.section is not None and open_box(fit.hole.b, fit.section.a, base, centre, axis) else fit,
                centre, axis) for fit, centre, axis in fits]
    widest = max((fit.section.a for fit, _, _ in emptied if fit.section is not None), default=0.0)
    return [fit for fit, centre, axis in emptied
            if fit.part is not None or not open_box(fit.hole.b, widest, base, centre, axis)]


def open_box(narrowest: float, widest: float, mesh: trimesh.Trimesh, centre: np.ndarray, axis: np.ndarray) -> bool:
    """Whether a loop of ``mesh`` ``narrowest`` [m] across (its section's short side) is an
    open box's cavity for a part ``widest`` [m] at its widest (its section's long side): it
    leaves it more than :data:`CAVITY_ROOM` of room, so it locates nothing of that size, and
    it has a floor (the ray from its ``centre`` [m] down the unit ``axis`` goes into the
    solid: no opening through)."""
    return narrowest - widest > CAVITY_ROOM and roofed(mesh, centre, -axis)


def roomy(hole: Loop, part: Loop) -> bool:
    """Whether the ``hole`` loop may leave the ``part``'s loop in it more than
    :data:`CAVITY_ROOM` across (:func:`open_box`), by bounds that need no minimum-area
    rectangle (whose sides cost a turn per hull edge, a second on a fine round loop): the
    hole's short side is at most the square root of its axis-aligned box's area, the
    part's long side at least the square root of its own area. False: it does not."""
    box = np.ptp(hole.points, axis=0)
    return math.sqrt(float(box[0] * box[1])) - math.sqrt(part.area) > CAVITY_ROOM
