"""The ``depth`` ``geometry.toml`` states of a hole: to where its part's tip is in the CAD
when the part goes in sideways (:func:`sideways_depth`) or rests on the hole's entry or a
ledge (:func:`down_depth`), else the measured depth. Lengths in metres."""

from __future__ import annotations

import numpy as np
import shapely

from executor.cad.derive import Derived, HoleFit
from executor.cad.operations.plate import LEVEL
from executor.cad.sections import slice_loops
from executor.cad.sweep import DIRECTIONS


def sideways_depth(derived: Derived, fit: HoleFit) -> float:
    """The ``depth`` [m] of a hole entered sideways (or from below): from its entry along
    its axis to where its part's tip is in the CAD (the taught goal: nothing stops a part
    in a through hole), or the measured depth of an empty one."""
    if fit.part is None:
        return fit.depth
    return fit.entry - float((derived.parts[fit.part].mesh.vertices @ np.array(DIRECTIONS[fit.axis])).min())


STOP_PROBE = 1e-4
"""How far [m] under a part's tip the base is cut to see whether the hole narrows there (and
above and under a hole's entry, and how far beyond the hole a part resting on it reaches)."""


def down_depth(derived: Derived, fit: HoleFit) -> float:
    """The ``depth`` [m] of a hole entered down: to where its part's tip is in the CAD where
    the part rests on the hole's entry (its outline just above the entry reaches more than
    :data:`STOP_PROBE` beyond the base's loop around the hole just under it, so not at a
    nominal zero-clearance fit: a switch hanging by its flange through a slot
    of a case's 2 mm top, its tip 19.4 mm down where the measured depth says 2 mm, through
    the top, or 42 mm, to the case's rim) or where the base's opening just under the tip
    does not hold the part's section at the middle of its stretch in the hole (a plate on
    the ledge of a recess: the cell's goal, where the part rests, is the CAD's, not the floor
    down the hole's centre line); else the measured depth (to that floor, or through)."""
    if fit.part is None:
        return fit.depth
    mesh = derived.parts[fit.part].mesh
    (_, _, tip), (_, _, top) = mesh.bounds
    up = np.array([0.0, 0.0, 1.0])
    base = derived.parts[derived.base].mesh
    if abs(fit.entry - tip - fit.depth) > LEVEL:
        rim = [shapely.Polygon(loop.points) for loop in slice_loops(base, up, fit.entry - STOP_PROBE)
               if loop.contains(fit.hole.centre)]
        above = shapely.union_all([shapely.Polygon(loop.points)
                                   for loop in slice_loops(mesh, up, fit.entry + STOP_PROBE)])
        if rim and not above.is_empty and not above.within(min(rim, key=lambda loop: loop.area).buffer(STOP_PROBE)):
            return fit.entry - float(tip)
    if fit.entry - tip >= fit.depth - LEVEL:  # on the floor, or below the entry
        return fit.depth
    below = [shapely.Polygon(loop.points) for loop in slice_loops(base, up, tip - STOP_PROBE)
             if loop.contains(fit.hole.centre)]
    outline = shapely.union_all([shapely.Polygon(loop.points)
                                 for loop in slice_loops(mesh, up, (tip + min(top, fit.entry)) / 2)])
    passes = bool(below) and outline.within(min(below, key=lambda loop: loop.area))
    return fit.depth if passes else fit.entry - float(tip)
