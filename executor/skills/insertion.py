"""The insertion proper (paper 3.2 steps 2–4): the taught DMP from where the search ended
to the goal, adapted on-line toward the reference wrench (admittance), slowed by phase
stopping, monitored by eqs. (6)/(7), with the wiggle exception strategy on a breach and
the goal check at the end."""

from __future__ import annotations

import math
from dataclasses import dataclass

import msgspec
import numpy as np
import pybullet as pb

from executor.cell_description import CellDescription
from executor.control.admittance import Admittance
from executor.control.detector import Detector
from executor.control.ilc import ExecutionLayer, ExecutionTrace
from executor.control.motion import Motion
from executor.skills.dmp import PhaseClock, Skill
from executor.skills.search_params import SINK_DEPTH
from executor.skills.wiggle import wiggle
from executor.world.arm import turn_quats_z, turn_z
from executor.world.scene import TIME_STEP

# The insertion gives up when phase stopping has stretched it beyond this many τ.
TIMEOUT_FACTOR = 3.0
END_SETTLE_TIME = 0.05  # [s] held at the end before p_end is read
MAX_WIGGLES = 1  # exception strategy runs per attempt
_ORIGIN = (0.0, 0.0, 0.0)  # the zero translation of the rotations composed with multiplyTransforms
JAM_DEPTH = SINK_DEPTH
"""[m] below the entry: the part has sunk into the hole's entry chamfer (the search's
criterion of "in the hole"), so a breach there is a jam, not a part on the surface.  A
too-big part never gets there (measured: at most 0.08 mm below the entry when eq. (6)
fires, with the default uncertainty); a tilted tight peg wedged in the chamfer is 1 mm
deep."""


@dataclass
class InsertionResult:
    """``completed``: the DMP ran to its end without an unresolved eq. (6)/(7) breach;
    ``reached``: goal check passed where the execution ended (the success criterion:
    an interrupted execution succeeds only if the part is already at its goal);
    ``end_error`` ‖p_end − p_goal‖ [m] (p_goal: the taught end in the found hole, not moved
    by the admittance); ``jammed``: a breach inside the hole, or the part
    stuck in the hole at the end of the trajectory."""

    completed: bool
    reached: bool
    end_error: float
    jammed: bool
    wiggles: int
    phase_reached: float
    trace: ExecutionTrace | None = None


def rotvec_quat_xyzw(rotvec: np.ndarray) -> np.ndarray:
    """Quaternion (x, y, z, w) of a rotation vector [rad]."""
    angle = math.sqrt(rotvec.dot(rotvec))  # ‖rotvec‖ as np.linalg.norm computes it, without its overhead
    if angle < 1e-12:
        return np.array([0.0, 0.0, 0.0, 1.0])
    x, y, z = (np.sin(angle / 2) * rotvec / angle).tolist()
    return np.array([x, y, z, math.cos(angle / 2)])


@dataclass(frozen=True)
class InsertionTask:
    """One insertion: where it goes and what the cell knows of the pair.

    ``hole_origin`` (3,) [m]: the origin of the hole frame, the hole centre on the plate top
    where the search found it; ``gripper_lever`` [m]: from the grasp to the part's tip (the
    wiggle's lever); ``yaw`` [rad]: the hole frame's turn about z (the tool yaw aligned to
    the hole's estimated yaw; the skill's poses and reference wrench are in the frame it
    was taught in); ``yaw_compliant``: the admittance also turns the part about the tool
    axis (a part aligned to a rect hole's estimated yaw, :func:`needs_yaw_compliance`);
    ``correction`` (bins, 5): the pair's ILC pose correction over the phase (dx, dy, dz
    [m], rx, ry [rad], :mod:`executor.control.ilc`), added to the
    command; ``wiggle_enabled``: the wiggle exception strategy may run on a jam."""

    hole_origin: np.ndarray
    gripper_lever: float
    yaw: float = 0.0
    yaw_compliant: bool = False
    correction: np.ndarray | None = None
    wiggle_enabled: bool = True


def insert(motion: Motion, skill: Skill, detector: Detector, task: InsertionTask, admittance: Admittance | None,
           *, phase_stopping: bool = True, record: bool = False) -> InsertionResult:
    """Run the skill in the hole frame of ``task`` (:class:`InsertionTask`), starting from
    the current tip pose, its path never above that pose's height, with the task's ILC
    correction added to the command.

    The execution layer: ``admittance`` None is pure position control along the DMP;
    ``phase_stopping`` False lets the DMP run at its own pace whatever the forces;
    ``record`` keeps the per-step wrench deviations and admittance offsets in
    ``result.trace`` for ILC.

    A breach with the tip sunk into the hole (deeper than ``JAM_DEPTH``: in the entry
    chamfer or past it) is a jam: the wiggle runs once and the insertion goes on;
    a breach with the part still on the plate surface, or a second one, stops the
    execution; the goal check then decides.  A trajectory that ends with the part stuck
    in the hole short of the goal (forces below the thresholds) is a jam as well: the
    wiggle runs there, and the goal is checked again."""
    hole_origin, gripper_lever, yaw = task.hole_origin, task.gripper_lever, task.yaw
    feedforward, wiggle_enabled = task.correction, task.wiggle_enabled
    s = motion.read()
    goal = skill.demo_goal
    times, pos, quats = skill.rollout(turn_z(s.tip_pos - hole_origin, -yaw), turn_quats_z(s.tip_quat_xyzw, -yaw),
                                      goal[:3], np.roll(goal[3:], -1))
    # Never above where the search left the part: a skill moved to a shallower hole than its
    # teaching's (Skill.deeper keeps the forcing terms) first rises about 2.7 mm for 5 mm
    # shallower, lifting the part out of the hole or off the pin it found, to land beside it.
    pos[:, 2] = np.minimum(pos[:, 2], pos[0, 2])
    clock = PhaseClock(times, turn_z(pos, yaw) + hole_origin, turn_quats_z(quats, yaw), detector.thresholds.f_slow)
    d_pos, d_rot = np.zeros(3), np.zeros(3)
    wiggles, jammed, completed = 0, False, True
    budget = int(TIMEOUT_FACTOR * clock.duration / TIME_STEP)
    taught = skill.wrench.tabulate()
    wrench_table = np.concatenate([turn_z(taught[:, :3], yaw), turn_z(taught[:, 3:], yaw)], axis=1)
    last = len(wrench_table) - 1
    ff = np.zeros((1, 5)) if feedforward is None else feedforward
    ff_last = len(ff) - 1
    if admittance is not None:  # its translation bound for z too, no yaw bound unless it turns the part
        bound_pos = np.full(3, admittance.bound[0])
        bound_rot = np.array([admittance.bound[2], admittance.bound[3], admittance.bound[4] if admittance.yaw else 0.0])
    else:  # no admittance offsets to keep in range
        bound_pos, bound_rot = np.zeros(3), np.zeros(3)
    # Per phase bin of the correction, made once instead of every step: its position (3,)
    # [m], its rotation as a quaternion (x, y, z, w), and the range left to the
    # admittance's offsets (position [m], rotation vector [rad]: low, high).
    ff_bins: list[tuple[np.ndarray, list[float], tuple[np.ndarray, ...]]] = []
    for c in ff:
        ff_pos, ff_rot = c[:3], np.array([c[3], c[4], 0.0])
        room = (-bound_pos - ff_pos, bound_pos - ff_pos, -bound_rot - ff_rot, bound_rot - ff_rot)
        ff_bins.append((ff_pos, rotvec_quat_xyzw(ff_rot).tolist(), room))

    def ff_at(phase: float) -> tuple[np.ndarray, list[float], tuple[np.ndarray, ...]]:
        return ff_bins[min(int(phase * len(ff)), ff_last)]

    trace = ExecutionTrace() if record else None
    for _ in range(budget):
        if clock.done:
            break
        pos_d, quat_d = clock.pose()
        ff_pos, ff_quat, (pos_low, pos_high, rot_low, rot_high) = ff_at(clock.phase)
        pos_d = pos_d + ff_pos
        quat_d = np.array(pb.multiplyTransforms(_ORIGIN, ff_quat, _ORIGIN, quat_d)[1])
        w_des = wrench_table[int(clock.phase * last + 0.5)]
        quat_cmd = np.array(pb.multiplyTransforms(_ORIGIN, rotvec_quat_xyzw(d_rot), _ORIGIN, quat_d)[1])
        s = motion.step(pos_d + d_pos, quat_cmd, phase=clock.phase, wrench_des=w_des)
        f_dev, m_dev = s.force - w_des[:3], s.torque - w_des[3:]
        f_norm, _, violated = detector.update(f_dev, m_dev)
        if admittance is not None:
            d_pos, d_rot = admittance.update(f_dev, m_dev, TIME_STEP)
            if feedforward is not None:  # correction plus admittance stay within the admittance's bound
                d_pos = np.minimum(np.maximum(d_pos, pos_low), pos_high)  # np.clip, without its overhead
                d_rot = np.minimum(np.maximum(d_rot, rot_low), rot_high)
        if trace is not None:
            trace.add(clock.phase, np.array([f_dev[0], f_dev[1], f_dev[2], m_dev[0], m_dev[1]]))
        if violated:
            jammed = jammed or bool(s.tip_pos[2] < hole_origin[2] - JAM_DEPTH)
            if not (jammed and wiggle_enabled and wiggles < MAX_WIGGLES):
                completed = False
                break
            wiggle(motion, pos_d + d_pos, quat_cmd, gripper_lever, clock.phase, w_des)
            wiggles += 1
            detector.clear()
            continue
        clock.advance(TIME_STEP, f_norm if phase_stopping else 0.0)
    else:
        completed = False
    pos_d, quat_d = clock.pose()
    ff_pos = ff_at(clock.phase)[0]
    pos_d = pos_d + ff_pos
    end = motion.hold(pos_d + d_pos, quat_d, END_SETTLE_TIME) if completed else motion.read()
    # p_goal: the taught end in the hole the search found, moved by ILC's lateral
    # correction (not its z, which only shapes the push, never where the part must end).
    # Not by the admittance's offset: that follows the reference wrench, which a part held
    # by the hole's walls meets only by pressing one, so it can drift to its bound while
    # the part stays in the hole.
    p_goal = hole_origin + turn_z(skill.end_position, yaw) + ff_pos * np.array([1.0, 1.0, 0.0])
    reached, err = detector.goal_reached(end.tip_pos, p_goal)
    stalled = completed and not reached and bool(end.tip_pos[2] < hole_origin[2] - JAM_DEPTH)
    jammed = jammed or stalled  # stuck in the hole below the thresholds: a jam too
    if stalled and wiggle_enabled and wiggles < MAX_WIGGLES:
        wiggle(motion, pos_d + d_pos, quat_d, gripper_lever, clock.phase, wrench_table[last])
        wiggles += 1
        end = motion.hold(pos_d + d_pos, quat_d, END_SETTLE_TIME)
        reached, err = detector.goal_reached(end.tip_pos, p_goal)
    return InsertionResult(completed, reached, err, jammed, wiggles, clock.phase, trace)


def needs_yaw_compliance(part_kind: str, hole_kind: str) -> bool:
    """Whether the insertion corrects the part's yaw: a square or rect part in a rect hole,
    whose yaw the vision estimates with an error (a round part has no yaw to correct; a
    square hole's yaw is known, as it always was)."""
    return hole_kind == "rect" and part_kind != "round"


def insert_in_layer(motion: Motion, skill: Skill, detector: Detector, task: InsertionTask, layer: ExecutionLayer,
                    *, description: CellDescription) -> InsertionResult:
    """:func:`insert` under an execution layer: its admittance (P or PI, none for pure
    position control; turning the part about the tool axis when ``task.yaw_compliant``)
    with the admittance of the cell ``description``, phase stopping and recording; with
    ``layer.stiff`` the insertion tracks with the description's ``position_gains`` and the
    controller's own gains come back after (the search and the release stay compliant)."""
    params = description.admittance if layer.integral else msgspec.structs.replace(description.admittance,
                                                                                      integral_gain=0.0)
    admittance = Admittance(params, yaw=task.yaw_compliant) if layer.admittance else None
    controller = motion.controller
    compliant = controller.gains
    if layer.stiff:
        controller.gains = description.position_gains
    try:
        return insert(motion, skill, detector, task, admittance, phase_stopping=layer.phase_stopping,
                      record=layer.ilc)
    finally:
        controller.gains = compliant
