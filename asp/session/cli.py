"""``./run.sh session``: the end-to-end learning session, planner and cells over Zenoh.

The command line of :mod:`asp.session.run`: the options become one
:class:`asp.session.settings.SessionSettings` (:func:`session_settings`), the session
runs from it, and a summary (or, with ``--json``, the result) is printed.
"""

from __future__ import annotations

import argparse
import json
import shlex
import sys
from pathlib import Path

from msgspec import UNSET, UnsetType

from asp.session.cells import ROOT
from asp.session.run import LOG, run_session
from asp.session.settings import (
    MAX_CELLS,
    MAX_PLANS,
    MAX_WAIT_S,
    PRECEDENCE_MODES,
    SessionSettings,
    fit_text,
    prior_statement,
    read_session_file,
)
from asp.sizes.cli import add_model_option, add_prior_options, check_prior_options
from asp.sizes.learner import MAX_CONFIRM
from asp.sizes.policies import policy_names
from asp.solve import encoding
from bridge.assembly import load_assembly
from bridge.cell_settings import add_cell_arguments, cell_settings_of
from bridge.cli_types import (
    MAX_SEED,
    PROGRAM,
    ArgumentParser,
    add_assembly_argument,
    backend_option,
    comma_list,
    finite_float,
    int_in,
    nonempty_path,
    path_setting,
)
from bridge.errors import EXIT_UNSOLVABLE
from bridge.keys import check_cell_id
from bridge.recording.sinks import add_viewer_arguments, hosted_viewer, keep_serving, viewer_of
from bridge.session import add_endpoint_arguments


def build_parser() -> argparse.ArgumentParser:
    parser = ArgumentParser(prog="session", description=__doc__.split("\n\n")[0])
    add_assembly_argument(parser)
    parser.add_argument("--cells", type=int_in(0, MAX_CELLS), default=1,
                        help=f"cell co-processes to start, 0 to {MAX_CELLS} (default 1; 0: use cells on the network)")
    parser.add_argument("--policy", default="best", choices=policy_names(),
                        help="experiment selection policy (default best: fewest experiments)")
    parser.add_argument("--seed", type=int_in(0, MAX_SEED), default=0, help="seed of the policy and the trials")
    add_model_option(parser)
    add_prior_options(parser)
    parser.add_argument("--confirm", type=int_in(0, MAX_CONFIRM), default=0, metavar="K",
                        help="re-test each essential experiment until its result leads by K+1 answers "
                             "(default 0: trust the cell's answer; see sizes learn --confirm)")
    parser.add_argument("--demos", type=Path, metavar="FILE",
                        help="demonstrations (default: the assembly's demos.txt); a part placed into a "
                             "hole (p1@r1) is a fit the size learning starts from")
    parser.add_argument("--precedence", choices=PRECEDENCE_MODES, default="demos",
                        help="how precedence is learned: demos (Algorithm 1 on every demonstration, default) or "
                             "explore (at most 2 demonstrations, the CAD's geometric precedence when the product "
                             "has one, and precedence experiments at the cell, chosen by ASP)")
    parser.add_argument("--out", type=nonempty_path, help="run folder (default runs/<UTC time>)")
    parser.add_argument("--resume", type=nonempty_path, metavar="RUN", help="continue a killed session")
    parser.add_argument("--backend", choices=("sim", "truth", "franka"), default="sim",
                        help="cells started here: sim (PyBullet), truth (answers from the geometry's "
                             "cross-sections, no simulation) or franka (a Franka arm through franky, "
                             "docs/franka.md)")
    parser.add_argument("--backend-option", type=backend_option, action="append", default=[], metavar="KEY=VALUE",
                        help="an option of the cells' backend, e.g. host=172.16.0.2 for franka (repeatable)")
    parser.add_argument("--delay", type=finite_float(0.0, 3600.0), default=0.0, metavar="S",
                        help="truth backend: seconds each experiment takes (default 0)")
    parser.add_argument("--timeout", type=finite_float(0.0, MAX_WAIT_S, low_open=True), default=120.0, metavar="S",
                        help="one experiment at one cell before it is re-sent (default 120)")
    parser.add_argument("--wait-for-cell", type=finite_float(0.0, MAX_WAIT_S), default=60.0, metavar="S",
                        help="how long to wait while no cell is alive (default 60)")
    parser.add_argument("--plans", type=int_in(1, MAX_PLANS), default=5, metavar="K",
                        help="plans to compute (default 5)")
    parser.add_argument("--allow-cells", type=comma_list(check_cell_id, "cell ids"), metavar="ID,...",
                        help="with --cells 0: use only these cells (default: any cell that shows a token); "
                             "a session that starts its cells uses only those")
    parser.add_argument("--assemble", action="store_true",
                        help="then assemble the first plan in the first cell (as the assemble subcommand "
                             "does); the JSON gains \"assembly\"")
    parser.add_argument("--json", action="store_true", help="print the JSON result")
    add_endpoint_arguments(parser)
    add_viewer_arguments(parser)
    add_cell_arguments(parser, cell_seed=False)  # cell c<k>'s cell seed: --seed + k - 1 (session_settings)
    return parser


def session_settings(args: argparse.Namespace) -> SessionSettings:
    """The settings the options of :func:`build_parser` give; the cells' first cell seed is
    ``--seed``. PlannerError for ``--tolerance`` without ``--prior cad``."""
    check_prior_options(args)
    return SessionSettings(
        assembly=args.assembly, policy=args.policy, model=args.model, seed=args.seed, confirm=args.confirm,
        size_prior=args.prior, tolerance_m=args.tolerance, precedence=args.precedence,
        demos=path_setting(args.demos), cell=cell_settings_of(args, cell_seed=args.seed), out=path_setting(args.out),
        resume=path_setting(args.resume), cells=args.cells, backend=args.backend,
        backend_options=dict(args.backend_option), delay_s=args.delay,
        timeout_s=args.timeout, wait_for_cell_s=args.wait_for_cell, plans=args.plans,
        allow_cells=None if args.allow_cells is None else tuple(args.allow_cells), assemble=args.assemble,
        listen=tuple(args.listen), connect=tuple(args.connect), zenoh_config=path_setting(args.zenoh_config))


def _program() -> str:
    """How to call this program again: the repository's ``run.sh`` (absolute, so it works
    from any folder) in a checkout, else the installed console command."""
    wrapper = ROOT / "run.sh"
    return shlex.quote(str(wrapper)) if wrapper.is_file() else PROGRAM


def _assembly_line(report: dict) -> str:
    errors = report["final_pose_error_mm"]
    worst = max(errors.values(), default=0.0)
    manual = f" ({len(report['manual'])} placed by hand: {' '.join(report['manual'])})" if report["manual"] else ""
    return (f"assembly of plan 1: assembled {report['assembled']}, {len(report['steps'])} steps{manual}, "
            f"{len(report['replans'])} re-plan(s), largest pose error {worst:.2f} mm, {report['wall_s']:.1f} s")


def _versus_line(truth: dict[str, bool | int | None], matches: bool | None) -> str:
    """The summary's comparison with the product's truths, saying which cannot be made."""
    sizes = "unknown (no sizes.lp)" if truth["sizes_equal"] is None else truth["sizes_equal"]
    precedence = ("unknown (no precedence.lp)" if truth["precedence_sound"] is None
                  else f"{truth['precedence_sound']} ({truth['precedence_extra']} pairs more than required)")
    verdict = "unknown" if matches is None else matches
    return (f"versus the truth: sizes equal {sizes}, every true precedence learned {precedence}; "
            f"matches truth: {verdict}")


def _explored_lines(explored: dict | UnsetType) -> list[str]:
    """The lines of ``--precedence explore``: the experiments, what each pair rests on."""
    if explored is UNSET:
        return []
    return [f"precedence by exploration: {explored['experiments']} experiment(s), {explored['sim_s']:.1f} s "
            f"simulated, {explored['wall_s']:.1f} s wall; what each pair rests on:",
            *(f"  {line}" for line in explored["rests_on"])]


def _stated_lines(result: dict) -> list[str]:
    """The summary's lines on what was not observed as the CAD states it: the pairs taken
    from ``sizes.lp`` (no cell can try them), the fits with room under what the sim cell
    resolves that it built with room."""
    lines = []
    if result["not_observed"]:
        fits = [f"{p}->{h}" for p, h, outcome in result["not_observed"] if outcome == "fit"]
        lines.append(f"not observed (no cell can try them; from sizes.lp, the CAD): {len(result['not_observed'])} "
                     f"pairs, {len(fits)} fit" + (f": {' '.join(fits)}" if fits else ""))
    nominal = result["nominal_fits"]
    if nominal:
        rooms = nominal.get("cad_room_m", {})
        lines.append(f"observed with {nominal['room_m'] * 1e3:.3f} mm of room per side, not at the CAD's room "
                     "(under what the sim cell resolves; room 0 unless given): "
                     + " ".join(fit_text(rooms, p, h) for p, h in nominal["pairs"]))
    return lines


def _summary(result: dict, run: Path) -> str:
    """The human ending of a session: what was learned, the files written, what to run next."""
    settings = read_session_file(run)
    assert settings.journal is not UNSET and settings.truth is not UNSET and settings.assignment is not UNSET
    cells: dict[str, int] = {}
    for entry in settings.journal:
        cells[entry["cell"]] = cells.get(entry["cell"], 0) + 1
    assembly = load_assembly(settings.assembly)
    plan = (f"plan 1 of {len(result['plans'])}: " + " ".join(
        assembly.step_text(s["part"], s["hole"]) for s in result["plans"][0])
        if result["plans"] else f"no plan: {result['error']}")
    files = sorted(p.name for p in run.iterdir() if p.is_file() and not p.name.startswith("."))
    python = shlex.quote(sys.executable)
    learned = shlex.quote(str(run.resolve() / "learned.lp"))  # the "next" commands work from any folder
    part = result["fits"][0][0] if result["fits"] else None  # none when nothing fits (or nothing to learn)
    asked = [] if part is None else [
        (f"holes {part} fits into", f"echo '#show. #show H : fits({part},H).' | {python} -m clingo {learned} -")]
    return "\n".join([
        f"run {result['run']}: {result['experiments']} experiments "
        f"({', '.join(f'{c}: {n}' for c, n in sorted(cells.items()))}) in {settings.wall_s:.1f} s",
        "fits: " + " ".join(f"{p}->{h}" for p, h in result["fits"])
        + (f" (started from {len(result['demonstrated'])} seen in the demonstrations)"
           if result["demonstrated"] else ""),
        f"assumes: {result['assumption']}",
        *([] if settings.prior is UNSET or settings.prior is None else [f"assumes: {prior_statement(settings.prior)}"]),
        *_stated_lines(result),
        *(f"model changed: {change}" for change in result["model_changes"]),
        f"must precede: {len(result['must_precede'])} pairs",
        *_explored_lines(settings.precedence_explored),
        "assignment: " + (" ".join(f"{p}->{h}" for p, h in settings.assignment.items()) or "none"),
        plan,
        _versus_line(settings.truth, result["matches_truth"]),
        *([_assembly_line(result["assembly"])] if "assembly" in result else []),
        f"files written in {run}: {' '.join(files)}",
        "next:",
        *(f"  {(label + ':').ljust(23)} {command}" for label, command in (
            ("view the recording", f"{_program()} view {shlex.quote(str(run.resolve()))}"),
            *asked,
            *([("five complete plans", f"{python} -m clingo {shlex.quote(str(encoding('plans.lp')))} {learned} 5")]
              if result["plans"] else []),
        )),
    ])


def main(argv: list[str]) -> int:
    args = build_parser().parse_args(argv)
    viewer = viewer_of(args)
    with hosted_viewer(viewer) as live:
        result = run_session(session_settings(args), live)
        print(json.dumps(result) if args.json else _summary(result, Path(result["run"])), flush=True)
        keep_serving(viewer)
    stopped = result.get("error") or result.get("assembly", {}).get("error")
    if stopped:
        LOG.error("%s", stopped)
        return EXIT_UNSOLVABLE
    return 0
