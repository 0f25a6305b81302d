"""The hole frame: the skills insert down its z axis, whatever way the hole points.

The search, the insertion (DMP, admittance, phase stopping, eqs. (6)/(7), wiggle, ILC,
goal check) and teaching are written for a part going down (-z) into a hole whose entry
is at a height. A hole entered sideways (``axis`` ``+x``, ``-x``, ``+y``, ``-y`` in
``geometry.toml``) gets a :class:`HoleFrame`: its z axis points out of the hole (against
the insertion), its x and y are the axes its section was measured in
(:func:`hole_rotation`), and it is the cell frame turned about the hole's entry centre.
:class:`executor.control.motion.Motion` with a frame carries every commanded pose and
feed-forward wrench into the cell frame and every reading (tip pose, velocities,
Jacobian, wrench) out of it, so the same skill code runs in it unchanged; a hole entered
down has no frame (the identity, and its trials are unchanged bit for bit).

A hole's yaw about z is here too: the rotation it turns a hole or a boss by
(:func:`yaw_quat`) and the tool yaw that aligns a part with it (:func:`aligned_yaw`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # the arm module loads PyBullet, which the import of a product does not need
    from executor.world.arm import ArmState

_OUT = {"+x": (-1.0, 0.0, 0.0), "-x": (1.0, 0.0, 0.0), "+y": (0.0, -1.0, 0.0), "-y": (0.0, 1.0, 0.0),
        "-z": (0.0, 0.0, 1.0)}
"""Out of the hole (the removal direction) for each insertion axis."""


def hole_rotation(axis: str) -> np.ndarray:
    """The rotation (3 × 3, columns x, y, z of the hole frame in the cell frame) of a hole
    entered along ``axis`` (``-z``, ``+x``, ``-x``, ``+y``, ``-y``): z out of the hole, x
    and y the slice axes the import measures its section in
    (:func:`executor.cad.sections.frame_of` of the removal direction: x the cell's x, or
    its y for a hole along x), right-handed; the identity for ``-z``."""
    out = np.array(_OUT[axis])
    helper = np.array([1.0, 0.0, 0.0]) if abs(out[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = helper - np.dot(helper, out) * out
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(out, x), out])


def quat_mul(a: np.ndarray | tuple[float, ...], b: np.ndarray | tuple[float, ...]) -> np.ndarray:
    """The product a·b of quaternions (x, y, z, w)."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return np.array([aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
                     aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz])


def _quat_of(rotation: np.ndarray) -> tuple[float, float, float, float]:
    """The quaternion (xyzw) of a rotation matrix whose entries are 0 and ±1."""
    m = rotation
    w = np.sqrt(max(0.0, 1.0 + m[0, 0] + m[1, 1] + m[2, 2])) / 2
    x = np.copysign(np.sqrt(max(0.0, 1.0 + m[0, 0] - m[1, 1] - m[2, 2])) / 2, m[2, 1] - m[1, 2])
    y = np.copysign(np.sqrt(max(0.0, 1.0 - m[0, 0] + m[1, 1] - m[2, 2])) / 2, m[0, 2] - m[2, 0])
    z = np.copysign(np.sqrt(max(0.0, 1.0 - m[0, 0] - m[1, 1] + m[2, 2])) / 2, m[1, 0] - m[0, 1])
    return float(x), float(y), float(z), float(w)


@dataclass(frozen=True)
class HoleFrame:
    """The cell frame turned by ``rotation`` (3 × 3, :func:`hole_rotation`) about ``entry``
    (3,) [m], the centre of the hole's entry, which both frames share: a point p of the
    hole frame is ``entry + rotation (p - entry)`` in the cell frame."""

    rotation: np.ndarray
    entry: np.ndarray
    quat: tuple[float, float, float, float]
    """The rotation as a quaternion (xyzw)."""

    def pose_to_cell(self, pos: np.ndarray, quat_xyzw: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """A pose (position [m], quaternion xyzw) of the hole frame in the cell frame."""
        return self.points_to_cell(pos), quat_mul(self.quat, quat_xyzw)

    def points_to_cell(self, points: np.ndarray) -> np.ndarray:
        """Points (..., 3) [m] of the hole frame in the cell frame."""
        return self.entry + (np.asarray(points) - self.entry) @ self.rotation.T

    def points_in(self, points: np.ndarray) -> np.ndarray:
        """Points (..., 3) [m] of the cell frame in the hole frame."""
        return self.entry + (np.asarray(points) - self.entry) @ self.rotation

    def vector_to_cell(self, vector: np.ndarray) -> np.ndarray:
        """A vector (..., 3) of the hole frame (a force, a velocity) in the cell frame."""
        return np.asarray(vector) @ self.rotation.T

    def state_in(self, state: ArmState) -> ArmState:
        """A reading of the cell frame expressed in the hole frame (joints unchanged)."""
        from executor.world.arm import ArmState

        back = self.rotation.T
        inverse = (-self.quat[0], -self.quat[1], -self.quat[2], self.quat[3])
        quat = quat_mul(inverse, state.tip_quat_xyzw)
        jac = np.vstack([back @ state.jac[:3], back @ state.jac[3:]])
        return ArmState(state.q, state.qd, back @ (state.tip_pos - self.entry) + self.entry, quat, back @ state.tip_vel,
                        back @ state.tip_omega, jac, back @ state.force, back @ state.torque)


def hole_frame(axis: str, entry: tuple[float, float, float]) -> HoleFrame | None:
    """The frame a hole entered along ``axis`` is inserted in, about its ``entry`` centre
    [m]; None for a hole entered down (``-z``: the cell frame itself)."""
    if axis == "-z":
        return None
    rotation = hole_rotation(axis)
    return HoleFrame(rotation, np.array(entry, dtype=float), _quat_of(rotation))


def yaw_quat(yaw: float) -> tuple[float, float, float, float]:
    """The rotation by ``yaw`` [rad] about z (xyzw): a turned hole's or boss's orientation."""
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


def aligned_yaw(part_kind: str, hole_kind: str, yaw: float) -> float:
    """The tool yaw [rad] that puts a part of ``part_kind`` along a hole of ``hole_kind``
    whose x axis is at ``yaw`` [rad]: 0 when either is round (nothing to align), else
    ``yaw`` reduced by the symmetry of the pair (a quarter turn when either is square,
    a half turn for rect in rect, a whole turn with a polygon: its ``yaw`` includes the
    turn the polygon relation found,
    :func:`executor.world.geometry.fit_pose`) into the half period
    around 0, the smallest turn of the wrist."""
    if "round" in (part_kind, hole_kind):
        return 0.0
    kinds = (part_kind, hole_kind)
    period = 2 * math.pi if "polygon" in kinds else math.pi / 2 if "square" in kinds else math.pi
    return yaw - period * round(yaw / period)
