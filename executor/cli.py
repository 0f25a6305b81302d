"""Command line of the simulated cell: ``teach``, ``trial``, ``sizes``, ``export``, ``campaign``, ``serve``,
``margins``.

``./run.sh executor trial --part p1 --hole r1 --trials 3 --json`` prints
``{"trials": [{"outcome", "attempts", "max_force_dev", "max_torque_dev", "end_error",
"duration_s", ...}, ...], "summary": {...}}``.  Bad input: ``error: ...`` and exit code 2.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
from collections.abc import Sequence
from pathlib import Path

from bridge.cell_settings import (
    add_cell_arguments,
    add_cell_description_argument,
    cell_settings_of,
)
from bridge.cli_types import (
    MAX_SEED,
    ArgumentParser,
    add_assembly_argument,
    backend_option,
    comma_list,
    int_in,
    nonempty_path,
    png_path,
)
from bridge.files import write_atomic
from bridge.recording.sinks import (
    NO_VIEWER,
    Viewer,
    add_viewer_arguments,
    hosted_viewer,
    keep_serving,
    viewer_of,
)

MAX_TRIALS = 100_000
"""``trial --trials N``: at most this many trials (trial k uses seed+k)."""
MAX_ATTEMPTS = 10
"""``trial --attempts``: at most this many attempts per trial."""


def _teach(args: argparse.Namespace) -> int:
    from executor import ExecutorError
    from executor.cell_description import load_cell_description
    from executor.skills.teach import Demonstrator, TeachingCell, chosen_shapes, scripted_demonstration, teach_all
    from executor.world.geometry import load_geometry

    if args.demonstration == "hand" and args.backend != "franka":
        raise ExecutorError("--demonstration hand: a person guides the part on a real arm; expected --backend franka")
    description = load_cell_description(args.cell_description)
    geometry = load_geometry(args.assembly, description)
    chosen_shapes(geometry, args.shapes)  # an unknown name is refused before a cell starts
    cell: TeachingCell
    demonstrate: Demonstrator = scripted_demonstration
    if args.backend == "franka":
        from executor.control.ilc import layer_named
        from executor.franka.backend import franka_options
        from executor.franka.cell import FrankaCell
        from executor.franka.teach import FrankaTeacher

        options = franka_options(dict(args.backend_option))
        if any(options.offset):
            # The taught poses are the geometry's (product frame) as they are sent to the arm.
            raise ExecutorError("--backend-option offset: teaching on the arm does not move its poses by the "
                                "offset; expected offset=0,0,0 (the plate where geometry.toml puts it in the "
                                "robot's base frame)")
        arm = FrankaCell(geometry, description, layer_named("full"), options)
        cell = FrankaTeacher(arm)
        close = arm.stop
        if args.demonstration == "hand":
            from executor.franka.guide import HandGuiding

            demonstrate = HandGuiding(lambda line: print(line, flush=True))
    else:
        from executor.trial import Cell, CellSetup

        if args.backend_option:
            raise ExecutorError("--backend-option: the sim backend takes none (expected --backend franka)")
        sim = Cell(args.assembly, setup=CellSetup(description=description))
        cell, close = sim, sim.close
    try:
        written = teach_all(cell, demonstrate, args.shapes)
    finally:
        close()
    for path in written:
        print(f"wrote {path}")
    if not cell.geometry.parts:
        print(f"no skill to teach: {cell.geometry.folder / 'geometry.toml'} has no part the cell inserts (every "
              "part is placed by hand)")
    return 0


def _summary(results: list[dict]) -> dict:
    """Counts and medians over the trials of one part-hole pair."""
    outcomes = [r["outcome"] for r in results]
    return {
        "trials": len(results),
        "fit": outcomes.count("fit"),
        "no_fit": outcomes.count("no_fit"),
        "fit_first_attempt": sum(1 for r in results if r["outcome"] == "fit" and r["attempts"] == 1),
        "median_duration_s": statistics.median(r["duration_s"] for r in results),
        "median_sim_steps_per_s": statistics.median(r["sim_steps_per_s"] for r in results),
        "median_real_time_factor": statistics.median(r["real_time_factor"] for r in results),
    }


def _trial(args: argparse.Namespace) -> int:
    viewer = viewer_of(args)
    with hosted_viewer(viewer) as live:
        return _trials(args, live, viewer)


def _trials(args: argparse.Namespace, live: Viewer, viewer: Viewer) -> int:
    """The trials of ``executor trial``, recorded to ``args.rrd`` and streamed to ``live``;
    with ``viewer.serve`` the web viewer stays up at the end until Ctrl-C."""
    from executor.trial import Cell, cell_setup

    setup = cell_setup(cell_settings_of(args))  # the cell description checked before anything is written
    logger = None
    if args.plot:
        from bridge.files import check_writable

        check_writable(Path(args.plot))  # before the trials
    if args.rrd or args.plot or live != NO_VIEWER:
        from executor.rerun_log import AttemptLogger, LogTarget

        logger = AttemptLogger(target=LogTarget(rrd_path=args.rrd, viewer=live), keep_traces=bool(args.plot))
    cell = Cell(args.assembly, gui=args.gui, logger=logger, setup=setup)
    try:
        results = []
        for k in range(args.trials):
            result = cell.run_trial(args.part, args.hole, seed=args.seed + k, max_attempts=args.attempts)
            results.append(result.to_json())
            if not args.json:
                r = results[-1]
                print(
                    f"{args.part}->{args.hole} seed {args.seed + k}: {r['outcome']} after {r['attempts']} "
                    f"attempt(s); max |dF| {r['max_force_dev']:.1f} N, max |dM| {r['max_torque_dev']:.2f} Nm, "
                    f"end error {1000 * r['end_error']:.1f} mm, {r['duration_s']:.2f} s wall "
                    f"({r['real_time_factor']:.1f}x real time)"
                )
        summary = _summary(results)
        if args.plot:
            from executor.campaign.plots import first_attempts, plot_fig17

            assert logger is not None
            plot_fig17(*first_attempts(logger.traces), Path(args.plot))
        if args.json:
            print(json.dumps({"trials": results, "summary": summary}, indent=2), flush=True)
        else:
            print(f"summary: {summary['fit']}/{summary['trials']} fit, median {summary['median_duration_s']:.2f} s "
                  "wall", flush=True)
        keep_serving(viewer)
    finally:
        cell.close()
        if logger is not None:
            logger.close()
    return 0


def _sizes(args: argparse.Namespace) -> int:
    """Print or write the sizes.lp of ``geometry.toml``
    (:func:`executor.world.geometry.sizes_lp_text`)."""
    from executor.world.geometry import sizes_lp_text

    text = sizes_lp_text(args.assembly)
    if args.out is None:
        sys.stdout.write(text)
    else:
        write_atomic(args.out, text)
        print(f"wrote {args.out}")
    return 0


def _export(args: argparse.Namespace) -> int:
    from executor.assembly.export import export_cell
    from executor.cell_description import load_cell_description

    description = load_cell_description(args.cell_description)  # checked even where not used (--assembled)
    if args.assembled:
        from executor.cad.assembled import write_assembled

        files = write_assembled(args.assembly, args.out)
        print(f"wrote {len(files) - 1} part mesh(es) in the assembled pose and import.toml in {args.out}")
        return 0

    written = export_cell(args.assembly, args.out, description)
    print(f"wrote {written[0]} and {len(written) - 1} mesh file(s) in {args.out / 'meshes'}")
    return 0


# Subcommands owned by other modules: subcommand -> (module whose ``main(argv)`` runs it,
# imported lazily; help text).
_DELEGATED = {
    "campaign": ("executor.campaign.run",
                 "Fig. 18: randomised executions of every part-hole pair"),
    "serve": ("executor.serve", "serve insertion requests over Zenoh"),
    "margins": ("executor.campaign.margins",
                "measure the wrench and end-error margins the thresholds come from"),
}


def build_parser() -> argparse.ArgumentParser:
    parser = ArgumentParser(prog="executor", description="The simulated PyBullet assembly cell (paper 3).")
    sub = parser.add_subparsers(dest="command", required=True)

    teach = sub.add_parser("teach", help="record the demonstrations (DMP + reference wrench)")
    add_assembly_argument(teach)
    teach.add_argument("--backend", choices=("sim", "franka"), default="sim",
                       help="sim: in the PyBullet cell; franka: on a Franka arm through franky (docs/franka.md) "
                            "(default sim)")
    teach.add_argument("--backend-option", type=backend_option, action="append", default=[], metavar="KEY=VALUE",
                       help="franka: an option of the arm, e.g. host=172.16.0.2 (repeatable)")
    teach.add_argument("--demonstration", choices=("scripted", "hand"), default="scripted",
                       help="scripted: the cell guides the part down its hole; hand: a person guides it on the arm, "
                            "compliant (--backend franka only; docs/franka.md, Teaching) (default scripted)")
    teach.add_argument("--shapes", type=comma_list(str, "part shapes such as peg_d10,peg_d11"), metavar="SHAPE,...",
                       help="teach only these part shapes (of geometry.toml's [part_shapes]); the stored skills of "
                            "the others are kept (default: every shape)")
    add_cell_description_argument(teach)
    teach.set_defaults(func=_teach)

    trial = sub.add_parser("trial", help="insert one part into one hole, N randomised trials")
    trial.add_argument("--part", required=True, help="part id, e.g. p1, p3, sh, tp")
    trial.add_argument("--hole", required=True, help="hole id, e.g. r1, s1, br")
    trial.add_argument("--trials", type=int_in(1, MAX_TRIALS), default=1,
                       help="number of randomised trials (default 1)")
    trial.add_argument("--seed", type=int_in(0, MAX_SEED), default=0,
                       help="seed of the first trial; trial k uses seed+k")
    trial.add_argument("--attempts", type=int_in(1, MAX_ATTEMPTS), default=2,
                       help="attempts per trial before 'no_fit' (default 2)")
    add_assembly_argument(trial)
    trial.add_argument("--gui", action="store_true", help="open the PyBullet GUI")
    trial.add_argument("--save", "--rrd", dest="rrd", metavar="FILE", type=nonempty_path,
                       help="save a Rerun recording of every attempt to this .rrd file")
    add_viewer_arguments(trial)
    trial.add_argument("--plot", metavar="FILE", type=png_path,
                       help="draw Fig. 17 (forces and torques over the DMP phase of the first successful "
                       "and the first failed attempt, against their desired profiles) to this PNG")
    trial.add_argument("--json", action="store_true", help="print JSON instead of text")
    add_cell_arguments(trial)
    trial.set_defaults(func=_trial)

    sizes = sub.add_parser("sizes", help="write the sizes.lp (which part fits which hole) that the geometry makes")
    add_assembly_argument(sizes, purpose="the product whose fits are derived from geometry.toml")
    sizes.add_argument("--out", metavar="FILE", type=nonempty_path, help="write it to FILE (default: print it)")
    sizes.set_defaults(func=_sizes)

    export = sub.add_parser("export", help="write the assembling cell as URDF and meshes (arm, plate, every part)")
    add_assembly_argument(export, purpose="the product whose cell is written")
    export.add_argument("out", metavar="OUT", type=nonempty_path, help="folder to write cell.urdf and meshes/ into")
    export.add_argument("--assembled", action="store_true",
                        help="instead: one closed mesh per part in the assembled pose (OUT/<part>.obj, m) and "
                             "OUT/import.toml, the input of the import subcommand")
    add_cell_description_argument(export)
    export.set_defaults(func=_export)

    for name, (_module, help_text) in _DELEGATED.items():
        sub.add_parser(name, help=help_text, add_help=False)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run one subcommand of the cell (the command line's ``executor`` subcommand, which
    reports errors and exit codes)."""
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv and argv[0] in _DELEGATED:
        import importlib

        module, _help = _DELEGATED[argv[0]]
        return int(importlib.import_module(module).main(argv[1:]) or 0)
    args = build_parser().parse_args(argv)
    return int(args.func(args) or 0)


