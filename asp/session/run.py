"""``./run.sh session``: the end-to-end learning session, planner and cells over Zenoh.

1. learns must-precede from the assembly's demonstrations (Algorithm 1; ``--demos FILE``
   for others); parts they place into holes (``p1@r1``) are fits the size learner
   starts from (paper 4.2, last paragraph);
2. starts ``--cells N`` cell co-processes (``executor serve``) connected to the planner's
   loopback endpoint (``--cells 0 --connect EP`` uses cells already on the network);
3. learns which part fits which hole, keeping every alive cell busy with experiments
   none of whose outcomes can entail another's (:func:`_learn_sizes`,
   :mod:`asp.session.oracle`); every finished experiment is journaled (fsynced) before
   the learner uses it;
4. assigns holes (the paper's greedy rule, else a matching) and computes complete plans, each run through the checker;
5. writes ``RUN/learned.lp`` (the project's facts vocabulary), ``RUN/assignment.lp``,
   ``RUN/session.json``, ``RUN/journal.jsonl`` and the Rerun recordings ``RUN/*.rrd``
   (planner and cells in one recording id), and prints a summary (``--json``: the
   contract ``{"run", "experiments", "fits", "must_precede", "plans", "matches_truth"}``).

``--resume RUN`` continues a killed session: the journal is replayed into the learner,
no finished experiment is run again. The sizes are learned over the parts and holes of
the assembly's ``sizes.lp`` (Cranfield: pegs p1 p2 p3 p4 sh, holes r1 r2 s1 s2 br), or,
without one, over the parts with role ``peg`` and all holes. ``matches_truth``: the
learned part-hole relation equals ``sizes.lp`` and every true precedence constraint
(``precedence.lp``) is learned, so every admitted sequence is feasible.
"""

from __future__ import annotations

import argparse
import json
import logging
import re
import shlex
import shutil
import sys
import time
import uuid
from contextlib import ExitStack
from datetime import UTC, datetime
from pathlib import Path

import zenoh

from asp import PlannerError
from asp.plans.assign import feasible_assignment, load_learned_facts
from asp.plans.plans import Plan, check_plan, plans
from asp.precedence.demos import demo_facts, load_demos
from asp.precedence.learn import learn_must_precede
from asp.precedence.relation import Relation, precedence_facts, reduction, true_relation
from asp.session.cells import CellProcess, cell_seed, serve_argv
from asp.session.folder import RunLock, lock_run_folder
from asp.session.journal import JOURNAL_NAME, Journal
from asp.session.log import PlannerLog
from asp.session.oracle import ZenohOracle
from asp.sizes.cli import add_model_option
from asp.sizes.learner import MAX_CONFIRM, SizeLearner, SizeLearningResult
from asp.sizes.models import MODELS, SizeModel, model_for
from asp.sizes.oracle import TruthOracle
from asp.sizes.policies import policy_names
from asp.solve import encoding, fact, write_facts
from bridge import BridgeError
from bridge.assembly import Assembly, load_assembly
from bridge.cell_options import add_cell_arguments, cell_argv, parse_cell_argv
from bridge.cli_types import MAX_SEED, PROGRAM, ArgumentParser, add_assembly_argument, comma_list, finite_float, int_in
from bridge.client import CellDirectory, CellPool
from bridge.errors import EXIT_UNSOLVABLE
from bridge.files import make_folder, write_atomic
from bridge.inputs import read_bytes, shorten
from bridge.keys import check_cell_id
from bridge.recording.sinks import NO_VIEWER, Viewer, add_viewer_arguments, hosted_viewer, keep_serving, viewer_of
from bridge.session import DEFAULT_ENDPOINT, add_endpoint_arguments, free_loopback_endpoint, open_session

LOG = logging.getLogger(__name__)
SETTINGS = "session.json"
MAX_WAIT_S = 86_400.0
"""--timeout, --wait-for-cell: at most a day [s]; --delay at most an hour."""
MAX_CELLS = 64
"""--cells: at most this many cell co-processes."""
MAX_PLANS = 1000
"""--plans: at most this many plans (they are written to session.json)."""


def build_parser() -> argparse.ArgumentParser:
    parser = ArgumentParser(prog="session", description=__doc__.split("\n\n")[0])
    add_assembly_argument(parser)
    parser.add_argument("--cells", type=int_in(0, MAX_CELLS), default=1,
                        help=f"cell co-processes to start, 0 to {MAX_CELLS} (default 1; 0: use cells on the network)")
    parser.add_argument("--policy", default="best", choices=policy_names(),
                        help="experiment selection policy (default best: fewest experiments)")
    parser.add_argument("--seed", type=int_in(0, MAX_SEED), default=0, help="seed of the policy and the trials")
    add_model_option(parser)
    parser.add_argument("--confirm", type=int_in(0, MAX_CONFIRM), default=0, metavar="K",
                        help="re-test each essential experiment until its result leads by K+1 answers "
                             "(default 0: trust the cell's answer; see sizes learn --confirm)")
    parser.add_argument("--demos", type=Path, metavar="FILE",
                        help="demonstrations (default: the assembly's demos.txt); a part placed into a "
                             "hole (p1@r1) is a fit the size learning starts from")
    parser.add_argument("--out", type=Path, help="run folder (default runs/<UTC time>)")
    parser.add_argument("--resume", type=Path, metavar="RUN", help="continue a killed session")
    parser.add_argument("--backend", choices=("sim", "truth"), default="sim",
                        help="cells started here: sim (PyBullet) or truth (answers from the geometry's "
                             "cross-sections, no simulation)")
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
    add_cell_arguments(parser, cell_seed=False)  # cell c<k>'s cell seed: --seed + k - 1 (asp.session.cells)
    return parser


def _run_folder(args: argparse.Namespace) -> tuple[Path, dict, RunLock, bool]:
    """The run folder, locked for this session (:mod:`asp.session.folder`), its settings
    (read back when resuming) and whether this start created the folder. ``--out``
    creates the folder and refuses one that holds a session (journaled experiments or a
    finished run); a folder a failed start left (one that existed before) may be used again."""
    if args.resume is not None:
        path = args.resume / SETTINGS
        if not path.is_file():
            raise PlannerError(f"--resume {args.resume}: expected a run folder holding {SETTINGS}")
        lock = lock_run_folder(args.resume)
        try:
            settings = _resume_settings(path)
        except PlannerError:
            lock.release()
            raise
        settings["starts"] = int(settings.get("starts", 1)) + 1
        return args.resume, settings, lock, False
    if args.confirm < 0:
        raise PlannerError(f"--confirm {args.confirm}: expected a number >= 0")
    run = args.out or Path("runs") / datetime.now(UTC).strftime("%Y%m%dT%H%M%SZ")
    created = not run.exists()
    lock = lock_run_folder(make_folder(run))
    if _holds_session(run):
        lock.release()
        raise PlannerError(f"--out {run}: already holds a session (its journal); "
                           f"use --resume {run} or another folder")
    settings = {"assembly": args.assembly, "policy": args.policy, "model": args.model, "seed": args.seed,
                "confirm": args.confirm,
                "recording_id": str(uuid.uuid4()), "starts": 1, "status": "running", "cell_options": cell_argv(args)}
    if args.demos is not None:  # absolute: a resume may run from another folder
        settings["demos"] = str(args.demos.absolute())
    return run, settings, lock, created


def _holds_session(run: Path) -> bool:
    """Whether ``run`` holds a session to resume rather than overwrite: a journal with
    at least one line, or settings with status ``done``."""
    journal = run / JOURNAL_NAME
    if journal.is_file() and journal.stat().st_size > 0:
        return True
    try:
        return json.loads(read_bytes(run / SETTINGS, "session settings file", error=PlannerError)
                          ).get("status") == "done"
    except (PlannerError, ValueError, AttributeError):
        return False


MAX_STARTS = 1_000_000
"""The most starts (the first and its resumes) a run folder records."""
MAX_RECORDING_ID = 64
"""The longest recording id [characters]: the cells' request ids are built from it."""
_RECORDING_ID = re.compile(rf"[A-Za-z0-9_-]{{1,{MAX_RECORDING_ID}}}")

_SETTING_TYPES: dict[str, tuple[type, bool]] = {
    "assembly": (str, True), "policy": (str, True), "seed": (int, True), "recording_id": (str, True),
    "confirm": (int, False), "starts": (int, False), "demos": (str, False), "cell_options": (list, False),
    "model": (str, False)}
"""The settings a resumed session reads back: key → (type, required)."""


def _resume_settings(path: Path) -> dict:
    """The settings of ``RUN/session.json``; PlannerError naming the file and the key when
    it is unreadable, not a JSON object, lacks a key or holds a value of the wrong type or range."""
    data = read_bytes(path, "session settings file", error=PlannerError)
    try:
        settings = json.loads(data)
    except (ValueError, RecursionError) as exc:
        raise PlannerError(f"{path}: not JSON ({shorten(exc, 80)}); expected the settings a session wrote") from None
    if not isinstance(settings, dict):
        raise PlannerError(f"{path}: a JSON {type(settings).__name__}; expected an object with the session's settings")
    for key, (kind, required) in _SETTING_TYPES.items():
        if (key not in settings or (key == "model" and settings[key] is None)) and not required:
            continue
        value = settings.get(key)
        if not isinstance(value, kind) or isinstance(value, bool):
            got = "nothing" if key not in settings else shorten(json.dumps(value))
            expected = {int: "an integer", str: "a string", list: "a list of the cell's options"}[kind]
            raise PlannerError(f'{path}: "{key}": expected {expected}, got {got}')
    checks = [("policy", settings["policy"] in policy_names(), f"one of {', '.join(policy_names())}"),
              ("model", settings.get("model") in (None, *MODELS), f"null or one of {', '.join(MODELS)}"),
              ("seed", 0 <= settings["seed"] <= MAX_SEED, f"an integer from 0 to {MAX_SEED}"),
              ("confirm", 0 <= settings.get("confirm", 0) <= MAX_CONFIRM, f"an integer from 0 to {MAX_CONFIRM}"),
              ("starts", 1 <= settings.get("starts", 1) < MAX_STARTS,
               f"an integer from 1 to {MAX_STARTS - 1} (a resume adds one)"),
              ("recording_id", _RECORDING_ID.fullmatch(settings["recording_id"]) is not None,
               f"1 to {MAX_RECORDING_ID} letters, digits, '_' or '-' (a session writes a UUID)")]
    for key, ok, expected in checks:
        if not ok:
            raise PlannerError(f'{path}: "{key}": expected {expected}, got {shorten(json.dumps(settings[key]))}')
    try:
        options = settings.get("cell_options", [])
        if not all(isinstance(arg, str) for arg in options):
            raise ValueError("not all strings")
        parse_cell_argv(options)
    except ValueError as exc:
        raise PlannerError(f'{path}: "cell_options": {shorten(exc, 120)}; expected the options of a sim cell') from None
    return settings


def _save(run: Path, settings: dict) -> None:
    write_atomic(run / SETTINGS, json.dumps(settings, indent=2) + "\n")


def _sizes_domain(assembly: Assembly, requested_model: str | None
                  ) -> tuple[list[str], list[str], TruthOracle | None, SizeModel]:
    """Parts and holes to learn, the truth (``sizes.lp``, if the product has one) and the
    size model of the run (refused before any cell starts when it is unsound for the product)."""
    if assembly.has_file("sizes.lp"):
        known = TruthOracle.from_assembly(str(assembly.folder))
        truth: TruthOracle | None = known
        parts, holes = list(known.parts), list(known.holes)
    else:
        truth, parts, holes = None, [p.id for p in assembly.parts if p.role == "peg"], assembly.hole_ids
        if not parts or not holes:
            raise PlannerError(f"assembly '{assembly.name}': no sizes.lp and no pegs/holes to learn")
    model = model_for(parts, requested_model, assembly.size_model, assembly.sections())
    return parts, holes, truth, model


def _endpoints(args: argparse.Namespace) -> tuple[list[str], list[str]]:
    """(listen, connect) of the planner: it listens for its own cells, else connects."""
    if args.cells > 0:
        return args.listen or [free_loopback_endpoint()], args.connect
    return args.listen, args.connect or ([] if args.zenoh_config else [DEFAULT_ENDPOINT])


def _learn_sizes(oracle: ZenohOracle, learner: SizeLearner, journal: Journal,
                 log: PlannerLog) -> SizeLearningResult:
    """Replay the journal, then keep every alive cell busy until the learner is done.

    Whenever cells are free, the learner is asked for as many pairs as free cells,
    independent of the running experiments and of each other, and they are submitted
    at once; when there are none, the free cells wait for a running experiment to finish.
    """
    def record(part: str, hole: str, result: str, cell: str, started: int) -> None:
        learner.record(part, hole, result)
        log.experiment(started, part, hole, result, cell, learner.knowledge)

    for entry in list(journal.entries):
        record(entry.part, entry.hole, entry.result, entry.cell, entry.experiment)
    if journal.entries:
        LOG.info("resumed: %d experiments from the journal; %d pairs unknown",
                  len(journal.entries), len(learner.knowledge.unknown))
    running: list[tuple[str, str]] = []
    while True:
        free = max(1, oracle.alive_cells()) - len(running)
        if free > 0:
            batch = learner.next_batch(free, pending=running)
            if not batch and not running:
                return learner.result()
            for pair in batch:
                oracle.submit(*pair)
                running.append(pair)
        finished = oracle.next_result()
        running.remove((finished.part, finished.hole))
        record(finished.part, finished.hole, finished.result, finished.cell, finished.experiment)
        attempts = "" if finished.attempts is None else f"{finished.attempts} attempt(s), "
        LOG.info("experiment %d on %s: %s -> %s %s (%s%.1f s); %d pairs unknown", finished.experiment,
                  finished.cell, finished.part, finished.hole, finished.result, attempts, finished.wall_s,
                  len(learner.knowledge.unknown))


def _learned_atoms(assembly: Assembly, demos_atoms: list, relation: Relation,
                   sizes: SizeLearningResult) -> list:
    atoms = [fact("part", p) for p in assembly.part_ids] + [fact("hole", h) for h in assembly.hole_ids]
    atoms += demos_atoms + precedence_facts(relation) + sizes.facts()
    return list(dict.fromkeys(atoms))


def _learned_header(assembly: Assembly, run: Path, sizes: SizeLearningResult) -> str:
    """The comment atop ``learned.lp``: where it comes from, what it assumes, what its ids name."""
    lines = [f"Learned by a session on {assembly.name} ({run}).", f"Assumes: {sizes.model.assumption()}."]
    lines += [f"Model changed: {change}." for change in sizes.model_changes]
    lines += ["Parts:"]
    lines += [f"  {part.id}: {part.name}" for part in assembly.parts]
    lines += ["Holes:", *(f"  {hole.id}: {hole.name}" for hole in assembly.holes)]
    lines += ["must_precede(A,B): A before B; fits(P,H) / no_fit(P,H): part P goes / does not go into hole H."]
    return "\n".join(lines)


def _versus_truth(truth: TruthOracle | None, required: set[tuple[str, str]] | None, fits: list[tuple[str, str]],
                  must_precede: list[tuple[str, str]]) -> dict[str, bool | int | None]:
    """The learned relations against the assembly's truths (None where unknown).

    ``precedence_sound``: every true constraint was learned, so every sequence the
    learned relation admits is feasible; ``precedence_extra``: learned pairs that the
    truth does not require (orders the demonstrations happened not to vary). ``required``:
    the pairs of the assembly's ``precedence.lp`` (None without one).
    """
    versus: dict[str, bool | int | None] = {
        "sizes_equal": None if truth is None else set(fits) == truth.fits,
        "precedence_sound": None, "precedence_extra": None}
    if required is not None:
        versus["precedence_sound"] = required <= set(must_precede)
        versus["precedence_extra"] = len(set(must_precede) - required)
    return versus


def _plans(learned: Path, count: int) -> tuple[dict[str, str], list[Plan]]:
    facts = load_learned_facts([learned])
    assignment = feasible_assignment(facts)
    found = plans(facts, n=count)
    for plan in found:
        errors = check_plan(facts, plan.steps)
        if errors:
            raise PlannerError(f"plan {plan.as_json()} fails the checker: {errors}")
    return assignment, found


def _assemble(session: zenoh.Session, cell_ids: list[str], learned: Path, plan: Plan, seed: int,
              args: argparse.Namespace, process: CellProcess | None) -> dict:
    """Execute ``plan`` in the session's first cell (:mod:`asp.assemble`; ``process``: its
    process if the session started it); the report, with ``"error"`` when the product
    could not be finished."""
    from asp.assemble.driver import ZenohDriver
    from asp.assemble.execute import AssemblyStopped, execute

    if not cell_ids:
        raise PlannerError("--assemble needs a cell of this session (--cells 1 or more)")
    started = time.perf_counter()
    driver = ZenohDriver(session, cell_ids[0], seed, args.timeout, process)
    try:
        report = execute(load_learned_facts([learned]), plan, driver)
    except AssemblyStopped as exc:
        report = dict(exc.report, error=str(exc))
    report["wall_s"] = round(time.perf_counter() - started, 3)
    return report


def run_session(args: argparse.Namespace, viewer: Viewer = NO_VIEWER) -> dict:
    """Run (or resume) a session; returns the JSON result. Planner and cells also stream
    their recordings live to ``viewer``."""
    started = time.perf_counter()
    run, settings, lock, created = _run_folder(args)
    try:
        return _run_locked(args, run, settings, started, viewer)
    except BaseException:
        if created and not _holds_session(run):  # failed at start: no half-made run folder
            shutil.rmtree(run, ignore_errors=True)
        raise
    finally:
        lock.release()


def _run_locked(args: argparse.Namespace, run: Path, settings: dict, started: float, viewer: Viewer) -> dict:
    """:func:`run_session` in the locked run folder ``run``; ``started``: its
    ``time.perf_counter()`` [s] at the start."""
    assembly = load_assembly(settings["assembly"])
    parts, holes, truth, model = _sizes_domain(assembly, settings.get("model"))
    # Every input file is read before any cell starts: bad input fails fast.
    demos = load_demos(settings.get("demos") or assembly.file("demos.txt"), assembly.part_ids, assembly.hole_ids)
    relation = learn_must_precede(demos)
    learner = SizeLearner(parts, holes, settings["policy"], settings["seed"],
                          confirm=int(settings.get("confirm", 0)), demonstrated=demos.placements(), model=model)
    required = set(true_relation(assembly).pairs()) if assembly.has_file("precedence.lp") else None
    run_id = re.sub(r"[^A-Za-z0-9_-]", "-", settings["recording_id"])
    listen, connect = _endpoints(args)
    suffix = "" if settings["starts"] == 1 else f"-{settings['starts']}"
    cell_ids = [f"c{k}" for k in range(1, args.cells + 1)]
    journal = Journal(run)
    try:
        journal.check_ids(parts, holes)
    except PlannerError:
        journal.close()
        raise
    _save(run, settings)
    with ExitStack() as stack:
        stack.callback(journal.close)
        session = open_session(listen, connect, args.zenoh_config)
        stack.callback(session.close)
        directory = CellDirectory(session)
        stack.callback(directory.close)
        cells: list[CellProcess] = []
        stack.callback(lambda: [cell.stop() for cell in cells])
        for number, cell_id in enumerate(cell_ids, start=1):  # they start up in parallel with each other and us
            cells.append(CellProcess(cell_id, serve_argv(
                cell_id, backend=args.backend, assembly=str(assembly.folder), connect=listen[:1],
                delay_s=args.delay, rrd=run / f"{cell_id}{suffix}.rrd",
                recording_id=settings["recording_id"], zenoh_config=args.zenoh_config, viewer_url=viewer.connect,
                ilc_state=run / f"{cell_id}-ilc.json", cell_options=settings.get("cell_options", []),
                cell_seed=cell_seed(settings["seed"], number))))
        log = PlannerLog(run / f"planner{suffix}.rrd", settings["recording_id"], cell_ids, viewer,
                         assembling=cell_ids[:1] if args.assemble else ())
        stack.callback(log.close)
        log.precedence(relation.parts, reduction(relation))
        abandoned = [event.experiment for event in journal.abandon_in_flight()]
        if abandoned:
            settings.setdefault("abandoned", []).extend(abandoned)
            LOG.warning("resume: experiment(s) %s were running when the session stopped; abandoned (their pairs "
                        "are asked again, under new numbers, if still needed)", ", ".join(map(str, abandoned)))
        allowed = cell_ids if args.cells > 0 else (args.allow_cells or None)  # by default only its own cells
        pool = CellPool(session, directory, timeout=args.timeout, wait_for_cell=args.wait_for_cell, allowed=allowed)
        stack.callback(pool.close)
        oracle = ZenohOracle(pool, directory, journal, run_id, settings["seed"])
        for cell in cells:
            cell.wait_for_line("ready", timeout=args.wait_for_cell)
        try:
            directory.wait_for(max(1, len(cell_ids)), timeout=args.wait_for_cell)
        except BridgeError as exc:
            raise PlannerError(f"cells: {exc}") from None
        timings = {"cells_ready_s": time.perf_counter() - started}
        LOG.info("assumes: %s", model.assumption())  # once every input was checked and the cells are up
        try:
            sizes = _learn_sizes(oracle, learner, journal, log)
        finally:
            for incident in pool.incidents:  # timeouts, conflicting replies, dropped cells
                LOG.warning("%s", incident)
        timings["learned_s"] = time.perf_counter() - started
        learned = run / "learned.lp"
        for change in sizes.model_changes:
            LOG.warning("model changed: %s", change)
        write_facts(learned, _learned_atoms(assembly, demo_facts(demos), relation, sizes),
                    header=_learned_header(assembly, run, sizes))
        assignment, found = _plans(learned, args.plans)
        write_facts(run / "assignment.lp", [fact("assigned", p, h) for p, h in assignment.items()],
                    header="A hole assignment of learned.lp (the paper's greedy one when it finds one, "
                           "else a matching; paper 2.2).")
        log.assignment(assignment)
        assembly_report = (_assemble(session, cell_ids, learned, found[0], settings["seed"], args,
                                     cells[0] if cells else None) if args.assemble else None)
    fits = sorted(sizes.knowledge.fits)
    must_precede = relation.pairs()
    versus = _versus_truth(truth, required, fits, must_precede)
    matches = None if None in versus.values() else versus["sizes_equal"] and versus["precedence_sound"]
    result = {
        "run": str(run),
        "experiments": len(journal.entries),
        "fits": [list(pair) for pair in fits],
        "must_precede": [list(pair) for pair in must_precede],
        "plans": [plan.as_json() for plan in found],
        "matches_truth": matches,
        "model": sizes.model.name,
        "assumption": sizes.model.assumption(),
        "model_changes": list(sizes.model_changes),
        "demonstrated": [list(pair) for pair in sizes.demonstrated],
    }
    settings.update(result, status="done", truth=versus, assignment=assignment, cells=cell_ids,
                    journal=[{"part": e.part, "hole": e.hole, "result": e.result, "cell": e.cell,
                              "retest": e.retest} for e in journal.entries],
                    wall_s=round(time.perf_counter() - started, 3),
                    timings={k: round(v, 3) for k, v in timings.items()})
    if assembly_report is not None:
        settings["assembly_run"] = assembly_report  # "assembly" in session.json names the assembly
        result["assembly"] = assembly_report
    _save(run, settings)
    return result


def _program() -> str:
    """How to call this program again: the repository's ``run.sh`` (absolute, so it works
    from any folder) in a checkout, else the installed console command."""
    wrapper = Path(__file__).resolve().parents[2] / "run.sh"
    return shlex.quote(str(wrapper)) if wrapper.is_file() else PROGRAM


def _assembly_line(report: dict) -> str:
    errors = report["final_pose_error_mm"]
    worst = max(errors.values(), default=0.0)
    return (f"assembly of plan 1: assembled {report['assembled']}, {len(report['steps'])} steps, "
            f"{len(report['replans'])} re-plan(s), largest pose error {worst:.2f} mm, {report['wall_s']:.1f} s")


def _summary(result: dict, run: Path) -> str:
    """The human ending of a session: what was learned, the files written, what to run next."""
    settings = json.loads((run / SETTINGS).read_text(encoding="utf-8"))
    cells: dict[str, int] = {}
    for entry in settings["journal"]:
        cells[entry["cell"]] = cells.get(entry["cell"], 0) + 1
    plan = " ".join(f"{s['part']}" + (f"->{s['hole']}" if s["hole"] else "") for s in result["plans"][0])
    files = sorted(p.name for p in run.iterdir() if p.is_file() and not p.name.startswith("."))
    python = shlex.quote(sys.executable)
    learned = shlex.quote(str(run / "learned.lp"))
    part = result["fits"][0][0] if result["fits"] else "p1"
    return "\n".join([
        f"run {result['run']}: {result['experiments']} experiments "
        f"({', '.join(f'{c}: {n}' for c, n in sorted(cells.items()))}) in {settings['wall_s']:.1f} s",
        "fits: " + " ".join(f"{p}->{h}" for p, h in result["fits"])
        + (f" (started from {len(result['demonstrated'])} seen in the demonstrations)"
           if result["demonstrated"] else ""),
        f"assumes: {result['assumption']}",
        *(f"model changed: {change}" for change in result["model_changes"]),
        f"must precede: {len(result['must_precede'])} pairs",
        "assignment: " + " ".join(f"{p}->{h}" for p, h in settings["assignment"].items()),
        f"plan 1 of {len(result['plans'])}: {plan}",
        f"versus the truth: sizes equal {settings['truth']['sizes_equal']}, every true "
        f"precedence learned {settings['truth']['precedence_sound']} "
        f"({settings['truth']['precedence_extra']} pairs more than required); "
        f"matches truth: {result['matches_truth']}",
        *([_assembly_line(result["assembly"])] if "assembly" in result else []),
        f"files written in {run}: {' '.join(files)}",
        "next:",
        *(f"  {label + ':':<24}{command}" for label, command in (
            ("view the recording", f"{_program()} view {shlex.quote(str(run))}"),
            (f"holes {part} fits into", f"echo '#show. #show H : fits({part},H).' | {python} -m clingo {learned} -"),
            ("five complete plans", f"{python} -m clingo {shlex.quote(str(encoding('plans.lp')))} {learned} 5"),
        )),
    ])


def main(argv: list[str]) -> int:
    args = build_parser().parse_args(argv)
    viewer = viewer_of(args)
    with hosted_viewer(viewer) as live:
        result = run_session(args, live)
        print(json.dumps(result) if args.json else _summary(result, Path(result["run"])), flush=True)
        keep_serving(viewer)
    stopped = result.get("assembly", {}).get("error")
    if stopped:
        LOG.error("%s", stopped)
        return EXIT_UNSOLVABLE
    return 0
