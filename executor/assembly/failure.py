"""Why a plan step failed, read from the world where the part stopped: the reasons a
precedence experiment reports (:data:`bridge.messages.FailureReason`), observed, never
inferred from a rule.

- ``blocked``: after its last attempt the part, or a part fixed to it that moves with it
  (a head screwed into it), touches another part of the product that is not what it goes
  into (a peg: the base; a cover: the base and the pegs in its holes; a head: its part), or
  it never got below the entry of its place (its hole's top, the pin tops, the socket's
  top): something kept it out. The parts it carries are never among those blocking it
  (a pendulum's head touches the pendulum wherever it is);
- ``jammed``: it got below that entry, touching only what it goes into, and stuck before
  its goal;
- ``unsupported``: it reached its goal but did not stay there once let go (decided by the
  step, :data:`executor.assembly.step.STAY_TOLERANCE`).
"""

from __future__ import annotations

from collections.abc import Collection, Mapping
from typing import Literal

import pybullet as pb

from executor.assembly.world import AssemblyWorld
from executor.world.frames import HoleFrame

ENTRY_MARGIN = 0.001
"""How far below its place's entry the part's TCP must be to count as entered [m]."""
TOUCH_DISTANCE = 0.0005
"""Bodies closer than this count as touching [m] (contact points are within PyBullet's margin)."""

StuckReason = Literal["blocked", "jammed"]


def touching(world: AssemblyWorld, part: str, among: Collection[str]) -> tuple[str, ...]:
    """The parts of ``among`` whose bodies are within :data:`TOUCH_DISTANCE` of ``part``'s, sorted."""
    body, client = world.frames[part].body, world.client
    return tuple(sorted(other for other in among if other != part and pb.getClosestPoints(
        body, world.frames[other].body, TOUCH_DISTANCE, physicsClientId=client)))


def why_stuck(world: AssemblyWorld, part: str, targets: Collection[str], entry_z: float,
              placed: Collection[str], carried: Collection[str] = (),
              frame: HoleFrame | None = None) -> tuple[StuckReason, tuple[str, ...]]:
    """Why ``part``, stopped short of its goal and still held, is stuck: (``blocked``, the
    parts of ``placed`` outside ``targets`` and ``carried`` that it or a part of ``carried``
    (fixed to it, moving with it: :func:`carried_by`) touches) when there are any;
    (``jammed``, ()) when its TCP is below ``entry_z`` [m] by :data:`ENTRY_MARGIN` (z of
    the hole's ``frame`` for a hole entered sideways); else (``blocked``, ())."""
    moving = {part, *carried}
    others = [p for p in placed if p not in targets and p not in moving]
    obstacles = tuple(sorted({o for m in moving for o in touching(world, m, others)}))
    if obstacles:
        return "blocked", obstacles
    tcp = world.position(part) + world.frames[part].tcp
    tcp_z = float((tcp if frame is None else frame.points_in(tcp))[2])
    return ("jammed" if tcp_z < entry_z - ENTRY_MARGIN else "blocked"), ()


def targets_of(part: str, skill: str, base: str, covers_over: Mapping[str, Collection[str]],
               into: Mapping[str, str], hole_of: Mapping[str, str]) -> set[str]:
    """What ``part`` goes into and may touch when it is stuck: the base (a peg, a cover),
    the pegs standing in a cover's holes (``covers_over``: cover → its holes; ``hole_of``:
    placed peg → its hole), a head's part (``into``)."""
    if skill == "insert_socket":
        return {into[part]}
    if skill == "insert_over":
        over = set(covers_over[part])
        return {base} | {peg for peg, hole in hole_of.items() if hole in over}
    return {base}


def carried_by(part: str, into: Mapping[str, str], placed: Collection[str]) -> set[str]:
    """The parts fixed to ``part`` that move with it: the heads of ``placed`` screwed into it
    (``into``: head → the part it goes into)."""
    return {head for head, owner in into.items() if owner == part and head in placed}
