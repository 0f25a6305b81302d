"""The settings of a learning session, and ``RUN/session.json``, their encoding.

:class:`SessionSettings` is one start of a session, built once at the edge (the command
line, :mod:`asp.session.cli`, or :func:`assembly_constraints.api.run_session`).
:class:`SessionFile` is ``session.json``: the settings that stay with the run folder
(assembly, policy, model, seed, confirmations, demonstrations, the cells' settings, the
size prior), the recording id and the count of starts, and, once the session is done, its result.
:func:`read_session_file` is its one decoder: a resume, ``assemble --run``, ``bench
assemble``, the summary and :func:`assembly_constraints.api.read_run` read it.

A folder written before the settings were typed (``"cell_options"``: the cell's options
as command-line arguments, no ``"format"``) is decoded too: its options are read as the
fields of :class:`bridge.cell_settings.CellSettings`.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping
from pathlib import Path
from typing import Annotated, Any, Literal

import msgspec
from msgspec import UNSET, Meta, UnsetType

from asp import PlannerError
from asp.sizes.cad_prior import MAX_TOLERANCE_M, prior_text
from asp.sizes.learner import MAX_CONFIRM
from asp.sizes.models import MODELS
from asp.sizes.policies import policy_names
from asp.sizes.truth_oracle import Result
from bridge.cell_settings import (
    DEFAULT_CELL,
    MAGNITUDE_FIELDS,
    CellSettings,
    Seed,
    validation_text,
)
from bridge.files import write_atomic
from bridge.inputs import read_bytes, shorten
from bridge.messages import MAX_RUN_ID as MAX_RECORDING_ID

SESSION_FILE = "session.json"
SESSION_FORMAT = 2
"""The format ``session.json`` is written in (1: the untyped one, without ``"format"``)."""
MAX_WAIT_S = 86_400.0
"""``timeout_s``, ``wait_for_cell_s``: at most a day [s]; ``delay_s`` at most an hour."""
MAX_CELLS = 64
"""``cells``: at most this many cell co-processes."""
MAX_PLANS = 1000
"""``plans``: at most this many plans (they are written to session.json)."""
MAX_STARTS = 1_000_000
"""The most starts (the first and its resumes) a run folder records."""
MAX_DELAY_S = 3600.0
"""``delay_s``: at most an hour [s]."""
PRODUCT_FILES = ("assembly.toml", "geometry.toml", "sizes.lp", "precedence.lp", "demos.txt", "nominal_sizes.lp")
"""The files of a product folder its digest covers (the meshes ``geometry.toml`` names are
pinned by the SHA-256 it states for each)."""
PRESENT_PRODUCT_FILES = ("cell_order.lp",)
"""Files the digest covers where present (an absent one leaves the digest of the others as
it was): the cell's own orders an import writes for the fingers' grip."""

RecordingId = Annotated[str, Meta(pattern=rf"^[A-Za-z0-9_-]{{1,{MAX_RECORDING_ID}}}$")]
Digest = Annotated[str, Meta(pattern=r"^[0-9a-f]{64}$")]
Backend = Literal["sim", "truth", "franka"]
Delay = Annotated[float, Meta(ge=0.0, le=MAX_DELAY_S)]
Confirm = Annotated[int, Meta(ge=0, le=MAX_CONFIRM)]
Tolerance = Annotated[float, Meta(ge=0.0, le=MAX_TOLERANCE_M)]
PrecedenceMode = Literal["demos", "explore"]
PRECEDENCE_MODES: tuple[PrecedenceMode, ...] = ("demos", "explore")


def _check_choices(policy: str, model: str | None, size_prior: str | None, tolerance_m: float) -> None:
    """ValueError (msgspec reports it with the struct's path) unless ``policy`` and ``model``
    are known and a tolerance comes with a prior."""
    if policy not in policy_names():
        raise ValueError(f"policy {policy!r}: expected one of {', '.join(policy_names())}")
    if model is not None and model not in MODELS:
        raise ValueError(f"model {model!r}: expected null or one of {', '.join(MODELS)}")
    if size_prior is None and tolerance_m:
        raise ValueError(f"tolerance_m {tolerance_m:g}: applies to size_prior \"cad\" only (expected 0 without it)")


class SessionSettings(msgspec.Struct, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """One start of a session.

    What is learned: ``assembly`` (a shipped one's name or a folder), ``policy``,
    ``model`` (None: the product's, else ``sections``), ``seed`` (of the policy and the
    trials), ``confirm`` K (re-tests until a result leads by K+1), ``demos`` (a file;
    None: the assembly's ``demos.txt``), ``cell``: the simulated cells' settings, cell
    ``c<k>`` with cell seed ``cell.cell_seed + k - 1`` (the command line sets
    ``cell.cell_seed`` to ``seed``), ``size_prior`` (``cad``: the learner starts from the
    outcomes the assembly's nominal sections decide beyond ``tolerance_m`` [m],
    :mod:`asp.sizes.cad_prior`; None: no prior), and the ``backend``
    of the cells it starts (``truth``: each experiment takes ``delay_s`` [s]), ``precedence``
    (``demos``: Algorithm 1 on the demonstrations; ``explore``: at most 2 of them, the
    geometric precedence and experiments at the cell, :mod:`asp.session.precedence`). These
    are kept in ``session.json``; a resume takes them from there and ignores its own.
    ``backend_options``: the ``--backend-option`` pairs of those cells (a ``franka`` cell's
    ``host``, ...: how to reach the arm, not what is learned, so not kept).

    How: ``out`` (None: ``runs/<UTC time>``) or ``resume`` (a run folder); ``cells``
    co-processes to start (0: use cells on the network, only ``allow_cells`` if given); ``timeout_s`` [s]
    one experiment at one cell before it is sent again; ``wait_for_cell_s`` [s] while no
    cell is alive; ``plans``: how many to compute; ``assemble``: then assemble plan 1 in
    the first cell; ``listen``, ``connect``, ``zenoh_config``: the planner's Zenoh
    endpoints and config file.
    """

    assembly: str = "cranfield"
    policy: str = "best"
    model: str | None = None
    seed: Seed = 0
    confirm: Confirm = 0
    demos: str | None = None
    cell: CellSettings = DEFAULT_CELL
    size_prior: Literal["cad"] | None = None
    tolerance_m: Tolerance = 0.0
    precedence: PrecedenceMode = "demos"
    out: str | None = None
    resume: str | None = None
    cells: Annotated[int, Meta(ge=0, le=MAX_CELLS)] = 1
    backend: Backend = "sim"
    backend_options: dict[str, str] = {}
    delay_s: Delay = 0.0
    timeout_s: Annotated[float, Meta(gt=0.0, le=MAX_WAIT_S)] = 120.0
    wait_for_cell_s: Annotated[float, Meta(ge=0.0, le=MAX_WAIT_S)] = 60.0
    plans: Annotated[int, Meta(ge=1, le=MAX_PLANS)] = 5
    allow_cells: tuple[str, ...] | None = None
    assemble: bool = False
    listen: tuple[str, ...] = ()
    connect: tuple[str, ...] = ()
    zenoh_config: str | None = None


def checked(settings: SessionSettings) -> SessionSettings:
    """``settings`` if every field is in its range and the policy and model are known (a
    struct built in Python is not checked as a decoded one is); PlannerError naming the
    field otherwise."""
    try:
        _check_choices(settings.policy, settings.model, settings.size_prior, settings.tolerance_m)
        return msgspec.convert(msgspec.to_builtins(settings), SessionSettings)
    except msgspec.ValidationError as exc:
        raise PlannerError(f"session settings: {validation_text(exc)}") from None
    except ValueError as exc:
        raise PlannerError(f"session settings: {exc}") from None


class DecidedPrior(msgspec.Struct, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """What a session's size prior decided: its ``kind`` (``cad``), ``tolerance_m`` [m],
    the ``pairs`` it was over (parts × holes learned) and the outcomes it ``decided``
    ([part, hole, result])."""

    kind: Literal["cad"]
    tolerance_m: Tolerance
    pairs: Annotated[int, Meta(ge=0)]
    decided: list[tuple[str, str, Result]]


class NominalFits(msgspec.Struct, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """The fits whose room in the CAD is under what a sim session's cell resolves (nominal
    zero-clearance fits, room 0; bores on pins with a positive room under it) that the cell
    tries, built with ``room_m`` [m] per side (:data:`bridge.product.nominal.NOMINAL_FIT_ROOM`):
    the ``pairs`` [part, hole] whose outcomes are observed in that model, not at the CAD's
    room; ``cad_room_m``: "part->hole" -> the CAD's room per side [m] of those with room
    above 0 (the others room 0)."""

    room_m: Annotated[float, Meta(gt=0)]
    pairs: list[tuple[str, str]]
    cad_room_m: dict[str, float] = msgspec.field(default_factory=dict)


def fit_text(cad_room_m: Mapping[str, float], part: str, hole: str) -> str:
    """``part->hole``, with the CAD's room per side [mm] where ``cad_room_m``
    (:attr:`asp.session.settings.NominalFits.cad_room_m`) gives one."""
    room = cad_room_m.get(f"{part}->{hole}")
    return f"{part}->{hole}" + ("" if room is None else f" ({room * 1e3:+.4f} mm)")


class SessionFile(msgspec.Struct, kw_only=True, forbid_unknown_fields=True):
    """``RUN/session.json``: the settings kept with the run folder (see
    :class:`SessionSettings`; ``backend`` and ``delay_s`` None in a folder written before
    they were kept), the ``product`` digest (:func:`product_digest`; None: not recorded),
    its Rerun ``recording_id``, how many times it was
    started, ``status`` and the experiments abandoned by resumes; once ``done``, the
    result (the ``session --json`` contract: ``run``, ``experiments``, ``fits``,
    ``must_precede``, ``plans``, ``matches_truth``, and more: the size model used and
    what it assumes, what the size prior decided (``prior``, set at each start; None
    without one), the pairs no cell can try, taken from ``sizes.lp`` and not observed
    (``not_observed``: [part, hole, result], set at each start), the nominal zero-clearance
    fits its sim cell builds with room (``nominal_fits``: :class:`NominalFits`, None
    without), the truth comparison, the assignment, the cells, the journal,
    wall time [s] and timings [s], the assembly run, with ``--precedence explore`` what the
    exploration did (:meth:`asp.session.precedence.ExploredPrecedence.summary`), and the ``error`` when the learned
    product has no complete assignment). Fields not yet known are absent."""

    format: int = SESSION_FORMAT
    assembly: str
    policy: str
    model: str | None = None
    seed: Seed
    confirm: Confirm = 0
    demos: str | None = None
    cell: CellSettings = DEFAULT_CELL
    size_prior: Literal["cad"] | None = None
    tolerance_m: Tolerance = 0.0
    precedence: PrecedenceMode = "demos"
    backend: Backend | None = None
    delay_s: Delay | None = None
    product: Digest | None = None
    recording_id: RecordingId
    starts: Annotated[int, Meta(ge=1, lt=MAX_STARTS)] = 1
    status: Literal["running", "done"] = "running"
    abandoned: list[int] = []
    run: str | UnsetType = UNSET
    experiments: int | UnsetType = UNSET
    fits: list[tuple[str, str]] | UnsetType = UNSET
    must_precede: list[tuple[str, str]] | UnsetType = UNSET
    plans: list[list[dict[str, str | None]]] | UnsetType = UNSET
    matches_truth: bool | None | UnsetType = UNSET
    assumption: str | UnsetType = UNSET
    prior: DecidedPrior | None | UnsetType = UNSET
    model_changes: list[str] | UnsetType = UNSET
    demonstrated: list[tuple[str, str]] | UnsetType = UNSET
    not_observed: list[tuple[str, str, Result]] | UnsetType = UNSET
    nominal_fits: NominalFits | None | UnsetType = UNSET
    truth: dict[str, bool | int | None] | UnsetType = UNSET
    assignment: dict[str, str] | UnsetType = UNSET
    cells: list[str] | UnsetType = UNSET
    journal: list[dict[str, Any]] | UnsetType = UNSET
    wall_s: float | UnsetType = UNSET
    timings: dict[str, float] | UnsetType = UNSET
    assembly_run: dict[str, Any] | UnsetType = UNSET
    precedence_explored: dict[str, Any] | UnsetType = UNSET
    error: str | UnsetType = UNSET

    def __post_init__(self) -> None:
        if self.format != SESSION_FORMAT:
            raise ValueError(f"format {self.format}: expected {SESSION_FORMAT} (written by another version; "
                             "start a new session)")
        _check_choices(self.policy, self.model, self.size_prior, self.tolerance_m)


def prior_statement(prior: DecidedPrior) -> str:
    """The line a run prints (and ``learned.lp`` keeps) as the assumption its size prior makes."""
    return prior_text([((p, h), result) for p, h, result in prior.decided], prior.tolerance_m, prior.pairs)


def new_session_file(settings: SessionSettings, recording_id: str) -> SessionFile:
    """The ``session.json`` of a new run folder (its ``product`` digest is set once the
    product is loaded)."""
    return SessionFile(assembly=settings.assembly, policy=settings.policy, model=settings.model, seed=settings.seed,
                       confirm=settings.confirm, demos=settings.demos, cell=settings.cell,
                       size_prior=settings.size_prior, tolerance_m=settings.tolerance_m,
                       precedence=settings.precedence, backend=settings.backend,
                       delay_s=settings.delay_s, recording_id=recording_id)


KEPT_OPTIONS = {"policy": "--policy", "model": "--model", "seed": "--seed", "confirm": "--confirm",
                "demos": "--demos", "size_prior": "--prior", "tolerance_m": "--tolerance",
                "precedence": "--precedence", "backend": "--backend",
                "delay_s": "--delay"}
"""The settings ``session.json`` keeps (besides ``cell``) and their options."""


def resumed_settings(settings: SessionSettings, record: SessionFile) -> tuple[SessionSettings, list[str]]:
    """The settings a resume runs with: ``settings`` with the backend and delay kept in
    ``record`` (a record without them gets ``settings``' ones, in place), and the options
    of ``settings`` that are not their defaults and differ from what ``record`` keeps (the
    resume ignores them: the run folder's settings win)."""
    if record.backend is None or record.delay_s is None:
        record.backend, record.delay_s = settings.backend, settings.delay_s
    default = SessionSettings()
    ignored = [f"{option} {getattr(settings, name)}" for name, option in KEPT_OPTIONS.items()
               if getattr(settings, name) not in (getattr(default, name), getattr(record, name))]
    seedless = msgspec.structs.replace(settings.cell, cell_seed=record.cell.cell_seed)
    if seedless not in (msgspec.structs.replace(DEFAULT_CELL, cell_seed=record.cell.cell_seed), record.cell):
        ignored.append("the cell options")
    return msgspec.structs.replace(settings, backend=record.backend, delay_s=record.delay_s), ignored


def product_digest(folder: Path) -> str:
    """The SHA-256 (hex) of the product folder's files :data:`PRODUCT_FILES` (each one's
    name and bytes; an absent one counts as absent), and :data:`PRESENT_PRODUCT_FILES` where
    present: equal digests, the same product."""
    digest = hashlib.sha256()
    for name in (*PRODUCT_FILES, *(name for name in PRESENT_PRODUCT_FILES if (folder / name).exists())):
        path = folder / name
        data = read_bytes(path, f"product file {name}", error=PlannerError) if path.exists() else None
        digest.update(f"{name} {-1 if data is None else len(data)}\n".encode())
        digest.update(data or b"")
    return digest.hexdigest()


def _from_format_1(data: dict[str, Any]) -> dict[str, Any]:
    """A ``session.json`` of format 1 as format 2: its ``"cell_options"`` (``["--layer",
    L, "--<magnitude>", "X", ...]``) become ``"cell"``, whose cell seed was the session
    seed; ValueError naming an option that is none of the cell's."""
    options = data.pop("cell_options", [])
    if not isinstance(options, list) or len(options) % 2 or not all(isinstance(arg, str) for arg in options):
        raise ValueError(f'"cell_options" {shorten(json.dumps(options), 80)}: expected pairs of an option '
                         "and its value")
    magnitudes = {field.name for field in MAGNITUDE_FIELDS}
    cell: dict[str, Any] = {"cell_seed": data.get("seed", 0), "magnitudes": {}}
    for option, value in zip(options[::2], options[1::2], strict=True):
        name = option.removeprefix("--").replace("-", "_")
        if name == "layer":
            cell["layer"] = value
        elif name in magnitudes:
            try:
                cell["magnitudes"][name] = float(value)
            except ValueError:
                raise ValueError(f'"cell_options": {option} {shorten(value, 40)}: expected a number') from None
        else:
            raise ValueError(f'"cell_options": {shorten(option, 40)}: expected --layer or a magnitude of the cell')
    return {**data, "format": SESSION_FORMAT, "cell": cell}


def read_session_file(run: Path) -> SessionFile:
    """The ``session.json`` of run folder ``run``; PlannerError naming the file and the
    field, and what was expected, when it is missing, not JSON or not one a session writes."""
    path = run / SESSION_FILE
    if not path.is_file():
        raise PlannerError(f"{run}: not a run folder (expected {SESSION_FILE} in it)")
    data = read_bytes(path, "session settings file (JSON)", error=PlannerError)
    try:
        raw = json.loads(data)
    except (ValueError, RecursionError) as exc:
        raise PlannerError(f"{path}: not JSON ({shorten(exc, 80)}); expected the settings a session wrote") from None
    if not isinstance(raw, dict):
        raise PlannerError(f"{path}: a JSON {type(raw).__name__}; expected an object with the session's settings")
    old = "format" not in raw
    try:
        return msgspec.convert(_from_format_1(raw) if old else raw, SessionFile)
    except msgspec.ValidationError as exc:
        text = validation_text(exc)
        if old and text.startswith('"cell.'):
            text = f'"cell_options" (format 1, read as "cell"): {text}'
        raise PlannerError(f"{path}: {shorten(text, 200)}") from None
    except ValueError as exc:  # format 1's cell options
        raise PlannerError(f"{path}: {shorten(exc, 200)}") from None


def write_session_file(run: Path, record: SessionFile) -> None:
    """Write ``run/session.json`` atomically (indented, the fields not yet known left out)."""
    write_atomic(run / SESSION_FILE, msgspec.json.format(msgspec.json.encode(record), indent=2).decode() + "\n")
