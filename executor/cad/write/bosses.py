"""The plate's bosses: the side of the square boss around every hole (:func:`plate_tile`) and a
hole's own side where those would overlap (:func:`own_tiles`). Lengths in metres."""

from __future__ import annotations

import math

import numpy as np

from bridge.product.checks import overlapping_bosses
from executor.cad.derive import Derived, HoleFit

_BOSS_WALL = 0.002
"""The wall a boss leaves beyond its hole's chamfered mouth on each side when the holes'
spacing does not set its side [m]."""


def plate_tile(fits: list[HoleFit]) -> float:
    """The side of the square boss around every hole [m]: the measured boss when the base
    has one around each hole, else the largest square the holes' spacing leaves room for."""
    bosses = [f.outer.b for f in fits if f.outer is not None and f.outer.kind in ("square", "rect")]
    spacing = min((max(abs(a.position[0] - b.position[0]), abs(a.position[1] - b.position[1]))
                   for i, a in enumerate(fits) for b in fits[i + 1:]), default=0.04)
    widest = max([max(f.hole.a, f.hole.b) + 2 * f.chamfer for f in fits], default=0.0)
    tile = min([*bosses, spacing, 0.04])
    return tile if tile > widest else widest + 2 * _BOSS_WALL


def own_tiles(derived: Derived, tile: float, chamfer: float) -> dict[str, float]:
    """Each hole's own boss side [m] where bosses of side ``tile`` (:func:`plate_tile`) around
    every hole would overlap; none where they do not. A hole's boss is its section's
    widest side, or twice its outline's farthest reach from its centre, with the
    ``chamfer`` on each side (its need) and :data:`_BOSS_WALL` of wall
    beyond, at most ``tile``, and no wider than leaves each neighbour's boss half the room
    between the two needs: the distance of their centres (the larger of x and y, or
    straight for a turned hole) plus half the difference of the needs."""
    fits = {hid: fit for hid, fit in derived.holes.items() if fit.axis == "+z"}
    turned = {hid for hid, fit in fits.items() if fit.hole.yaw}
    if overlapping_bosses({hid: (*fit.position, tile) for hid, fit in fits.items()}, turned) is None:
        return {}
    need = {hid: max(fit.hole.a, fit.hole.b, 2 * float(np.abs(fit.hole.outline).max())) + 2 * chamfer
            for hid, fit in fits.items()}  # a polygon's outline may reach farther on one side

    def apart(a: str, b: str) -> float:
        (xa, ya), (xb, yb) = fits[a].position, fits[b].position
        return math.hypot(xa - xb, ya - yb) if {a, b} & turned else max(abs(xa - xb), abs(ya - yb))

    own = {hid: min([need[hid] + 2 * _BOSS_WALL, tile,
                     *(apart(hid, other) + (need[hid] - need[other]) / 2 for other in fits if other != hid)])
           for hid in fits}
    return {hid: side for hid, side in own.items() if side < tile}
