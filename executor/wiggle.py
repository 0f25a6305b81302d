"""Exception strategy on jamming (paper 3.2): shake the part like a human would.

Around each of the three tool axes in turn, one 2 Hz period (0.5 s) of a sinusoidal
10 N force along the axis together with the torque of that force at the part's rim
(10 N × radius) about the axis, on top of the impedance holding the interrupted pose.
Then the insertion continues.
"""

from __future__ import annotations

import math

import numpy as np

from executor.arm import quat_to_matrix
from executor.motion import Motion
from executor.scene import TIME_STEP

AMPLITUDE = 10.0  # [N]
FREQUENCY = 2.0  # [Hz]


def wiggle(motion: Motion, pos: np.ndarray, quat_xyzw: np.ndarray, rim_radius: float, phase: float,
           wrench_des: np.ndarray) -> None:
    """Shake about each tool axis while holding the pose (tip [m], quaternion xyzw)."""
    axes = quat_to_matrix(quat_xyzw)
    n = int(round(1.0 / FREQUENCY / TIME_STEP))
    for axis in axes.T:
        for k in range(n):
            amp = AMPLITUDE * math.sin(2 * math.pi * FREQUENCY * k * TIME_STEP)
            ff = np.concatenate([amp * axis, amp * rim_radius * axis])
            motion.step(pos, quat_xyzw, ff, phase=phase, wrench_des=wrench_des)
