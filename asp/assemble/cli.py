"""``./run.sh assemble``: execute one plan step by step in a simulated cell, monitored.

    ./run.sh assemble [--run RUN [--plan K] | PLAN.json [FACTS.lp ...] | FACTS.lp ...]
                      [--assembly A] [--seed S] [--block-hole H] [--rrd FILE] [--json]
                      [--backend {sim,truth,franka} [--backend-option KEY=VALUE ...]]
                      [--uncertainty {random,cell} [--cell-seed C] [--layer L] [--<magnitude> X ...]]

The plan: plan K (default 1) of a session's run folder (``RUN/session.json``, facts
``RUN/learned.lp``), a plan JSON file (``[{"part", "hole"}, ...]``, ``{"plan": [...]}`` or
the ``{"plans": [...]}`` of ``plan --json``), or plan K of learned facts files; with none
of these, plan K of the assembly's true facts (``sizes.lp``, ``precedence.lp``).
Re-planning after a failed step uses the same facts.

The planner starts one cell (``executor serve``) on loopback and sends it one step
request per plan step over Zenoh (:mod:`asp.assemble.driver`); the cell keeps its world
between steps.  JSON (``--json``): ``{"plan", "steps": [{"part", "hole", "skill",
"outcome", "attempts", "duration_s", "max_force_dev", ...}], "assembled", "manual": [part],
"manual_reasons": {part: why}, "final_pose_error_mm": {part: mm}, "replans": [{"step", "reason", "plan"}], ...}``.
Exit code 3 when the product cannot be finished (e.g. no hole left for a part).

``--uncertainty cell`` gives the plan steps the uncertainty of a single-trial cell (the
magnitudes' options, systematic part from ``--cell-seed``), its execution layer
``--layer`` and, with ``full``, ILC (docs/assembly.md); the default ``random`` is the
assembling cell's own random errors, and then those options must keep their defaults.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

from msgspec import UNSET

from asp import PlannerError
from asp.assemble.driver import assembling_cell
from asp.assemble.execute import AssemblyStopped, execute, with_manual_reasons
from asp.assemble.inputs import (
    check_facts_product,
    check_plan_product,
    plan_of_json,
    read_plan_json,
)
from asp.assemble.settings import (
    MAX_PLAN_INDEX,
    MAX_STEP_S,
    AssemblySettings,
    assembling_cell_settings,
    check_assembling_backend,
)
from asp.plans.assign import LearnedFacts, load_learned_facts, product_facts
from asp.plans.plans import Plan, plans
from asp.session.settings import SESSION_FILE, SessionFile, read_session_file
from bridge.assembly import Assembly, load_assembly
from bridge.cell_settings import (
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
    backend_option,
    finite_float,
    int_in,
    nonempty_path,
    path_setting,
)
from bridge.errors import EXIT_UNSOLVABLE
from bridge.session import add_endpoint_arguments


def build_parser() -> argparse.ArgumentParser:
    parser = ArgumentParser(prog="assemble", description=__doc__.split("\n\n")[0])
    parser.add_argument("inputs", nargs="*", type=Path, metavar="PLAN.json|FACTS.lp",
                        help="a plan JSON file and/or learned facts files (default: the assembly's true facts)")
    parser.add_argument("--run", type=Path, metavar="RUN", help="a session's run folder: its plans and learned facts")
    parser.add_argument("--plan", type=int_in(1, MAX_PLAN_INDEX), default=1, metavar="K",
                        help="which plan (1-based, default 1)")
    add_assembly_argument(parser, default=None, purpose="its parts, holes and geometry (default: the run's, "
                                                        "else cranfield)")
    parser.add_argument("--seed", type=int_in(0, MAX_SEED), default=0, help="seed of the cell's random grasp, "
                        "vision and search errors (default 0)")
    parser.add_argument("--block-hole", action="append", default=[], metavar="H",
                        help="put an obstacle in hole H (fault injection; repeatable)")
    parser.add_argument("--backend", choices=("sim", "truth", "franka"), default="sim",
                        help="the cell: sim (PyBullet, default), truth (geometry rule, no simulation) or franka "
                             "(a Franka arm through franky, docs/franka.md)")
    parser.add_argument("--backend-option", type=backend_option, action="append", default=[], metavar="KEY=VALUE",
                        help="franka: an option of the arm, e.g. host=172.16.0.2 (repeatable)")
    parser.add_argument("--timeout", type=finite_float(0.0, MAX_STEP_S, low_open=True), default=300.0, metavar="S",
                        help="one step at the cell (default 300)")
    parser.add_argument("--save", "--rrd", dest="rrd", type=nonempty_path, metavar="FILE",
                        help="save the cell's Rerun recording to this .rrd file")
    parser.add_argument("--json", action="store_true", help="print the JSON result")
    add_assembly_uncertainty_argument(parser)
    add_cell_arguments(parser)
    add_endpoint_arguments(parser)
    return parser


def assembly_settings(args: argparse.Namespace) -> AssemblySettings:
    """The settings the options of :func:`build_parser` give."""
    return AssemblySettings(
        inputs=tuple(map(str, args.inputs)), run=path_setting(args.run), plan=args.plan, assembly=args.assembly,
        seed=args.seed, block_holes=tuple(args.block_hole), backend=args.backend,
        backend_options=dict(args.backend_option), timeout_s=args.timeout,
        rrd=path_setting(args.rrd), cell=cell_settings_of(args), listen=tuple(args.listen),
        connect=tuple(args.connect), zenoh_config=path_setting(args.zenoh_config))


def truth_sources(assembly: Assembly) -> str:
    """The assembly's true facts files, as messages name them."""
    return f"{assembly.file('sizes.lp')}, {assembly.file('precedence.lp')}"


def truth_facts(assembly: Assembly) -> LearnedFacts:
    """The assembly's true sizes and precedence as learned facts (``must_precede`` closed),
    with what the product says about its holes (:func:`asp.plans.assign.product_facts`)."""
    return load_learned_facts([assembly.file("sizes.lp"), assembly.file("precedence.lp")], product_facts(assembly))


def session_plans(run: Path) -> tuple[SessionFile, list[list[dict[str, str | None]]]]:
    """The ``session.json`` of run folder ``run`` and its plans; PlannerError naming the
    file when it is not that of a finished session."""
    record = read_session_file(run)
    if record.plans is UNSET:
        raise PlannerError(f'{run / SESSION_FILE}: expected the session.json of a finished session (with "plans")')
    return record, record.plans


def resolve(settings: AssemblySettings) -> tuple[Assembly, LearnedFacts, Plan]:
    """The assembly, the facts for re-planning and the plan to execute."""
    inputs = [Path(p) for p in settings.inputs]
    jsons = [p for p in inputs if p.suffix == ".json"]
    lps = [p for p in inputs if p.suffix != ".json"]
    if len(jsons) > 1 or (settings.run is not None and inputs):
        raise PlannerError("expected --run RUN, or one PLAN.json with optional FACTS.lp files, or FACTS.lp files")
    name = settings.assembly
    index = settings.plan
    plan: Plan | None = None
    plan_source = ""
    if settings.run is not None:
        run = Path(settings.run)
        record, found = session_plans(run)
        name = name or record.assembly
        if len(found) < index:
            raise PlannerError(f"{run / SESSION_FILE}: --plan {index}, but the run has {len(found)} plan(s)")
        plan_source = f"{run / SESSION_FILE}: plans[{index}]"
        plan = plan_of_json(found[index - 1], plan_source)
        lps = [run / "learned.lp"]
    assembly = load_assembly(name or "cranfield")
    unknown = [hole for hole in settings.block_holes if hole not in assembly.hole_ids]
    if unknown:
        raise PlannerError(f"--block-hole {unknown[0]}: expected a hole of {assembly.name} "
                           f"({', '.join(assembly.hole_ids)})")
    facts = load_learned_facts(lps, product_facts(assembly)) if lps else truth_facts(assembly)
    check_facts_product(assembly, facts, ", ".join(map(str, lps)) or truth_sources(assembly))
    if jsons:
        plan_source = str(jsons[0])
        plan = read_plan_json(jsons[0], index)
    if plan is None:
        found_plans = plans(facts, n=index)
        if len(found_plans) < index:
            raise PlannerError(f"--plan {index}: the facts admit only {len(found_plans)} plan(s)")
        plan_source, plan = f"plan {index} of the facts", found_plans[index - 1]
    check_plan_product(facts, plan, plan_source)
    return assembly, facts, plan


def _summary(report: dict) -> str:
    lines = []
    for k, step in enumerate(report["steps"], start=1):
        lines.append(f"{k}: {step['part']}" + (f"->{step['hole']}" if step["hole"] else "")
                     + f" {step['skill']}: {step['outcome']} ({step['attempts']} attempt(s), "
                     f"{step['duration_s']:.1f} s, max force dev {step['max_force_dev']:.1f} N)")
    for replan in report["replans"]:
        lines.append(f"re-plan at step {replan['step']}: {replan['reason']}; new plan "
                     + " ".join(s["part"] + (f"->{s['hole']}" if s["hole"] else "") for s in replan["plan"]))
    if report["manual"]:
        lines.append(f"placed by hand (manual, the cell has no operation for them): {' '.join(report['manual'])}")
        lines += [f"  {part}: {reason}" for part, reason in report["manual_reasons"].items()]
    errors = report["final_pose_error_mm"]
    if errors:
        worst = max(errors, key=lambda p: errors[p])
        lines.append(f"pose errors: largest {errors[worst]:.2f} mm ({worst})")
    lines.append(f"assembled: {report['assembled']} in {report['wall_s']:.1f} s")
    return "\n".join(lines)


def assembling_cell_of(settings: AssemblySettings, assembly: Assembly, cell: CellSettings) -> ServeSettings:
    """The settings of the cell that assembles ``assembly``: the backend and its options of
    ``settings``, the checked ``cell`` (:func:`assembling_cell_settings`)."""
    return ServeSettings(assembly=str(assembly.folder), backend=settings.backend,
                         backend_options=settings.backend_options, block_holes=tuple(settings.block_holes),
                         rrd=settings.rrd, zenoh_config=settings.zenoh_config, cell=cell)


def assemble(settings: AssemblySettings) -> tuple[dict, int]:
    """Start the cell, run the plan; (report, exit code)."""
    started = time.perf_counter()
    check_assembling_backend(settings)
    cell = assembling_cell_settings(settings.cell, settings.backend)
    assembly, facts, plan = resolve(settings)
    served = assembling_cell_of(settings, assembly, cell)
    with assembling_cell(served, settings.seed, settings.timeout_s, listen=settings.listen,
                         connect=settings.connect) as driver:
        try:
            report, code = execute(facts, plan, driver), 0
        except AssemblyStopped as exc:
            report, code = dict(exc.report, error=str(exc)), EXIT_UNSOLVABLE
    report = with_manual_reasons(report, assembly.manual)
    report["wall_s"] = round(time.perf_counter() - started, 3)
    return report, code


def main(argv: list[str]) -> int:
    args = build_parser().parse_args(argv)
    report, code = assemble(assembly_settings(args))
    print(json.dumps(report) if args.json else _summary(report))
    if code == EXIT_UNSOLVABLE:
        print(f"error: {report['error']}", file=sys.stderr)
    return code
