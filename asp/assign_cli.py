"""``./run.sh assign FACTS.lp ... [--all] [--json]``: hole assignments from learned facts.

Prints the paper's greedy assignment (ASP's first one if greedy gets stuck on sizes that
are not a biorder although an assignment exists), or with ``--all`` every feasible one.
JSON: ``{"assignments": [{"p1": "r1", ...}, ...]}``. An unsolvable assembly exits with
code 3 (bad input: 2) and names the part that gets no hole; with ``--json`` stdout also
gets ``{"assignments": [], "error": "...", "part": "sh"}``.
"""

from __future__ import annotations

import argparse
import json
import sys

from asp.assign import UnsolvableAssembly, all_assignments, feasible_assignment, load_learned_facts

EXIT_UNSOLVABLE = 3
"""Exit code of a valid but unsolvable assembly (bad input exits with 2)."""


def facts_parser(prog: str, description: str) -> argparse.ArgumentParser:
    """A parser taking learned facts files and ``--json`` (shared by assign and plan)."""
    parser = argparse.ArgumentParser(prog=prog, description=description)
    parser.add_argument("facts", nargs="+", metavar="FACTS.lp",
                        help="learned facts files (part/1, hole/1, fits/2, must_precede/2, ...)")
    parser.add_argument("--json", action="store_true", help="print JSON on stdout")
    return parser


def report_unsolvable(exc: UnsolvableAssembly, key: str, as_json: bool) -> int:
    """Print why the assembly is unsolvable (stderr; JSON with an empty ``key`` list)."""
    print(f"error: {exc}", file=sys.stderr)
    if as_json:
        print(json.dumps({key: [], "error": str(exc), "part": exc.part}))
    return EXIT_UNSOLVABLE


def main(argv: list[str]) -> int:
    parser = facts_parser(
        "./run.sh assign",
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
