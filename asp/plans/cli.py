"""The ``assign`` and ``plan`` commands: hole assignments and complete plans from learned facts.

``./run.sh assign FACTS.lp ... [--all] [--json]`` prints the paper's greedy assignment
(ASP's first one if greedy gets stuck on sizes that are not a biorder although an
assignment exists), or with ``--all`` every feasible one.
JSON: ``{"assignments": [{"p1": "r1", ...}, ...]}``. An unsolvable assembly exits with
code 3 (bad input: 2) and names the part that gets no hole; with ``--json`` stdout also
gets ``{"assignments": [], "error": "...", "part": "sh"}``.

``./run.sh plan FACTS.lp ... [-n K] [--optimal --assembly A] [--json]``: complete plans.
JSON: ``{"plans": [[{"part": p, "hole": h|null}, ...], ...]}``; with ``--optimal`` also
``"cost"``: the total tool travel of each plan [mm] (all optimal plans share it; clingo
has proven it is the least). An unsolvable assembly exits with code 3 like ``assign``.
"""

from __future__ import annotations

import argparse
import json
import sys

import clingo

from asp import PlannerError
from asp.plans.assign import (
    UnsolvableAssembly,
    all_assignments,
    feasible_assignment,
    load_learned_facts,
    product_facts,
)
from asp.plans.plans import HOME, Plan, plans, travel_facts
from asp.solve import write_facts
from bridge.assembly import MAX_COORDINATE, load_assembly
from bridge.cli_types import ArgumentParser, add_assembly_argument, finite_float, int_in
from bridge.errors import EXIT_UNSOLVABLE

MAX_PLANS = 1_000_000
"""``plan -n K``: at most this many plans (0 = all)."""

MAX_TIME_LIMIT = 86_400.0
"""``plan --time-limit S``: at most a day [s]."""


def facts_parser(prog: str, description: str) -> argparse.ArgumentParser:
    """A parser taking learned facts files and ``--json`` (shared by assign and plan)."""
    parser = ArgumentParser(prog=prog, description=description)
    parser.add_argument("facts", nargs="+", metavar="FACTS.lp",
                        help="learned facts files (part/1, hole/1, fits/2, must_precede/2, ...)")
    parser.add_argument("--json", action="store_true", help="print JSON on stdout")
    return parser


def report_unsolvable(exc: UnsolvableAssembly, key: str, as_json: bool) -> int:
    """Print why the assembly is unsolvable (stderr; JSON with an empty ``key`` list)."""
    print(f"error: {exc}", file=sys.stderr)
    if as_json:
        print(json.dumps({key: [], "error": str(exc), "part": exc.part, "parts": list(exc.parts)}))
    return EXIT_UNSOLVABLE


def assign_main(argv: list[str]) -> int:
    """``./run.sh assign``."""
    parser = facts_parser(
        "assign",
        "Hole assignments from learned facts: the paper's greedy one (biggest part first "
        "into the smallest free hole it fits; ASP's first one if greedy gets stuck on sizes "
        f"that are not a biorder), or every feasible one. Exit {EXIT_UNSOLVABLE}: "
        "the assembly is not solvable (the part without a hole is named).",
    )
    parser.add_argument("--all", action="store_true", help="every feasible assignment (ASP)")
    args = parser.parse_args(argv)
    facts = load_learned_facts(args.facts)
    try:
        assignments = all_assignments(facts) if args.all else [feasible_assignment(facts)]
    except UnsolvableAssembly as exc:
        return report_unsolvable(exc, "assignments", args.json)
    if args.json:
        print(json.dumps({"assignments": [dict(sorted(a.items())) for a in assignments]}))
    else:
        for assignment in assignments:
            print(" ".join(f"{part}->{hole}" for part, hole in sorted(assignment.items())))
    return 0


def _text(plan: Plan) -> str:
    return ", ".join(step.part if step.hole is None else f"{step.part}->{step.hole}"
                     for step in plan.steps)


def plan_main(argv: list[str]) -> int:
    """``./run.sh plan``."""
    parser = facts_parser(
        "plan",
        "Complete assembly plans from learned facts: orders of all parts respecting "
        "must_precede, each part that needs a hole in a distinct hole it fits. "
        f"Exit {EXIT_UNSOLVABLE}: the assembly is not solvable.",
    )
    parser.add_argument("-n", "--plans", dest="n", type=int_in(0, MAX_PLANS), default=1, metavar="K",
                        help="how many plans (0 = all; default 1; as session --plans)")
    parser.add_argument("--optimal", action="store_true",
                        help="plans of least total tool travel [mm] (needs --assembly)")
    add_assembly_argument(parser, None, purpose="gives the positions for --optimal, how many parts each hole "
                                                "takes and the holes the cell can use")
    parser.add_argument("--home", type=finite_float(-MAX_COORDINATE, MAX_COORDINATE), nargs=2, default=HOME,
                        metavar=("X", "Y"),
                        help="tool home [m] (default: 0 0, the cell origin)")
    parser.add_argument("--time-limit", type=finite_float(0.0, MAX_TIME_LIMIT, low_open=True), metavar="S",
                        help="give up (exit 2) when the search takes longer than S seconds")
    parser.add_argument("--travel-out", metavar="FILE.lp",
                        help="also write the travel/3 facts (leg lengths [mm]) for plain clingo")
    args = parser.parse_args(argv)
    if (args.optimal or args.travel_out) and not args.assembly:
        raise PlannerError("--optimal and --travel-out need --assembly (part and hole positions)")
    assembly = load_assembly(args.assembly) if args.assembly else None
    facts = load_learned_facts(args.facts, () if assembly is None else product_facts(assembly))
    travel: list[clingo.Symbol] = []
    if assembly is not None and (args.optimal or args.travel_out):
        travel = travel_facts(assembly, facts, tuple(args.home))
    if args.travel_out:
        write_facts(args.travel_out, travel, header="travel(From,To,D): leg lengths [mm]")
    try:
        found = plans(facts, args.n, optimal=args.optimal, travel=travel, time_limit_s=args.time_limit)
    except UnsolvableAssembly as exc:
        return report_unsolvable(exc, "plans", args.json)
    if args.json:
        result: dict[str, object] = {"plans": [plan.as_json() for plan in found]}
        if args.optimal:
            result["cost"] = found[0].cost
        print(json.dumps(result))
    else:
        for plan in found:
            cost = f" (travel {plan.cost} mm)" if plan.cost is not None else ""
            print(_text(plan) + cost)
    return 0
