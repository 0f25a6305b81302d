"""What keeps a real Franka arm safe while the skills drive it (docs/franka.md, "Safety").

- **Speed**: franky's relative dynamics factor scales the arm's velocity, acceleration and
  jerk limits of every motion franky plans (the carrying moves of
  :meth:`executor.franka.cell.FrankaCell.move_to`, the stop); the skills under impedance
  keep their own speeds (the search 2.5-4.5 cm/s, the insertion's taught path).
- **Force**: libfranka's collision behaviour: a joint torque or Cartesian force above its
  threshold stops the arm with a reflex (a ``ControlException``); the impedance's
  stiffness is capped (:data:`MAX_TRANSLATIONAL_STIFFNESS`, :data:`MAX_ROTATIONAL_STIFFNESS`)
  and its position error clipped, so the commanded force on a blocked tool stays bounded
  (stiffness × clip).
- **Workspace**: every desired tool pose is checked against a box before it is sent
  (:meth:`Workspace.check`); a pose outside stops the motion (:class:`SafetyStop`).
- **A stop on any error**: the backend stops the arm and answers the request with an error
  (the cell keeps serving), :mod:`executor.franka.backend`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from executor import ExecutorError

MAX_TRANSLATIONAL_STIFFNESS = 3000.0
"""[N/m] the largest translational stiffness sent to the arm (Franka's own Cartesian
impedance goes to 3000 N/m); the cell's stiff layer (20000 N/m) is capped to it."""
MAX_ROTATIONAL_STIFFNESS = 300.0
"""[Nm/rad] the largest rotational stiffness sent to the arm (Franka's own: 300 Nm/rad)."""
ERROR_CLIP = 0.02
"""[m] the largest position error the impedance acts on: at most 40 N from the spring at
the cell's 2000 N/m (60 N at :data:`MAX_TRANSLATIONAL_STIFFNESS`) however far the
reference runs away; above the detector's F_stop (30 N), so eq. (6) can still fire."""


class SafetyStop(ExecutorError):
    """The arm was stopped before a motion left the safe set."""


@dataclass(frozen=True)
class Limits:
    """``dynamics``: franky's relative dynamics factor (0, 1]; ``torque_threshold`` [Nm]
    per joint and ``force_threshold`` [N, Nm] per Cartesian axis of libfranka's collision
    behaviour (above them the arm stops with a reflex)."""

    dynamics: float = 0.2
    torque_threshold: float = 20.0
    force_threshold: float = 30.0

    def __post_init__(self) -> None:
        if not 0.0 < self.dynamics <= 1.0:
            raise ExecutorError(f"dynamics = {self.dynamics}: expected a factor in (0, 1]")
        if not 0.0 < self.torque_threshold <= 87.0:
            raise ExecutorError(f"torque threshold = {self.torque_threshold}: expected (0, 87] Nm")
        if not 0.0 < self.force_threshold <= 100.0:
            raise ExecutorError(f"force threshold = {self.force_threshold}: expected (0, 100] N")


@dataclass(frozen=True)
class Workspace:
    """The box [m] (robot base frame) the tool tip must stay in: ``low`` and ``high`` corners."""

    low: tuple[float, float, float] = (0.15, -0.6, 0.0)
    high: tuple[float, float, float] = (0.85, 0.6, 0.7)

    def __post_init__(self) -> None:
        if not all(lo < hi for lo, hi in zip(self.low, self.high)):
            raise ExecutorError(f"workspace {self.low}..{self.high}: expected low < high on every axis")

    def check(self, pos: np.ndarray) -> None:
        """SafetyStop naming the position when ``pos`` [m] is outside the box."""
        if not (np.all(pos >= self.low) and np.all(pos <= self.high)):
            raise SafetyStop(f"tool pose {np.round(pos, 4).tolist()} m is outside the workspace "
                             f"{list(self.low)}..{list(self.high)} m; the arm was stopped")


def capped(k_trans: float, k_rot: float) -> tuple[float, float]:
    """The stiffnesses [N/m, Nm/rad] capped to what is sent to the arm."""
    return min(k_trans, MAX_TRANSLATIONAL_STIFFNESS), min(k_rot, MAX_ROTATIONAL_STIFFNESS)
