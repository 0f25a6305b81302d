"""The plain records of the cell's experiments, shared by the trial (:mod:`executor.trial`),
the Rerun log (:mod:`executor.rerun_log`) and the command lines: the random circumstances
of one attempt (:class:`AttemptSetup`: grasp error [m, rad], vision error [m], friction), what
one attempt showed (:class:`AttemptEvidence`: wrench deviations [N, Nm], end error [m],
times [s]) and a whole trial (:class:`TrialResult`, with its ``--json`` form).  Kept apart
from the trial so the logger can name them without importing the simulation.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np

from executor.world import TIME_STEP


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
    ilc_iteration: int = 0
    """executions of this ILC key before this one (0: no correction yet, or ILC off)"""
    ilc_correction_norm: float = 0.0
    """RMS over the phase of the feed-forward correction used [m and rad, 4 axes]"""


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
    """The circumstances of one attempt, unknown to the robot: grasp offset [m] and tilt
    (rotation vector [rad]) of the part in the hand, vision error of the hole estimate
    [m], seed of the stochastic search, friction coefficient of the part in the hole
    (None: the scene's own, 0.25), error of the hole's estimated yaw [rad] (0 but for a
    rect hole).  Drawn by :class:`executor.world.perturbation.CellBias`."""

    grasp_offset: np.ndarray
    grasp_tilt: np.ndarray
    vision_error: np.ndarray
    search_seed: int = 0
    friction: float | None = None
    vision_yaw: float = 0.0
