"""``./run.sh bench precedence-physics``: does the cell's physics enforce each precedence constraint?

For every cover edge a->b of the true precedence graph (the transitive reduction of
``precedence.lp``) two sequences run, each in a fresh cell (``executor serve``), step by
step over Zenoh, without re-planning and stopping at the first failed step:

- the violating one: b before a, every other pair of the true closure respected (it
  exists because a cover edge has no other path from a to b); a as early as possible, b
  right before it (``edge_sequences.lp``).  The edge breaks at the step that places a.
  The edge is *enforced* when the cell reports a failure at or before that step;
  a violating sequence the cell completes is reported as such;
- the compliant one: an admitted sequence with a right before b where the other
  constraints allow it, b as early as possible.  It must be assembled.

The cell is not told the precedence: a failure comes from its monitoring (the
insertion's force and goal checks, the part not staying where it was let go).  Holes:
plan 1 of the true facts (every peg keeps its hole in both sequences).  Exit code 1 when
an admitted (compliant) sequence was not assembled.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import ThreadPoolExecutor
from contextlib import AbstractContextManager
from dataclasses import dataclass, field

import clingo

from assembly_constraints.asp import PlannerError
from assembly_constraints.asp.assemble.cli import truth_facts
from assembly_constraints.asp.assemble.driver import assembling_cell
from assembly_constraints.asp.assemble.execute import StepDriver, step_json
from assembly_constraints.asp.plans.plans import PlanStep, plans
from assembly_constraints.asp.precedence.relation import Pair, Relation, reduction, true_relation
from assembly_constraints.asp.solve import fact, solve
from assembly_constraints.bridge import BridgeError
from assembly_constraints.bridge.assembly import Assembly, load_assembly
from assembly_constraints.bridge.cell_settings import ServeSettings
from assembly_constraints.bridge.cli_types import (
    MAX_SEED,
    ArgumentParser,
    add_assembly_argument,
    add_jobs_argument,
    comma_list,
    finite_float,
    int_in,
    nonempty_path,
)
from assembly_constraints.bridge.files import check_writable, write_atomic
from assembly_constraints.bridge.progress import progress

DriverFactory = Callable[[], AbstractContextManager[StepDriver]]
"""Starts a fresh cell for one sequence and yields its driver."""


def edge_sequence(relation: Relation, edge: Pair, violate: bool) -> tuple[str, ...]:
    """The sequence that tests cover edge ``edge`` = (a, b) of the closed ``relation``:
    with ``violate`` b before a and every other pair respected, a as early as possible and
    b right before it; else an admitted sequence with a right before b where possible.
    PlannerError when ``edge`` is not a cover edge."""
    a, b = edge
    if edge not in reduction(relation):
        raise PlannerError(f"{a}-{b}: not a cover edge of the precedence graph (expected one of "
                           f"{', '.join(f'{x}-{y}' for x, y in reduction(relation))})")
    pairs = [p for p in relation.pairs() if p != edge] + [(b, a) if violate else edge]
    atoms = [fact("part", p) for p in relation.parts]
    atoms += [fact("rank", p, k) for k, p in enumerate(relation.parts, start=1)]
    atoms += [fact("must_precede", x, y) for x, y in pairs] + [fact("exercised", *((b, a) if violate else edge))]
    best: list[clingo.Symbol] = []

    def on_model(model: clingo.Model) -> None:
        best[:] = model.symbols(shown=True)

    result = solve(["edge_sequences.lp"], atoms, ["--opt-mode=opt"], on_model)
    if not result.satisfiable:
        raise PlannerError(f"{a}-{b}: no sequence {'violates only this edge' if violate else 'is admitted'}")
    steps = sorted((s.arguments[0].number, str(s.arguments[1])) for s in best)
    return tuple(part for _, part in steps)


def violated_pairs(relation: Relation, sequence: Sequence[str]) -> list[Pair]:
    """The pairs (a, b) of ``relation`` that ``sequence`` places in the order b, a."""
    position = {p: i for i, p in enumerate(sequence)}
    return [(a, b) for a, b in relation.pairs() if position[a] > position[b]]


@dataclass
class SequenceRun:
    """One sequence in one fresh cell: ``steps`` as the cell reported them (stopped at the
    first failure), ``break_step`` (1-based) the step that places the edge's first part."""

    kind: str
    sequence: list[PlanStep]
    break_step: int
    steps: list[dict] = field(default_factory=list)
    error: str | None = None
    wall_s: float = 0.0

    @property
    def failed_step(self) -> int | None:
        """The first step (1-based) that did not fit, or the step the cell could not run."""
        for k, step in enumerate(self.steps, start=1):
            if step["outcome"] != "fit":
                return k
        return len(self.steps) + 1 if self.error else None

    @property
    def completed(self) -> bool:
        return self.failed_step is None and len(self.steps) == len(self.sequence)

    @property
    def detected(self) -> bool:
        """A failure at or before the breaking step."""
        failed = self.failed_step
        return failed is not None and failed <= self.break_step

    def as_json(self) -> dict:
        return {"kind": self.kind, "sequence": [{"part": s.part, "hole": s.hole} for s in self.sequence],
                "break_step": self.break_step, "steps_run": len(self.steps), "failed_step": self.failed_step,
                "detected": self.detected, "completed": self.completed, "error": self.error,
                "wall_s": round(self.wall_s, 3), "steps": self.steps}


def run_sequence(cell: DriverFactory, run: SequenceRun, stop_at_break: bool = False) -> SequenceRun:
    """Run ``run.sequence`` in a fresh cell, stopping at the first failed step (and after
    the breaking step with ``stop_at_break``); a step the cell could not run (an error
    reply, a lost cell) ends the run with ``error`` set."""
    started = time.perf_counter()
    last = run.break_step if stop_at_break else len(run.sequence)
    try:
        with cell() as driver:
            for k, step in enumerate(run.sequence[:last], start=1):
                reply = driver.step(k, step.part, step.hole)
                run.steps.append({**step_json(reply), "pose_errors_mm": {p: round(e, 3)
                                                                         for p, e in reply.pose_errors_mm}})
                if reply.result != "fit":
                    break
    except PlannerError as exc:
        run.error = str(exc)
    run.wall_s = time.perf_counter() - started
    return run


def edge_runs(relation: Relation, holes: dict[str, str | None], edges: Sequence[Pair]) -> Iterator[SequenceRun]:
    """The violating and the compliant run of every edge, not yet run."""
    for a, b in edges:
        for kind, violate in (("violating", True), ("compliant", False)):
            order = edge_sequence(relation, (a, b), violate)
            yield SequenceRun(kind, [PlanStep(p, holes[p]) for p in order], order.index(a if violate else b) + 1)


def verdict(violating: SequenceRun) -> str:
    """What the violating run says about its edge."""
    if violating.error:
        return "cell error"
    if violating.detected:
        return "enforced"
    return "completed (not enforced)" if violating.completed else "failed late"


def _failure_text(run: SequenceRun) -> str:
    failed = run.failed_step
    if failed is None:
        return "-"
    if failed > len(run.steps):
        return f"{failed}: error"
    step = run.steps[failed - 1]
    worst = max(step["pose_errors_mm"].values(), default=None)
    placed = "none placed" if worst is None else f"worst placed {worst:.1f} mm"
    return (f"{failed}: {step['part']} {step['outcome']} ({step['attempts']} att., "
            f"{step['max_force_dev']:.0f} N, {step['pose_error_mm']:.1f} mm; {placed})")


def table(edges: Sequence[Pair], runs: Sequence[SequenceRun]) -> str:
    """The printed table: one line per edge and kind of sequence."""
    lines = [f"{'edge':<7} {'kind':<10} {'sequence':<32} {'break':>5} {'run':>4}  {'first failure':<58} result"]
    for (a, b), (violating, compliant) in zip(edges, zip(runs[0::2], runs[1::2])):
        for run in (violating, compliant):
            result = verdict(run) if run is violating else ("assembled" if run.completed else "NOT ASSEMBLED")
            order = " ".join(s.part for s in run.sequence)
            lines.append(f"{a + '-' + b:<7} {run.kind:<10} {order:<32} {run.break_step:>5} {len(run.steps):>4}  "
                         f"{_failure_text(run):<58} {result}")
    enforced = sum(v.detected for v in runs[0::2])
    completed = sum(v.completed for v in runs[0::2])
    assembled = sum(c.completed for c in runs[1::2])
    lines.append(f"{enforced}/{len(edges)} edges enforced (failure at or before the breaking step), "
                 f"{completed} violating sequence(s) completed, {assembled}/{len(edges)} compliant assembled")
    return "\n".join(lines)


def report_json(assembly: Assembly, seed: int, edges: Sequence[Pair], runs: Sequence[SequenceRun]) -> dict:
    """``{"assembly", "seed", "edges": [{"edge", "verdict", "violating", "compliant"}], "enforced",
    "violating_completed", "compliant_assembled"}``."""
    pairs = list(zip(runs[0::2], runs[1::2]))
    return {"assembly": assembly.name, "seed": seed,
            "edges": [{"edge": f"{a}-{b}", "verdict": verdict(v), "violating": v.as_json(), "compliant": c.as_json()}
                      for (a, b), (v, c) in zip(edges, pairs)],
            "enforced": sum(v.detected for v, _ in pairs), "violating_completed": sum(v.completed for v, _ in pairs),
            "compliant_assembled": sum(c.completed for _, c in pairs)}


def _edge(text: str) -> Pair:
    a, sep, b = text.partition("-")
    if not (sep and a and b):
        raise ValueError(text)
    return a, b


def build_parser() -> argparse.ArgumentParser:
    parser = ArgumentParser(prog="bench precedence-physics", description=__doc__.split("\n\n")[0])
    add_assembly_argument(parser)
    parser.add_argument("--edges", type=comma_list(_edge, "edges A-B"), metavar="A-B,...",
                        help="only these cover edges (default: all)")
    parser.add_argument("--seed", type=int_in(0, MAX_SEED), default=0,
                        help="seed of the cells' random grasp, vision and search errors (default 0)")
    add_jobs_argument(parser, "cells")
    parser.add_argument("--timeout", type=finite_float(0.0, 86_400.0, low_open=True), default=300.0, metavar="S",
                        help="one step at the cell [s] (default 300)")
    parser.add_argument("--json", action="store_true", help="print the JSON result instead of the table")
    parser.add_argument("--out", type=nonempty_path, metavar="FILE", help="also write the JSON result to FILE")
    return parser


def main(argv: list[str]) -> int:
    args = build_parser().parse_args(argv)
    try:
        assembly = load_assembly(args.assembly)
        relation = true_relation(assembly)
        edges = args.edges or reduction(relation)
        holes = {s.part: s.hole for s in plans(truth_facts(assembly), 1)[0].steps}
        pending = list(edge_runs(relation, holes, edges))
        if args.out is not None:
            check_writable(args.out)
    except (PlannerError, BridgeError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2

    def cell() -> AbstractContextManager[StepDriver]:
        return assembling_cell(ServeSettings(assembly=str(assembly.folder)), args.seed, args.timeout)

    with ThreadPoolExecutor(args.jobs) as pool:
        runs = list(progress(pool.map(lambda run: run_sequence(cell, run), pending), desc="sequences",
                             total=len(pending)))
    report = report_json(assembly, args.seed, edges, runs)
    if args.out is not None:
        write_atomic(args.out, json.dumps(report, indent=1) + "\n")
    print(json.dumps(report) if args.json else table(edges, runs))
    return 0 if all(c.completed for c in runs[1::2]) else 1
