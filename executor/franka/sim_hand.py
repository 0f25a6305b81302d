"""A person's hand in franky-sim's MuJoCo world, for testing the teaching by hand-guiding
(:mod:`executor.franka.guide`): it holds a part (the one in the robot's hand) and pulls the
part's frame origin (its bottom face's centre) along a path with a spring-damper, the
force capped as a hand's is, as an external force on the part (``xfrc_applied``): what a
real arm's wrench estimate sees as the environment's, here the flange sensor's."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import mujoco
import numpy as np

HAND_STIFFNESS = 4000.0
"""[N/m] of the hand's pull toward its path: a firm hand. The simulated FR3's joints have
dry friction (MuJoCo ``frictionloss`` up to 1.14 N m, as a real arm's), a few newtons at the
tool: a hand of 400 N/m stopped 2 mm off the hole's centre, on its rim."""
HAND_DAMPING = 150.0  # [N s/m] of the hand against the part's velocity
HAND_FORCE = 30.0  # [N] the largest pull


@dataclass(frozen=True)
class Waypoint:
    """Where the hand's path reaches ``point`` [m] (MuJoCo's world: the robot's base frame),
    ``duration`` [s] of simulated time after the previous waypoint (a minimum-jerk segment)."""

    point: tuple[float, float, float]
    duration: float


class GuidingHand:
    """Pulls ``body`` (a MuJoCo body id) along ``waypoints`` from where the body's origin is
    at the first :meth:`apply`, then holds the last point for ``hold`` [s] and lets go.
    :meth:`apply` runs before each simulation step (franky-sim's stepping thread)."""

    def __init__(self, body: int, waypoints: Sequence[Waypoint], hold: float) -> None:
        self.body, self.waypoints, self.hold = body, list(waypoints), hold
        self._t0: float | None = None
        self._start = np.zeros(3)
        self.done = False
        self.peak = 0.0
        """[N] the largest force the hand applied."""

    def target(self, t: float) -> np.ndarray:
        """The path's point [m] at ``t`` [s] after the hand took hold."""
        here = self._start
        for waypoint in self.waypoints:
            point = np.array(waypoint.point)
            if t < waypoint.duration:
                s = t / waypoint.duration
                return here + (point - here) * (10 * s**3 - 15 * s**4 + 6 * s**5)
            t -= waypoint.duration
            here = point
        return here

    @property
    def duration(self) -> float:
        """[s] of the path, without the hold."""
        return sum(w.duration for w in self.waypoints)

    def apply(self, model: mujoco.MjModel, data: mujoco.MjData) -> None:
        """Set the hand's force on the body for the next step (zero once it let go)."""
        if self.done:
            return
        origin = data.xpos[self.body]
        if self._t0 is None:
            self._t0, self._start = float(data.time), origin.copy()
        t = float(data.time) - self._t0
        if t > self.duration + self.hold:
            data.xfrc_applied[self.body] = 0.0
            self.done = True
            return
        velocity = np.zeros(6)
        mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_BODY, self.body, velocity, 0)
        force = HAND_STIFFNESS * (self.target(t) - origin) - HAND_DAMPING * velocity[3:]
        norm = float(np.linalg.norm(force))
        if norm > HAND_FORCE:
            force *= HAND_FORCE / norm
        self.peak = max(self.peak, min(norm, HAND_FORCE))
        data.xfrc_applied[self.body, :3] = force
        # applied at the body's origin, not at its centre of mass where MuJoCo applies it
        data.xfrc_applied[self.body, 3:] = np.cross(origin - data.xipos[self.body], force)
