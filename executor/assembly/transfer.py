"""Collision-free motions of the tool between tray and product: up to a safe height, across,
and down, each a straight line with a minimum-jerk time law at a tip speed, made longer
where that would turn a joint faster than :data:`RATE_MARGIN` of its speed limit
(:func:`rate_steps`), tracked by the impedance controller (the arm and the held part are
simulated all along).  Moves use twice the
controller's damping (the insertion gains are lightly damped: a 0.5 m move rang for
about a second); the gains are restored after each move.  The tool points down, turned
about z by a yaw that a move changes with the same time law (a part aligned to a rect
hole's estimated yaw; ``Motion.tool_yaw`` is where it stands); down a hole's frame when
the motion has one (a hole entered sideways), :func:`reorient` turning it there and back
(where that turn ends the arm short, a move in joint space at the carrying height after it,
whose tool path is not a line)."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import TypeVar

import msgspec
import numpy as np
import pybullet as pb

from executor.control.controller import ImpedanceController
from executor.control.motion import Motion
from executor.world.arm import LIMIT_MARGIN, REST_POSTURE, Arm, rotation_error, tool_quat
from executor.world.frames import HoleFrame
from executor.world.scene import TIME_STEP

DAMPING_FACTOR = 2.0
SAFE_Z = 0.20  # [m] TCP height for carrying: above every part standing on the plate or the tray
SPEED = 0.5  # [m/s] mean speed of a move
DESCENT_SPEED = 0.15  # [m/s] mean speed of the last move of a carry, down to the goal
DESCENT_CLEARANCE = 0.03
"""[m] a carry goes down at :data:`SPEED` to this far above its goal, only the rest at
:data:`DESCENT_SPEED` (nothing stands between the carrying height and there)."""
SETTLE = 0.5  # [s] at most held at the end of a move, until the TCP is within its tolerance at rest
TOLERANCE = 0.001  # [m] where the part is to be placed
VIA_TOLERANCE = 0.01  # [m] at the corners of a carry
TURN_TOLERANCE = 0.15  # [rad] of the tool's orientation where :func:`reorient` ends (it lags the turn by up to 0.07)
SEEDS = [REST_POSTURE, *(REST_POSTURE + np.array([0.0] * 6 + [roll]) for roll in (-np.pi / 2, np.pi / 2))]
"""Where :func:`reorient`'s IK starts, in turn: the arm's rest posture, the wrist rolled a quarter turn each way."""
JOINT_SPEED = 0.8  # [rad/s] mean rate of the farthest-turning joint in a joint-space move
RATE_MARGIN = 0.85
"""A move's planned joint rates stay within this fraction of each joint's speed limit
(:attr:`executor.world.arm.Arm.rate_limit`): room for the controller's tracking, which
the plan does not model."""
RATE_SAMPLES = 8  # stretches of a Cartesian move over which its joint rates are planned
PEAK_RATE = 1.875  # the minimum-jerk law's peak rate, in units of the move's mean (at its middle)
T = TypeVar("T", float, np.ndarray)


def move_line(motion: Motion, goal: np.ndarray, after_step: Callable[[], None] | None = None,
              speed: float = SPEED, settle: float = SETTLE, tolerance: float = TOLERANCE,
              yaw: float | None = None) -> None:
    """The TCP in a straight line to ``goal`` [m], tool pointing down and turning to ``yaw``
    [rad] (None: keeping its yaw); then held until it is within ``tolerance`` [m] at rest
    (speed below ``tolerance`` per 0.1 s), or ``settle`` [s] has passed."""
    yaw0, yaw1 = motion.tool_yaw, motion.tool_yaw if yaw is None else yaw
    _damped(motion, goal, after_step, speed, settle, tolerance, lambda blend: tool_quat(yaw0 + blend * (yaw1 - yaw0)))
    motion.tool_yaw = yaw1


def reorient(motion: Motion[ImpedanceController], goal: np.ndarray, frame: HoleFrame | None, yaw: float,
             after_step: Callable[[], None] | None = None) -> None:
    """The TCP in a straight line to ``goal`` [m, cell frame] while the tool turns from
    pointing down its motion's frame to pointing down ``frame`` (None: the cell's), turned
    by ``yaw`` [rad] (spherical interpolation, the same time law); the motion then moves
    in ``frame``. Carries a part to a hole entered sideways and back. Where that line ends
    the arm short of the pose or near a joint's limit (:func:`_stuck`: the turn, under the
    Cartesian controller, takes the arm through its joints' limits on a long path), the arm
    then moves in joint space (:func:`move_joints`) to a solution of its IK for the pose
    (:meth:`executor.world.arm.Arm.solve` from :data:`SEEDS`), from which the moves
    in ``frame`` start."""
    start = motion.cell_pose(np.zeros(3), tool_quat(motion.tool_yaw))[1]
    end = tool_quat(yaw) if frame is None else frame.pose_to_cell(np.zeros(3), tool_quat(yaw))[1]
    motion.frame = None
    _damped(motion, goal, after_step, SPEED, SETTLE, VIA_TOLERANCE,
            lambda blend: np.array(pb.getQuaternionSlerp(list(start), list(end), blend)))
    arm = motion.controller.arm
    if _stuck(motion, goal, end) and (q := arm.solve(goal, end, SEEDS)) is not None:
        move_joints(motion, q, after_step)
    motion.frame, motion.tool_yaw = frame, yaw


def _stuck(motion: Motion[ImpedanceController], goal: np.ndarray, quat_xyzw: np.ndarray) -> bool:
    """Whether the arm rests more than :data:`VIA_TOLERANCE` [m] or :data:`TURN_TOLERANCE`
    [rad] from the pose (cell frame), or a joint within :data:`executor.world.arm.LIMIT_MARGIN`
    of its limit."""
    arm = motion.controller.arm
    state = arm.read()
    near_limit = np.any(state.q < arm.lower + LIMIT_MARGIN) or np.any(state.q > arm.upper - LIMIT_MARGIN)
    return bool(near_limit or np.linalg.norm(state.tip_pos - goal) > VIA_TOLERANCE
                or np.linalg.norm(rotation_error(quat_xyzw, state.tip_quat_xyzw)) > TURN_TOLERANCE)


def move_joints(motion: Motion[ImpedanceController], q_goal: np.ndarray,
                after_step: Callable[[], None] | None = None) -> None:
    """The arm's joints from where they are to ``q_goal`` [rad] with the minimum-jerk time
    law, the farthest turning at :data:`JOINT_SPEED` on average, under the joint servo
    (:meth:`executor.control.controller.ImpedanceController.step_joints`); then held until
    at rest there (each joint within 1 mrad, slower than 10 mrad/s), or :data:`SETTLE` [s]
    has passed. For free space only: the tool's path is not a line."""
    arm = motion.controller.arm
    q0 = arm.read().q
    span = q_goal - q0
    n = max(1, int(float(np.max(np.abs(span))) / JOINT_SPEED / TIME_STEP),
            math.ceil(float(np.max(PEAK_RATE * np.abs(span) / (RATE_MARGIN * arm.rate_limit))) / TIME_STEP))
    observer = motion.observer
    if observer is not None:
        observer.begin("joint")
    for k in range(1, n + settle_steps(SETTLE) + 1):
        blend, rate = minimum_jerk(min(1.0, k / n))
        state = motion.controller.step_joints(q0 + blend * span, (rate / (n * TIME_STEP) if k < n else 0.0) * span)
        motion.steps += 1
        if after_step is not None:
            after_step()
        if observer is not None:
            observer.step()
        if k >= n and np.max(np.abs(state.q - q_goal)) < 1e-3 and np.max(np.abs(state.qd)) < 1e-2:
            break
    if observer is not None:
        observer.end()


def _damped(motion: Motion, goal: np.ndarray, after_step: Callable[[], None] | None, speed: float, settle: float,
            tolerance: float, turn: Callable[[float], np.ndarray]) -> None:
    """:func:`_track` with the controller's damping raised by :data:`DAMPING_FACTOR`."""
    controller = motion.controller
    gains = controller.gains
    controller.gains = msgspec.structs.replace(gains, d_trans=DAMPING_FACTOR * gains.d_trans,
                                               d_rot=DAMPING_FACTOR * gains.d_rot)
    try:
        _track(motion, goal, after_step, speed, settle, tolerance, turn)
    finally:
        controller.gains = gains


def _track(motion: Motion, goal: np.ndarray, after_step: Callable[[], None] | None, speed: float, settle: float,
           tolerance: float, turn: Callable[[float], np.ndarray]) -> None:
    """The TCP from where it is to ``goal`` [m] along a line, the tool at ``turn(blend)``
    (a quaternion xyzw) as the minimum-jerk blend goes from 0 to 1, then held (:func:`move_line`).
    The move takes its distance at the mean ``speed`` [m/s], or longer where the joint rates
    that asks would go beyond :data:`RATE_MARGIN` of their limits (:func:`rate_steps`)."""
    start = motion.read().tip_pos
    distance = float(np.linalg.norm(goal - start))

    def line(blends: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        poses = [motion.cell_pose(start + blend * (goal - start), turn(blend)) for blend in blends]
        return np.array([p[0] for p in poses]), np.array([p[1] for p in poses])

    n = max(1, int(distance / speed / TIME_STEP), rate_steps(motion.controller.arm, line))
    observer = motion.observer
    if observer is not None:
        observer.begin("descent" if speed == DESCENT_SPEED else "line")
    for k in range(1, n + settle_steps(settle) + 1):
        blend = minimum_jerk(min(1.0, k / n))[0]
        state = motion.step(start + blend * (goal - start), turn(blend))
        if after_step is not None:
            after_step()
        if observer is not None:
            observer.step()
        at_rest = np.linalg.norm(state.tip_vel) < 10 * tolerance
        if k >= n and at_rest and np.linalg.norm(state.tip_pos - goal) < tolerance:
            break
    if observer is not None:
        observer.end()


def rate_steps(arm: Arm, line: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]) -> int:
    """The fewest control steps in which a minimum-jerk move along ``line`` (the tip's
    positions [m] and orientations (xyzw) at an array of blends, cell frame) asks every
    joint at most :data:`RATE_MARGIN` of its limit: the arm's postures along it
    (:meth:`executor.world.arm.Arm.posture_path`) at :data:`RATE_SAMPLES` + 1 evenly spaced
    blends; each joint's change between two of them, per unit of blend, times the law's
    fastest blend rate between them (:data:`PEAK_RATE` where they straddle the middle).
    Every rate scales as the inverse of the move's duration."""
    blends = np.linspace(0.0, 1.0, RATE_SAMPLES + 1)
    path = arm.posture_path(*line(blends))
    law, law_rate = minimum_jerk(np.linspace(0.0, 1.0, 1001))
    fastest = np.array([law_rate[np.searchsorted(law, min(max(0.5, a), b))] for a, b in zip(blends, blends[1:])])
    per_blend = np.abs(np.diff(path, axis=0)) * RATE_SAMPLES
    peak = float(np.max(per_blend * fastest[:, None] / arm.rate_limit))  # the move in 1 s
    return math.ceil(peak / RATE_MARGIN / TIME_STEP)


def freest_yaw(motion: Motion, points: np.ndarray, yaws: Sequence[float]) -> float:
    """The tool yaw [rad] among ``yaws`` (cell frame, the tool pointing down) with which the
    arm, going from where it is through ``points`` (n × 3 [m], cell frame) in straight lines,
    its tool turning from :attr:`Motion.tool_yaw` to that yaw over the first and keeping it
    after, keeps its joints farthest inside their limits: its postures
    (:meth:`executor.world.arm.Arm.posture_path`) at :data:`RATE_SAMPLES` + 1 evenly spaced
    points of each line, the largest smallest room of a joint from its nearer limit over
    them, then the next smallest (rooms to 1 mrad; the first of ``yaws`` on a tie). A yaw
    and that yaw plus a whole turn are the same pose reached by opposite turns of the wrist."""
    arm = motion.controller.arm
    legs = [motion.read().tip_pos, *points]
    blends = np.linspace(0.0, 1.0, RATE_SAMPLES + 1)
    tips = np.concatenate([a + blends[:, None] * (b - a) for a, b in zip(legs, legs[1:])])

    def rooms(yaw: float) -> tuple[float, ...]:
        turn = motion.tool_yaw + np.concatenate([blends * (yaw - motion.tool_yaw), np.full(len(tips) - len(blends), yaw
                                                                                             - motion.tool_yaw)])
        path = arm.posture_path(tips, np.array([tool_quat(t) for t in turn]))
        room = np.min(np.minimum(path - arm.lower, arm.upper - path), axis=0)
        return tuple(np.round(np.sort(room), 3))

    return max(yaws, key=rooms)


def minimum_jerk(s: T) -> tuple[T, T]:
    """The minimum-jerk law at ``s``, the fraction of the move's duration gone (0 to 1; a
    number or an array): the blend (0 to 1) and its rate per unit of ``s``."""
    return 10 * s**3 - 15 * s**4 + 6 * s**5, 30 * s**2 * (1 - s) ** 2


def settle_steps(duration: float) -> int:
    return int(round(duration / TIME_STEP))


def carry(motion: Motion, goal: np.ndarray, after_step: Callable[[], None] | None = None,
          safe_z: float = SAFE_Z, tolerance: float = TOLERANCE, yaw: float = 0.0) -> None:
    """Lift to ``safe_z``, move across above ``goal`` turning the tool to ``yaw`` [rad], go
    down to :data:`DESCENT_CLEARANCE` above it, then down to it [m] (slowly, until within
    ``tolerance`` [m])."""
    here = motion.read().tip_pos
    high = max(safe_z, float(goal[2]), float(here[2]))
    if here[2] < high - 1e-3:
        move_line(motion, np.array([here[0], here[1], high]), after_step, tolerance=VIA_TOLERANCE)
    move_line(motion, np.array([goal[0], goal[1], high]), after_step, tolerance=VIA_TOLERANCE, yaw=yaw)
    if high - goal[2] > DESCENT_CLEARANCE + 1e-3:
        move_line(motion, goal + np.array([0.0, 0.0, DESCENT_CLEARANCE]), after_step, tolerance=VIA_TOLERANCE)
    move_line(motion, goal, after_step, speed=DESCENT_SPEED, tolerance=tolerance)
