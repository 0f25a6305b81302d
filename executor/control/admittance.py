"""On-line adaptation toward the reference wrench (paper 3.1/3.2, after Abu-Dakka 2015).

A bounded mass-damper-spring admittance per axis, driven by a PI law of the wrench
deviation (the paper's "admittance PI control law"), shifts the commanded pose by δ:

    M δ̈ + D δ̇ + K δ = ΔW + K_i ∫ΔW dt,     ΔW = W_mes − W_des,     |δ| ≤ bound

on the lateral forces (x, y → translation) and the tilting torques (x, y → rotation),
and for a part that must be aligned in yaw (a rect part or hole) on the torque about the
tool axis too (z → rotation about z, ``yaw_bound``): the walls of a slot turn the part
toward the slot's real yaw when vision got it wrong.
The proportional part answers at once; the integral part keeps adapting while a
deviation persists (which is what DMP phase stopping gives it time to do) and holds
the offset that cancelled it; in contact, the measured wrench unwinds the integral when
the offset overshoots, and the spring then returns δ to the reference (without the
spring, a pure integrator keeps the offset it reached and drives the pose away once the
contact that caused it is gone). The integral is clamped to what holds δ at its bound
(anti-windup). The insertion axis z is left to the DMP and to phase stopping.
Integrated with semi-implicit Euler at the control rate.
"""

from __future__ import annotations

from typing import Annotated

import msgspec
import numpy as np

Positive = Annotated[float, msgspec.Meta(gt=0.0, le=1e6, description="a number in (0, 1e6]")]
Bound = Annotated[float, msgspec.Meta(gt=0.0, le=0.5, description="a number in (0, 0.5] (m or rad)")]


class AdmittanceParams(msgspec.Struct, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """Translation: mass [kg], damping [N·s/m], stiffness [N/m], bound [m];
    rotation: inertia [kg·m²], damping [Nm·s/rad], stiffness [Nm/rad], bound [rad].
    Natural frequency ≈ 30 rad/s, critically damped; ``integral_gain`` K_i [1/s] of
    the PI drive (time constant 1/K_i = 0.5 s; 0: P only, the integral stays 0); the yaw
    axis has the rotation's inertia, damping and stiffness and its own bound [rad] (4°:
    twice the cell's largest yaw error of the vision, ``--vision-yaw-max``)."""

    mass: Positive = 1.5
    damping: Positive = 90.0
    stiffness: Positive = 1350.0
    bound: Bound = 0.002
    inertia: Positive = 0.011
    rot_damping: Positive = 0.66
    rot_stiffness: Positive = 10.0
    rot_bound: Bound = 0.035
    integral_gain: Annotated[float, msgspec.Meta(ge=0.0, le=1000.0, description="a number in [0, 1000] 1/s")] = 2.0
    yaw_bound: Bound = 0.07


class Admittance:
    """State δ = (dx, dy, rx, ry) with velocities, and rz with ``yaw``; ``update`` returns
    the pose offset.

    The state is kept as Python floats, one per axis: ``update`` runs once per 1 ms
    control step, and per-axis float arithmetic costs a fraction of numpy's on 4-vectors
    (the same IEEE operations in the same order, so the same numbers)."""

    def __init__(self, params: AdmittanceParams, yaw: bool = False) -> None:
        p = params
        self.yaw = yaw
        n = 5 if yaw else 4
        self.mass = np.array([p.mass, p.mass, p.inertia, p.inertia, p.inertia])[:n]
        self.damping = np.array([p.damping, p.damping, p.rot_damping, p.rot_damping, p.rot_damping])[:n]
        self.stiffness = np.array([p.stiffness, p.stiffness, p.rot_stiffness, p.rot_stiffness, p.rot_stiffness])[:n]
        self.bound = np.array([p.bound, p.bound, p.rot_bound, p.rot_bound, p.yaw_bound])[:n]
        self.integral_gain = p.integral_gain
        # Anti-windup: no more integral than holds δ at its bound (none at all for P only).
        self.integral_limit = self.stiffness * self.bound / p.integral_gain if p.integral_gain > 0 else np.zeros(n)
        self._axes = [(float(m), float(d), float(k), float(b), float(lim)) for m, d, k, b, lim in
                      zip(self.mass, self.damping, self.stiffness, self.bound, self.integral_limit)]
        self.reset()

    def reset(self) -> None:
        """Back to rest at the reference: no offset, velocity or integral."""
        n = len(self._axes)
        self._offset = [0.0] * n
        self._velocity = [0.0] * n
        self._integral = [0.0] * n

    @property
    def offset(self) -> np.ndarray:
        """δ per axis [m, m, rad, rad(, rad)]."""
        return np.array(self._offset)

    @property
    def velocity(self) -> np.ndarray:
        """dδ/dt per axis [m/s, rad/s]."""
        return np.array(self._velocity)

    @property
    def integral(self) -> np.ndarray:
        """∫ΔW dt per axis [N·s, Nm·s]."""
        return np.array(self._integral)

    def update(self, force_dev: np.ndarray, torque_dev: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
        """Advance by ``dt`` [s] with the wrench deviation (world frame) [N, Nm]; returns
        the translation offset (3,) [m] and the rotation vector offset (3,) [rad]."""
        error = [float(force_dev[0]), float(force_dev[1]), float(torque_dev[0]), float(torque_dev[1])]
        if self.yaw:
            error.append(float(torque_dev[2]))
        ki = self.integral_gain
        offset, velocity, integral = self._offset, self._velocity, self._integral
        for i, (mass, damping, stiffness, bound, limit) in enumerate(self._axes):
            integral[i] = min(max(integral[i] + error[i] * dt, -limit), limit)
            acc = (error[i] + ki * integral[i] - damping * velocity[i] - stiffness * offset[i]) / mass
            velocity[i] += acc * dt
            moved = offset[i] + velocity[i] * dt
            offset[i] = min(max(moved, -bound), bound)
            if offset[i] != moved:
                velocity[i] = 0.0
        yaw = offset[4] if self.yaw else 0.0
        return np.array([offset[0], offset[1], 0.0]), np.array([offset[2], offset[3], yaw])
