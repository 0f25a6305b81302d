"""Exception strategy on jamming (paper 3.2): shake the part like a human would.

Along each of the three tool axes in turn, one 2 Hz period (0.5 s) of a sinusoidal
10 N force applied at the gripper (``lever`` [m] above the tip on the tool axis, so the
lateral forces also rock the part about the tip), on top of the impedance holding the
interrupted pose.  Then the insertion continues.
"""

from __future__ import annotations

import math

import numpy as np

from executor.control.motion import Motion
from executor.world.arm import cross, quat_to_matrix
from executor.world.scene import TIME_STEP

AMPLITUDE = 10.0  # [N]
FREQUENCY = 2.0  # [Hz]


def wiggle(motion: Motion, pos: np.ndarray, quat_xyzw: np.ndarray, lever: float, phase: float,
           wrench_des: np.ndarray) -> None:
    """Shake along each tool axis while holding the pose (tip [m], quaternion xyzw)."""
    axes = quat_to_matrix(quat_xyzw)
    arm = -lever * axes[:, 2]  # from the tip to the gripper [m]
    n = int(round(1.0 / FREQUENCY / TIME_STEP))
    for axis in axes.T:
        for k in range(n):
            force = AMPLITUDE * math.sin(2 * math.pi * FREQUENCY * k * TIME_STEP) * axis
            motion.step(pos, quat_xyzw, np.concatenate([force, cross(arm, force)]), phase=phase,
                        wrench_des=wrench_des)
