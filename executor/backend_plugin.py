"""What a cell's backend implements, and loading one by name (``serve --backend module:Class``).

``executor serve`` answers the protocol (docs/protocol.md: validation, idempotency, queue,
liveliness); a backend only runs experiments. A real cell plugs in its robot by writing a
class with

- ``__init__(self, context: CellContext)``: connect to the robot; raise
  :class:`executor.ExecutorError` with a one-line message if it cannot (exit 2);
- ``run(self, request: InsertRequest) -> tuple[Result, Evidence | None]``: insert
  ``request.part`` into ``request.hole`` once and say ``"fit"`` or ``"no_fit"``, with
  the measurements if there are any. Raise :class:`UnknownPair` for a part or hole the
  cell does not have (the planner gets ``unknown_id``), :class:`executor.ExecutorError`
  when the experiment could not run (``failed``, which the planner sends again);
- ``run_step(self, request: StepRequest) -> StepOutcome``: carry out one step of a plan
  (``./run.sh assemble``), keeping the product between the steps of one plan run, one
  run at a time (:func:`check_run`: :class:`RunActive`, the planner gets ``run_active``);
  a step the product does not allow raises :class:`InvalidStep` (``invalid_step``, see
  :func:`check_step`) before anything moves; a cell that only learns may raise
  :class:`executor.ExecutorError` (the planner gets ``failed``);
- optionally ``run_precedence(self, experiment: PrecedenceExperiment) -> ExperimentRun``: a
  precedence experiment (set the ``placed`` parts at their goals, assemble ``sequence``,
  stop at the first failing step and say why), checked first with
  :func:`check_experiment`; :class:`InvalidStep` when the placed parts do not stay where
  they were set; a backend without it answers ``failed``;
- ``close(self)``: release the robot.

``run`` is called from one thread, one experiment at a time. Start it with
``assembly-constraints executor serve --backend my_package.my_module:MyBackend
--backend-option speed=0.2`` (the module must be importable: installed, or on
``PYTHONPATH``). :class:`executor.replay.ReplayBackend` is a worked example; docs/backends.md
describes the interface and docs/ros2.md how a backend reaches a ROS 2 robot.
"""

from __future__ import annotations

import importlib
import re
from collections.abc import Collection, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Protocol

from bridge.messages import Evidence, InsertRequest, Result, StepEvidence, StepRequest
from bridge.precedence.experiment import FailureReason, PrecedenceExperiment
from executor import ExecutorError, UnknownPair

_SPEC = re.compile(r"^([A-Za-z_][\w.]*):([A-Za-z_]\w*)$")


class InvalidStep(ExecutorError):
    """A plan step the product does not allow: a peg without a hole of the plate, a hole
    for a part placed without one, a part already placed."""


class RunActive(ExecutorError):
    """A plan step of another run while the cell's world holds an unfinished run."""


def check_step(part: str, hole: str | None, *, parts: Collection[str], pegs: Collection[str],
               holes: Collection[str], placed: Collection[str]) -> None:
    """Refuse a step before anything moves: UnknownPair for a part not of the product
    (``parts``), InvalidStep for a peg (``pegs``) without a hole of ``holes``, a hole for
    another part, or a part already ``placed``."""
    if part not in parts:
        raise UnknownPair(f"unknown part '{part}' (expected one of {', '.join(sorted(parts))})")
    if part in pegs and hole not in holes:
        raise InvalidStep(f"peg '{part}' needs a hole of the plate ({', '.join(sorted(holes))}), got {hole!r}")
    if part not in pegs and hole is not None:
        raise InvalidStep(f"part '{part}' is placed without a hole, got hole '{hole}'")
    if part in placed:
        raise InvalidStep(f"part '{part}' is already placed")


def check_run(current: str | None, run: str, parts: Collection[str], placed: Collection[str]) -> None:
    """RunActive when a step of plan run ``run`` comes while the world belongs to run
    ``current`` (None: no run yet) and its product is unfinished (a part of ``parts`` is
    not ``placed``): a cell's world holds one product, another run must wait until it is
    complete (or the cell restarts); the refused step changes nothing."""
    if current is not None and run != current and not set(parts) <= set(placed):
        raise RunActive(f"plan run {current} holds the cell's world ({len(set(placed) & set(parts))} of "
                        f"{len(parts)} parts placed); a step of run {run} waits until that product is "
                        "complete or the cell restarts")


StepOutcome = tuple[Result, StepEvidence, dict[str, float]]
"""A plan step's outcome, its evidence and every placed part's distance from its goal [mm]."""


@dataclass(frozen=True)
class ExperimentRun:
    """What a cell saw carrying out a precedence experiment: the 1-based ``failed_step`` of
    its sequence and the ``reason`` (None, None: every step done), the placed parts the
    failing part touched where it stopped (``blocked_by``, observed), a one-line ``detail``
    and the simulated time ``sim_s`` [s]."""

    failed_step: int | None = None
    reason: FailureReason | None = None
    blocked_by: tuple[str, ...] = ()
    detail: str = ""
    sim_s: float = 0.0


def check_experiment(experiment: PrecedenceExperiment, *, parts: Collection[str], pegs: Collection[str],
                     holes: Collection[str]) -> None:
    """Refuse a precedence experiment before anything moves: every step of ``placed`` then
    ``sequence`` checked by :func:`check_step` against the ones before it, and InvalidStep
    for a hole given twice."""
    placed: list[str] = []
    used: set[str] = set()
    for step in (*experiment.placed, *experiment.sequence):
        check_step(step.part, step.hole, parts=parts, pegs=pegs, holes=holes, placed=placed)
        if step.hole is not None and step.hole in used:
            raise InvalidStep(f"hole '{step.hole}' is given twice (the second time to {step.part}); "
                              "expected every hole at most once")
        placed.append(step.part)
        if step.hole is not None:
            used.add(step.hole)


class Backend(Protocol):
    """Runs one insertion experiment or one plan step."""

    def run(self, request: InsertRequest) -> tuple[Result, Evidence | None]:
        """The outcome and its evidence; ExecutorError for a bad part or hole."""
        ...

    def run_step(self, request: StepRequest) -> StepOutcome:
        """The plan step's outcome (the cell keeps its world between the steps of one plan
        run); ExecutorError for a bad part or hole, or when the cell cannot run plan steps."""
        ...

    def close(self) -> None: ...


@dataclass(frozen=True)
class CellContext:
    """What ``executor serve`` tells a backend it loads: the cell's id, the assembly (a
    shipped one's name or a folder), where to save a Rerun recording (None: none) under
    which recording id, and the ``--backend-option KEY=VALUE`` pairs."""

    cell_id: str
    assembly: str
    rrd: Path | None = None
    recording_id: str | None = None
    options: Mapping[str, str] = field(default_factory=dict)

    def option(self, key: str) -> str:
        """The value of ``--backend-option KEY=...``; ExecutorError when it was not given."""
        if key not in self.options:
            raise ExecutorError(f"this backend needs --backend-option {key}=...")
        return self.options[key]


def load_backend(spec: str, context: CellContext) -> Backend:
    """Import ``module:Class`` and construct it with ``context``; ExecutorError naming the
    spec when the module or class is missing or the class lacks ``run``/``close``."""
    match = _SPEC.match(spec)
    if match is None:
        raise ExecutorError(f"--backend {spec!r}: expected sim, truth or MODULE:CLASS")
    module_name, class_name = match.groups()
    try:
        module = importlib.import_module(module_name)
    except ImportError as exc:
        raise ExecutorError(f"--backend {spec}: cannot import {module_name} ({exc})") from None
    factory = getattr(module, class_name, None)
    if not isinstance(factory, type) or not all(callable(getattr(factory, m, None)) for m in ("run", "close")):
        raise ExecutorError(f"--backend {spec}: expected a class {class_name} in {module_name} "
                            "with the methods run(request) and close()")
    return factory(context)
