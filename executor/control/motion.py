"""One physics step at a time: the impedance controller plus bookkeeping (sim time,
step count, decimated logging).  Search, insertion and wiggle all move through it."""

from __future__ import annotations

from typing import Protocol

import numpy as np

from assembly_constraints.executor.control.controller import ImpedanceController
from assembly_constraints.executor.world.arm import ArmState
from assembly_constraints.executor.world.scene import TIME_STEP

APPROACH_SETTLE_TIME = 0.02  # [s] held at a start pose before the F/T sensor is tared
# Log every this many physics steps (10 ms of sim time).
LOG_EVERY = 10
_ZERO3 = np.zeros(3)


class StepLogger(Protocol):
    """What Motion logs into (:class:`assembly_constraints.executor.rerun_log.AttemptLogger` is one): sim time
    [s], DMP phase, tool tip [m], measured and desired force [N] and torque [Nm]."""

    def log_step(self, sim_time: float, phase: float, tool_pos: np.ndarray, force_mes: np.ndarray,
                 force_des: np.ndarray, torque_mes: np.ndarray, torque_des: np.ndarray) -> None: ...


class Motion:
    """Steps the controller toward desired poses; counts sim time [s] and logs."""

    def __init__(self, controller: ImpedanceController, logger: StepLogger | None = None) -> None:
        self.controller = controller
        self.logger = logger
        self.steps = 0
        self.tool_yaw = 0.0
        """[rad] the yaw of the pointing-down tool the transfers last commanded
        (:mod:`assembly_constraints.executor.assembly.transfer`): where their next move turns it from."""

    @property
    def sim_time(self) -> float:
        """Simulated time since the cell was built [s]."""
        return self.steps * TIME_STEP

    def step(self, pos_des: np.ndarray, quat_des_xyzw: np.ndarray, wrench_ff: np.ndarray | None = None,
             phase: float = 0.0, wrench_des: np.ndarray | None = None) -> ArmState:
        """One 1 ms step toward the pose (tip [m], quaternion); ``phase`` (0..1) and the
        desired wrench [N, Nm] only go to the log.  Returns the state before the step."""
        state = self.controller.step(pos_des, quat_des_xyzw, wrench_ff)
        if self.logger is not None and self.steps % LOG_EVERY == 0:
            f_des = _ZERO3 if wrench_des is None else wrench_des[:3]
            m_des = _ZERO3 if wrench_des is None else wrench_des[3:]
            self.logger.log_step(self.sim_time, phase, state.tip_pos, state.force, f_des, state.torque, m_des)
        self.steps += 1
        return state

    def hold(self, pos: np.ndarray, quat_xyzw: np.ndarray, duration: float) -> ArmState:
        """Hold a pose for ``duration`` [s]; returns the last state."""
        state = self.step(pos, quat_xyzw)
        for _ in range(int(round(duration / TIME_STEP)) - 1):
            state = self.step(pos, quat_xyzw)
        return state
