"""The control loop's fast paths compute what the plain computations do: the arm's one
batched reading against PyBullet's own velocities, a skill's remembered DMP forcing terms
against a fresh DMP, an admittance after ``reset`` against a new one, the detector's
window against its definition (max over time of the window minimum). Within one process,
so the comparisons are exact where the claim is "the same numbers"."""

from __future__ import annotations

import numpy as np
import pybullet as pb
import pytest

from executor.assembly.transfer import SEEDS, move_joints
from executor.control.admittance import Admittance, AdmittanceParams
from executor.control.detector import Detector, Thresholds
from executor.skills.dmp import load_skill, xyzw_to_wxyz
from executor.trial import Cell
from executor.world import TIME_STEP
from executor.world.arm import LIMIT_MARGIN, quat_to_matrix, rotation_error, tool_quat
from executor.world.geometry import load_geometry
from tests._tolerances import PATH_BOUND


@pytest.fixture(scope="module")
def cell():
    c = Cell()
    c.run_trial("p1", "r1", 3)  # the arm ends holding the part in its hole
    yield c
    c.close()


def test_one_batched_reading_gives_what_separate_queries_give(cell: Cell) -> None:
    """``Arm.read`` takes q, q̇ and the sensor's wrench from one query: they must be the
    joints' and the sensor's own (a shuffled index breaks it), and the angular rows of
    the Jacobian times q̇ the link's angular velocity."""
    motion = cell.motion_for("p1")
    arm = motion.controller.arm
    arm.set_grasp_error(np.array([0.0008, -0.0005, 0.0]), np.array([0.0, 0.01, 0.0, 1.0]) / np.hypot(0.01, 1.0))
    motion.hold(arm.read().tip_pos + [0.0, 0.0, 0.01], np.array([1.0, 0.0, 0.0, 0.0]), 0.02)  # moving up
    arm.tare = np.zeros(6)
    arm.reset(arm.read().q)  # at rest now: the filtered wrench starts from zero
    pb.stepSimulation(physicsClientId=arm.client)
    state = arm.read()
    joints = pb.getJointStates(arm.robot, arm.joints, physicsClientId=arm.client)
    assert np.array_equal(state.q, [j[0] for j in joints]) and np.array_equal(state.qd, [j[1] for j in joints])
    sensor = np.array(pb.getJointState(arm.robot, arm.sensor, physicsClientId=arm.client)[2])
    link_quat = pb.getLinkState(arm.robot, arm.sensor, computeForwardKinematics=1, physicsClientId=arm.client)[5]
    rot = np.array(pb.getMatrixFromQuaternion(link_quat)).reshape(3, 3)
    assert np.allclose(state.force, -(rot @ (0.1 * sensor[:3])), atol=1e-12)  # one filter step from zero
    assert np.allclose(state.jac[3:] @ state.qd, state.tip_omega, atol=1e-9)


def test_tip_position_velocity_and_jacobian_refer_to_one_point(cell: Cell) -> None:
    """During a controlled motion that turns the tool (ω up to ~2 rad/s) with a grasp
    error, the read tip velocity is the finite difference of the read tip position and
    J·q̇: all three refer to the believed tip. PyBullet's link velocity is its centre of
    mass's, 25 mm up the part: read as the tip's it is off by ω × 25 mm (tens of mm/s
    here). IK puts the believed tip at its target."""
    motion = cell.motion_for("p1")
    arm = motion.controller.arm
    tilt = np.array([0.0, 0.02, 0.0, 1.0]) / np.hypot(0.02, 1.0)
    arm.set_grasp_error(np.array([0.0008, -0.0005, 0.0003]), tilt)
    start, start_quat = np.array([0.55, 0.05, 0.2]), tool_quat(0.3)
    arm.inverse_kinematics(start, start_quat)
    reached = arm.read()
    assert np.linalg.norm(reached.tip_pos - start) < PATH_BOUND
    assert np.linalg.norm(rotation_error(start_quat, reached.tip_quat_xyzw)) < PATH_BOUND / 0.06
    motion.controller.reset()
    states = []
    for k in range(300):
        t = k * TIME_STEP
        pos = start + np.array([0.04 * np.sin(8 * t), 0.03 * np.sin(5 * t), -0.02 * t])
        states.append(motion.step(pos, tool_quat(0.3 + 0.4 * np.sin(6 * t))))
    pos = np.array([s.tip_pos for s in states])
    vel = np.array([s.tip_vel for s in states])
    omega = np.array([s.tip_omega for s in states])
    # PyBullet integrates semi-implicitly (q[k+1] = q[k] + dt q̇[k+1]): the step from state
    # k to k+1 moves with the velocity read at k+1. Measured gap 0.2 mm/s at 0.3 m/s,
    # from the curvature of the path within a step.
    finite_difference = (pos[1:] - pos[:-1]) / TIME_STEP
    assert np.abs(finite_difference - vel[1:]).max() < 1e-3  # [m/s]
    assert np.linalg.norm(omega, axis=1).max() * 0.025 > 0.02  # the COM's velocity would be off by > 20 mm/s
    # J q̇ is the same kinematics as PyBullet's link state, which differs from it by up to
    # 1e-7 m/s here (1e-15 rad/s for ω).
    jac_vel = np.array([s.jac @ s.qd for s in states])
    assert np.abs(jac_vel[:, :3] - vel).max() < 1e-6  # [m/s]
    assert np.abs(jac_vel[:, 3:] - omega).max() < 1e-9  # [rad/s]


def test_remembered_forcing_terms_give_the_rollout_of_a_fresh_dmp() -> None:
    skill = load_skill(load_geometry("cranfield").folder, "round_peg")
    goal = skill.demo_goal
    for start in (np.array([0.0, 0.0, 0.003]), np.array([0.0004, -0.0002, 0.0031]), np.array([0.0, 0.0, 0.003])):
        quat = np.array([1.0, 0.0, 0.0, 0.0])
        times, pos, quats = skill.rollout(start, quat, goal[:3], np.roll(goal[3:], -1))
        fresh = skill.make_dmp()
        fresh.configure(start_y=np.concatenate([start, xyzw_to_wxyz(quat)]), goal_y=goal)
        t_ref, y_ref = fresh.open_loop()
        assert np.array_equal(times, t_ref)
        assert np.array_equal(pos, y_ref[:, :3])
        assert np.array_equal(xyzw_to_wxyz(quats), y_ref[:, 3:])


def test_a_reset_admittance_answers_as_a_new_one() -> None:
    used = Admittance(AdmittanceParams(), yaw=True)
    for _ in range(300):
        used.update(np.array([5.0, -3.0, 1.0]), np.array([0.2, 0.1, 0.05]), 0.001)
    assert np.abs(used.offset).max() > 0
    used.reset()
    new = Admittance(AdmittanceParams(), yaw=True)
    for k in range(200):
        force, torque = np.array([np.sin(k / 9), 2.0, 0.0]), np.array([0.1, -0.1 * np.cos(k / 7), 0.3])
        assert all(np.array_equal(a, b) for a, b in zip(used.update(force, torque, 0.001),
                                                        new.update(force, torque, 0.001)))
    assert np.array_equal(used.integral, new.integral) and np.array_equal(used.velocity, new.velocity)


def test_the_detector_keeps_the_largest_sustained_deviation() -> None:
    thresholds = Thresholds(persist_steps=5)
    detector = Detector(thresholds)
    rng = np.random.default_rng(4)
    forces = rng.uniform(0.0, 40.0, 60)
    fired = []
    for f in forces:
        fired.append(detector.update(np.array([f, 0.0, 0.0]), np.zeros(3))[2])
    windows = np.lib.stride_tricks.sliding_window_view(forces, 5).min(axis=1)
    assert detector.max_force_dev == pytest.approx(windows.max(), abs=1e-12)
    assert fired[4:] == [bool(w >= thresholds.f_stop) for w in windows]
    assert not any(fired[:4])


def test_the_arm_s_ik_within_its_limits_leaves_it_as_it_was_and_the_joint_move_takes_it_there(cell: Cell) -> None:
    """:meth:`Arm.solve` for the tool pointing along +y above the plate (where the Cartesian
    turn from pointing down ends with joints 2 and 7 at their limits, docs/cell.md): a
    solution inside every limit by LIMIT_MARGIN, the tip on the pose, the arm's joints
    untouched; none for a pose 2 m out; the joint servo then takes the arm there."""
    motion = cell.motion_for("p1")
    arm = motion.controller.arm
    arm.set_grasp_error(np.zeros(3), np.array([0.0, 0.0, 0.0, 1.0]))
    arm.inverse_kinematics(np.array([0.25, 0.4, 0.2]), tool_quat(0.0))  # above a tray
    motion.controller.reset()
    before = arm.read().q
    along_y = np.array(pb.multiplyTransforms((0, 0, 0), pb.getQuaternionFromEuler((np.pi / 2, 0, 0)),
                                             (0, 0, 0), list(tool_quat(0.0)))[1])
    goal = np.array([0.56, -0.1, 0.2])
    q = arm.solve(goal, along_y, SEEDS)
    assert q is not None and np.array_equal(arm.read().q, before)
    assert np.all(q >= arm.lower + LIMIT_MARGIN) and np.all(q <= arm.upper - LIMIT_MARGIN)
    assert arm.solve(np.array([2.0, 0.0, 0.2]), along_y, SEEDS) is None
    move_joints(motion, q)
    state = arm.read()
    assert np.max(np.abs(state.q - q)) < 0.002 and np.linalg.norm(state.tip_pos - goal) < 0.002
    assert quat_to_matrix(state.tip_quat_xyzw)[:, 2] == pytest.approx([0.0, 1.0, 0.0], abs=0.01)
