"""Teaching on the arm (``executor teach --backend franka``): the scripted demonstration of
:mod:`executor.skills.teach` run by the Franka (a part picked from the table by the hand,
guided along the same minimum-jerk path down its ``demo_hole``, replayed to record the
reference wrench from the arm's estimate), stored as the PyBullet cell's skills are; or,
with ``--demonstration hand``, a person's demonstration by hand-guiding
(:mod:`executor.franka.guide`) in place of the scripted path (docs/franka.md, "Teaching")."""

from __future__ import annotations

import numpy as np

from executor import ExecutorError
from executor.control.motion import APPROACH_SETTLE_TIME, Motion
from executor.franka.cell import FrankaCell

ABOVE_START = 0.02  # [m] the part comes down onto the start from this far above
SAME_PLACE = 0.005  # [m] a start this close (horizontally) is reached without the carrying height


class FrankaTeacher:
    """A :class:`executor.skills.teach.TeachingCell` on a :class:`FrankaCell`."""

    def __init__(self, cell: FrankaCell) -> None:
        self.cell = cell
        self.geometry = cell.geometry
        self.thresholds = cell.description.thresholds

    def motion_for(self, part: str) -> Motion:
        """The part picked from its place on the table (one put back first)."""
        if self.cell.held != part:
            self.cell.put_back()
            self.cell.pick(part)
        return self.cell.motion

    def hold_at(self, motion: Motion, tip: np.ndarray, quat_xyzw: np.ndarray) -> None:
        """Above the start, straight down onto it, settled, the wrench tared: the
        grasp is the one the hand made (the real one, not known to the robot)."""
        cell = self.cell
        if motion.frame is not None:
            raise ExecutorError("a hole entered sideways: the Franka backend teaches and inserts down (-z) only")
        above = tip + np.array([0.0, 0.0, ABOVE_START])
        here = cell.arm.read().tip_pos
        yaw = float(2 * np.arctan2(quat_xyzw[1], quat_xyzw[0]))  # of tool_quat(yaw)
        if np.linalg.norm(here[:2] - tip[:2]) > SAME_PLACE:
            cell.carry_to(above, yaw=yaw)
        else:
            cell.move_to(above, yaw)
        cell.move_to(tip)
        motion.hold(tip, quat_xyzw, APPROACH_SETTLE_TIME)
        cell.arm.tare_sensor()

    def let_go(self) -> None:
        """Out of the hole and back to its place on the table."""
        self.cell.lift()
        self.cell.put_back()
