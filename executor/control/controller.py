"""Torque-mode Cartesian impedance control of the tool tip at 1 kHz.

    τ = Jᵀ [K_t (x_d − x) − D_t ẋ + f_ff ;  K_r e_R − D_r ω + m_ff] + g(q) + C(q, q̇) q̇ + τ_null

with the Jacobian of the believed tip, gravity/Coriolis from PyBullet's inverse dynamics
and a null-space posture spring.  K_t = 2000 N/m makes the force against an obstacle
K_t × overtravel (20 N per 10 mm), soft enough to be safe, stiff enough to insert.
"""

from __future__ import annotations

import numpy as np
import pybullet as pb

from executor.control.gains import ImpedanceGains
from executor.world.arm import REST_POSTURE, Arm, ArmState, rotation_error

JOINT_BANDWIDTH = 2 * np.pi * 4.0
"""[rad/s] the natural frequency of :meth:`ImpedanceController.step_joints`'s joint servo
(critically damped, each joint as its own unit mass through the arm's mass matrix)."""


class ImpedanceController:
    """Tracks a tip pose with a Cartesian spring-damper; one ``step`` per physics step."""

    # The null-space projector changes slowly: recompute it every this many steps.
    PROJECTOR_PERIOD = 50

    def __init__(self, arm: Arm, client: int, gains: ImpedanceGains) -> None:
        self.arm, self.client, self.gains = arm, client, gains
        self._steps = 0
        self._null_projector = np.eye(7)
        self._wrench = np.zeros(6)  # the commanded tip wrench [N, Nm], rewritten every step

    def reset(self) -> None:
        """Forget the cached null-space projector (call after teleporting the arm), so an
        attempt does not depend on what ran before it."""
        self._steps = 0
        self._null_projector = np.eye(7)

    def step(self, pos_des: np.ndarray, quat_des_xyzw: np.ndarray,
             wrench_ff: np.ndarray | None = None) -> ArmState:
        """Read the arm, command the torques toward the desired pose (plus an optional
        feed-forward wrench [N, Nm] in the world frame), advance the physics one step.
        Returns the state read *before* the step."""
        g = self.gains
        s = self.arm.read()
        wrench = self._wrench
        wrench[:3] = g.k_trans * (pos_des - s.tip_pos) - g.d_trans * s.tip_vel
        wrench[3:] = g.k_rot * rotation_error(quat_des_xyzw, s.tip_quat_xyzw) - g.d_rot * s.tip_omega
        if wrench_ff is not None:
            wrench += wrench_ff
        jac = s.jac
        tau = jac.T @ wrench + self.arm.gravity_coriolis(s.q, s.qd)
        # Null-space posture: the posture torque projected through I − Jᵀ J⁺ᵀ.
        if self._steps % self.PROJECTOR_PERIOD == 0:
            self._null_projector = np.eye(7) - jac.T @ np.linalg.pinv(jac).T
        self._steps += 1
        tau += self._null_projector @ (g.k_null * (REST_POSTURE - s.q) - g.d_null * s.qd)
        self.arm.command(tau)
        pb.stepSimulation(physicsClientId=self.client)
        return s

    def step_joints(self, q_des: np.ndarray, qd_des: np.ndarray) -> ArmState:
        """A joint-space step for moves in free space (:func:`executor.assembly.transfer.move_joints`):
        computed torque M(q) [ω² (q_d − q) + 2ω (q̇_d − q̇)] + g(q) + C(q, q̇) q̇ toward the
        joint angles [rad] and rates [rad/s], ω = :data:`JOINT_BANDWIDTH` (the held part,
        a body of its own, is carried by the servo's stiffness); advances the physics one step.
        Returns the state read before it."""
        s = self.arm.read()
        w = JOINT_BANDWIDTH
        mass = np.array(pb.calculateMassMatrix(self.arm.robot, s.q.tolist(), physicsClientId=self.client))
        tau = mass @ (w * w * (q_des - s.q) + 2 * w * (qd_des - s.qd)) + self.arm.gravity_coriolis(s.q, s.qd)
        self.arm.command(tau)
        pb.stepSimulation(physicsClientId=self.client)
        self._steps = 0  # the null-space projector recomputed at the next Cartesian step
        return s
