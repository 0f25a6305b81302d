"""One insertion experiment: part P into hole H, up to two attempts (paper 3.2).

Per attempt: a fresh non-repeatable grasp (≤ 1 mm lateral offset, ≤ 1° tilt of the part
in the hand, unknown to the robot) and a fresh vision estimate of the hole (σ = 1.5 mm
per axis, at most 3 mm off); the part is brought above the estimate, the hole is
searched, the taught skill inserts it, the detector decides, and the part goes back to
its start on the tray.  A failed attempt is repeated once; two failures mean "no_fit".
The transfer between tray and plate is kinematic (joint-space, not simulated): only
the force-controlled part of the task is.
"""

from __future__ import annotations

import time
import zlib
from dataclasses import asdict, dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from executor import ExecutorError
from executor.control.admittance import Admittance
from executor.control.controller import ImpedanceController
from executor.control.detector import Detector, Thresholds
from executor.control.motion import Motion
from executor.skills.dmp import Skill, load_skill
from executor.skills.insertion import insert, rotvec_quat_xyzw
from executor.skills.search import hole_search
from executor.world.arm import TOOL_DOWN_QUAT_XYZW, Arm
from executor.world.geometry import load_geometry
from executor.world.scene import TIME_STEP, Scene, require_display, scene_shapes

if TYPE_CHECKING:
    from executor.rerun_log import AttemptLogger

GRASP_OFFSET_MAX = 0.001  # [m] lateral offset of the part in the hand
GRASP_TILT_MAX = np.radians(1.0)  # [rad]
VISION_SIGMA = 0.0015  # [m] per axis
VISION_MAX = 0.003  # [m]
APPROACH_HEIGHT = 0.0025  # [m] above the plate where the search starts
SETTLE_TIME = 0.02  # [s] at the approach pose before the F/T sensor is tared


@dataclass
class AttemptEvidence:
    """What one attempt showed: outcome "fit"/"no_fit", max ‖F_mes − F_des‖ [N], max
    ‖M_mes − M_des‖ [Nm], ‖p_end − p_goal‖ [m], wall time [s], simulated time [s], whether
    eq. (6)/(7) fired (jam), exception-strategy runs, DMP phase reached (0..1)."""

    outcome: str
    max_force_dev: float
    max_torque_dev: float
    end_error: float
    duration_s: float
    sim_time_s: float
    jammed: bool
    wiggles: int
    phase_reached: float
    hole_found: bool = False


@dataclass
class TrialResult:
    """A trial of up to ``max_attempts`` attempts; maxima over attempts, wall time [s] of all."""

    part: str
    hole: str
    outcome: str
    attempts: int
    max_force_dev: float
    max_torque_dev: float
    end_error: float
    duration_s: float
    evidence: list[AttemptEvidence] = field(default_factory=list)

    def to_json(self) -> dict:
        """The contract keys plus sim time, steps per second and real-time factor."""
        sim = sum(e.sim_time_s for e in self.evidence)
        return {
            "part": self.part,
            "hole": self.hole,
            "outcome": self.outcome,
            "attempts": self.attempts,
            "max_force_dev": self.max_force_dev,
            "max_torque_dev": self.max_torque_dev,
            "end_error": self.end_error,
            "duration_s": self.duration_s,
            "sim_time_s": sim,
            "sim_steps_per_s": sim / TIME_STEP / self.duration_s if self.duration_s > 0 else 0.0,
            "real_time_factor": sim / self.duration_s if self.duration_s > 0 else 0.0,
            "evidence": [asdict(e) for e in self.evidence],
        }


@dataclass(frozen=True)
class AttemptSetup:
    """The random circumstances of one attempt: grasp offset [m] and tilt (rotation
    vector [rad]) of the part in the hand, vision error of the hole estimate [m], seed
    of the stochastic search."""

    grasp_offset: np.ndarray
    grasp_tilt: np.ndarray
    vision_error: np.ndarray
    search_seed: int = 0

    @classmethod
    def draw(cls, rng: np.random.Generator) -> AttemptSetup:
        r = GRASP_OFFSET_MAX * np.sqrt(rng.uniform())
        a = rng.uniform(0, 2 * np.pi)
        tilt_axis = rng.uniform(0, 2 * np.pi)
        tilt = GRASP_TILT_MAX * rng.uniform() * np.array([np.cos(tilt_axis), np.sin(tilt_axis), 0.0])
        vision = rng.normal(0.0, VISION_SIGMA, 2)
        vision *= min(1.0, VISION_MAX / max(np.linalg.norm(vision), 1e-12))
        return cls(np.array([r * np.cos(a), r * np.sin(a), 0.0]), tilt, vision, int(rng.integers(2**31)))


def trial_rng(seed: int, part: str, hole: str) -> np.random.Generator:
    """The random stream of one trial: same seed, part and hole → same trial."""
    return np.random.default_rng([seed, zlib.crc32(part.encode()), zlib.crc32(hole.encode())])


class Cell:
    """The simulated cell, reused for many trials: one DIRECT PyBullet client per part
    shape (made on first use), so a trial depends on its seed only."""

    def __init__(self, assembly: str = "cranfield", gui: bool = False, logger: AttemptLogger | None = None,
                 thresholds: Thresholds = Thresholds()) -> None:
        self.geometry = load_geometry(assembly)
        if gui:
            require_display()
        self.gui = gui
        self.logger = logger
        self.thresholds = thresholds
        self._skills: dict[str, Skill] = {}
        self._scenes: dict[str, Scene] = {}  # one PyBullet client per part shape
        self._motions: dict[str, Motion] = {}
        self._motion: Motion | None = None
        self.scene: Scene | None = None  # the client of the part in the hand
        if logger is not None:
            logger.log_scene(scene_shapes(self.geometry))

    def _check(self, part: str, hole: str) -> Skill:
        if part not in self.geometry.parts:
            raise ExecutorError(f"unknown part '{part}' (expected one of {', '.join(sorted(self.geometry.parts))})")
        if hole not in self.geometry.holes:
            raise ExecutorError(f"unknown hole '{hole}' (expected one of {', '.join(sorted(self.geometry.holes))})")
        shape = self.geometry.parts[part].shape
        if shape not in self._skills:
            self._skills[shape] = load_skill(self.geometry.folder, shape)
        return self._skills[shape]

    def motion_for(self, part: str) -> Motion:
        """Put the part in the hand; the Motion driving the arm that holds it.  Each part
        shape has its own PyBullet client, made on first use (with ``gui``, the first
        one is the GUI); the step count carries over, so sim time only grows."""
        spec = self.geometry.parts[part]
        scene = self._scenes.get(spec.shape)
        if scene is None:
            scene = Scene(self.geometry, spec.shape, gui=self.gui and not self._scenes)
            self._scenes[spec.shape] = scene
            arm = Arm(scene.client, scene.robot)
            self._motions[spec.shape] = Motion(ImpedanceController(arm, scene.client), self.logger)
        scene.hold(spec)
        motion = self._motions[spec.shape]
        if self._motion is not None and motion is not self._motion:
            motion.steps = self._motion.steps
        self._motion, self.scene = motion, scene
        return motion

    def run_trial(self, part: str, hole: str, seed: int, max_attempts: int = 2) -> TrialResult:
        """Insert ``part`` into ``hole`` with up to ``max_attempts`` attempts."""
        self._check(part, hole)
        if max_attempts < 1:
            raise ExecutorError(f"max_attempts = {max_attempts}: expected at least 1")
        rng = trial_rng(seed, part, hole)
        start = time.perf_counter()
        evidence: list[AttemptEvidence] = []
        for attempt in range(1, max_attempts + 1):
            if self.logger is not None:
                self.logger.begin_attempt(part, hole, seed, attempt)
            ev = self.run_attempt(part, hole, AttemptSetup.draw(rng))
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

    def run_attempt(self, part: str, hole: str, setup: AttemptSetup, wiggle_enabled: bool = True) -> AttemptEvidence:
        """One attempt under given circumstances; the part returns to its start after."""
        skill = self._check(part, hole)
        wall0 = time.perf_counter()
        motion = self.motion_for(part)
        sim0 = motion.steps
        arm = motion.controller.arm
        spec, hole_spec = self.geometry.parts[part], self.geometry.holes[hole]
        arm.set_grasp_error(setup.grasp_offset, rotvec_quat_xyzw(setup.grasp_tilt))
        surface = float(self.geometry.plate["top_z"])
        est_xy = np.array(hole_spec.position) + setup.vision_error
        quat = TOOL_DOWN_QUAT_XYZW
        approach = np.array([est_xy[0], est_xy[1], surface + APPROACH_HEIGHT])
        arm.inverse_kinematics(approach, quat)
        motion.controller.reset()
        motion.hold(approach, quat, SETTLE_TIME)
        arm.tare_sensor()
        found = hole_search(motion, est_xy, surface, approach[2], quat,
                            np.random.default_rng(setup.search_seed))
        if self.logger is not None and len(found.path):
            self.logger.log_search_path(found.path)
        detector = Detector(self.thresholds)
        origin = np.array([found.hole_xy[0], found.hole_xy[1], found.surface_z])
        lever = spec.length - float(self.geometry.gripper["grasp_depth"])
        result = insert(motion, skill, origin, detector, Admittance(), lever, wiggle_enabled)
        self._scenes[spec.shape].release()
        return AttemptEvidence(
            "fit" if result.reached else "no_fit", detector.max_force_dev, detector.max_torque_dev,
            result.end_error, time.perf_counter() - wall0, (motion.steps - sim0) * TIME_STEP,
            result.jammed, result.wiggles, result.phase_reached, found.found,
        )

    def close(self) -> None:
        for scene in self._scenes.values():
            scene.close()
