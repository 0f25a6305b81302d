"""The arm as the controller sees it: joint state, the believed tool-tip pose, Jacobian,
gravity/Coriolis torques and the wrist force/torque sensor.

The part link's frame is the part's *real* tip.  The grasp is not repeatable: the robot
believes the tip sits at ``real ∘ grasp_error⁻¹``, so every pose the controller reads or
commands is the believed one, and the part really ends up offset and tilted.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pybullet as pb
from scipy.spatial.transform import Rotation

from executor import ExecutorError

N_JOINTS = 7
# Comfortable posture (elbow up, tool down) for IK and the null-space term [rad].
REST_POSTURE = np.array([0.0, 0.6, 0.0, -1.4, 0.0, 1.1, 0.0])
TOOL_DOWN_QUAT_XYZW = np.array([1.0, 0.0, 0.0, 0.0])
LIMIT_MARGIN = 0.1
"""[rad] how far inside its joint limits :meth:`Arm.solve` keeps the arm: room for the
controller's motions from there (a joint at its limit stops the tool short)."""
SOLVED = 0.0005  # [m] how near its pose :meth:`Arm.solve` puts the tip
SOLVED_TURN = 0.005  # [rad] and how near its orientation
RELAXED = 0.001
"""[rad] :meth:`Arm.posture_path` repeats a pose's IK from its answer until no joint moves more than this"""
RELAX_CALLS = 4  # or this many times
_ORIGIN = (0.0, 0.0, 0.0)


def tool_quat(yaw: float) -> np.ndarray:
    """The tool pointing down, turned by ``yaw`` [rad] about the world z axis (xyzw):
    Rz(yaw) · :data:`TOOL_DOWN_QUAT_XYZW`, so the held part's x axis points at angle
    ``yaw``; exactly :data:`TOOL_DOWN_QUAT_XYZW` at yaw 0."""
    return np.array([math.cos(yaw / 2), math.sin(yaw / 2), 0.0, 0.0])


def turn_z(vectors: np.ndarray, yaw: float) -> np.ndarray:
    """Vectors (..., 3) turned by ``yaw`` [rad] about z (returned unchanged at yaw 0)."""
    if yaw == 0.0:
        return vectors
    c, s = math.cos(yaw), math.sin(yaw)
    out = np.array(vectors, dtype=float)
    out[..., 0] = c * vectors[..., 0] - s * vectors[..., 1]
    out[..., 1] = s * vectors[..., 0] + c * vectors[..., 1]
    return out


def turn_quats_z(quats_xyzw: np.ndarray, yaw: float) -> np.ndarray:
    """Orientations (..., 4) xyzw turned by ``yaw`` [rad] about the world z axis:
    Rz(yaw) · q (returned unchanged at yaw 0)."""
    if yaw == 0.0:
        return quats_xyzw
    s, c = math.sin(yaw / 2), math.cos(yaw / 2)
    x, y, z, w = (quats_xyzw[..., k] for k in range(4))
    return np.stack([c * x - s * y, c * y + s * x, c * z + s * w, c * w - s * z], axis=-1)


def quat_to_matrix(quat_xyzw: np.ndarray) -> np.ndarray:
    """3×3 rotation matrix of a unit quaternion (x, y, z, w)."""
    return np.array(pb.getMatrixFromQuaternion(list(quat_xyzw))).reshape(3, 3)


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """3-vector cross product (np.cross costs ~10 µs per call on 3-vectors)."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def rotation_error(quat_des_xyzw: np.ndarray, quat_xyzw: np.ndarray) -> np.ndarray:
    """Rotation vector [rad] (world frame) that turns ``quat_xyzw`` into ``quat_des_xyzw``."""
    x1, y1, z1, w1 = quat_des_xyzw
    x2, y2, z2, w2 = -quat_xyzw[0], -quat_xyzw[1], -quat_xyzw[2], quat_xyzw[3]
    w = w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2
    v = np.array([
        w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
        w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
        w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
    ])
    return 2.0 * v if w >= 0 else -2.0 * v


@dataclass(slots=True)
class ArmState:
    """One reading: joints [rad, rad/s], believed tip pose/velocity [m, m/s, rad/s], the
    tip Jacobian (6×7: linear rows, then angular) and the measured contact wrench at the
    tip (world frame) [N, Nm]."""

    q: np.ndarray
    qd: np.ndarray
    tip_pos: np.ndarray
    tip_quat_xyzw: np.ndarray
    tip_vel: np.ndarray
    tip_omega: np.ndarray
    jac: np.ndarray
    force: np.ndarray
    torque: np.ndarray


class Dropped(ExecutorError):
    """The part on the suction cup was pulled off it: the force pulling it away exceeded the
    cup's holding force (:attr:`Arm.hold_limit`); it is no longer held."""


class Arm:
    """Reads and drives the ``kuka_iiwa`` + flange + part multibody in torque mode;
    ``hold_limit`` [N], set while the suction cup holds the part: :meth:`read` raises
    :class:`Dropped` once the sensor's force pulling the part off the cup along the tool's
    axis (its weight, its inertia, the contacts pulling it) exceeds it."""

    def __init__(self, client: int, robot: int) -> None:
        self.client, self.robot = client, robot
        names = [pb.getJointInfo(robot, j, physicsClientId=client)[1].decode() for j in
                 range(pb.getNumJoints(robot, physicsClientId=client))]
        if "ft_sensor" not in names:
            raise ExecutorError(f"robot body {robot}: no 'ft_sensor' joint (expected the generated arm URDF)")
        self.sensor = names.index("ft_sensor")
        self.joints = list(range(N_JOINTS))
        self._read_joints = [*self.joints, self.sensor]  # one getJointStates per read
        pb.enableJointForceTorqueSensor(robot, self.sensor, True, physicsClientId=client)
        # PyBullet's IK turns the link's inertial frame (its principal axes, which PyBullet
        # chooses for an inertia tensor with products of inertia: a polygon peg's, a mesh
        # part's) to the target orientation, not the link frame: the target is turned by it.
        self._inertial_quat = tuple(pb.getDynamicsInfo(robot, self.sensor, physicsClientId=client)[4])
        info = [pb.getJointInfo(robot, j, physicsClientId=client) for j in self.joints]
        self.lower = np.array([i[8] for i in info])
        """[rad] each joint's lower limit (the URDF's, which PyBullet enforces)."""
        self.upper = np.array([i[9] for i in info])
        """[rad] each joint's upper limit."""
        self.rate_limit = np.array([i[11] for i in info])
        """[rad/s] each joint's speed limit (the URDF's ``velocity``:
        :data:`executor.world.geometry.JOINT_RATE_LIMITS`), which PyBullet does not enforce."""
        self._zeros = [0.0] * N_JOINTS
        self.set_grasp_error(np.zeros(3), np.array([0.0, 0.0, 0.0, 1.0]))
        self.tare = np.zeros(6)
        self._wrench_filtered = np.zeros(6)
        self.hold_limit: float | None = None

    def set_grasp_error(self, offset: np.ndarray, quat_xyzw: np.ndarray) -> None:
        """Real tip = believed tip ∘ (offset [m], rotation) in the believed tip frame."""
        inv_pos, inv_quat = pb.invertTransform(list(offset), list(quat_xyzw))
        self._inv_pos, self._inv_quat = np.array(inv_pos), tuple(inv_quat)
        self._inv_pos_list = list(inv_pos)
        self.grasp_offset, self.grasp_quat_xyzw = np.array(offset), np.array(quat_xyzw)

    def reset(self, q: np.ndarray) -> None:
        """Teleport the joints to ``q`` [rad] at rest and switch the joint motors off."""
        for j, qj in zip(self.joints, q):
            pb.resetJointState(self.robot, j, float(qj), 0.0, physicsClientId=self.client)
        pb.setJointMotorControlArray(self.robot, self.joints, pb.VELOCITY_CONTROL, forces=self._zeros,
                                     physicsClientId=self.client)
        self._wrench_filtered = np.zeros(6)

    def inverse_kinematics(self, tip_pos: np.ndarray, tip_quat_xyzw: np.ndarray) -> np.ndarray:
        """Joint angles [rad] putting the *believed* tip at the pose (a few IK iterations;
        used only to place the arm before an attempt, never per control step)."""
        real_pos, real_quat = self._ik_target(tip_pos, tip_quat_xyzw)
        q = REST_POSTURE.copy()
        for _ in range(4):
            self.reset(q)
            q = np.array(pb.calculateInverseKinematics(
                self.robot, self.sensor, real_pos, real_quat, restPoses=list(REST_POSTURE),
                maxNumIterations=200, residualThreshold=1e-6, physicsClientId=self.client)[:N_JOINTS])
        self.reset(q)
        return q

    def _ik_target(self, tip_pos: np.ndarray, tip_quat_xyzw: np.ndarray) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """The sensor link's pose (its inertial frame's orientation) PyBullet's IK is to put
        where the *believed* tip is at the pose."""
        real_pos, real_quat = pb.multiplyTransforms(list(tip_pos), list(tip_quat_xyzw),
                                                    list(self.grasp_offset), list(self.grasp_quat_xyzw))
        if self._inertial_quat != (0.0, 0.0, 0.0, 1.0):  # in doubles: PyBullet's product rounds to float32
            real_quat = tuple((Rotation.from_quat(real_quat) * Rotation.from_quat(self._inertial_quat)).as_quat())
        return tuple(real_pos), tuple(real_quat)

    def solve(self, tip_pos: np.ndarray, tip_quat_xyzw: np.ndarray, seeds: list[np.ndarray]) -> np.ndarray | None:
        """Joint angles [rad] at least :data:`LIMIT_MARGIN` inside the joint limits putting
        the *believed* tip within :data:`SOLVED` of the pose (:data:`SOLVED_TURN` of its
        orientation): PyBullet's IK from each of ``seeds`` in turn, which also pulls to it,
        the first such; None where none is. The arm is left as it was (its joints and their
        rates restored; nothing steps). PyBullet's IK given the limits ends millimetres off
        the pose: the limits are checked instead."""
        c, r = self.client, self.robot
        saved = [(j[0], j[1]) for j in pb.getJointStates(r, self.joints, physicsClientId=c)]
        real_pos, real_quat = self._ik_target(tip_pos, tip_quat_xyzw)
        try:
            for seed in seeds:
                q = seed
                for _ in range(4):
                    self._set(q)
                    q = np.array(pb.calculateInverseKinematics(
                        r, self.sensor, real_pos, real_quat, restPoses=list(seed), maxNumIterations=200,
                        residualThreshold=1e-6, physicsClientId=c)[:N_JOINTS])
                self._set(q)
                ls = pb.getLinkState(r, self.sensor, computeForwardKinematics=1, physicsClientId=c)
                quat = np.array(pb.multiplyTransforms(_ORIGIN, ls[5], _ORIGIN, self._inv_quat)[1])
                within = bool(np.all(q >= self.lower + LIMIT_MARGIN) and np.all(q <= self.upper - LIMIT_MARGIN))
                if within and self.tip_error(tip_pos) < SOLVED and np.linalg.norm(
                        rotation_error(np.asarray(tip_quat_xyzw), quat)) < SOLVED_TURN:
                    return q
            return None
        finally:
            for j, (qj, rate) in zip(self.joints, saved):
                pb.resetJointState(r, j, qj, rate, physicsClientId=c)

    def posture_path(self, tip_pos: np.ndarray, tip_quats_xyzw: np.ndarray) -> np.ndarray:
        """Joint angles [rad] (n × 7) putting the *believed* tip at each of the poses in turn
        (n × 3 [m], n × 4 xyzw; cell frame): PyBullet's IK within the joint limits, toward
        :data:`REST_POSTURE`, from the angles before (the first from the arm's now), repeated
        from its own answer until the pull toward that posture has come to rest
        (:data:`RELAXED`, :data:`RELAX_CALLS`). The postures the arm passes through where the
        Cartesian impedance controller carries its tip along the poses: its null-space
        spring pulls to that posture, the limits stop the joints. The arm is left as it was
        (its joints and their rates restored; nothing steps)."""
        c, r = self.client, self.robot
        saved = [(j[0], j[1]) for j in pb.getJointStates(r, self.joints, physicsClientId=c)]
        limits = {"lowerLimits": self.lower.tolist(), "upperLimits": self.upper.tolist(),
                  "jointRanges": (self.upper - self.lower).tolist(), "restPoses": REST_POSTURE.tolist()}
        path = np.full((len(tip_pos), N_JOINTS), np.inf)
        try:
            for k, (pos, quat) in enumerate(zip(tip_pos, tip_quats_xyzw)):
                real_pos, real_quat = self._ik_target(pos, quat)
                for _ in range(RELAX_CALLS):
                    q = np.array(pb.calculateInverseKinematics(r, self.sensor, real_pos, real_quat,
                                                               maxNumIterations=50, residualThreshold=1e-5,
                                                               physicsClientId=c, **limits)[:N_JOINTS])
                    self._set(q)
                    moved = float(np.max(np.abs(q - path[k])))
                    path[k] = q
                    if moved < RELAXED:
                        break
            return path
        finally:
            for j, (qj, rate) in zip(self.joints, saved):
                pb.resetJointState(r, j, qj, rate, physicsClientId=c)

    def _set(self, q: np.ndarray) -> None:
        for j, qj in zip(self.joints, q):
            pb.resetJointState(self.robot, j, float(qj), 0.0, physicsClientId=self.client)

    def tip_error(self, tip_pos: np.ndarray) -> float:
        """How far [m] the believed tip is from ``tip_pos`` now (a reach check after
        :meth:`inverse_kinematics`; reads no sensor, so the wrench filter is untouched)."""
        ls = pb.getLinkState(self.robot, self.sensor, computeForwardKinematics=1, physicsClientId=self.client)
        rot = np.array(pb.getMatrixFromQuaternion(ls[5])).reshape(3, 3)
        return float(np.linalg.norm(np.array(ls[4]) + rot @ self._inv_pos - np.asarray(tip_pos)))

    def read(self) -> ArmState:
        """The current state; the wrench is tared and low-pass filtered (α = 0.1 per 1 ms step, τ ≈ 10 ms).

        Position, velocity, angular velocity and Jacobian all refer to the believed tip;
        the torque to the point the same lever away from the part's centre of mass, about
        which the sensor measures (docs/cell.md, "Which point PyBullet's quantities refer to").
        Called once per control step: four PyBullet queries (the joints and the sensor
        in one ``getJointStates``, the sensor link's pose and velocity, the Jacobian)."""
        c, r = self.client, self.robot
        js = pb.getJointStates(r, self._read_joints, physicsClientId=c)
        q_list = [j[0] for j in js[:N_JOINTS]]
        ls = pb.getLinkState(r, self.sensor, computeLinkVelocity=1, computeForwardKinematics=1,
                             physicsClientId=c)
        rot = np.array(pb.getMatrixFromQuaternion(ls[5])).reshape(3, 3)
        lever = rot @ self._inv_pos
        tip_pos = np.array(ls[4]) + lever
        tip_quat = np.array(pb.multiplyTransforms(_ORIGIN, ls[5], _ORIGIN, self._inv_quat)[1])
        # ls[6] is the velocity of the link's centre of mass (ls[0]), not of its frame
        # (ls[4]): carry it to the believed tip with ω × (tip − COM).
        (vx, vy, vz), (wx, wy, wz), (lx, ly, lz) = ls[6], ls[7], (tip_pos - ls[0]).tolist()
        omega = np.array(ls[7])
        tip_vel = np.array([vx + (wy * lz - wz * ly), vy + (wz * lx - wx * lz), vz + (wx * ly - wy * lx)])
        jl, ja = pb.calculateJacobian(r, self.sensor, self._inv_pos_list, q_list, self._zeros, self._zeros,
                                      physicsClientId=c)
        filtered = self._wrench_filtered
        filtered += 0.1 * ((np.array(js[N_JOINTS][2]) - self.tare) - filtered)
        # The sensor's z (along the part, away from the flange) reads -m g with the part
        # hanging from the tool pointing down at rest: the pull on the cup is its negative,
        # low-passed as the contact wrench (the tare added back: weight and inertia count).
        if self.hold_limit is not None and (pull := -float(filtered[2] + self.tare[2])) > self.hold_limit:
            raise Dropped(f"the suction cup let go: {pull:.2f} N pulled the part off it along the tool's axis, "
                          f"more than its holding force ({self.hold_limit:g} N); the part dropped")
        # The contact wrench on the part is the flange's negative (weight removed by the tare).
        force = -(rot @ filtered[:3])
        torque = -(rot @ filtered[3:]) - cross(lever, force)
        return ArmState(np.array(q_list), np.array([j[1] for j in js[:N_JOINTS]]), tip_pos, tip_quat, tip_vel,
                        omega, np.array(jl + ja), force, torque)

    def tare_sensor(self) -> None:
        """Zero the F/T sensor (call at rest, out of contact): removes the part's weight."""
        self.tare = np.array(pb.getJointState(self.robot, self.sensor, physicsClientId=self.client)[2])
        self._wrench_filtered = np.zeros(6)

    def gravity_coriolis(self, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """Joint torques [Nm] holding the arm against gravity and Coriolis forces."""
        return np.array(pb.calculateInverseDynamics(self.robot, q.tolist(), qd.tolist(), self._zeros,
                                                    physicsClientId=self.client))

    def command(self, tau: np.ndarray) -> None:
        """Apply joint torques [Nm] for the next step."""
        pb.setJointMotorControlArray(self.robot, self.joints, pb.TORQUE_CONTROL, forces=tau.tolist(),
                                     physicsClientId=self.client)
