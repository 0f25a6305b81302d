"""Collision-free motions of the tool between tray and product: up to a safe height, across,
and down, each a straight line with a minimum-jerk time law, tracked by the impedance
controller (the arm and the held part are simulated all along).  Moves use twice the
controller's damping (the insertion gains are lightly damped: a 0.5 m move rang for
about a second); the gains are restored after each move.  The tool points down, turned
about z by a yaw that a move changes with the same time law (a part aligned to a rect
hole's estimated yaw; ``Motion.tool_yaw`` is where it stands); down a hole's frame when
the motion has one (a hole entered sideways), :func:`reorient` turning it there and back."""

from __future__ import annotations

from collections.abc import Callable

import msgspec
import numpy as np
import pybullet as pb

from executor.control.motion import Motion
from executor.world.arm import tool_quat
from executor.world.frames import HoleFrame
from executor.world.scene import TIME_STEP

DAMPING_FACTOR = 2.0
SAFE_Z = 0.20  # [m] TCP height for carrying: above every part standing on the plate or the tray
SPEED = 0.5  # [m/s] mean speed of a move
DESCENT_SPEED = 0.15  # [m/s] mean speed of the last move of a carry, down to the goal
SETTLE = 0.5  # [s] at most held at the end of a move, until the TCP is within its tolerance at rest
TOLERANCE = 0.001  # [m] where the part is to be placed
VIA_TOLERANCE = 0.01  # [m] at the corners of a carry


def move_line(motion: Motion, goal: np.ndarray, after_step: Callable[[], None] | None = None,
              speed: float = SPEED, settle: float = SETTLE, tolerance: float = TOLERANCE,
              yaw: float | None = None) -> None:
    """The TCP in a straight line to ``goal`` [m], tool pointing down and turning to ``yaw``
    [rad] (None: keeping its yaw); then held until it is within ``tolerance`` [m] at rest
    (speed below ``tolerance`` per 0.1 s), or ``settle`` [s] has passed."""
    yaw0, yaw1 = motion.tool_yaw, motion.tool_yaw if yaw is None else yaw

    def turn(blend: float) -> np.ndarray:
        motion.tool_yaw = yaw0 + blend * (yaw1 - yaw0)
        return tool_quat(motion.tool_yaw)

    _damped(motion, goal, after_step, speed, settle, tolerance, turn)


def reorient(motion: Motion, goal: np.ndarray, frame: HoleFrame | None, yaw: float,
             after_step: Callable[[], None] | None = None) -> None:
    """The TCP in a straight line to ``goal`` [m, cell frame] while the tool turns from
    pointing down its motion's frame to pointing down ``frame`` (None: the cell's), turned
    by ``yaw`` [rad] (spherical interpolation, the same time law); the motion then moves
    in ``frame``. Carries a part to a hole entered sideways and back."""
    start = motion.cell_pose(np.zeros(3), tool_quat(motion.tool_yaw))[1]
    end = tool_quat(yaw) if frame is None else frame.pose_to_cell(np.zeros(3), tool_quat(yaw))[1]
    motion.frame = None
    _damped(motion, goal, after_step, SPEED, SETTLE, VIA_TOLERANCE,
            lambda blend: np.array(pb.getQuaternionSlerp(list(start), list(end), blend)))
    motion.frame, motion.tool_yaw = frame, yaw


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
    (a quaternion xyzw) as the minimum-jerk blend goes from 0 to 1, then held (:func:`move_line`)."""
    start = motion.read().tip_pos
    distance = float(np.linalg.norm(goal - start))
    n = max(1, int(distance / speed / TIME_STEP))
    for k in range(1, n + settle_steps(settle) + 1):
        s = min(1.0, k / n)
        blend = 10 * s**3 - 15 * s**4 + 6 * s**5
        state = motion.step(start + blend * (goal - start), turn(blend))
        if after_step is not None:
            after_step()
        at_rest = np.linalg.norm(state.tip_vel) < 10 * tolerance
        if k >= n and at_rest and np.linalg.norm(state.tip_pos - goal) < tolerance:
            break


def settle_steps(duration: float) -> int:
    return int(round(duration / TIME_STEP))


def carry(motion: Motion, goal: np.ndarray, after_step: Callable[[], None] | None = None,
          safe_z: float = SAFE_Z, tolerance: float = TOLERANCE, yaw: float = 0.0) -> None:
    """Lift to ``safe_z``, move across above ``goal`` turning the tool to ``yaw`` [rad], go
    down to it [m] (slowly, until within ``tolerance`` [m])."""
    here = motion.read().tip_pos
    high = max(safe_z, float(goal[2]), float(here[2]))
    if here[2] < high - 1e-3:
        move_line(motion, np.array([here[0], here[1], high]), after_step, tolerance=VIA_TOLERANCE)
    move_line(motion, np.array([goal[0], goal[1], high]), after_step, tolerance=VIA_TOLERANCE, yaw=yaw)
    move_line(motion, goal, after_step, speed=DESCENT_SPEED, tolerance=tolerance)
