"""Why a plan step failed, read from the world where the part stopped: the reasons a
precedence experiment reports (:data:`bridge.messages.FailureReason`), observed, never
inferred from a rule.

- ``blocked``: after its last attempt the part touches another part of the product that is
  not what it goes into (a peg: the base; a cover: the base and the pegs in its holes; a
  head: its part), or it never got below the entry of its place (its hole's top, the pin
  tops, the socket's top): something kept it out;
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
              placed: Collection[str], frame: HoleFrame | None = None) -> tuple[StuckReason, tuple[str, ...]]:
    """Why ``part``, stopped short of its goal and still held, is stuck: (``blocked``, the
    other parts it touches) when it touches a part of ``placed`` not in ``targets``;
    (``jammed``, ()) when its TCP is below ``entry_z`` [m] by :data:`ENTRY_MARGIN` (z of
    the hole's ``frame`` for a hole entered sideways); else (``blocked``, ())."""
    obstacles = touching(world, part, [p for p in placed if p not in targets])
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
