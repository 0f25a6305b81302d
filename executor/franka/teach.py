"""Teaching on the arm (``executor teach --backend franka``): the scripted demonstration of
:mod:`executor.skills.teach` run by the Franka (a part picked from the table by the hand,
its ``demo_hole`` found by the insertion's hole search, the part guided along the same
minimum-jerk path down it, replayed to record the reference wrench from the arm's
estimate), stored as the PyBullet cell's skills are (into a hole entered sideways all of it
in the hole's frame, as :meth:`FrankaCell.insert`); or,
with ``--demonstration hand``, a person's demonstration by hand-guiding
(:mod:`executor.franka.guide`) in place of the scripted path (docs/franka.md, "Teaching")."""

from __future__ import annotations

import numpy as np

from executor import ExecutorError
from executor.control.motion import APPROACH_SETTLE_TIME, Motion
from executor.franka.cell import FrankaCell

ABOVE_START = 0.02  # [m] the part comes down onto the start from this far above
SAME_PLACE = 0.005  # [m] a start this close (horizontally) is reached without the carrying height
SEARCH_SEED = 0  # the hole search's spiral draws in teaching (a trial's seed draws them in an insertion)


class FrankaTeacher:
    """A :class:`executor.skills.teach.TeachingCell` on a :class:`FrankaCell`."""

    def __init__(self, cell: FrankaCell) -> None:
        self.cell = cell
        self.geometry = cell.geometry
        self.thresholds = cell.description.thresholds
        self.rng = np.random.default_rng(SEARCH_SEED)

    def motion_for(self, part: str) -> Motion:
        """The part picked from its place on the table (one put back first)."""
        if self.cell.held != part:
            self.cell.put_back()
            self.cell.pick(part)
        return self.cell.motion

    def find_hole(self, motion: Motion, origin: np.ndarray, quat_xyzw: np.ndarray) -> np.ndarray:
        """The held part over the hole's calibrated entry ``origin`` [m], the insertion's hole
        search (:meth:`FrankaCell.search`): the entry where the part sank into the hole, in
        the robot's reading of the tip (a grasp or calibration error of 2 mm puts a part
        brought straight down onto the calibrated entry on the plate beside the hole).
        ExecutorError when the search finds no hole. ``origin``, ``quat_xyzw`` and the entry
        returned are in the motion's frame (the hole's)."""
        found = self.cell.search(origin, quat_xyzw, self.rng)
        if not found.found:
            radius = self.cell.description.search.max_radius
            raise ExecutorError(f"the hole search found no hole within {radius * 1000:.1f} mm of "
                                f"{np.round(origin, 4).tolist()} m (the held part's demo_hole); expected the plate "
                                "where geometry.toml puts it and the part in the hand (docs/franka.md, Set-up)")
        return np.array([found.hole_xy[0], found.hole_xy[1], origin[2]])

    def hold_at(self, motion: Motion, tip: np.ndarray, quat_xyzw: np.ndarray) -> None:
        """Above the start (in the motion's frame: out of it along a sideways hole's axis),
        straight down onto it, settled, the wrench tared: the grasp is the one the hand
        made (the real one, not known to the robot)."""
        cell = self.cell
        above = tip + np.array([0.0, 0.0, ABOVE_START])
        here = motion.read().tip_pos
        if np.linalg.norm(here[:2] - tip[:2]) > SAME_PLACE:
            cell.enter(above, quat_xyzw)
        else:
            cell.move_to(*motion.cell_pose(above, quat_xyzw))
        cell.move_to(motion.cell_pose(tip, quat_xyzw)[0])
        motion.hold(tip, quat_xyzw, APPROACH_SETTLE_TIME)
        cell.arm.tare_sensor()

    def let_go(self) -> None:
        """Out of the hole and back to its place on the table."""
        self.cell.lift()
        self.cell.put_back()
