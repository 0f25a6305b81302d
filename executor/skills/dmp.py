"""The taught skill: a Cartesian DMP (movement-primitives, Ude et al. 2014) for the tip
pose, a reference wrench as radial basis functions over the phase, and DMP phase
stopping.

Poses of a skill are in the *hole frame*: position relative to the hole centre on the
plate top [m], orientation in the cell frame.  A skill is stored as JSON under
``data/<assembly>/demonstrations/<shape>.json`` with the record of its teaching
(:class:`TaughtOn`: the part, the hole and their sections, the end error of the replay);
a skill without that record, or whose teaching did not reach its goal, is refused when
loaded, so no trial runs on a failed demonstration.

Phase stopping: the DMP is rolled out once per attempt (``open_loop``) over its own time
t ∈ [0, τ]; during execution t advances by dt / (1 + ‖ΔF‖ / F_slow), so a large wrench
deviation slows the reference (it never jumps: the rollout is a function of t only).
The phase reported everywhere is t / τ ∈ [0, 1].
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from movement_primitives.dmp import CartesianDMP

from bridge.files import make_folder, write_atomic
from bridge.inputs import read_text
from executor import ExecutorError

if TYPE_CHECKING:
    from executor.world.geometry import CellGeometry

# Rollout resolution of the DMP [s]; poses in between are interpolated linearly.
ROLLOUT_DT = 0.005
N_WEIGHTS = 12
N_WRENCH_RBF = 20


def xyzw_to_wxyz(quat_xyzw: np.ndarray) -> np.ndarray:
    return np.roll(np.asarray(quat_xyzw, dtype=float), 1, axis=-1)


def wxyz_to_xyzw(quat_wxyz: np.ndarray) -> np.ndarray:
    return np.roll(np.asarray(quat_wxyz, dtype=float), -1, axis=-1)


@dataclass
class WrenchProfile:
    """Reference wrench [N, Nm] (6 values) as normalised Gaussian RBFs over the phase."""

    centres: np.ndarray
    width: float
    weights: np.ndarray  # (n_rbf, 6)

    def _features(self, phase: np.ndarray) -> np.ndarray:
        act = np.exp(-((np.atleast_1d(phase)[:, None] - self.centres[None, :]) ** 2) / (2 * self.width**2))
        return act / act.sum(axis=1, keepdims=True)

    @classmethod
    def fit(cls, phase: np.ndarray, wrench: np.ndarray, n_rbf: int = N_WRENCH_RBF) -> WrenchProfile:
        """Least-squares fit (lightly regularised) of (N,) phases and (N, 6) wrenches."""
        centres = np.linspace(0.0, 1.0, n_rbf)
        profile = cls(centres, 0.5 / (n_rbf - 1), np.zeros((n_rbf, 6)))
        phi = profile._features(phase)
        profile.weights = np.linalg.solve(phi.T @ phi + 1e-6 * np.eye(n_rbf), phi.T @ wrench)
        return profile

    def tabulate(self, n: int = 501) -> np.ndarray:
        """(n, 6) wrenches at phases 0, 1/(n−1), …, 1: a look-up table for the control loop."""
        return self._features(np.linspace(0.0, 1.0, n)) @ self.weights


class _MemoForcingTerm:
    """A DMP forcing term that remembers its values: the forcing term and the phase are
    functions of the DMP time only (not of the start or goal), and every rollout of a
    skill integrates over the same times, so its rollouts after the first compute none
    of them again (the same numbers; a rollout costs a third)."""

    def __init__(self, term: Any) -> None:
        self.term = term
        self._forces: dict[Any, np.ndarray] = {}
        self._phases: dict[Any, Any] = {}

    @staticmethod
    def _key(x: Any) -> Any:
        return x if isinstance(x, float) else np.asarray(x).tobytes()

    def forcing_term(self, z: Any) -> np.ndarray:
        key = self._key(z)
        value = self._forces.get(key)
        if value is None:
            value = self._forces[key] = self.term.forcing_term(z)
        return value.copy()

    def phase(self, t: Any) -> Any:
        key = self._key(t)
        if key not in self._phases:
            self._phases[key] = self.term.phase(t)
        return self._phases[key]

    def __getattr__(self, name: str) -> Any:
        return getattr(self.term, name)


@dataclass(frozen=True)
class TaughtOn:
    """What a skill was taught on: ``part`` in ``hole`` (ids), their sections (``kind``
    and sides (a, b) [m]), the hole's ``depth`` [m], and ``end_error`` [m], the distance
    of the replay's end from the demonstration's goal (0.5 mm above the hole's bottom),
    accepted when at most ``goal_tolerance`` [m] (the cell's, as for a trial)."""

    part: str
    part_kind: str
    part_sides: tuple[float, float]
    hole: str
    hole_kind: str
    hole_sides: tuple[float, float]
    depth: float
    end_error: float
    goal_tolerance: float

    @property
    def reached(self) -> bool:
        """Whether the taught insertion reached its goal."""
        return self.end_error <= self.goal_tolerance

    def failure(self) -> str:
        """``part p3 in hole r1: end error 24.9 mm, more than the 3.0 mm goal tolerance``."""
        return (f"part {self.part} in hole {self.hole}: end error {1000 * self.end_error:.1f} mm, more than the "
                f"{1000 * self.goal_tolerance:.1f} mm goal tolerance")

    def to_json(self) -> dict:
        return {"part": self.part, "part_kind": self.part_kind, "part_sides": _rounded(self.part_sides),
                "hole": self.hole, "hole_kind": self.hole_kind, "hole_sides": _rounded(self.hole_sides),
                "depth": self.depth, "end_error": round(self.end_error, 9), "goal_tolerance": self.goal_tolerance}

    @classmethod
    def from_json(cls, data: dict) -> TaughtOn:
        """The record of a skill file; ValueError/KeyError/TypeError on a malformed one."""
        def sides(key: str) -> tuple[float, float]:
            a, b = (float(v) for v in data[key])
            return a, b

        numbers = {key: float(data[key]) for key in ("depth", "end_error", "goal_tolerance")}
        if not all(math.isfinite(v) and v >= 0 for v in numbers.values()):
            raise ValueError(f"depth, end_error, goal_tolerance: expected numbers >= 0, got {numbers}")
        return cls(str(data["part"]), str(data["part_kind"]), sides("part_sides"), str(data["hole"]),
                   str(data["hole_kind"]), sides("hole_sides"), **numbers)


@dataclass
class Skill:
    """A taught insertion: DMP weights, demo start/goal (hole frame), duration τ [s], the
    expected end position p_goal [m] (hole frame, from the replay), the wrench profile and
    the record of its teaching (None while it is being taught)."""

    shape: str
    execution_time: float
    weights: np.ndarray
    demo_start: np.ndarray  # [x, y, z, qw, qx, qy, qz]
    demo_goal: np.ndarray
    end_position: np.ndarray
    wrench: WrenchProfile
    taught: TaughtOn | None = None
    _dmp: CartesianDMP | None = field(default=None, init=False, repr=False, compare=False)

    def make_dmp(self) -> CartesianDMP:
        dmp = CartesianDMP(execution_time=self.execution_time, dt=ROLLOUT_DT, n_weights_per_dim=N_WEIGHTS)
        dmp.set_weights(self.weights)
        return dmp

    def _rollout_dmp(self) -> CartesianDMP:
        """The skill's DMP for rollouts, made once, its forcing terms remembered."""
        if self._dmp is None:
            self._dmp = self.make_dmp()
            self._dmp.forcing_term_pos = _MemoForcingTerm(self._dmp.forcing_term_pos)
            self._dmp.forcing_term_rot = _MemoForcingTerm(self._dmp.forcing_term_rot)
        return self._dmp

    def deeper(self, offset: float) -> Skill:
        """This skill in a hole ``offset`` [m] deeper than the one it was taught in
        (negative: shallower): the same DMP weights, duration and reference wrench over the
        phase, its goal and expected end position ``offset`` lower. The hole frame's origin
        is the entry, so a skill moves with the entry's height as it is; only the depth
        needs this. ``self`` itself at offset 0."""
        if offset == 0.0:
            return self
        down = np.array([0.0, 0.0, offset])
        moved = Skill(self.shape, self.execution_time, self.weights, self.demo_start,
                      self.demo_goal - np.concatenate([down, np.zeros(4)]), self.end_position - down, self.wrench,
                      self.taught)
        moved._dmp = self._rollout_dmp()  # its remembered forcing terms do not depend on the goal
        return moved

    def in_hole(self, depth: float) -> Skill:
        """This skill in a hole ``depth`` [m] deep: :meth:`deeper` by the difference from the
        depth of the hole it was taught in (its record); ExecutorError for a skill without one."""
        if self.taught is None:
            raise ExecutorError(f"skill {self.shape}: no record of its teaching (the depth it was taught at)")
        return self.deeper(depth - self.taught.depth)

    def rollout(self, start_pos: np.ndarray, start_quat_xyzw: np.ndarray, goal_pos: np.ndarray,
                goal_quat_xyzw: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The DMP from a start to a goal pose (hole frame): times (N,) [s], positions
        (N, 3) [m] and quaternions (N, 4) xyzw."""
        dmp = self._rollout_dmp()
        dmp.configure(start_y=np.concatenate([start_pos, xyzw_to_wxyz(start_quat_xyzw)]),
                      goal_y=np.concatenate([goal_pos, xyzw_to_wxyz(goal_quat_xyzw)]))
        t, y = dmp.open_loop()
        return np.asarray(t), y[:, :3], wxyz_to_xyzw(y[:, 3:])

    def to_json(self) -> dict:
        return {
            "shape": self.shape,
            "execution_time": self.execution_time,
            "weights": _rounded(self.weights),
            "demo_start": _rounded(self.demo_start),
            "demo_goal": _rounded(self.demo_goal),
            "end_position": _rounded(self.end_position),
            "wrench_centres": _rounded(self.wrench.centres),
            "wrench_width": self.wrench.width,
            "wrench_weights": _rounded(self.wrench.weights),
            **({} if self.taught is None else {"taught": self.taught.to_json()}),
        }

    @classmethod
    def from_json(cls, data: dict) -> Skill:
        arr = {k: np.array(v, dtype=float) for k, v in data.items() if isinstance(v, list)}
        taught = data.get("taught")
        return cls(data["shape"], float(data["execution_time"]), arr["weights"], arr["demo_start"],
                   arr["demo_goal"], arr["end_position"],
                   WrenchProfile(arr["wrench_centres"], float(data["wrench_width"]), arr["wrench_weights"]),
                   None if taught is None else TaughtOn.from_json(taught))


def _rounded(a: np.ndarray | tuple[float, ...]) -> list:
    return np.round(np.asarray(a, dtype=float), 9).tolist()


def fit_dmp(times: np.ndarray, positions: np.ndarray, quats_xyzw: np.ndarray) -> np.ndarray:
    """DMP weights imitating a demonstrated tip trajectory (hole frame)."""
    dmp = CartesianDMP(execution_time=float(times[-1]), dt=ROLLOUT_DT, n_weights_per_dim=N_WEIGHTS)
    dmp.imitate(times, np.hstack([positions, xyzw_to_wxyz(quats_xyzw)]))
    return dmp.get_weights()


def skill_path(folder: Path, shape: str) -> Path:
    return folder / "demonstrations" / f"{shape}.json"


def save_skill(folder: Path, skill: Skill) -> Path:
    """Write the skill to ``<folder>/demonstrations/<shape>.json`` (atomically); returns the
    path. Only a skill whose teaching reached its goal is written (ExecutorError otherwise)."""
    path = skill_path(folder, skill.shape)
    _check_taught(path, skill)
    make_folder(path.parent)
    return write_atomic(path, json.dumps(skill.to_json(), indent=1) + "\n")


def load_skill(folder: Path, shape: str) -> Skill:
    """The stored skill of a part shape; ExecutorError if it was never taught."""
    path = skill_path(folder, shape)
    if not path.is_file():
        raise ExecutorError(
            f"part shape '{shape}': no demonstration at {path} (expected one; run ./run.sh executor teach "
            f"--assembly {folder})")
    text = read_text(path, "taught skill (JSON)", error=ExecutorError)
    try:
        skill = Skill.from_json(json.loads(text))
    except (ValueError, KeyError, TypeError) as exc:
        raise ExecutorError(f"{path}: not a taught skill ({type(exc).__name__}: {str(exc)[:80]}); "
                            "run ./run.sh executor teach") from None
    _check_taught(path, skill)
    return skill


SECTION_TOLERANCE = 1e-6
"""[m] a recorded side and the product's that differ by more are a changed section (the
record keeps 9 decimals, so a saved skill matches its product exactly)."""


def load_product_skill(geometry: CellGeometry, shape: str) -> Skill:
    """The stored skill of ``shape`` (:func:`load_skill`), refused (ExecutorError naming
    the file and the change) unless the part and the hole it was taught on are still in the
    product with the sections its record gives: a part resized or a hole reshaped since
    the teaching would run a skill never shown to fit there."""
    skill = load_skill(geometry.folder, shape)
    assert skill.taught is not None  # load_skill refuses a skill without its record
    taught, path = skill.taught, skill_path(geometry.folder, shape)
    part, hole = geometry.parts.get(taught.part), geometry.holes.get(taught.hole)
    for role, recorded, kind, sides in (("part", part, taught.part_kind, taught.part_sides),
                                        ("hole", hole, taught.hole_kind, taught.hole_sides)):
        name = taught.part if role == "part" else taught.hole
        if recorded is None:
            raise ExecutorError(f"{path}: taught on {role} {name}, which the product no longer has; "
                                "run ./run.sh executor teach")
        if recorded.kind != kind or max(abs(a - b) for a, b in zip(recorded.sides, sides)) > SECTION_TOLERANCE:
            raise ExecutorError(f"{path}: taught on {role} {name} {_section(kind, sides)}, the product's {name} is "
                                f"{_section(recorded.kind, recorded.sides)}; run ./run.sh executor teach")
    if part is not None and part.shape != shape:
        raise ExecutorError(f"{path}: taught on part {taught.part}, whose shape is now {part.shape}, not {shape}; "
                            "run ./run.sh executor teach")
    return skill


def check_product_skills(geometry: CellGeometry) -> None:
    """The skill of every part shape of the product loads and was taught on it as it is
    (:func:`load_product_skill`); ExecutorError naming the first that is not. A cell runs
    this before it serves, so a bad skill ends it at the start, not at its first request."""
    for shape in sorted({part.shape for part in geometry.parts.values()}):
        load_product_skill(geometry, shape)


def _section(kind: str, sides: tuple[float, float]) -> str:
    """``round 10.00 x 10.00 mm``: a section's kind and sides."""
    a, b = sides
    return f"{kind} {1000 * a:.2f} x {1000 * b:.2f} mm"


def _check_taught(path: Path, skill: Skill) -> None:
    """ExecutorError naming ``path`` unless ``skill`` records a teaching that reached its goal."""
    if skill.taught is None:
        raise ExecutorError(f"{path}: no record of its teaching (expected \"taught\": the part, the hole and the "
                            "end error); run ./run.sh executor teach")
    if not skill.taught.reached:
        raise ExecutorError(f"{path}: its demonstration did not reach its goal ({skill.taught.failure()}); "
                            "run ./run.sh executor teach with a demo_hole the part passes")


class PhaseClock:
    """DMP time with phase stopping: t advances by dt / (1 + ‖ΔF‖ / F_slow) [s]."""

    def __init__(self, times: np.ndarray, positions: np.ndarray, quats_xyzw: np.ndarray, f_slow: float) -> None:
        self.times, self.positions, self.quats, self.f_slow = times, positions, quats_xyzw, f_slow
        self.t = 0.0
        self.duration = float(times[-1])

    @property
    def phase(self) -> float:
        return min(1.0, self.t / self.duration)

    @property
    def done(self) -> bool:
        return self.t >= self.duration

    def advance(self, dt: float, force_deviation: float) -> None:
        self.t = min(self.duration, self.t + dt / (1.0 + force_deviation / self.f_slow))

    def pose(self) -> tuple[np.ndarray, np.ndarray]:
        """Desired position [m] and quaternion xyzw at the current DMP time."""
        k = min(int(self.t / ROLLOUT_DT), len(self.times) - 2)
        a = (self.t - self.times[k]) / (self.times[k + 1] - self.times[k])
        pos = (1 - a) * self.positions[k] + a * self.positions[k + 1]
        quat = (1 - a) * self.quats[k] + a * self.quats[k + 1]
        return pos, quat / math.sqrt(quat.dot(quat))  # ‖quat‖ as np.linalg.norm computes it
