"""One insertion experiment: part P into hole H, up to two attempts (paper 3.2).

Per attempt: a grasp of the part and a vision estimate of the hole, both off by errors
unknown to the robot, and a friction of the hole (:mod:`executor.world.perturbation`:
a systematic part per cell, a random part per attempt); the part is brought above the
estimate, the hole is searched, the taught skill inserts it with the chosen execution
layer (:class:`executor.control.ilc.ExecutionLayer`: admittance, phase stopping, ILC),
the detector decides, and the part goes back to its start on the tray.  A failed attempt
is repeated once; two failures mean "no_fit".  With ILC, each successful execution
updates the correction of its (part shape, hole), kept for the cell's next executions
(and saved to ``ilc_state`` if given).
The transfer between tray and plate is kinematic (joint-space, not simulated): only
the force-controlled part of the task is.  The records it returns (the attempt's setup and
evidence, the trial's result) are plain types in :mod:`executor.evidence`.
"""

from __future__ import annotations

import time
import zlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from bridge.cell_settings import CellSettings, Magnitudes
from executor import ExecutorError, UnknownPair
from executor.cell_description import CellDescription, load_cell_description
from executor.control.controller import ImpedanceController
from executor.control.detector import Detector
from executor.control.ilc import ExecutionLayer, Ilc, correction_norm, layer_named
from executor.control.motion import APPROACH_SETTLE_TIME, Motion
from executor.evidence import AttemptEvidence, AttemptSetup, TrialResult
from executor.rerun_arm import ArmRecorder
from executor.skills.dmp import Skill, load_product_skill
from executor.skills.insertion import (
    InsertionTask,
    insert_in_layer,
    needs_yaw_compliance,
    rotvec_quat_xyzw,
)
from executor.skills.search import hole_search
from executor.world import SIZE_RESOLUTION
from executor.world.arm import Arm, tool_quat
from executor.world.assets import current_assets
from executor.world.frames import aligned_yaw
from executor.world.geometry import fit_pose, load_geometry, margin
from executor.world.perturbation import CellBias
from executor.world.scene import TIME_STEP, Scene, hole_rims, require_display, scene_shapes

if TYPE_CHECKING:
    from executor.rerun_log import AttemptLogger

APPROACH_HEIGHT = 0.0025  # [m] above the plate where the search starts
REACH_TOLERANCE = 0.005
"""[m] an arm placed by IK farther than this from its pose does not reach it (IK ends within
1 µm of a pose it reaches): the attempt or the teaching stops with an error, no outcome."""
PLATE_MESH_COLOR = (180, 185, 190)  # RGB of the plate's bosses in the Rerun scene


def place_arm(arm: Arm, tip: np.ndarray, quat_xyzw: np.ndarray, what: str) -> None:
    """The arm placed by IK at the pose (tip [m], quaternion xyzw, cell frame) of ``what``;
    ExecutorError naming it when the arm does not reach it (:data:`REACH_TOLERANCE`)."""
    arm.inverse_kinematics(tip, quat_xyzw)
    missed = arm.tip_error(tip)
    if missed > REACH_TOLERANCE:
        raise ExecutorError(f"the arm does not reach {what} at ({', '.join(f'{1e3 * v:.1f}' for v in tip)}) mm: its "
                            f"tip ends {1e3 * missed:.1f} mm from it; expected a pose within its reach (place the "
                            "product nearer the arm: import --place X,Y)")


def _room_kind(room: float) -> str:
    """How a section's room [m] reads: room, a nominal zero-clearance fit (0 exactly, as the
    import states one), or an interference."""
    return "room" if room > 0 else "a nominal zero-clearance fit" if room == 0 else "an interference"


def trial_rng(seed: int, part: str, hole: str) -> np.random.Generator:
    """The random stream of one trial: same seed, part and hole → same trial."""
    return np.random.default_rng([seed, zlib.crc32(part.encode()), zlib.crc32(hole.encode())])


@dataclass(frozen=True)
class CellSetup:
    """What a simulated cell is, decoded (:func:`cell_setup`): ``layer``, its execution layer
    (a name of :data:`executor.control.ilc.LAYERS` or one);
    ``magnitudes``, of its uncertainty (units per field of
    :class:`bridge.cell_settings.Magnitudes`); ``cell_seed``, the seed of
    its systematic errors; ``description``, its gripper, gains, thresholds, admittance and
    ILC parameters."""

    layer: str | ExecutionLayer = "full"
    magnitudes: Magnitudes = field(default_factory=Magnitudes)
    cell_seed: int = 0
    description: CellDescription = field(default_factory=CellDescription)


def cell_setup(settings: CellSettings) -> CellSetup:
    """The :class:`CellSetup` of the cell settings, the cell description file they name read
    and checked here, the one place it is decoded (BridgeError naming the file, table and
    key)."""
    description = None if settings.description is None else Path(settings.description)
    return CellSetup(settings.layer, settings.magnitudes, settings.cell_seed, load_cell_description(description))


class Cell:
    """The simulated cell, reused for many trials: one DIRECT PyBullet client per part
    shape (made on first use), so a trial depends on its seed, the cell seed and, with
    ILC, on the executions before it (the learned corrections) only.

    ``setup``: the execution layer, the magnitudes of the cell's uncertainty and the seed of
    its systematic part (drawn into ``bias``,
    :class:`executor.world.perturbation.CellBias`), the cell's
    description (:class:`CellSetup`); ``ilc_state``: a JSON file the ILC corrections are
    read from (if it exists) and saved to after every update."""

    def __init__(self, assembly: str = "cranfield", gui: bool = False, logger: AttemptLogger | None = None,
                 *, setup: CellSetup = CellSetup(), ilc_state: Path | None = None) -> None:
        self.description = setup.description
        self.geometry = load_geometry(assembly, self.description)
        if gui:
            require_display()
        self.gui = gui
        self.logger = logger
        self.thresholds = self.description.thresholds
        self.ilc_state = ilc_state
        self.reset_state(layer=setup.layer, magnitudes=setup.magnitudes, cell_seed=setup.cell_seed)
        self._skills: dict[str, Skill] = {}
        self._scenes: dict[str, Scene] = {}  # one PyBullet client per part shape
        self._motions: dict[str, Motion] = {}
        self._arms: dict[str, ArmRecorder] = {}  # for the Rerun log, one per part shape
        self._motion: Motion | None = None
        self.scene: Scene | None = None  # the client of the part in the hand
        if logger is not None:
            logger.log_scene(scene_shapes(self.geometry))
            plate_obj = current_assets(self.geometry) / "plate.obj"
            logger.log_scene_mesh("plate_mesh", self.geometry.base_mesh or plate_obj, PLATE_MESH_COLOR)
            logger.log_hole_rims(hole_rims(self.geometry))
            if self.geometry.parts:  # a product whose every part is placed by hand has no arm to show
                logger.log_arm_at_rest(self._arm_of(min(self.geometry.parts.items())[1].shape))

    def reset_state(self, *, layer: str | ExecutionLayer = "full", magnitudes: Magnitudes | None = None,
                    cell_seed: int = 0) -> None:
        """Become another cell on the same PyBullet clients: this execution layer, new
        systematic errors, the ILC corrections of ``ilc_state`` (if it exists) or none."""
        self.layer = layer_named(layer) if isinstance(layer, str) else layer
        self.bias = CellBias(Magnitudes() if magnitudes is None else magnitudes, cell_seed)
        d = self.description
        self.ilc = Ilc(d.ilc, d.gains, d.admittance)
        if self.ilc_state is not None:
            self.ilc.load(self.ilc_state)

    def check_pair(self, part: str, hole: str) -> Skill:
        """The taught skill of ``part``'s shape; UnknownPair naming an unknown part or hole,
        or a peg and a pin, a part with a bore and a hole (:func:`executor.world.geometry.feature_passes`);
        ExecutorError for a pair whose room or interference per side is below
        :data:`executor.world.scene.SIZE_RESOLUTION` (the physics cannot tell them apart) or
        that the geometry states a near miss (``near_miss``)."""
        if part not in self.geometry.parts:
            raise UnknownPair(f"unknown part '{part}' (expected one of {', '.join(sorted(self.geometry.parts))})")
        if hole not in self.geometry.holes:
            raise UnknownPair(f"unknown hole '{hole}' (expected one of {', '.join(sorted(self.geometry.holes))})")
        spec, feature = self.geometry.parts[part], self.geometry.holes[hole]
        if spec.bore != feature.pin:
            raise UnknownPair(f"part '{part}' {'goes onto pins' if spec.bore else 'goes into holes'}, '{hole}' is "
                              f"{'a pin' if feature.pin else 'a hole'}: the cell does not try that pair")
        if part in feature.near_miss:
            raise ExecutorError(
                f"part '{part}' into '{hole}': the geometry states it a near miss (near_miss): it misses the hole by "
                "less than the cell's peg lacks at its corners, rounded by the hull margin, plus what the cell "
                "resolves: it claims neither fit nor no_fit (docs/cell.md#what-the-physics-resolves)")
        room = margin(feature, spec) if feature.pin else margin(spec, feature)
        if abs(room) / 2 < SIZE_RESOLUTION:
            raise ExecutorError(
                f"part '{part}' {'onto' if feature.pin else 'into'} '{hole}': the geometry gives it "
                f"{room * 500:+.3f} mm per side ({_room_kind(room)}), less than the "
                f"{SIZE_RESOLUTION * 1000:g} mm the simulated cell resolves: it claims neither fit nor no_fit "
                "(docs/cell.md#what-the-physics-resolves)")
        shape = self.geometry.parts[part].shape
        if shape not in self._skills:
            self._skills[shape] = load_product_skill(self.geometry, shape)
        return self._skills[shape]

    def motion_for(self, part: str) -> Motion[ImpedanceController]:
        """Put the part in the hand, the scene that of its demonstration's hole
        (:meth:`executor.world.scene.Scene.feature`); the Motion driving the arm that holds
        it.  Each part shape has its own PyBullet client, made on first use (with ``gui``,
        the first one is the GUI); the step count carries over, so sim time only grows."""
        spec = self.geometry.parts[part]
        scene = self._scene_of(spec.shape)
        scene.hold(spec)
        scene.feature(spec.demo_hole)  # teaching's; a trial's own hole: _attempt
        if self.logger is not None:
            self.logger.attach_arm(self._arm_of(spec.shape), part)
        motion = self._motions[spec.shape]
        motion.controller.arm.hold_limit = self.geometry.gripper.cup_force if spec.tool == "suction" else None
        if self._motion is not None and motion is not self._motion:
            motion.steps = self._motion.steps
        self._motion, self.scene = motion, scene
        return motion

    def find_hole(self, motion: Motion, origin: np.ndarray, quat_xyzw: np.ndarray) -> np.ndarray:
        """Teaching: the hole where the geometry puts it (the held part is exactly in the
        hand, :meth:`hold_at`; no search)."""
        return origin

    def hold_at(self, motion: Motion, tip: np.ndarray, quat_xyzw: np.ndarray) -> None:
        """Teaching (:class:`executor.skills.teach.TeachingCell`): the held part exactly in
        the hand, the teaching friction, the arm placed at the pose (in the motion's frame)
        and settled, the sensor tared."""
        assert self.scene is not None  # set by motion_for
        self.scene.set_friction(None)
        arm = motion.controller.arm
        arm.set_grasp_error(np.zeros(3), np.array([0.0, 0.0, 0.0, 1.0]))
        place_arm(arm, *motion.cell_pose(tip, quat_xyzw), "the demonstration's start")
        motion.controller.reset()
        motion.hold(tip, quat_xyzw, APPROACH_SETTLE_TIME)
        arm.tare_sensor()

    def let_go(self) -> None:
        """Teaching: the part out of the hand."""
        assert self.scene is not None  # set by motion_for
        self.scene.release()

    def _scene_of(self, shape: str) -> Scene:
        """The PyBullet client of ``shape``'s arm, made (with its Motion) on first use."""
        scene = self._scenes.get(shape)
        if scene is None:
            scene = Scene(self.geometry, shape, gui=self.gui and not self._scenes)
            self._scenes[shape] = scene
            arm = Arm(scene.client, scene.robot)
            self._motions[shape] = Motion(ImpedanceController(arm, scene.client, self.description.gains), self.logger)
        return scene

    def _arm_of(self, shape: str) -> ArmRecorder:
        """The Rerun recorder of ``shape``'s arm (its client made on first use)."""
        if shape not in self._arms:
            scene = self._scene_of(shape)
            self._arms[shape] = ArmRecorder(scene.client, scene.robot)
        return self._arms[shape]

    def run_trial(self, part: str, hole: str, seed: int, max_attempts: int = 2) -> TrialResult:
        """Insert ``part`` into ``hole`` with up to ``max_attempts`` attempts; UnknownPair
        naming an unknown part or hole."""
        skill = self.check_pair(part, hole)
        if max_attempts < 1:
            raise ExecutorError(f"max_attempts = {max_attempts}: expected at least 1")
        rng = trial_rng(seed, part, hole)
        start = time.perf_counter()
        evidence: list[AttemptEvidence] = []
        for attempt in range(1, max_attempts + 1):
            if self.logger is not None:
                self.logger.begin_attempt(part, hole, seed, attempt)
            ev = self._attempt(part, hole, skill, self.draw_setup(rng, part, hole))
            if self.logger is not None:
                self.logger.end_attempt(ev)
            evidence.append(ev)
            if ev.outcome == "fit":
                break
        return TrialResult(
            part, hole, evidence[-1].outcome, len(evidence),
            max(e.max_force_dev for e in evidence), max(e.max_torque_dev for e in evidence),
            evidence[-1].end_error, time.perf_counter() - start, evidence,
        )

    def draw_setup(self, rng: np.random.Generator, part: str, hole: str) -> AttemptSetup:
        """The circumstances of one attempt: this cell's systematic errors plus random ones
        from ``rng`` (with a yaw error of the estimate for a rect hole)."""
        return self.bias.draw(rng, self.geometry.parts[part].shape, hole, self.geometry.holes[hole].kind == "rect")

    def ilc_key(self, part: str, hole: str) -> str:
        """ILC corrections are kept per (part shape, hole) (docs/decisions.md)."""
        return f"{self.geometry.parts[part].shape}:{hole}"

    def run_attempt(self, part: str, hole: str, setup: AttemptSetup, wiggle_enabled: bool = True) -> AttemptEvidence:
        """One attempt under given circumstances; the part returns to its start after."""
        return self._attempt(part, hole, self.check_pair(part, hole), setup, wiggle_enabled)

    def _attempt(self, part: str, hole: str, taught: Skill, setup: AttemptSetup,
                 wiggle_enabled: bool = True) -> AttemptEvidence:
        """:meth:`run_attempt` with the pair checked and its taught skill given."""
        spec, hole_spec = self.geometry.parts[part], self.geometry.holes[hole]
        skill = taught.in_hole(hole_spec.depth)
        wall0 = time.perf_counter()
        motion = self.motion_for(part)
        self._scenes[spec.shape].feature(hole)
        sim0 = motion.steps
        arm = motion.controller.arm
        layer = self.layer
        key = self.ilc_key(part, hole)
        correction, iteration = self.ilc.correction(key) if layer.ilc else (None, 0)
        self._scenes[spec.shape].set_friction(setup.friction)
        arm.set_grasp_error(setup.grasp_offset, rotvec_quat_xyzw(setup.grasp_tilt))
        surface = hole_spec.top_z
        turn, shift = fit_pose(spec, hole_spec)
        est_xy = np.array(hole_spec.position) + shift + setup.vision_error
        yaw = aligned_yaw(spec.kind, hole_spec.kind, hole_spec.yaw + turn + setup.vision_yaw)
        quat = tool_quat(yaw)
        approach = np.array([est_xy[0], est_xy[1], surface + APPROACH_HEIGHT])
        motion.frame = hole_spec.frame  # the hole's: the attempt runs down its z axis
        try:
            place_arm(arm, *motion.cell_pose(approach, quat), f"the approach to hole '{hole}'")
            motion.controller.reset()
            motion.hold(approach, quat, APPROACH_SETTLE_TIME)
            arm.tare_sensor()
            found = hole_search(motion, est_xy, surface, approach[2], quat,
                                np.random.default_rng(setup.search_seed), self.description.search)
            if self.logger is not None and len(found.path):
                self.logger.log_search_path(found.path if motion.frame is None
                                            else motion.frame.points_to_cell(found.path))
            detector = Detector(self.thresholds)
            origin = np.array([found.hole_xy[0], found.hole_xy[1], found.surface_z])
            lever = spec.length - spec.held_depth(self.geometry.gripper)
            task = InsertionTask(origin, lever, yaw, needs_yaw_compliance(spec.kind, hole_spec.kind), correction,
                                 wiggle_enabled)
            result = insert_in_layer(motion, skill, detector, task, layer, description=self.description)
        finally:
            motion.frame = None
        self._scenes[spec.shape].release()
        if result.reached and result.trace is not None:
            learned = self.ilc.update(key, result.trace)
            if self.ilc_state is not None:
                self.ilc.save(self.ilc_state)
            if self.logger is not None:
                self.logger.log_ilc(key, iteration + 1, correction_norm(learned))
        return AttemptEvidence(
            "fit" if result.reached else "no_fit", detector.max_force_dev, detector.max_torque_dev,
            result.end_error, time.perf_counter() - wall0, (motion.steps - sim0) * TIME_STEP,
            result.jammed, result.wiggles, result.phase_reached, found.found,
            iteration, 0.0 if correction is None else correction_norm(correction),
        )

    def close(self) -> None:
        for scene in self._scenes.values():
            scene.close()
