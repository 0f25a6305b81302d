"""``./run.sh plan FACTS.lp ... [-n K] [--optimal --assembly A] [--json]``: complete plans.

JSON: ``{"plans": [[{"part": p, "hole": h|null}, ...], ...]}``; with ``--optimal`` also
``"cost"``: the total tool travel of each plan [mm] (all optimal plans share it; clingo
has proven it is the least). An unsolvable assembly exits with code 3 like ``assign``.
"""

from __future__ import annotations

import json

import clingo

from asp import PlannerError
from asp.assign import UnsolvableAssembly, load_learned_facts
from asp.assign_cli import EXIT_UNSOLVABLE, facts_parser, report_unsolvable
from asp.facts import write_facts
from asp.plans import HOME, Plan, plans, travel_facts
from bridge.assembly import load_assembly


def _text(plan: Plan) -> str:
    return ", ".join(step.part if step.hole is None else f"{step.part}->{step.hole}"
                     for step in plan.steps)


def main(argv: list[str]) -> int:
    parser = facts_parser(
        "./run.sh plan",
        "Complete assembly plans from learned facts: orders of all parts respecting "
        "must_precede, each part that needs a hole in a distinct hole it fits. "
        f"Exit {EXIT_UNSOLVABLE}: the assembly is not solvable.",
    )
    parser.add_argument("-n", type=int, default=1, metavar="K", help="how many plans (0 = all; default 1)")
    parser.add_argument("--optimal", action="store_true",
                        help="plans of least total tool travel [mm] (needs --assembly)")
    parser.add_argument("--assembly", metavar="A", help="assembly (name under data/ or folder) for positions")
    parser.add_argument("--home", type=float, nargs=2, default=HOME, metavar=("X", "Y"),
                        help="tool home [m] (default: 0 0, the cell origin)")
    parser.add_argument("--time-limit", type=float, metavar="S",
                        help="give up (exit 2) when the search takes longer than S seconds")
    parser.add_argument("--travel-out", metavar="FILE.lp",
                        help="also write the travel/3 facts (leg lengths [mm]) for plain clingo")
    args = parser.parse_args(argv)
    if args.n < 0:
        raise PlannerError(f"-n {args.n}: expected 0 (all) or a positive number of plans")
    if (args.optimal or args.travel_out) and not args.assembly:
        raise PlannerError("--optimal and --travel-out need --assembly (part and hole positions)")
    facts = load_learned_facts(args.facts)
    travel: list[clingo.Symbol] = []
    if args.optimal or args.travel_out:
        travel = travel_facts(load_assembly(args.assembly), facts, tuple(args.home))
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
