"""``assembly-constraints``: the one command line of the planner and the cell.

``assembly-constraints [-v | -q] SUBCOMMAND [ARGS...]`` runs one subcommand; each takes
``--help``. :data:`SUBCOMMANDS` is the one registry: the planner's subcommands, the cell's
under ``executor`` (:mod:`executor.cli`), the benchmarks of both under ``bench``
(:data:`BENCHMARKS`), and ``protocol``, which writes the published message schemas
(:mod:`bridge.protocol_schema`). The tests run this same command line.
Modules are imported lazily, so ``--help`` of one subcommand does not pay for the others.

Exit codes (:mod:`bridge.errors`): 0 done, 1 a check failed, 2 bad input or usage (a
missing subcommand too; every :class:`bridge.errors.ToolError`), 3 an unsolvable
assembly, 130 interrupted (Ctrl-C), 143 terminated (SIGTERM; both after the processes the
command started were stopped), 141 stdout closed.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import sys
from collections.abc import Callable, Sequence

from assembly_constraints import __version__
from bridge.cli_types import PROGRAM, ArgumentParser, configure_logging, run_command
from bridge.errors import ToolError

BENCHMARKS: dict[str, str] = {
    "precedence": "asp.bench.precedence",
    "sizes": "asp.bench.sizes",
    "plan": "asp.bench.plans",
    "session": "asp.bench.session",
    "dominance": "asp.bench.dominance",
    "mesh": "asp.bench.mesh",
    "precedence-physics": "asp.bench.precedence_physics",
    "precedence-explore": "asp.bench.precedence_explore",
    "assemble": "asp.bench.assemble_plans",
    "executor": "executor.campaign.bench",
    "reach": "executor.campaign.reach",
    "rates": "executor.campaign.rates",
    "physics": "executor.campaign.physics",
    "engines": "executor.campaign.engines",
    "import": "executor.campaign.import_bench",
    "corpus": "assembly_constraints.corpus_bench",
}
"""``bench TOPIC``: topic → the module whose ``main(argv)`` runs it (each prints its figures)."""

SUBCOMMANDS: dict[str, tuple[str, str]] = {
    "precedence": ("asp.precedence.cli", "learn/count/sample/evaluate/suggest precedence"),
    "sizes": ("asp.sizes.cli", "learn/evaluate which part fits which hole"),
    "assign": ("asp.plans.cli:assign_main", "hole assignments from learned facts"),
    "plan": ("asp.plans.cli:plan_main", "complete assembly plans from learned facts"),
    "session": ("asp.session.cli", "the end-to-end learning session (planner + cells)"),
    "assemble": ("asp.assemble.cli",
                 "execute a plan in a simulated cell, monitored and re-planned"),
    "view": ("asp.view.cli", "open a session's Rerun recording"),
    "bench": ("assembly_constraints.cli:bench_main", "benchmarks (bench TOPIC --help): " + ", ".join(BENCHMARKS)),
    "executor": ("executor.cli",
                 "the simulated PyBullet cell: teach, trial, campaign, margins, serve, export"),
    "import": ("executor.cad.cli",
               "a product from its CAD (STEP or meshes): holes, sections, geometric precedence"),
    "protocol": ("bridge.protocol_schema",
                 "write or check the JSON Schema of every Zenoh message"),
    "router": ("bridge.session:router_main",
               "a Zenoh router (router mode of eclipse-zenoh) for cells on other hosts"),
}
"""Every subcommand: name → (``module`` or ``module:function`` taking argv, one-line help)."""


def bench_main(argv: list[str]) -> int:
    """``bench TOPIC``: the planner's and the cell's benchmarks (:data:`BENCHMARKS`)."""
    parser = ArgumentParser(prog="bench", description="Benchmarks: each prints its figures (medians, ratios); "
                            "docs/results.md lists the measured values and the commands.")
    parser.add_argument("topic", nargs="?", choices=list(BENCHMARKS), metavar="TOPIC",
                        help=f"one of: {', '.join(BENCHMARKS)}")
    parser.add_argument("arguments", nargs=argparse.REMAINDER, metavar="ARGS",
                        help="the benchmark's options (see bench TOPIC --help)")
    args = parser.parse_args(argv)
    if args.topic is None:
        parser.error(f"expected a benchmark, one of: {', '.join(BENCHMARKS)}")
    return int(_entry(BENCHMARKS[args.topic])(args.arguments) or 0)


def build_parser() -> argparse.ArgumentParser:
    """The top of the parser tree: global options and the subcommand's name; the
    subcommand parses the rest of the arguments itself."""
    commands = SUBCOMMANDS
    listing = "\n".join(f"  {name:<11} {text}" for name, (_, text) in commands.items())
    parser = ArgumentParser(
        prog=PROGRAM, formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Learn assembly constraints by demonstration and active exploration: precedence\n"
                    "from demonstrated sequences, which part fits which hole from a robot cell's\n"
                    "experiments, and complete assembly plans.",
        epilog=f"subcommands (each takes --help):\n{listing}\n\n"
               "exit codes: 0 done, 1 a check failed, 2 bad input or usage, 3 an unsolvable assembly")
    parser.add_argument("--version", action="version", version=f"{PROGRAM} {__version__}",
                        help="print the version and exit")
    loudness = parser.add_mutually_exclusive_group()
    loudness.add_argument("-v", "--verbose", action="store_true",
                          help="also log details (log level DEBUG)")
    loudness.add_argument("-q", "--quiet", action="store_true",
                          help="log errors only: no progress, no warnings (log level ERROR)")
    parser.add_argument("subcommand", nargs="?", choices=list(commands), metavar="SUBCOMMAND",
                        help=f"one of: {', '.join(commands)}")
    parser.add_argument("arguments", nargs=argparse.REMAINDER, metavar="ARGS",
                        help="the subcommand's arguments (see SUBCOMMAND --help)")
    return parser


def _entry(target: str) -> Callable[[list[str]], int]:
    module, _, function = target.partition(":")
    return getattr(importlib.import_module(module), function or "main")


def main(argv: Sequence[str] | None = None) -> int:
    """Run one subcommand; returns its exit code (see the module's docstring)."""
    parser = build_parser()
    args = parser.parse_args(list(sys.argv[1:] if argv is None else argv))
    if args.subcommand is None:
        parser.error(f"expected a subcommand, one of: {', '.join(SUBCOMMANDS)} (see --help)")
    configure_logging(logging.DEBUG if args.verbose else logging.ERROR if args.quiet else logging.INFO)
    target, _ = SUBCOMMANDS[args.subcommand]
    return run_command(lambda: int(_entry(target)(args.arguments) or 0), (ToolError,))


if __name__ == "__main__":
    sys.exit(main())
