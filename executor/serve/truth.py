"""The ``truth`` backend of a cell node: answers from the cell's geometry (cross-sections),
or where the product has no ``geometry.toml`` from its ``sizes.lp``, and precedence
experiments from the product's ``precedence.lp``, without simulation, optionally after a
delay, to measure the bridge and test the protocol quickly."""

from __future__ import annotations

import time
import uuid
from pathlib import Path

import clingo

from bridge import BridgeError
from bridge.assembly import load_assembly
from bridge.cell_settings import ServeSettings
from bridge.inputs import read_bytes
from bridge.messages import Evidence, InsertRequest, Result, StepEvidence, StepRequest
from bridge.precedence.experiment import FailureReason, PrecedenceExperiment, first_missing
from bridge.recording.sinks import NO_VIEWER, Viewer
from executor import ExecutorError
from executor.backend_plugin import (
    ExperimentRun,
    InvalidStep,
    StepOutcome,
    UnknownPair,
    check_experiment,
    check_run,
    check_step,
)
from executor.world.geometry import feature_passes, load_geometry


def _facts(path: Path, what: str, expected: str) -> list[clingo.Symbol]:
    """The atoms of the ASP facts file ``path``; ExecutorError naming it when it does not parse."""
    control = clingo.Control(["--warn=none"])
    try:
        control.add("base", [], read_bytes(path, what).decode("utf-8", "replace"))
        control.ground([("base", [])])
    except RuntimeError:
        raise ExecutorError(f"{path}: expected ASP facts {expected} (it does not parse)") from None
    return [atom.symbol for atom in control.symbolic_atoms]


def sizes_truth(path: Path) -> tuple[set[str], set[str], set[tuple[str, str]]]:
    """The pegs (``part/1``), holes (``hole/1``) and ``fits/2`` pairs of a product's
    ``sizes.lp`` (closed world); ExecutorError naming the file when it does not parse."""
    atoms = _facts(path, "sizes (ASP facts)", "part/1, hole/1, fits/2")
    pegs = {str(a.arguments[0]) for a in atoms if a.match("part", 1)}
    holes = {str(a.arguments[0]) for a in atoms if a.match("hole", 1)}
    return pegs, holes, {(str(a.arguments[0]), str(a.arguments[1])) for a in atoms if a.match("fits", 2)}


def precedence_truth(path: Path) -> set[tuple[str, str]]:
    """The transitive closure of the ``precedence_edge/2`` and ``must_precede/2`` pairs of a
    product's ``precedence.lp``; ExecutorError naming the file when it does not parse."""
    atoms = _facts(path, "precedence (ASP facts)", "part/1, precedence_edge/2")
    pairs = {(str(a.arguments[0]), str(a.arguments[1])) for a in atoms
             if a.match("precedence_edge", 2) or a.match("must_precede", 2)}
    while True:
        longer = pairs | {(a, d) for a, b in pairs for c, d in pairs if b == c}
        if longer == pairs:
            return pairs
        pairs = longer


class TruthBackend:
    """Answers without simulation, after ``settings.delay_s`` [s]: from the cell's geometry
    (a part passes a hole when its cross-section does,
    :func:`executor.world.geometry.feature_passes`), or from the product's
    ``sizes.lp`` where it has no ``geometry.toml`` (the parts ``geometry.toml`` places by
    hand answer from ``sizes.lp`` on its holes the geometry has not: the pins an imported
    part goes onto); logs every outcome to Rerun if
    ``settings.rrd`` or ``settings.viewer_url`` is given; a hole of ``settings.block_holes``
    refuses every plan step. A precedence experiment's step fails when a part that must
    precede it (:func:`precedence_truth`) is not placed (``precedence``, at the later part's
    step, :func:`bridge.precedence.experiment.first_missing`) or its peg does not
    pass its hole (``size``) or its hole is blocked (``blocked``); a placed part missing such a
    part does not stay."""

    def __init__(self, settings: ServeSettings) -> None:
        assembly, cell_id = settings.assembly, settings.cell_id
        rrd, viewer = None if settings.rrd is None else Path(settings.rrd), Viewer(settings.viewer_url)
        try:
            assembly_of = load_assembly(assembly)
            if assembly_of.has_file("geometry.toml"):
                geometry = load_geometry(assembly)
                self._pegs, self._holes = set(geometry.parts), set(geometry.holes)
                self._manual: set[str] = set(geometry.tables.manual)
                self._fits = {(p, h) for p, part in geometry.parts.items() for h, hole in geometry.holes.items()
                              if feature_passes(part, hole)}
                if assembly_of.has_file("sizes.lp"):  # parts placed by hand onto features the cell does not model
                    pegs, holes, fits = sizes_truth(assembly_of.file("sizes.lp"))
                    pegs &= self._manual
                    holes -= self._holes
                    self._pegs |= pegs
                    self._holes |= holes
                    self._fits |= {(p, h) for p, h in fits if p in pegs or h in holes}
            else:
                self._pegs, self._holes, self._fits = sizes_truth(assembly_of.file("sizes.lp"))
                self._manual = set()
        except BridgeError as exc:
            raise ExecutorError(f"truth backend: {exc}") from None
        self._delay_s = settings.delay_s
        self._blocked = set(settings.block_holes)
        self._parts = tuple(assembly_of.part_ids)
        self._precedence_file = assembly_of.file("precedence.lp") if assembly_of.has_file("precedence.lp") else None
        self._precedence: set[tuple[str, str]] | None = None  # read on the first experiment
        self._run: str | None = None  # the plan run whose product is being built
        self._placed: dict[str, float] = {}  # its placed parts
        self._log = None
        if rrd is not None or viewer != NO_VIEWER:
            from executor.rerun_log import open_recording

            self._log = open_recording(settings.recording_id or str(uuid.uuid4()), rrd, viewer)
            self._entity = f"executor/{cell_id}/outcome"

    def run(self, request: InsertRequest) -> tuple[Result, Evidence | None]:
        if request.part not in self._pegs or request.hole not in self._holes:
            raise UnknownPair(f"unknown pair ({request.part},{request.hole}); expected a part "
                              f"of {tuple(sorted(self._pegs))} and a hole of {tuple(sorted(self._holes))}")
        if self._delay_s > 0:
            time.sleep(self._delay_s)  # stands in for the duration of a real insertion
        result: Result = "fit" if (request.part, request.hole) in self._fits else "no_fit"
        if self._log is not None:
            import rerun as rr

            if request.experiment:
                self._log.set_time("experiment", sequence=request.experiment)
            self._log.log(self._entity, rr.TextLog(f"{request.part}->{request.hole}: {result}"))
        return result, None

    def run_step(self, request: StepRequest) -> StepOutcome:
        """A peg fits when its cross-section passes the hole and the hole is not blocked;
        another part of the product is always placed (skill ``manual`` for one placed by
        hand). One plan run at a time; a step of another run, or one the product does not
        allow, is refused before anything changes
        (:func:`executor.backend_plugin.check_run`,
        :func:`executor.backend_plugin.check_step`)."""
        check_run(self._run, request.assembly, self._parts, self._placed)
        fresh = request.assembly != self._run
        check_step(request.part, request.hole, parts=self._parts, pegs=self._pegs, holes=self._holes,
                   placed=() if fresh else self._placed)
        if fresh:
            self._run, self._placed = request.assembly, {}
        placed = self._placed
        ok = request.hole is None or (request.hole not in self._blocked and (request.part, request.hole) in self._fits)
        if ok:
            placed[request.part] = 0.0
        skill = "manual" if request.part in self._manual else "truth"
        evidence = StepEvidence(skill=skill, attempts=1 if ok else 2, max_force_dev=0.0, max_torque_dev=0.0,
                                duration_s=0.0, sim_time_s=0.0, pose_error_mm=0.0)
        return ("fit" if ok else "no_fit"), evidence, dict(placed)

    def run_precedence(self, experiment: PrecedenceExperiment) -> ExperimentRun:
        check_experiment(experiment, parts=self._parts, pegs=self._pegs, holes=self._holes)
        if self._precedence is None:
            if self._precedence_file is None:
                raise ExecutorError("truth backend: the product has no precedence.lp to answer precedence "
                                    "experiments from")
            self._precedence = precedence_truth(self._precedence_file)
        if self._delay_s > 0:
            time.sleep(self._delay_s)
        placed = {step.part for step in experiment.placed}
        unstable = sorted(p for p in placed if self._missing(p, placed))
        if unstable:
            raise InvalidStep(f"the known state does not hold: {', '.join(unstable)} placed without "
                              f"{', '.join(sorted(set().union(*(self._missing(p, placed) for p in unstable))))}, "
                              "which the product's precedence puts first")
        before = {p: {a for a in self._parts if (a, p) in self._precedence} for p in self._parts}
        first = first_missing(experiment, before)
        for k, step in enumerate(experiment.sequence, start=1):
            if first is not None and first[0] == k:
                return ExperimentRun(k, "precedence", detail=f"{step.part} precedence (without "
                                     f"{' '.join(first[2])}; the truth backend, no physics)")
            reason: FailureReason | None = (
                "blocked" if step.hole in self._blocked else
                "size" if step.hole is not None and (step.part, step.hole) not in self._fits else None)
            if reason is not None:
                return ExperimentRun(k, reason, detail=f"{step.part} {reason} (into {step.hole}; the truth "
                                     "backend, no physics)")
        return ExperimentRun()

    def _missing(self, part: str, placed: set[str]) -> list[str]:
        """The parts the product's precedence puts before ``part`` that are not ``placed``, sorted."""
        assert self._precedence is not None
        return sorted(a for a in self._parts if (a, part) in self._precedence and a not in placed)

    def close(self) -> None:
        if self._log is not None:
            self._log.flush()
