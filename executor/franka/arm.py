"""A Franka arm behind the skills' interface (:class:`executor.control.motion.ArmController`):
franky's Cartesian impedance tracking motion, its reference set every control step.

The tool tip the skills drive is the end effector (the Franka Hand's TCP, between the
fingertips) moved ``tcp`` [m] along the tool axis: 0 with the hand empty, the held part's
length below the grip point with a part (:meth:`FrankyArm.set_tcp`). The state is read from
franky: the pose from ``O_T_EE``, the velocity from the zero Jacobian and the joint
velocities, the contact wrench from the arm's estimate ``O_F_ext_hat_K`` (the
environment's wrench on the end effector, base frame; pressing down gives +z), tared at
rest and low-pass filtered as the PyBullet cell's sensor (τ ≈ 10 ms), carried to the tip.

The control period: the skills step on their own clock, :data:`executor.world.scene.TIME_STEP`
(1 ms) per step. :meth:`FrankyController.step` sets the reference and then waits until
the robot's clock (``RobotState.time``) has advanced, so every step meets a new state and
a step is never shorter than one of the robot's 1 kHz cycles; when Python's step takes
longer than 1 ms, the robot's controller keeps tracking the last reference meanwhile and
the skill runs slower than taught (DMP, admittance and detector count steps, not robot
time). ``FrankyController.robot_period`` gives the robot time per step measured
(docs/franka.md has the figure against franky-sim).

The torque loop: franky computes the impedance's torques in its own thread of this process,
one command per robot cycle; on a loaded machine it misses cycles, and the robot applies
the last torques again (franky-sim) or counts them lost (a real arm, which stops with a
reflex when too many are). ``FrankyController.lowest_rate`` is the lowest
``control_command_success_rate`` (the share of the last 100 cycles whose command arrived)
the steps read since :meth:`FrankyController.watch_rate`.
"""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np

from executor import ExecutorError
from executor.control.gains import ImpedanceGains
from executor.franka.safety import ERROR_CLIP, SafetyStop, Workspace, capped
from executor.skills.insertion import rotvec_quat_xyzw
from executor.world.arm import ArmState, cross, quat_to_matrix, rotation_error
from executor.world.frames import quat_mul
from executor.world.scene import TIME_STEP

_POLL = 0.0002  # [s] between two looks at the robot's clock
_STALL = 2.0  # [s] of wall time without a new robot cycle: the connection is lost
FILTER = 0.1  # the wrench's low-pass per step (as the PyBullet cell's sensor)


class FrankyArm:
    """Reads a franky ``Robot``'s state as an :class:`ArmState` of the believed tool tip."""

    def __init__(self, robot: Any) -> None:
        import franky

        self.robot = robot
        self._frame = franky.Frame.EndEffector
        self.tcp = 0.0
        self.tare = np.zeros(6)
        self._filtered = np.zeros(6)
        self.command_rate = 0.0
        """libfranka's ``control_command_success_rate`` at the last :meth:`read`: the share
        of the last 100 robot cycles on which this client's control command arrived (0
        while no motion runs)."""

    def set_tcp(self, length: float) -> None:
        """The tool tip is ``length`` [m] below the end effector along the tool axis."""
        self.tcp = float(length)

    def _raw(self, state: Any) -> np.ndarray:
        return np.asarray(state.O_F_ext_hat_K, dtype=float)

    def read(self, state: Any = None) -> ArmState:
        """The robot's latest state (or ``state``, a franky ``RobotState``), as the skills
        read it (the module docstring)."""
        s = self.robot.state if state is None else state
        self.command_rate = float(s.control_command_success_rate)
        ee = s.O_T_EE
        rot = quat_to_matrix(np.asarray(ee.quaternion))
        lever = rot[:, 2] * self.tcp
        ee_pos = np.asarray(ee.translation, dtype=float)
        tip = ee_pos + lever
        q, dq = np.asarray(s.q, dtype=float), np.asarray(s.dq, dtype=float)
        jac = np.asarray(self.robot.model.zero_jacobian(self._frame, s), dtype=float)
        twist = jac @ dq
        omega = twist[3:]
        self._filtered += FILTER * ((self._raw(s) - self.tare) - self._filtered)
        force = self._filtered[:3].copy()
        torque = self._filtered[3:] - cross(lever, force)
        return ArmState(q, dq, tip, np.asarray(ee.quaternion, dtype=float), twist[:3] + cross(omega, lever), omega,
                        jac, force, torque)

    def tare_sensor(self) -> None:
        """Zero the wrench estimate here (at rest, out of contact): the held part's weight
        and the estimate's offset."""
        self.tare = self._raw(self.robot.state)
        self._filtered = np.zeros(6)

    def robot_time(self) -> float:
        """The robot's clock [s]."""
        return float(self.robot.state.time.to_sec())


class FrankyController:
    """The skills' controller on a Franka: a Cartesian impedance tracking motion whose
    reference is the desired tool pose moved back to the end effector; started by
    :meth:`start`, stopped by :meth:`stop`.

    ``gains``: the cell's impedance (stiffness capped, :func:`executor.franka.safety.capped`;
    the null-space gains are franky's own); ``workspace``: every desired tip position
    is checked before it is sent. A feed-forward wrench (the wiggle's) becomes the pose
    offset that makes the spring push with it (force / stiffness)."""

    def __init__(self, arm: FrankyArm, gains: ImpedanceGains, workspace: Workspace) -> None:
        self._arm = arm
        self._gains = gains
        self.workspace = workspace
        self._tracker: Any = None
        self._last_ref: tuple[np.ndarray, np.ndarray] | None = None  # the last reference of the end effector
        self._last_time = 0.0
        self.steps = 0
        self.robot_seconds = 0.0
        self.lowest_rate = 1.0

    @property
    def arm(self) -> FrankyArm:
        return self._arm

    @property
    def gains(self) -> ImpedanceGains:
        return self._gains

    @gains.setter
    def gains(self, gains: ImpedanceGains) -> None:
        self._gains = gains
        if self._tracker is not None:
            self._tracker.set_gains(gains=self._franky_gains())

    def _franky_gains(self) -> Any:
        import franky

        k_t, k_r = capped(self._gains.k_trans, self._gains.k_rot)
        scale_t, scale_r = math.sqrt(k_t / self._gains.k_trans), math.sqrt(k_r / self._gains.k_rot)
        return franky.CartesianImpedanceGains.isotropic(k_t, k_r, self._gains.d_trans * scale_t,
                                                        self._gains.d_rot * scale_r)

    @property
    def robot_period(self) -> float:
        """The robot time per control step so far [s] (0 before the first)."""
        return self.robot_seconds / self.steps if self.steps else 0.0

    def start(self) -> None:
        """Start tracking the current pose (the arm holds still)."""
        import franky

        if self._tracker is None:
            self._tracker = franky.CartesianImpedanceTracker(
                self._arm.robot, gains=self._franky_gains(), translational_error_clip=np.full(3, ERROR_CLIP),
                gains_time_constant=0.005)
            self._last_time = self._arm.robot_time()

    def stop(self) -> None:
        """Bring the arm to rest and end the tracking motion (after an error too)."""
        tracker, self._tracker, self._last_ref = self._tracker, None, None
        if tracker is not None:
            tracker.stop()

    def reset(self) -> None:
        """Nothing is cached between motions on the arm."""

    def watch_rate(self) -> None:
        """Start :attr:`lowest_rate` afresh (1)."""
        self.lowest_rate = 1.0

    def step(self, pos_des: np.ndarray, quat_des_xyzw: np.ndarray,
             wrench_ff: np.ndarray | None = None) -> ArmState:
        """Send the tip pose [m, xyzw] (plus the feed-forward wrench as a pose offset) and
        wait for the robot's next cycle; returns the state read before. SafetyStop when
        the pose is outside the workspace, ExecutorError when the arm is no longer in
        control (a reflex, a lost connection)."""
        self.workspace.check(pos_des)
        if self._tracker is None:
            self.start()
        s = self._arm.read()
        if self._arm.command_rate > 0.0:  # 0: the tracking loop has sent no command yet
            self.lowest_rate = min(self.lowest_rate, self._arm.command_rate)
        if wrench_ff is not None:
            k_t, k_r = capped(self._gains.k_trans, self._gains.k_rot)
            pos_des = pos_des + wrench_ff[:3] / k_t
            quat_des_xyzw = quat_mul(rotvec_quat_xyzw(wrench_ff[3:] / k_r), quat_des_xyzw)
        import franky

        ee_pos = pos_des - quat_to_matrix(quat_des_xyzw)[:, 2] * self._arm.tcp
        # The reference's twist, so that the damping acts on the tracking error rather
        # than on the motion itself (a reference moving at v would lag by D·v/K).
        if self._last_ref is None:
            twist = np.zeros(6)
        else:
            last_pos, last_quat = self._last_ref
            twist = np.concatenate([(ee_pos - last_pos) / TIME_STEP,
                                    rotation_error(quat_des_xyzw, last_quat) / TIME_STEP])
        self._last_ref = (ee_pos, np.asarray(quat_des_xyzw, dtype=float))
        self._tracker.set_target(franky.Affine(ee_pos, quat_des_xyzw), franky.Twist(twist[:3], twist[3:]))
        self._wait_cycle()
        return s

    def guide(self, damping: float) -> None:
        """Hand the arm over to a human hand: no spring on the translation, ``damping``
        [N s/m] per axis only; the tool's orientation held where it is by the cell's
        rotational gains (as :meth:`step` holds it). :meth:`stop` ends it."""
        import franky

        if self._tracker is None:
            self.start()
        gains = self._franky_gains()
        stiffness, damping_matrix = np.diag(gains.stiffness).copy(), np.diag(gains.damping).copy()
        stiffness[:3], damping_matrix[:3] = 0.0, damping
        ee = self._arm.robot.state.O_T_EE
        self._last_ref = None
        self._tracker.set_target(franky.Affine(np.asarray(ee.translation), np.asarray(ee.quaternion)),
                                 franky.Twist(np.zeros(3), np.zeros(3)))
        self._tracker.set_gains(gains=franky.CartesianImpedanceGains.diagonal(stiffness, damping_matrix))

    def sample(self) -> tuple[float, ArmState]:
        """Wait for the robot's next cycle; its clock [s] and its state then, read
        together. ExecutorError as :meth:`step`."""
        self._wait_cycle()
        state = self._arm.robot.state
        return float(state.time.to_sec()), self._arm.read(state)

    def _wait_cycle(self) -> None:
        robot = self._arm.robot
        deadline = time.monotonic() + _STALL
        while True:
            if not robot.is_in_control:
                self._tracker, self._last_ref = None, None
                raise ExecutorError("the arm stopped tracking (a reflex or an error of the robot)")
            now = self._arm.robot_time()
            if now > self._last_time:
                break
            if time.monotonic() > deadline:
                raise SafetyStop(f"no new robot state for {_STALL:g} s: the connection to the arm is lost")
            time.sleep(_POLL)
        self.robot_seconds += now - self._last_time
        self.steps += 1
        self._last_time = now
