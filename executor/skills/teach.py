"""Scripted kinesthetic teaching (paper 3.1), one skill per part shape.

Step 1, the demonstration: a "human" guides the tip along a minimum-jerk path (0.8 s,
longer for a travel over 40 mm: :data:`DEMO_SPEED`) from 2 mm inside the entrance of the
shape's ``demo_hole`` (where the hole search leaves the part; exactly aligned, the part
turned to the hole's yaw, perfect grasp) down to 0.5 mm above the hole's bottom (in a
hole entered sideways, down its frame's z axis to its depth, where the CAD has the
part's tip: :mod:`executor.world.frames`); the tip poses are recorded at 1 kHz and
encoded as a Cartesian DMP. On an arm, whose grasp and plate calibration carry real
errors, the hole is first found with the held part by the insertion's hole search
(:meth:`TeachingCell.find_hole`), and the demonstration and the replay run in the hole
frame there. Step 2, the replay: the DMP is executed by the impedance
controller alone and the wrench it meets is recorded: the reference F_des, M_des, fitted
with RBFs over the phase; the tip position where the replay ends is p_goal. Step 3, the
check: p_goal must lie within the cell's goal tolerance of the demonstration's goal (0.5
mm above the bottom); a part that does not pass its ``demo_hole`` stops on the entry
instead, and its teaching is refused (ExecutorError naming the part, the hole and the
end error), no skill written. The skill records what it was taught on
(:class:`executor.skills.dmp.TaughtOn`).

Poses, wrenches and p_goal are stored in the hole's frame (its
origin at the centre of the hole's entry, at the hole's own height, turned by the hole's
yaw), so the skill runs in a hole of any yaw and at any height; in a hole of another depth
its goal moves with the bottom, by the depth its record gives
(:meth:`executor.skills.dmp.Skill.in_hole`).
``./run.sh executor teach`` rebuilds ``data/<assembly>/demonstrations/<shape>.json``: every
shape (or those of ``--shapes``, the other shapes' files kept) is taught first, and the
files are written only when all were taught.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

import numpy as np

from executor import ExecutorError
from executor.control.detector import Thresholds
from executor.control.motion import APPROACH_SETTLE_TIME, Motion
from executor.skills.dmp import (
    PhaseClock,
    Skill,
    TaughtOn,
    WrenchProfile,
    fit_dmp,
    save_skill,
    xyzw_to_wxyz,
)
from executor.world.arm import tool_quat, turn_quats_z, turn_z
from executor.world.assets import regenerate_assets
from executor.world.frames import aligned_yaw
from executor.world.geometry import CellGeometry, fit_pose
from executor.world.scene import TIME_STEP

DEMO_DURATION = 0.8  # [s], or longer for a travel longer than DEMO_SPEED allows in it
DEMO_SPEED = 0.05
"""The demonstration's largest mean speed [m/s]: a deep insertion (a part going down a
150 mm pin) takes travel / DEMO_SPEED, so the compliant arm follows it (at 0.19 m/s it
ended 6.8 mm short); a hole up to 40 mm deep keeps DEMO_DURATION."""
DEMO_START_HEIGHT = -0.002  # [m] relative to the plate top: the search leaves the tip ~2 mm in the hole
DEMO_CLEARANCE = 0.0005  # [m] left between the part and the hole bottom at the end


class TeachingCell(Protocol):
    """What teaching needs of a cell (:class:`executor.trial.Cell` and
    :class:`executor.franka.teach.FrankaTeacher` are ones): its geometry and thresholds, a
    part put in the hand (:meth:`motion_for`), the hole found with it (:meth:`find_hole`),
    held at the demonstration's start (:meth:`hold_at`) and let go at the end
    (:meth:`let_go`)."""

    geometry: CellGeometry
    thresholds: Thresholds

    def motion_for(self, part: str) -> Motion:
        """Put the part in the hand; the Motion driving the arm that holds it."""
        ...

    def find_hole(self, motion: Motion, origin: np.ndarray, quat_xyzw: np.ndarray) -> np.ndarray:
        """The hole frame's origin [m] (the centre of the hole's entry) where the held
        part, turned to ``quat_xyzw``, finds the hole whose geometry puts it at ``origin``:
        ``origin`` itself in a simulated cell (the part exactly in the hand), where the hole
        search finds it on an arm (the real grasp and calibration errors). ExecutorError
        when no hole is found."""
        ...

    def hold_at(self, motion: Motion, tip: np.ndarray, quat_xyzw: np.ndarray) -> None:
        """The held part's tip at rest at ``tip`` [m] turned to ``quat_xyzw``, with the
        grasp taken as exact and the teaching friction, and the wrench tared there."""
        ...

    def let_go(self) -> None:
        """The part out of the hand (back where it waits)."""
        ...


@dataclass(frozen=True)
class Demonstration:
    """A demonstrated insertion: ``times`` [s] from 0 in steps of TIME_STEP, the tip's
    ``positions`` [m] and quaternions ``quats`` (xyzw) in the hole frame (turned by the
    hole's yaw), and ``start`` [m], the tip position (cell frame) the replay starts from."""

    times: np.ndarray
    positions: np.ndarray
    quats: np.ndarray
    start: np.ndarray


Demonstrator = Callable[[TeachingCell, Motion, np.ndarray, float, float], Demonstration]
"""Demonstrates an insertion with the part in the hand: (cell, motion, the hole frame's
origin [m], the depth of the demonstration's end below it [m] before the clearance, the
hole's yaw [rad]) → the :class:`Demonstration`. :func:`scripted_demonstration` is the
cell's; :class:`executor.franka.guide.HandGuiding` records a human's."""


def _min_jerk(s: np.ndarray) -> np.ndarray:
    return 10 * s**3 - 15 * s**4 + 6 * s**5


def _demonstrate(motion: Motion, origin: np.ndarray, bottom: float,
                 yaw: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Guide the tip down into the hole, the tool turned by ``yaw`` [rad] (the hole's);
    returns recorded times [s], positions [m] and quaternions (xyzw) in the hole frame
    (turned by ``yaw``)."""
    quat = tool_quat(yaw)
    travel = bottom - DEMO_CLEARANCE + DEMO_START_HEIGHT
    n = int(round(max(DEMO_DURATION, travel / DEMO_SPEED) / TIME_STEP))
    z = DEMO_START_HEIGHT + (-(bottom - DEMO_CLEARANCE) - DEMO_START_HEIGHT) * _min_jerk(np.linspace(0, 1, n))
    times, positions, quats = [], [], []
    for k in range(n):
        s = motion.step(origin + np.array([0.0, 0.0, z[k]]), quat)
        times.append(k * TIME_STEP)
        positions.append(turn_z(s.tip_pos - origin, -yaw))
        quats.append(turn_quats_z(s.tip_quat_xyzw, -yaw))
    return np.array(times), np.array(positions), np.array(quats)


def scripted_demonstration(cell: TeachingCell, motion: Motion, origin: np.ndarray, bottom: float,
                           yaw: float) -> Demonstration:
    """The scripted "human" (module docstring): held at 2 mm inside the entrance, guided
    along the minimum-jerk path to :data:`DEMO_CLEARANCE` above ``bottom`` [m]."""
    start = origin + np.array([0.0, 0.0, DEMO_START_HEIGHT])
    cell.hold_at(motion, start, tool_quat(yaw))
    return Demonstration(*_demonstrate(motion, origin, bottom, yaw), start)


def _replay(motion: Motion, skill: Skill, origin: np.ndarray,
            yaw: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Run the DMP without adaptation in the hole frame turned by ``yaw`` [rad]; returns
    phases, wrenches (N, 6) [N, Nm] and the end position [m], in the hole frame."""
    times, pos, quats = skill.rollout(skill.demo_start[:3], np.roll(skill.demo_start[3:], -1),
                                      skill.demo_goal[:3], np.roll(skill.demo_goal[3:], -1))
    clock = PhaseClock(times, turn_z(pos, yaw) + origin, turn_quats_z(quats, yaw), f_slow=1.0)
    phases, wrenches = [], []
    while not clock.done:
        p, q = clock.pose()
        s = motion.step(p, q, phase=clock.phase)
        phases.append(clock.phase)
        wrenches.append(np.concatenate([turn_z(s.force, -yaw), turn_z(s.torque, -yaw)]))
        clock.advance(TIME_STEP, 0.0)
    p, q = clock.pose()
    end = motion.hold(p, q, APPROACH_SETTLE_TIME)
    return np.array(phases), np.array(wrenches), turn_z(end.tip_pos - origin, -yaw)


def teach_shape(cell: TeachingCell, shape: str, demonstrate: Demonstrator = scripted_demonstration) -> Skill:
    """Demonstrate (``demonstrate``), encode and replay the skill of one part shape in its
    ``demo_hole``; ExecutorError naming the part, the hole and the end error when the
    replay ends farther than the cell's goal tolerance from the demonstration's goal."""
    geometry = cell.geometry
    part = next(p for pid, p in sorted(geometry.parts.items()) if p.shape == shape)
    hole = geometry.holes[part.demo_hole]
    turn, shift = fit_pose(part, hole)
    origin = np.array([*(np.array(hole.position) + shift), hole.top_z])
    # into a hole entered sideways the depth is where the CAD has the part's tip (nothing stops
    # it in a through hole); a part onto a pin rests against what its depth reaches, whatever its axis
    bottom = hole.depth + (DEMO_CLEARANCE if hole.sideways and not hole.pin else 0.0)
    motion = cell.motion_for(part.id)
    yaw = aligned_yaw(part.kind, hole.kind, hole.yaw + turn)
    motion.frame = hole.frame  # a hole entered sideways: demonstrated and replayed down its frame's z axis
    try:
        origin = cell.find_hole(motion, origin, tool_quat(yaw))
        demo = demonstrate(cell, motion, origin, bottom, yaw)
        weights = fit_dmp(demo.times, demo.positions, demo.quats)
        skill = Skill(shape, float(demo.times[-1]), weights,
                      np.concatenate([demo.positions[0], xyzw_to_wxyz(demo.quats[0])]),
                      np.concatenate([demo.positions[-1], xyzw_to_wxyz(demo.quats[-1])]),
                      np.zeros(3), WrenchProfile.fit(np.zeros(1), np.zeros((1, 6))))
        cell.hold_at(motion, demo.start, tool_quat(yaw))
        phases, wrenches, end = _replay(motion, skill, origin, yaw)
    finally:
        motion.frame = None
    skill.wrench = WrenchProfile.fit(phases, wrenches)
    skill.end_position = end
    cell.let_go()
    goal = np.array([0.0, 0.0, -(bottom - DEMO_CLEARANCE)])
    skill.taught = TaughtOn(part.id, part.kind, part.sides, hole.id, hole.kind, hole.sides, hole.depth,
                            float(np.linalg.norm(end - goal)), cell.thresholds.goal_tolerance)
    if not skill.taught.reached:
        raise ExecutorError(f"teaching {shape} failed: {skill.taught.failure()} (the part does not reach the "
                            f"bottom of its demo_hole; expected a hole it passes); no skill written")
    return skill


def chosen_shapes(geometry: CellGeometry, names: Sequence[str] | None) -> list[str]:
    """The part shapes to teach, sorted: ``names`` (``executor teach --shapes``), or every
    shape of the product when None; ExecutorError naming geometry.toml, the unknown names
    and the product's shapes when one is not a part shape of it."""
    shapes = sorted({p.shape for p in geometry.parts.values()})
    if names is None:
        return shapes
    unknown = sorted(set(names) - set(shapes))
    if unknown:
        raise ExecutorError(f"--shapes: no part shape {', '.join(unknown)} in {geometry.folder / 'geometry.toml'} "
                            f"(its shapes: {', '.join(shapes) or 'none'})")
    return sorted(set(names))


def teach_all(cell: TeachingCell, demonstrate: Demonstrator = scripted_demonstration,
              shapes: Sequence[str] | None = None) -> list[Path]:
    """Regenerate the assets of the cell's product and teach its part shapes (``shapes``,
    checked by :func:`chosen_shapes`; every shape when None), each demonstrated by
    ``demonstrate``, then write their skills (none when one teaching fails: ExecutorError,
    :func:`teach_shape`); the stored skills of the other shapes are kept. Returns the
    written files."""
    chosen = chosen_shapes(cell.geometry, shapes)
    written = regenerate_assets(cell.geometry)
    skills = [teach_shape(cell, shape, demonstrate) for shape in chosen]
    return written + [save_skill(cell.geometry.folder, skill) for skill in skills]
