"""The disassembly's stages and each part's insertion axis: stage by stage, the parts some
direction frees from those still in place leave (:func:`disassembled`); each one's way out,
reversed its insertion axis, is chosen among the directions free of the parts present as
the cell meets it (:func:`ways_in`, by :func:`_way_out`'s rules: up, down, the ways the
arm reaches sideways, then the product's geometry)."""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable

import networkx as nx
import numpy as np

from executor.cad.derive.derived import Derived
from executor.cad.fits.faces import TOUCH
from executor.cad.sections import frame_of

PREFERRED = (("+z",), ("-z",), ("-x", "+y", "-y"), ("+x",))
"""The classes a part's way out (its insertion axis reversed) is chosen by among those it
is free along, in order: up (the cell inserts from above), down, the horizontal ones whose
insertion the cell's arm was measured to reach sideways (-x, +y, -y: the insertions +x,
-y, +y of :data:`executor.cad.operations.arm.SIDEWAYS_HOLE_REACH`), so a part free both ways
along x goes in along +x however the CAD is turned about z, then +x; a zero-clearance
fit's axis that is none of these, last. Within a class the product's geometry chooses
(:func:`_way_out`)."""
LEAVING = tuple(d for kind in PREFERRED for d in kind)
"""The six axes in :data:`PREFERRED`'s order: the last rule between ways out the geometry
leaves tied (:func:`_way_out`)."""
TIED = 1e-6
"""Two ways out whose travels (or mass balances) differ by at most this [m] are tied for
that rule of :func:`_way_out` (a turn about z changes them by rounding alone)."""


def disassembled(result: Derived) -> set[str]:
    """Stage by stage, every part that some direction frees from the parts still in place
    leaves (``result.stages`` filled in; which way each goes, :func:`ways_in` chooses once
    the precedence is known); the parts no stage frees."""
    remaining = set(result.parts) - {result.base}
    while remaining:
        stage = sorted(pid for pid in remaining if any(
            not (result.blockers[(pid, d)] & (remaining | {result.base})) for d in result.directions))
        if not stage:
            break
        result.stages.append(stage)
        remaining -= set(stage)
    return remaining


def _way_out(result: Derived, pid: str, free: list[str], present: set[str]) -> str:
    """The way out part ``pid`` leaves along, of the directions ``free`` of the parts
    ``present`` (the base and the parts still in place): the first class of
    :data:`PREFERRED` holding one of them (a zero-clearance fit's axis of none of them,
    last), then within it by the product's geometry, each rule in the product's own terms,
    so that a turn about z chooses the same way:

    1. the shortest travel: the least distance [m] the part's body (it and the parts fixed
       to it) moves along the direction until it is past every triangle of the present
       parts in line with it (whose extent across the direction overlaps the body's by
       more than :data:`executor.cad.fits.faces.TOUCH`): a shaft free both ways goes in
       from the end nearer the product's face it passes, a wall beside that face, out of
       its line, not counted;
    2. the way away from the present parts' mass: the least component along the direction
       of the vector from the body's centre of mass to theirs (uniform density);
    3. :data:`LEAVING`'s order (a fit's axis after the six, in the order found).

    Ways within :data:`TIED` of the best are tied for a rule. Rule 3 is the cell frame's:
    a part that reaches it (equal travels, the present parts' mass centred across the ways,
    as in a product alike seen from either way) may go in from its other end with the
    product turned 180° about z."""
    def kind(d: str) -> int:
        return next((k for k, ways in enumerate(PREFERRED) if d in ways), len(PREFERRED))
    best = min(kind(d) for d in free)
    ways = [d for d in free if kind(d) == best]
    if len(ways) == 1:
        return ways[0]
    body = next(members for members in result.bodies.values() if pid in members)
    others = sorted(present - body)
    moving = np.vstack([result.parts[p].mesh.vertices for p in sorted(body)])
    fixed = np.vstack([result.parts[p].mesh.triangles for p in others])

    def travel(d: str) -> float:
        vector = np.array(result.directions[d])
        across = frame_of(vector)  # the cell's axes for the six: a quarter turn maps the boxes onto each other
        own = moving @ across.T
        theirs = fixed @ across.T
        inline = np.all((theirs.min(axis=1) < own.max(axis=0) - TOUCH)
                        & (theirs.max(axis=1) > own.min(axis=0) + TOUCH), axis=1)
        ahead = float((fixed[inline] @ vector).max()) if inline.any() else -math.inf
        return max(0.0, ahead - float((moving @ vector).min()))

    def mass_centre(ids: Iterable[str]) -> np.ndarray:
        meshes = [result.parts[p].mesh for p in ids]
        volumes = np.array([abs(m.volume) for m in meshes])
        return np.sum([v * m.center_mass for v, m in zip(volumes, meshes)], axis=0) / volumes.sum()

    apart = mass_centre(others) - mass_centre(sorted(body))
    for rule in (travel, lambda d: float(np.dot(apart, result.directions[d]))):
        values = {d: rule(d) for d in ways}
        least = min(values.values())
        ways = [d for d in ways if values[d] <= least + TIED]
        if len(ways) == 1:
            return ways[0]
    order = list(LEAVING) + [d for d in result.directions if d not in LEAVING]
    return min(ways, key=order.index)


def ways_in(result: Derived) -> None:
    """Each part's insertion axis judged as the cell meets the part (``result.axis`` filled
    in): of the directions free of the parts present then, the one :func:`_way_out`
    chooses. Present are the base, the parts still in place at the part's disassembly stage and
    the parts ``result.edges`` put before its body; absent, the parts they put after it (the
    parts it supports, those its ``blocks`` and ``locates`` pairs put later), in place at its
    stage or not (a box the box resting on it leaves free only sideways goes in from above,
    before that one). Where the parts put before it and
    not in place at its stage leave it no way, the stage's own, less the parts after it."""
    order = nx.DiGraph(list(result.edges))
    root = {pid: r for r, members in result.bodies.items() for pid in members}

    def related(pid: str, find: Callable[[nx.DiGraph, str], set[str]]) -> set[str]:
        return set().union(*(find(order, m) for m in result.bodies[root[pid]] if m in order))

    def free(pid: str, present: set[str]) -> list[str]:
        return [d for d in result.directions if not result.blockers[(pid, d)] & present]

    for k, stage in enumerate(result.stages):
        in_place = set().union(*result.stages[k:]) | {result.base}
        for pid in stage:
            later = related(pid, nx.descendants)
            present = (in_place | related(pid, nx.ancestors)) - later
            if not free(pid, present):  # the stage's own way out is free of every part in place
                present = in_place - later
            result.axis[pid] = _way_out(result, pid, free(pid, present), present)
