"""Learning across executions: iterative learning control (paper 3.1, after Abu-Dakka et
al. 2015 and Bristow et al. 2006), and the switchable execution layers it belongs to.

A feed-forward pose correction c(φ) = (dx, dy, dz, rx, ry) over the DMP phase φ
(``bins`` bins) is added to the commanded pose of the insertion: the axes the
admittance adapts and the insertion axis z, where the largest systematic deviations
are (a tilted tight peg wedges and pushes back; a hole with more friction than the
teaching one brakes).  After an execution that reached its goal, with e(φ) the mean
wrench deviation (Fx, Fy, Fz, Mx, My) in each bin:

    c_{k+1}(φ) = clip( λ · smooth( c_k(φ) + L · S · e_k(φ) ), ±bound )

S = diag(1/K_t, 1/K_t, 1/K_t, 1/K_r, 1/K_r) is the impedance controller's compliance (a pose
offset of d changes the contact wrench by about K·d), L the learning gain (share of the
error corrected per execution: in contact the systematic error shrinks by about 1 − L
per execution), λ the forgetting factor (the Q filter: what is not confirmed again
fades, so a one-off error does not stay), the z column faded out over the last 20 % of
the phase (``Z_TAPER_FROM``: the end stays where it was taught) and ``smooth`` a moving average over
``smoothing`` bins (no learning of contact noise).  The bound is the admittance's
(2 mm, 0.035 rad), and the insertion bounds the sum of correction and admittance offset
by it too (z by the translation bound): where a deviation cannot be removed by moving the part (a reference wrench
taught in a tighter hole), the correction saturates instead of drifting.  The next
execution so starts from what the previous ones learned about the systematic part of
the error (habitual grasp tilt and offset, a hole's calibration bias); the random part
stays for the on-line admittance.

Failed executions do not update c (their error is an obstruction, not an offset).
Corrections are keyed per (part shape, hole): docs/decisions.md says why.  The state
is saved as JSON (:meth:`Ilc.save`, atomically) and read back by :meth:`Ilc.load`.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import msgspec
import numpy as np

from bridge.cell_settings import LAYER_NAMES
from bridge.files import write_atomic
from bridge.inputs import duplicate_key, read_bytes, shorten
from executor import ExecutorError
from executor.control.admittance import AdmittanceParams

if TYPE_CHECKING:
    from executor.control.gains import ImpedanceGains

AXES = 5
"""The corrected axes: dx, dy, dz [m], rx, ry [rad]."""


def offset_bound(admittance: AdmittanceParams) -> np.ndarray:
    """Largest pose offset (dx, dy, dz [m], rx, ry [rad]) of correction plus admittance:
    the admittance's bounds (z by the translation bound)."""
    return np.array([admittance.bound] * 3 + [admittance.rot_bound] * 2)

Z_TAPER_FROM = 0.8
"""From this phase on the z correction fades linearly to 0 at the end: ILC shapes the
push along the way, never where the trajectory ends (the goal check stays the taught one)."""


@dataclass(frozen=True)
class ExecutionLayer:
    """Which parts of the paper's execution layer run (the hole search, the wiggle and the
    second attempt always do): the admittance (off: pure position control along the
    DMP), its integral part (off: P only), DMP phase stopping, ILC; ``stiff`` tracks the
    insertion with the cell description's ``position_gains`` (an
    industrial arm's position control) instead of the compliant impedance."""

    name: str
    admittance: bool
    integral: bool
    phase_stopping: bool
    ilc: bool
    stiff: bool


_POSITION, _ADMITTANCE_P, _ADMITTANCE_PI, _PI_PHASE_STOP, _FULL = LAYER_NAMES
LAYERS = {layer.name: layer for layer in (
    ExecutionLayer(_POSITION, admittance=False, integral=False, phase_stopping=False, ilc=False, stiff=True),
    ExecutionLayer(_ADMITTANCE_P, admittance=True, integral=False, phase_stopping=False, ilc=False, stiff=False),
    ExecutionLayer(_ADMITTANCE_PI, admittance=True, integral=True, phase_stopping=False, ilc=False, stiff=False),
    ExecutionLayer(_PI_PHASE_STOP, admittance=True, integral=True, phase_stopping=True, ilc=False, stiff=False),
    ExecutionLayer(_FULL, admittance=True, integral=True, phase_stopping=True, ilc=True, stiff=False),
)}
"""The variants of the ablation, from the least to the whole layer."""


def layer_named(name: str) -> ExecutionLayer:
    """The layer called ``name``; ExecutorError listing the known ones."""
    if name not in LAYERS:
        raise ExecutorError(f"unknown execution layer '{name}' (expected one of {', '.join(LAYERS)})")
    return LAYERS[name]


class IlcParams(msgspec.Struct, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """Phase bins, learning gain L (dimensionless), forgetting factor λ (dimensionless,
    per execution), smoothing window [bins] (at most the bins)."""

    bins: Annotated[int, msgspec.Meta(ge=1, le=10000, description="an integer in 1 .. 10000")] = 50
    learning_gain: Annotated[float, msgspec.Meta(gt=0.0, le=1.0, description="a number in (0, 1]")] = 0.5
    forgetting: Annotated[float, msgspec.Meta(gt=0.0, le=1.0, description="a number in (0, 1]")] = 0.95
    smoothing: Annotated[int, msgspec.Meta(ge=1, le=10000, description="an integer in 1 .. 10000")] = 5


@dataclass
class ExecutionTrace:
    """What one execution recorded per control step: phase (N,) and wrench deviation
    (N, 5) (Fx, Fy, Fz [N], Mx, My [Nm])."""

    phase: list[float] = field(default_factory=list)
    error: list[np.ndarray] = field(default_factory=list)

    def add(self, phase: float, error: np.ndarray) -> None:
        self.phase.append(phase)
        self.error.append(error)


class Ilc:
    """The corrections of one cell, per key, with how many executions taught each."""

    def __init__(self, params: IlcParams, gains: ImpedanceGains, admittance: AdmittanceParams) -> None:
        """``gains``: the controller's (its compliance S); ``admittance``: whose bounds
        bound the corrections (:func:`offset_bound`)."""
        self.params = params
        self.bound = offset_bound(admittance)
        centres = (np.arange(params.bins) + 0.5) / params.bins
        self.z_taper = np.clip((1.0 - centres) / (1.0 - Z_TAPER_FROM), 0.0, 1.0)
        self.gain = params.learning_gain / np.array([gains.k_trans] * 3 + [gains.k_rot] * 2)
        self.corrections: dict[str, np.ndarray] = {}
        self.iterations: dict[str, int] = {}

    def correction(self, key: str) -> tuple[np.ndarray, int]:
        """The (bins, 5) correction [m, m, m, rad, rad] of ``key`` and its iteration count."""
        return self.corrections.get(key, np.zeros((self.params.bins, AXES))), self.iterations.get(key, 0)

    def update(self, key: str, trace: ExecutionTrace) -> np.ndarray:
        """Learn from one successful execution; returns the new correction."""
        p = self.params
        old, iteration = self.correction(key)
        if not trace.phase:
            return old
        index = np.minimum((np.asarray(trace.phase) * p.bins).astype(int), p.bins - 1)
        count = np.bincount(index, minlength=p.bins)[:, None]
        sums = np.zeros((p.bins, AXES))
        np.add.at(sums, index, self.gain * np.asarray(trace.error))
        mean = np.divide(sums, count, out=np.zeros_like(sums), where=count > 0)
        kernel = np.ones(p.smoothing) / p.smoothing
        padded = np.pad(old + mean, ((p.smoothing // 2, p.smoothing - 1 - p.smoothing // 2), (0, 0)), mode="edge")
        smooth = np.stack([np.convolve(padded[:, j], kernel, mode="valid") for j in range(AXES)], axis=1)
        smooth[:, 2] *= self.z_taper
        self.corrections[key] = np.clip(p.forgetting * smooth, -self.bound, self.bound)
        self.iterations[key] = iteration + 1
        return self.corrections[key]

    def to_json(self) -> dict:
        return {"params": msgspec.structs.asdict(self.params), "keys": {
            key: {"iterations": self.iterations[key], "correction": c.tolist()}
            for key, c in sorted(self.corrections.items())}}

    def save(self, path: Path) -> None:
        """Write the state to ``path`` atomically (JSON)."""
        write_atomic(path, json.dumps(self.to_json()) + "\n")

    def load(self, path: Path) -> None:
        """Read the corrections saved at ``path`` (nothing if it does not exist);
        ExecutorError naming the file and the key if it is not such a state
        (:func:`read_state`)."""
        corrections, iterations = read_state(path, self.params, self.bound)
        self.corrections.update(corrections)
        self.iterations.update(iterations)


MAX_ITERATIONS = 2**31 - 1
"""The largest iteration count of a key an ILC state file may hold."""
MAX_KEY_CHARS = 200
"""The longest key (``shape:hole``) an ILC state file may hold."""


def read_state(path: Path, params: IlcParams, bound: np.ndarray) -> tuple[dict[str, np.ndarray], dict[str, int]]:
    """The corrections and iteration counts by key of the ILC state saved at ``path``
    (both empty if it does not exist), as :meth:`Ilc.save` writes it for ``params``.

    ExecutorError, one line naming the file and the key, unless it is a JSON object
    ``{"params": ..., "keys": {"<shape>:<hole>": {"iterations": N, "correction": C}}}``
    with ``params`` those of the cell (if given), each N an integer in 0 ..
    :data:`MAX_ITERATIONS` and each C a (bins, 5) list of finite numbers within
    ±``bound`` per axis (:func:`offset_bound`: what an update can produce).  Checked when the cell
    starts, so a damaged file is refused there, never at the first insertion."""
    if not path.exists():
        return {}, {}
    data = read_bytes(path, "ILC state file (JSON)", error=ExecutorError)
    try:
        state = json.loads(data)
        twice = duplicate_key(data)
    except (ValueError, UnicodeDecodeError) as exc:
        raise ExecutorError(f"{path}: not valid JSON ({shorten(exc, 80)}); expected the ILC state a cell saved") \
            from None
    except RecursionError:
        raise ExecutorError(f"{path}: nested too deeply; expected the ILC state a cell saved") from None

    def refuse(where: str, expected: str) -> ExecutorError:
        return ExecutorError(f"{path}: {where}: expected {expected} (the ILC state a cell saved)")

    if twice is not None:
        raise refuse(f"the key {shorten(repr(twice))}", "each key once in one object")
    if not isinstance(state, dict) or not set(state) <= {"params", "keys"} or "keys" not in state:
        raise refuse("the file", 'an object {"params": {...}, "keys": {...}}')
    if "params" in state and state["params"] != msgspec.structs.asdict(params):
        raise refuse('"params"', f"this cell's {json.dumps(msgspec.structs.asdict(params))}")
    keys = state["keys"]
    if not isinstance(keys, dict):
        raise refuse('"keys"', 'an object {"<shape>:<hole>": {"iterations": N, "correction": [...]}}')
    corrections: dict[str, np.ndarray] = {}
    iterations: dict[str, int] = {}
    for key, entry in keys.items():
        where = f'"keys" {shorten(json.dumps(key, ensure_ascii=True))}'
        shape, _colon, hole = key.partition(":")
        if len(key) > MAX_KEY_CHARS or not shape or not hole:
            raise refuse(where, f'a key "<shape>:<hole>" of at most {MAX_KEY_CHARS} characters')
        if not isinstance(entry, dict) or set(entry) != {"iterations", "correction"}:
            raise refuse(where, '{"iterations": N, "correction": [...]}')
        count = entry["iterations"]
        if type(count) is not int or not 0 <= count <= MAX_ITERATIONS:
            raise refuse(f"{where} iterations", f"an integer in 0 .. {MAX_ITERATIONS}, got "
                         f"{shorten(json.dumps(count, ensure_ascii=True))}")
        corrections[key], iterations[key] = _correction(entry["correction"], params.bins, bound, refuse, where), count
    return corrections, iterations


def _correction(rows: object, bins: int, bound: np.ndarray, refuse: Callable[[str, str], ExecutorError],
                where: str) -> np.ndarray:
    """The (bins, 5) correction array of the JSON ``rows``; ``refuse(where, expected)``
    raised naming the first bad row or value."""
    if not isinstance(rows, list) or len(rows) != bins:
        raise refuse(f"{where} correction", f"a list of {bins} rows (one per phase bin)")
    for k, row in enumerate(rows):
        if not isinstance(row, list) or len(row) != AXES:
            raise refuse(f"{where} correction[{k}]", f"a row of {AXES} numbers (dx, dy, dz [m], rx, ry [rad])")
        for axis, (value, limit) in enumerate(zip(row, bound, strict=True)):
            if type(value) not in (int, float) or not abs(value) <= limit:
                raise refuse(f"{where} correction[{k}][{axis}]", f"a number within ±{limit:g} "
                             f"{'m' if axis < 3 else 'rad'}, got {shorten(json.dumps(value, ensure_ascii=True))}")
    return np.array(rows, dtype=float)


_NORM_UNITS = np.array([1000.0, 1000.0, 1000.0, np.degrees(1.0), np.degrees(1.0)])


def correction_norm(correction: np.ndarray) -> float:
    """Size of a correction: RMS over the phase of the norm of (dx, dy, dz [mm], rx, ry [°]),
    so 1 means about a millimetre or a degree."""
    return float(np.sqrt(np.mean(np.sum((correction * _NORM_UNITS) ** 2, axis=1))))
