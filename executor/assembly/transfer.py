"""Collision-free motions of the tool between tray and product: up to a safe height, across,
and down, each a straight line with a minimum-jerk time law, tracked by the impedance
controller (the arm and the held part are simulated all along)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from executor.control.motion import Motion
from executor.world.arm import TOOL_DOWN_QUAT_XYZW
from executor.world.scene import TIME_STEP

SAFE_Z = 0.20  # [m] TCP height for carrying: above every part standing on the plate or the tray
SPEED = 0.6  # [m/s] mean speed of a move
SETTLE = 0.08  # [s] held at the end of a move


def move_line(motion: Motion, goal: np.ndarray, after_step: Callable[[], None] | None = None,
              speed: float = SPEED, settle: float = SETTLE) -> None:
    """The TCP in a straight line to ``goal`` [m], tool pointing down."""
    start = motion.controller.arm.read().tip_pos
    distance = float(np.linalg.norm(goal - start))
    n = max(1, int(distance / speed / TIME_STEP))
    for k in range(1, n + settle_steps(settle) + 1):
        s = min(1.0, k / n)
        blend = 10 * s**3 - 15 * s**4 + 6 * s**5
        motion.step(start + blend * (goal - start), TOOL_DOWN_QUAT_XYZW)
        if after_step is not None:
            after_step()


def settle_steps(duration: float) -> int:
    return int(round(duration / TIME_STEP))


def carry(motion: Motion, goal: np.ndarray, after_step: Callable[[], None] | None = None,
          safe_z: float = SAFE_Z) -> None:
    """Lift to ``safe_z``, move across above ``goal``, go down to it [m]."""
    here = motion.controller.arm.read().tip_pos
    high = max(safe_z, float(goal[2]), float(here[2]))
    if here[2] < high - 1e-3:
        move_line(motion, np.array([here[0], here[1], high]), after_step)
    move_line(motion, np.array([goal[0], goal[1], high]), after_step)
    move_line(motion, goal, after_step)
