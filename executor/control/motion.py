"""One control step at a time: an arm's impedance controller plus bookkeeping (time,
step count, decimated logging).  Search, insertion, wiggle and the transfers all move
through it, so they run unchanged on any arm behind :class:`ArmController`: the PyBullet
cell's (:class:`executor.control.controller.ImpedanceController`, one physics step per
control step) and a Franka's (:class:`executor.franka.arm.FrankyController`, paced by the
robot's 1 kHz clock)."""

from __future__ import annotations

from typing import Generic, Literal, Protocol, TypeVar

import numpy as np

from executor.control.gains import ImpedanceGains
from executor.world.arm import ArmState
from executor.world.frames import HoleFrame
from executor.world.scene import TIME_STEP

APPROACH_SETTLE_TIME = 0.02  # [s] held at a start pose before the F/T sensor is tared
# Log every this many physics steps (10 ms of sim time).
LOG_EVERY = 10
_ZERO3 = np.zeros(3)


class StepLogger(Protocol):
    """What Motion logs into (:class:`executor.rerun_log.AttemptLogger` is one): sim time
    [s], DMP phase, tool tip [m], measured and desired force [N] and torque [Nm]."""

    def log_step(self, sim_time: float, phase: float, tool_pos: np.ndarray, force_mes: np.ndarray,
                 force_des: np.ndarray, torque_mes: np.ndarray, torque_des: np.ndarray) -> None: ...


MoveKind = Literal["line", "descent", "joint"]
"""How a move in free space (:mod:`executor.assembly.transfer`) goes: ``line`` the tip in a
straight line (:func:`~executor.assembly.transfer.move_line`,
:func:`~executor.assembly.transfer.reorient`), ``descent`` such a line at
:data:`~executor.assembly.transfer.DESCENT_SPEED` (the slow end of a descent), ``joint``
the joints to a posture (:func:`~executor.assembly.transfer.move_joints`)."""


class MoveObserver(Protocol):
    """What watches the moves in free space a :class:`Motion` makes (the bench of their joint
    rates, :mod:`executor.campaign.rates`, is one): :meth:`begin` before a move's first
    control step, :meth:`step` after each of its steps (after the move's own per-step
    callback), :meth:`end` after its last (not called when the move raised)."""

    def begin(self, kind: MoveKind) -> None: ...

    def step(self) -> None: ...

    def end(self) -> None: ...


class ArmReader(Protocol):
    """The arm's state as the skills read it (believed tool tip, contact wrench)."""

    def read(self) -> ArmState: ...


class ArmController(Protocol):
    """What the skills drive: a Cartesian impedance about the tool tip whose ``gains``
    (:class:`ImpedanceGains`) a skill may change, one :meth:`step` per control period
    (:data:`TIME_STEP` of the skill's clock) toward a desired tip pose, and ``arm`` to read."""

    gains: ImpedanceGains

    @property
    def arm(self) -> ArmReader: ...

    def step(self, pos_des: np.ndarray, quat_des_xyzw: np.ndarray,
             wrench_ff: np.ndarray | None = None) -> ArmState:
        """One control period toward the tip pose [m, xyzw], plus an optional feed-forward
        wrench [N, Nm] (world frame); returns the state read before it."""
        ...

    def reset(self) -> None:
        """Forget what the controller cached about the arm's previous motion."""
        ...


C = TypeVar("C", bound=ArmController)


class Motion(Generic[C]):
    """Steps the controller toward desired poses; counts sim time [s] and logs.

    With a ``frame`` (:class:`executor.world.frames.HoleFrame`, set for the insertion into
    a hole entered sideways) the poses and feed-forward wrenches it takes and the states it
    returns are in that frame, so the skills insert down its z axis unchanged; the log
    stays in the cell frame."""

    def __init__(self, controller: C, logger: StepLogger | None = None) -> None:
        self.controller = controller
        self.logger = logger
        self.steps = 0
        self.tool_yaw = 0.0
        """[rad] the yaw of the pointing-down tool the transfers last commanded
        (:mod:`executor.assembly.transfer`): where their next move turns it from."""
        self.frame: HoleFrame | None = None
        self.observer: MoveObserver | None = None
        """Told of every move in free space the transfers make through this motion (None: none is)."""

    def read(self) -> ArmState:
        """The arm's state now (in the ``frame``, if any)."""
        state = self.controller.arm.read()
        return state if self.frame is None else self.frame.state_in(state)

    def cell_pose(self, pos: np.ndarray, quat_xyzw: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """A pose (tip [m], quaternion xyzw) of the ``frame`` in the cell frame (unchanged without one)."""
        return (pos, quat_xyzw) if self.frame is None else self.frame.pose_to_cell(pos, quat_xyzw)

    @property
    def sim_time(self) -> float:
        """Simulated time since the cell was built [s]."""
        return self.steps * TIME_STEP

    def step(self, pos_des: np.ndarray, quat_des_xyzw: np.ndarray, wrench_ff: np.ndarray | None = None,
             phase: float = 0.0, wrench_des: np.ndarray | None = None) -> ArmState:
        """One control step toward the pose (tip [m], quaternion); ``phase`` (0..1) and the
        desired wrench [N, Nm] only go to the log.  Returns the state before the step."""
        frame = self.frame
        if frame is not None:
            pos_des, quat_des_xyzw = frame.pose_to_cell(pos_des, quat_des_xyzw)
            if wrench_ff is not None:
                wrench_ff = frame.vector_to_cell(wrench_ff.reshape(2, 3)).reshape(6)
        state = self.controller.step(pos_des, quat_des_xyzw, wrench_ff)
        if self.logger is not None and self.steps % LOG_EVERY == 0:
            f_des = _ZERO3 if wrench_des is None else wrench_des[:3]
            m_des = _ZERO3 if wrench_des is None else wrench_des[3:]
            if frame is not None:
                f_des, m_des = frame.vector_to_cell(f_des), frame.vector_to_cell(m_des)
            self.logger.log_step(self.sim_time, phase, state.tip_pos, state.force, f_des, state.torque, m_des)
        self.steps += 1
        return state if frame is None else frame.state_in(state)

    def hold(self, pos: np.ndarray, quat_xyzw: np.ndarray, duration: float) -> ArmState:
        """Hold a pose for ``duration`` [s]; returns the last state."""
        state = self.step(pos, quat_xyzw)
        for _ in range(int(round(duration / TIME_STEP)) - 1):
            state = self.step(pos, quat_xyzw)
        return state
