"""The planner's command line: ``./run.sh <subcommand> ...``.

Each subcommand is a function ``main(argv) -> int`` of a module (``module:function``
names another function); modules are imported lazily so that ``--help`` of one does not
pay for the others. A
:class:`asp.PlannerError` (bad input) is printed as ``error: ...`` with exit code 2.
"""

from __future__ import annotations

import importlib
import sys

SUBCOMMANDS: dict[str, tuple[str, str]] = {
    "precedence": ("asp.precedence.cli", "learn/count/sample/evaluate/suggest precedence"),
    "sizes": ("asp.sizes.cli", "learn/evaluate which part fits which hole"),
    "assign": ("asp.plans.cli:assign_main", "hole assignments from learned facts"),
    "plan": ("asp.plans.cli:plan_main", "complete assembly plans from learned facts"),
    "session": ("asp.session.run", "the end-to-end learning session (planner + cells)"),
    "assemble": ("asp.assemble.cli", "execute a plan in a simulated cell, monitored and re-planned"),
    "view": ("asp.session.view", "open a session's Rerun recording"),
    "bench": ("asp.bench.cli", "benchmarks: precedence | sizes | plan | executor | session"),
}


def run_guarded(main, argv: list[str]) -> int:
    """Run ``main(argv)``; a PlannerError or BridgeError becomes one line ``error: ...`` on
    stderr and exit 2. When stdout's reader goes away (``... | head -1``) the command stops
    quietly with exit code 141 (:func:`bridge.cli_types.quiet_broken_pipe`)."""
    from asp import PlannerError
    from bridge import BridgeError
    from bridge.cli_types import run_command

    return run_command(lambda: int(main(argv) or 0), (PlannerError, BridgeError))


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    if not argv or argv[0] in ("-h", "--help"):
        print("usage: ./run.sh SUBCOMMAND [ARGS...]\n")
        for name, (_, text) in SUBCOMMANDS.items():
            print(f"  {name:<11} {text}")
        print("  executor    the simulated PyBullet cell (teach, trial, campaign, serve, margins)")
        return 0
    name, rest = argv[0], argv[1:]
    if name not in SUBCOMMANDS:
        print(f"error: unknown subcommand '{name}'; expected one of: "
              f"{', '.join([*SUBCOMMANDS, 'executor', 'test', 'lint'])}", file=sys.stderr)
        return 2
    module_name, _, function = SUBCOMMANDS[name][0].partition(":")
    module = importlib.import_module(module_name)
    return run_guarded(getattr(module, function or "main"), rest)


if __name__ == "__main__":
    sys.exit(main())
