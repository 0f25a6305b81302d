"""``./run.sh bench assemble``: plans drawn uniformly from a precedence relation, each
assembled in a fresh simulated cell with monitoring and re-planning.

    ./run.sh bench assemble --plans N --seed S [--run RUN | FACTS.lp ...] [--assembly A]
                            [--jobs J] [--backend sim|truth] [--timeout S] [--json]
                            [--uncertainty random|cell [--cell-seed C] [--layer L] [--<magnitude> X ...]]

The relation and the sizes: the learned facts of a session's run folder
(``RUN/learned.lp``) or of facts files, else the assembly's true ones (``precedence.lp``,
``sizes.lp``).  Plan k (1..N) is a sequence drawn exactly uniformly among the sequences
the relation admits (:class:`asp.precedence.count.UniformSampler`, as
``precedence sample``) with a hole assignment drawn uniformly among the feasible ones
(at most :data:`ASSIGNMENT_LIMIT`; Cranfield has 4), both from ``random.Random(S)``;
every plan passes the checker.  Plan k runs in a cell of its own started for it
(``executor serve``, a fresh world) whose random errors have seed S + k; with
``--uncertainty cell`` every cell has the cell options' uncertainty and layer
(:func:`asp.assemble.settings.assembling_cell_settings`, the same cell seed for all).

Prints per plan (to stderr with ``--json``), as it finishes: the plan, assembled,
re-plans, the worst final pose error of any part [mm] and the wall time [s] (cell
start-up included); then the summary: plans assembled, plans with every part within
:data:`TOLERANCE_MM`, the worst pose error and the median wall time.  Exit code 1
when a plan is not assembled or a part ends farther than the tolerance, else 0.
"""

from __future__ import annotations

import argparse
import json
import random
import statistics
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from asp import PlannerError
from asp.assemble.cli import session_plans, truth_facts, truth_sources
from asp.assemble.driver import assembling_cell
from asp.assemble.execute import AssemblyStopped, execute
from asp.assemble.inputs import check_facts_product
from asp.assemble.settings import MAX_STEP_S, assembling_cell_settings
from asp.plans.assign import LearnedFacts, all_assignments, load_learned_facts, product_facts
from asp.plans.plans import Plan, PlanStep, check_plan
from asp.precedence.count import UniformSampler
from asp.precedence.relation import Relation
from bridge.assembly import Assembly, load_assembly
from bridge.cell_settings import (
    DEFAULT_CELL,
    CellSettings,
    ServeSettings,
    add_assembly_uncertainty_argument,
    add_cell_arguments,
    cell_settings_of,
)
from bridge.cli_types import (
    MAX_SEED,
    ArgumentParser,
    add_assembly_argument,
    add_jobs_argument,
    finite_float,
    int_in,
)
from bridge.progress import progress

ASSIGNMENT_LIMIT = 10_000
"""A plan's assignment is drawn among at most this many feasible ones (clingo's first)."""

TOLERANCE_MM = 2.0
"""The issue's target: every part within this distance of its goal pose [mm]."""


def draw_plans(facts: LearnedFacts, n: int, seed: int) -> list[Plan]:
    """``n`` plans: each a sequence drawn uniformly among those ``facts.must_precede``
    and the cell's own orders admit (:attr:`asp.plans.assign.LearnedFacts.plan_order`),
    with a feasible hole assignment drawn uniformly; all from ``random.Random(seed)``.
    PlannerError when one fails the checker (it cannot: the checker guards the sampler)."""
    rng = random.Random(seed)
    sampler = UniformSampler(Relation.from_pairs(facts.parts, facts.plan_order))
    assignments = all_assignments(facts, ASSIGNMENT_LIMIT)
    drawn = []
    for _ in range(n):
        sequence = sampler.sample(rng)
        holes = rng.choice(assignments)
        plan = Plan(tuple(PlanStep(part, holes.get(part)) for part in sequence))
        errors = check_plan(facts, plan.steps)
        if errors:
            raise PlannerError(f"drawn plan {plan_text(plan.as_json())} fails the checker: {', '.join(errors)}")
        drawn.append(plan)
    return drawn


def plan_text(steps: list[dict]) -> str:
    """``bp p1->r1 ...``: a plan's parts in order, with their holes."""
    return " ".join(s["part"] + (f"->{s['hole']}" if s["hole"] else "") for s in steps)


def run_plan(assembly: Assembly, facts: LearnedFacts, plan: Plan, seed: int, timeout_s: float,
             backend: str = "sim", cell: CellSettings = DEFAULT_CELL) -> dict:
    """Assemble ``plan`` in a fresh cell (random errors seeded with ``seed``); the
    execution report with ``wall_s`` [s] and ``error`` (null, or why it stopped);
    ``cell``: the sim cell's settings."""
    started = time.perf_counter()
    error = None
    try:
        with assembling_cell(ServeSettings(assembly=str(assembly.folder), backend=backend, cell=cell), seed,
                             timeout_s) as driver:
            report = execute(facts, plan, driver)
    except AssemblyStopped as exc:
        report, error = exc.report, str(exc)
    except PlannerError as exc:  # the cell did not start or a step timed out: this plan failed
        report = {"plan": plan.as_json(), "steps": [], "assembled": False, "manual": [], "final_pose_error_mm": {},
                  "replans": [], "observations": [], "final_plan": plan.as_json()}
        error = str(exc)
    return dict(report, seed=seed, wall_s=round(time.perf_counter() - started, 3), error=error)


def _worst(report: dict) -> tuple[str | None, float]:
    errors = report["final_pose_error_mm"]
    if not errors:
        return None, float("nan")
    part = max(errors, key=lambda p: errors[p])
    return part, float(errors[part])


def _within(report: dict) -> bool:
    return bool(report["assembled"]) and _worst(report)[1] <= TOLERANCE_MM


def _median(values: list[float], digits: int) -> float | None:
    return round(statistics.median(values), digits) if values else None


def summary(reports: list[dict]) -> dict:
    """The figures over all plans (worst pose error [mm], median wall [s]) and over their
    steps at the cell (median simulated and cell wall time of a step [s]; the steps the
    arm carried out, not those placed by hand)."""
    worst = [(_worst(r)[1], _worst(r)[0], k) for k, r in enumerate(reports, start=1) if r["final_pose_error_mm"]]
    top = max(worst) if worst else (float("nan"), None, None)
    steps = [s for r in reports for s in r.get("steps", []) if s.get("skill") != "manual"]
    return {"plans": len(reports), "assembled": sum(bool(r["assembled"]) for r in reports),
            "within_tolerance": sum(_within(r) for r in reports), "tolerance_mm": TOLERANCE_MM,
            "worst_pose_error_mm": top[0], "worst_part": top[1], "worst_plan": top[2],
            "replans": sum(len(r["replans"]) for r in reports),
            "median_wall_s": _median([r["wall_s"] for r in reports], 1),
            "steps": len(steps), "median_step_sim_s": _median([s["sim_time_s"] for s in steps], 3),
            "median_step_cell_s": _median([s["duration_s"] for s in steps], 3)}


def _row(k: int, report: dict) -> str:
    part, worst = _worst(report)
    line = (f"{k:>2}: {plan_text(report['plan'])}  assembled {report['assembled']}, "
            f"{len(report['replans'])} re-plan(s), worst {worst:.2f} mm ({part}), {report['wall_s']:.1f} s")
    return line + (f"; {report['error']}" if report["error"] else "")


def _facts(args: argparse.Namespace) -> tuple[Assembly, LearnedFacts]:
    if args.run is not None and args.facts:
        raise PlannerError("expected --run RUN or FACTS.lp files, not both")
    name = args.assembly
    paths = list(args.facts)
    if args.run is not None:
        name = name or session_plans(args.run)[0].assembly
        paths = [args.run / "learned.lp"]
    assembly = load_assembly(name or "cranfield")
    facts = load_learned_facts(paths, product_facts(assembly)) if paths else truth_facts(assembly)
    check_facts_product(assembly, facts, ", ".join(map(str, paths)) or truth_sources(assembly))
    return assembly, facts


def build_parser() -> argparse.ArgumentParser:
    parser = ArgumentParser(prog="bench assemble", description=__doc__.split("\n\n")[0])
    parser.add_argument("facts", nargs="*", type=Path, metavar="FACTS.lp",
                        help="learned facts files (default: the assembly's true precedence and sizes)")
    parser.add_argument("--run", type=Path, metavar="RUN", help="a session's run folder: its learned facts")
    add_assembly_argument(parser, default=None, purpose="its parts, holes and geometry (default: the run's, "
                                                        "else cranfield)")
    parser.add_argument("--plans", type=int_in(1, 10_000), default=20, metavar="N",
                        help="plans to draw and assemble (default 20)")
    parser.add_argument("--seed", type=int_in(0, MAX_SEED - 10_000), default=0,
                        help="seed of the draw; plan k's cell has seed S + k (default 0)")
    add_jobs_argument(parser, "cells")
    parser.add_argument("--backend", choices=("sim", "truth"), default="sim",
                        help="the cells: sim (PyBullet, default) or truth (geometry rule, no simulation)")
    parser.add_argument("--timeout", type=finite_float(0.0, MAX_STEP_S, low_open=True), default=300.0, metavar="S",
                        help="one step at the cell [s] (default 300)")
    parser.add_argument("--json", action="store_true", help="print JSON {\"plans\": [report, ...], \"summary\"}")
    add_assembly_uncertainty_argument(parser)
    add_cell_arguments(parser)
    return parser


def main(argv: list[str]) -> int:
    args = build_parser().parse_args(argv)
    cell = assembling_cell_settings(cell_settings_of(args), args.backend)
    assembly, facts = _facts(args)
    drawn = draw_plans(facts, args.plans, args.seed)
    reports: list[dict] = [{}] * len(drawn)

    def one(k: int) -> None:
        reports[k] = run_plan(assembly, facts, drawn[k], args.seed + k + 1, args.timeout, args.backend, cell)
        print(_row(k + 1, reports[k]), file=sys.stderr if args.json else sys.stdout, flush=True)

    with ThreadPoolExecutor(max_workers=args.jobs) as pool:
        list(progress(pool.map(one, range(len(drawn))), desc="plans", total=len(drawn), unit="plan"))
    result = summary(reports)
    if args.json:
        print(json.dumps({"plans": reports, "summary": result}))
    else:
        print(f"assembled {result['assembled']}/{result['plans']}, every part within {TOLERANCE_MM} mm: "
              f"{result['within_tolerance']}/{result['plans']}; worst pose error "
              f"{result['worst_pose_error_mm']:.2f} mm ({result['worst_part']}, plan {result['worst_plan']}); "
              f"{result['replans']} re-plan(s); "
              f"median wall {result['median_wall_s']} s; {result['steps']} steps at the cell, median "
              f"{result['median_step_sim_s']} s simulated, {result['median_step_cell_s']} s wall at the cell")
    return 0 if result["within_tolerance"] == result["plans"] else 1
