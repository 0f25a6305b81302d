"""Failure detection (paper 3.2): eqs. (6) and (7) and the goal check.

    ‖F_mes − F_des‖ ≥ F_stop   (6)        ‖M_mes − M_des‖ ≥ M_stop   (7)
    ‖p_end − p_goal‖ > goal_tolerance      (the trajectory was not completed)

Thresholds come from margins measured with ``./run.sh executor margins`` (every
part-hole pair, detection off; the figures are in docs/results.md): fitting insertions
stay well below them, a too-big part pushed on by the impedance passes them.  One set of
thresholds for all pairs.  A violation must persist
``persist_steps`` steps to count (contact transients when an edge catches last 1–5 ms).
"""

from __future__ import annotations

import math
from typing import Annotated

import msgspec
import numpy as np


class Thresholds(msgspec.Struct, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """F_stop [N], M_stop [Nm] (eqs. 6, 7), F_slow [N] (phase stopping scale), goal
    tolerance [m], and how long a violation must persist [steps of 1 ms]. A file may not
    switch detection off; ``executor margins`` does (infinite thresholds) in code."""

    f_stop: Annotated[float, msgspec.Meta(gt=0.0, le=1000.0, description="a number in (0, 1000] N")] = 30.0
    m_stop: Annotated[float, msgspec.Meta(gt=0.0, le=100.0, description="a number in (0, 100] Nm")] = 4.5
    f_slow: Annotated[float, msgspec.Meta(gt=0.0, le=1000.0, description="a number in (0, 1000] N")] = 8.0
    goal_tolerance: Annotated[float, msgspec.Meta(gt=0.0, le=0.05, description="a number in (0, 0.05] m")] = 0.003
    persist_steps: Annotated[int, msgspec.Meta(ge=1, le=10000, description="an integer in 1 .. 10000")] = 20


class Detector:
    """Tracks the wrench deviation of one attempt; ``violated`` after a sustained breach.

    ``max_force_dev`` / ``max_torque_dev`` are the largest deviations *sustained* for
    ``persist_steps`` steps (max over time of the window minimum): directly comparable
    with F_stop and M_stop, blind to single-step contact spikes."""

    def __init__(self, thresholds: Thresholds) -> None:
        self.thresholds = thresholds
        self.max_force_dev = 0.0
        self.max_torque_dev = 0.0
        # The last ``persist_steps`` norms, as ring buffers of floats (one ``update`` per
        # 1 ms step: min() over 20 floats costs less than numpy's over a (20, 2) array).
        self._forces = [0.0] * thresholds.persist_steps
        self._torques = [0.0] * thresholds.persist_steps
        self._count = 0

    def update(self, force_dev: np.ndarray, torque_dev: np.ndarray) -> tuple[float, float, bool]:
        """Add one sample of the deviations (3,) [N], (3,) [Nm]; returns their norms and
        whether eq. (6) or (7) has held for ``persist_steps`` steps in a row."""
        f = math.sqrt(force_dev[0] ** 2 + force_dev[1] ** 2 + force_dev[2] ** 2)
        m = math.sqrt(torque_dev[0] ** 2 + torque_dev[1] ** 2 + torque_dev[2] ** 2)
        th = self.thresholds
        slot = self._count % th.persist_steps
        self._forces[slot], self._torques[slot] = f, m
        self._count += 1
        if self._count < th.persist_steps:
            return f, m, False
        f_sustained, m_sustained = min(self._forces), min(self._torques)
        self.max_force_dev = max(self.max_force_dev, f_sustained)
        self.max_torque_dev = max(self.max_torque_dev, m_sustained)
        return f, m, f_sustained >= th.f_stop or m_sustained >= th.m_stop

    def clear(self) -> None:
        """Forget the recent samples (after the exception strategy)."""
        self._count = 0

    def goal_reached(self, p_end: np.ndarray, p_goal: np.ndarray) -> tuple[bool, float]:
        """The goal check: (‖p_end − p_goal‖ ≤ tolerance, the distance [m])."""
        err = float(np.linalg.norm(np.asarray(p_end) - np.asarray(p_goal)))
        return err <= self.thresholds.goal_tolerance, err
