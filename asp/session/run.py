"""The end-to-end learning session (``./run.sh session``, :mod:`asp.session.cli`), planner
and cells over Zenoh, from its settings (:class:`asp.session.settings.SessionSettings`).

1. learns must-precede from the assembly's demonstrations (Algorithm 1; ``--demos FILE``
   for others); parts they place into holes (``p1@r1``) are fits the size learner
   starts from (paper 4.2, last paragraph);
2. starts ``--cells N`` cell co-processes (``executor serve``) connected to the planner's
   loopback endpoint (``--cells 0 --connect EP`` uses cells already on the network);
3. learns which part fits which hole (``--prior cad``: starting from the outcomes the
   nominal sections of an imported product decide), keeping every alive cell busy with experiments
   none of whose outcomes can entail another's (:func:`_learn_sizes`,
   :mod:`asp.session.zenoh_oracle`); every finished experiment is journaled (fsynced) before
   the learner uses it;
4. assigns holes (the paper's greedy rule, else a matching) and computes complete plans, each run through the checker;
5. writes ``RUN/learned.lp`` (the project's facts vocabulary), ``RUN/assignment.lp``,
   ``RUN/session.json``, ``RUN/journal.jsonl``, the Rerun recordings ``RUN/*.rrd``
   (planner and cells in one recording id) and their blueprint ``RUN/view.rbl``
   (:func:`view_blueprint`), and prints a summary (``--json``: the
   contract ``{"run", "experiments", "fits", "must_precede", "plans", "matches_truth"}``).

``--resume RUN`` continues a killed session: the journal is replayed into the learner,
no finished experiment is run again. The sizes are learned over the parts and holes of
the assembly's ``sizes.lp`` (Cranfield: pegs p1 p2 p3 p4 sh, holes r1 r2 s1 s2 br), or,
without one, over the parts with role ``peg`` and all holes. ``matches_truth``: the
learned part-hole relation equals ``sizes.lp`` and every true precedence constraint
(``precedence.lp``) is learned, so every admitted sequence is feasible.
"""

from __future__ import annotations

import logging
import shutil
import time
import uuid
from collections.abc import Mapping
from contextlib import ExitStack
from datetime import UTC, datetime
from pathlib import Path

import msgspec
import zenoh

from asp import PlannerError
from asp.plans.assign import UnsolvableAssembly, cell_orders, feasible_assignment, load_learned_facts, product_facts
from asp.plans.plans import Plan, check_plan, plans
from asp.precedence.demos import Demonstrations, demo_facts
from asp.precedence.explore.learner import SUPPORTS
from asp.precedence.explore.trials import write_trials
from asp.precedence.learn import learn_for_assembly, learn_must_precede, learn_with_prior
from asp.precedence.relation import Relation, load_relation, precedence_facts, reduction, true_relation
from asp.session.cells import CellProcess, cell_seed, stop_all
from asp.session.folder import RunLock, lock_run_folder
from asp.session.journal import JOURNAL_NAME, Journal
from asp.session.log import PlannerLog
from asp.session.precedence import (
    PRECEDENCE_JOURNAL,
    CellOracle,
    ExploredPrecedence,
    explore_demos,
    explore_precedence,
)
from asp.session.settings import (
    MAX_STARTS,
    SESSION_FILE,
    DecidedPrior,
    NominalFits,
    SessionFile,
    SessionSettings,
    checked,
    fit_text,
    new_session_file,
    prior_statement,
    product_digest,
    read_session_file,
    resumed_settings,
    write_session_file,
)
from asp.session.zenoh_oracle import Finished, ZenohOracle
from asp.sizes.cad_prior import cad_prior
from asp.sizes.knowledge import Pair
from asp.sizes.learner import LearningOptions, SizeLearner, SizeLearningResult
from asp.sizes.models import SizeModel, model_for
from asp.sizes.truth_oracle import Result, TruthOracle
from asp.solve import fact, write_facts
from bridge import BridgeError
from bridge.assembly import NEAR_MISS_BACKENDS, Assembly, load_assembly
from bridge.cell_settings import DEFAULT_CELL, ServeSettings
from bridge.client import CellDirectory, CellPool, PoolLimits
from bridge.files import make_folder
from bridge.product.nominal import NOMINAL_FIT_ROOM
from bridge.recording.layout import Contents, write_blueprint
from bridge.recording.reader import read_recording
from bridge.recording.sinks import NO_VIEWER, Viewer
from bridge.session import DEFAULT_ENDPOINT, LOOPBACK_ANY_PORT, bound_endpoints, open_session

LOG = logging.getLogger(__name__)
RESULT_KEYS = ("run", "experiments", "fits", "must_precede", "plans", "matches_truth", "model", "assumption",
               "prior", "model_changes", "demonstrated", "not_observed", "nominal_fits")
"""What :func:`run_session` returns (``session --json``), in this order, as ``session.json`` holds them."""
CRASH_WAIT_S = 2.0
"""How long the pool waits for a started cell's process to end when its links just closed
or it missed a reply [s]: the peer sees the sockets close a moment before the process can
be reaped."""


def _run_folder(settings: SessionSettings) -> tuple[Path, SessionFile, RunLock, bool]:
    """The run folder, locked for this session (:mod:`asp.session.folder`), its
    ``session.json`` (read back when resuming) and whether this start created the folder.
    ``out`` creates the folder and refuses one that holds a session (journaled experiments or a
    finished run); a folder a failed start left (one that existed before) may be used again."""
    if settings.resume is not None:
        resume = Path(settings.resume)
        if not (resume / SESSION_FILE).is_file():
            raise PlannerError(f"--resume {resume}: expected a run folder holding {SESSION_FILE}")
        lock = lock_run_folder(resume)
        try:
            record = read_session_file(resume)
            if record.starts + 1 >= MAX_STARTS:
                raise PlannerError(f"{resume / SESSION_FILE}: started {record.starts} times; "
                                   f"expected fewer than {MAX_STARTS - 1}")
        except PlannerError:
            lock.release()
            raise
        record.starts += 1
        return resume, record, lock, False
    run = Path(settings.out) if settings.out is not None else Path("runs") / datetime.now(UTC).strftime(
        "%Y%m%dT%H%M%SZ")
    created = not run.exists()
    lock = lock_run_folder(make_folder(run))
    if _holds_session(run):
        lock.release()
        raise PlannerError(f"--out {run}: already holds a session (its journal); "
                           f"use --resume {run} or another folder")
    # demos and a product folder absolute (a shipped product by its name): a resume may run from another folder
    demos = None if settings.demos is None else str(Path(settings.demos).absolute())
    product = Path(settings.assembly)
    assembly = str(product.absolute()) if (product / "assembly.toml").is_file() else settings.assembly
    return run, new_session_file(msgspec.structs.replace(settings, demos=demos, assembly=assembly),
                                 str(uuid.uuid4())), lock, created


def _holds_session(run: Path) -> bool:
    """Whether ``run`` holds a session to resume rather than overwrite: a journal with
    at least one line, a precedence journal, or a ``session.json`` with status ``done``."""
    journal = run / JOURNAL_NAME
    if (journal.is_file() and journal.stat().st_size > 0) or (run / PRECEDENCE_JOURNAL).is_file():
        return True
    try:
        return read_session_file(run).status == "done"
    except PlannerError:
        return False


def _sizes_domain(assembly: Assembly, requested_model: str | None
                  ) -> tuple[list[str], list[str], TruthOracle | None, SizeModel]:
    """Parts and holes to learn, the truth (``sizes.lp``, if the product has one) and the
    size model of the run (refused before any cell starts when it is unsound for the product).
    A ``sizes.lp`` naming no part or no hole (an imported product with no part in a hole or
    on a pin) leaves nothing to learn: every part is planned without a hole."""
    if assembly.has_file("sizes.lp"):
        known = TruthOracle.from_assembly(str(assembly.folder), allow_empty=True)
        truth: TruthOracle | None = known
        parts, holes = list(known.parts), list(known.holes)
    else:
        truth, parts, holes = None, [p.id for p in assembly.parts if p.role == "peg"], assembly.hole_ids
        if not parts or not holes:
            raise PlannerError(f"assembly '{assembly.name}': no sizes.lp and no pegs/holes to learn")
    model = model_for(parts, requested_model, assembly.size_model, assembly.sections())
    return parts, holes, truth, model


def _placed_by_hand(assembly: Assembly, backend: str, truth: TruthOracle | None, decided: list[tuple[Pair, Result]]
                    ) -> list[tuple[Pair, Result]]:
    """The outcomes of the pairs no cell of ``backend`` can try
    (:meth:`bridge.assembly.Assembly.tried_by_hand`: a part placed by hand, a hole the
    cell does not model, a near miss the PyBullet cell does not resolve), from the
    product's ``sizes.lp`` (an imported product's nominal sections), except those ``decided`` already."""
    if truth is None:
        return []
    known = {pair for pair, _ in decided}
    return [((part, hole), "fit" if (part, hole) in truth.fits else "no_fit")
            for part in truth.parts for hole in truth.holes
            if assembly.tried_by_hand(part, hole, backend) and (part, hole) not in known]


def _against_cell_orders(assembly: Assembly, pairs: list[Pair], truth: TruthOracle | None,
                         decided: list[tuple[Pair, Result]]) -> tuple[list[tuple[Pair, Result]], str | None]:
    """The pairs (of ``pairs``, the sizes' domain) whose trial would break one of the cell's
    own orders (``cell_order.lp``: the part tried goes in after a part standing in the
    trial's scene that the cell puts in after it, :meth:`bridge.assembly.Assembly.in_trial`),
    except those ``decided`` already,
    with their outcomes from the product's ``sizes.lp`` and the line a run prints for them
    (None without such a pair); PlannerError when there is such a pair and no ``sizes.lp``."""
    orders = set(cell_orders(assembly))
    known = {pair for pair, _ in decided}
    against = {(part, hole): sorted(q for q in assembly.in_trial(part, hole) if (part, q) in orders)
               for part, hole in pairs if (part, hole) not in known}
    against = {pair: stand for pair, stand in against.items() if stand}
    if not against:
        return [], None
    shown = " ".join(f"{p}->{h} ({' '.join(stand)} in place)" for (p, h), stand in sorted(against.items())[:8])
    if truth is None:
        raise PlannerError(f"{assembly.folder / 'cell_order.lp'}: the trials {shown} would break the cell's own "
                           "orders, and there is no sizes.lp to take their outcomes from")
    taken: list[tuple[Pair, Result]] = [(pair, "fit" if pair in truth.fits else "no_fit") for pair in sorted(against)]
    fits = sum(result == "fit" for _, result in taken)
    return taken, (f"{len(taken)} pairs whose trial would stand a part the cell puts in after the one tried (the "
                   f"cell's own orders, cell_order.lp: {shown}{' ...' if len(taken) > 8 else ''}) are taken from "
                   f"{assembly.folder / 'sizes.lp'} (the nominal sections, {fits} fit), not observed")


def _by_hand_statement(assembly: Assembly, backend: str, by_hand: list[tuple[Pair, Result]]) -> str:
    """The line a run prints (and ``learned.lp`` keeps) for the pairs it takes from
    ``sizes.lp`` because no cell of ``backend`` can try them."""
    fits = sum(result == "fit" for _, result in by_hand)
    shown = " ".join(f"{part}->{hole}" for (part, hole), _ in by_hand[:8]) + (" ..." if len(by_hand) > 8 else "")
    near = " or a near miss its physics does not resolve" if backend in NEAR_MISS_BACKENDS else ""
    return (f"{len(by_hand)} pairs no cell can try (a part placed by hand, a hole the cell does not model{near}: "
            f"{shown}) are taken from {assembly.folder / 'sizes.lp'} (the nominal sections, {fits} fit), not observed")


def _near_miss_statement(assembly: Assembly, backend: str, by_hand: list[tuple[Pair, Result]]) -> str | None:
    """The line a run prints (and ``learned.lp`` keeps) for the product's near misses
    (``near_miss`` of ``geometry.toml``) that its cells try: those of a backend not in
    :data:`bridge.assembly.NEAR_MISS_BACKENDS`, whose pegs lack no corners; None when
    there is none (or the backend takes them from ``sizes.lp``)."""
    taken = {pair for pair, _ in by_hand}
    tried = sorted(pair for pair in assembly.near_misses if pair not in taken)
    if backend in NEAR_MISS_BACKENDS or not tried:
        return None
    shown = " ".join(f"{part}->{hole}" for part, hole in tried[:8]) + (" ..." if len(tried) > 8 else "")
    return (f"{len(tried)} near miss(es) the PyBullet cell does not resolve ({shown}) are tried: backend {backend} "
            "does not build its pegs from sections with corners rounded by a hull margin")


def _nominal_fits(assembly: Assembly, backend: str, parts: list[str], holes: list[str]) -> NominalFits | None:
    """The fits with room under what the simulated cell (``backend`` sim) resolves that it
    tries with the room it builds them with (:data:`bridge.product.nominal.NOMINAL_FIT_ROOM`):
    the nominal zero-clearance fits and the fits it widens, bores on pins and pegs in holes
    of a base with its own mesh (:attr:`bridge.assembly.Assembly.widened`, with their CAD
    room); None with another
    backend or without such a pair among ``parts`` x ``holes``."""
    pairs = sorted(pair for pair in assembly.nominal_fits | set(assembly.widened)
                   if pair[0] in parts and pair[1] in holes and not assembly.tried_by_hand(*pair, backend))
    rooms = {f"{p}->{h}": assembly.widened[p, h] for p, h in pairs
             if (p, h) in assembly.widened and (p, h) not in assembly.nominal_fits}
    return NominalFits(room_m=NOMINAL_FIT_ROOM, pairs=pairs, cad_room_m=rooms) if backend == "sim" and pairs else None


def _nominal_statement(nominal: NominalFits) -> str:
    """The line a run prints (and ``learned.lp`` keeps) for the fits its simulated cell
    builds with room (:func:`_nominal_fits`)."""
    shown = " ".join(fit_text(nominal.cad_room_m, part, hole) for part, hole in nominal.pairs[:8]) + (
        " ..." if len(nominal.pairs) > 8 else "")
    return (f"{len(nominal.pairs)} fits stated by the CAD with room under what the simulated cell's physics resolves "
            f"({shown}; room 0 unless given) are built in that cell with {nominal.room_m * 1e3:.3f} mm of room per "
            "side: their outcomes are observed in that model, not at the CAD's room")



def _endpoints(settings: SessionSettings) -> tuple[list[str], list[str]]:
    """(listen, connect) of the planner: it listens for its own cells, else connects."""
    listen, connect = list(settings.listen), list(settings.connect)
    if settings.cells > 0:
        return listen or [LOOPBACK_ANY_PORT], connect
    return listen, connect or ([] if settings.zenoh_config else [DEFAULT_ENDPOINT])


def _learn_sizes(oracle: ZenohOracle, learner: SizeLearner, journal: Journal,
                 log: PlannerLog, timings: dict[str, float]) -> SizeLearningResult:
    """Replay the journal, then keep every alive cell busy until the learner is done.

    Whenever cells are free, the learner is asked for as many pairs as free cells,
    independent of the running experiments and of each other, and they are started at
    once; when there are none, the free cells wait for a running experiment to finish.
    Every experiment that finished meanwhile is taken and recorded with one closure
    solve (:meth:`SizeLearner.record_all`) before the next batch is planned, so with many
    cells the planner plans once per few results rather than once per result; the
    Rerun log of the results is queued (:class:`PlannerLog` writes it in its own thread)
    after the next batch has started.
    ``timings["planning_s"]`` adds up the time spent recording and choosing [s].
    """
    def record(finished: list[Finished]) -> None:
        started = time.perf_counter()
        learner.record_all([(f.part, f.hole, f.result) for f in finished])
        timings["planning_s"] += time.perf_counter() - started

    def write_log(finished: list[Finished]) -> None:
        for f in finished:
            log.experiment(f.experiment, f.part, f.hole, f.result, f.cell, learner.knowledge)
            attempts = "" if f.attempts is None else f"{f.attempts} attempt(s), "
            LOG.info("experiment %d on %s: %s -> %s %s (%s%.1f s); %d pairs unknown", f.experiment, f.cell,
                      f.part, f.hole, f.result, attempts, f.wall_s, len(learner.knowledge.unknown))

    timings.setdefault("planning_s", 0.0)
    for entry in journal.entries:  # one by one: the log shows the knowledge after each
        record([Finished(entry.part, entry.hole, entry.result, entry.cell, entry.experiment)])
        log.experiment(entry.experiment, entry.part, entry.hole, entry.result, entry.cell, learner.knowledge)
    if journal.entries:
        LOG.info("resumed: %d experiments from the journal; %d pairs unknown",
                  len(journal.entries), len(learner.knowledge.unknown))
    done: list[Finished] = []
    running: list[tuple[str, str]] = []
    while True:
        free = max(1, oracle.alive_cells()) - len(running)
        if free > 0:
            started = time.perf_counter()
            batch = learner.next_batch(free, pending=running)
            timings["planning_s"] += time.perf_counter() - started
            if not batch and not running:
                write_log(done)
                return learner.result()
            for pair in batch:
                oracle.submit(*pair)
                running.append(pair)
            oracle.dispatch()
        write_log(done)
        done = [oracle.next_result()]
        while (more := oracle.finished_result()) is not None:
            done.append(more)
        for f in done:
            running.remove((f.part, f.hole))
        record(done)


def _learned_atoms(assembly: Assembly, demos_atoms: list, relation: Relation,
                   sizes: SizeLearningResult, not_observed: list[Pair]) -> list:
    """The facts of ``learned.lp``; ``not_observed(P,H)`` for each pair taken from the
    product's ``sizes.lp`` because no cell can try it (:func:`_placed_by_hand`)."""
    atoms = [fact("part", p) for p in assembly.part_ids] + [fact("hole", h) for h in assembly.hole_ids]
    atoms += demos_atoms + precedence_facts(relation) + sizes.facts()
    atoms += [fact("not_observed", part, hole) for part, hole in not_observed] + product_facts(assembly)
    return list(dict.fromkeys(atoms))


def _learned_header(assembly: Assembly, run: Path, sizes: SizeLearningResult, prior: str | None) -> str:
    """The comment atop ``learned.lp``: where it comes from, what it assumes (``prior``:
    the size prior's statement, if any), what its ids name."""
    lines = [f"Learned by a session on {assembly.name} ({run}).", f"Assumes: {sizes.model.assumption()}."]
    lines += [] if prior is None else [f"Assumes: {prior}."]
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
              timeout_s: float, process: CellProcess | None, manual: Mapping[str, str]) -> dict:
    """Execute ``plan`` in the session's first cell (:mod:`asp.assemble`; ``process``: its
    process if the session started it; ``manual``: why the product places parts by hand);
    the report, with ``"error"`` when the product could not be finished."""
    from asp.assemble.driver import ZenohDriver
    from asp.assemble.execute import AssemblyStopped, execute, with_manual_reasons

    if not cell_ids:
        raise PlannerError("--assemble needs a cell of this session (--cells 1 or more)")
    started = time.perf_counter()
    driver = ZenohDriver(session, cell_ids[0], seed, timeout_s, process)
    try:
        report = execute(load_learned_facts([learned]), plan, driver)
    except AssemblyStopped as exc:
        report = dict(exc.report, error=str(exc))
    report = with_manual_reasons(report, manual)
    report["wall_s"] = round(time.perf_counter() - started, 3)
    return report


def _explore(session: zenoh.Session, cells: list[str], learned: Path, demos: Demonstrations, prior: Path | None,
             record: SessionFile, timeout_s: float, cell_before: tuple[Pair, ...]) -> ExploredPrecedence:
    """``session --precedence explore``: precedence from ``demos``, the geometric ``prior``
    (None: no CAD) and experiments at the first of ``cells`` keeping its own orders
    ``cell_before``, its pegs in the holes of an assignment of the sizes just learned (``learned``)."""
    if not cells:
        raise PlannerError("--precedence explore needs a cell (none is alive)")
    try:
        assignment = feasible_assignment(load_learned_facts([learned]))
    except UnsolvableAssembly as exc:
        raise PlannerError(f"--precedence explore: the learned sizes give no hole assignment to experiment "
                           f"with: {exc}") from None
    oracle = CellOracle(session, cells[0], assignment, seed=record.seed, timeout_s=timeout_s)
    explored = explore_precedence(demos, prior, oracle, run_id=f"{record.recording_id}.p",
                                  journal=learned.parent / PRECEDENCE_JOURNAL, cell_before=cell_before)
    LOG.info("precedence by exploration: %d demonstration(s), %s, %d experiment(s) at %s (%.1f s simulated)",
             len(demos.sequences), "no CAD" if prior is None else f"the CAD ({prior})", len(explored.trials),
             cells[0], explored.sim_s)
    return explored


def view_blueprint(run: Path) -> Path:
    """``RUN/view.rbl``, the blueprint of what ``RUN/*.rrd`` hold once every writer closed
    its file (:meth:`bridge.recording.layout.Contents.of`): an assembly tab
    only for a cell that assembled, each cell's Fig. 17 on its first fitting attempt."""
    summary = read_recording(sorted(run.glob("*.rrd")))
    return write_blueprint(run, Contents.of(summary.entities))


def run_session(settings: SessionSettings, viewer: Viewer = NO_VIEWER) -> dict:
    """Run (or resume) a session; returns the JSON result. Planner and cells also stream
    their recordings live to ``viewer``. PlannerError naming the field when a setting is
    out of its range."""
    started = time.perf_counter()
    settings = checked(settings)
    run, record, lock, created = _run_folder(settings)
    try:
        return _run_locked(settings, run, record, started, viewer)
    except BaseException:
        if created and not _holds_session(run):  # failed at start: no half-made run folder
            shutil.rmtree(run, ignore_errors=True)
        raise
    finally:
        lock.release()


def _resumed(settings: SessionSettings, record: SessionFile, run: Path) -> tuple[SessionSettings, list[str]]:
    """The settings a resume of ``run`` runs with: what its ``session.json`` (``record``)
    keeps wins over ``settings`` (:func:`resumed_settings`); and the warnings to give once
    the resume is checked: the options it ignores, a folder that kept no backend (written
    before it was kept)."""
    unrecorded = record.backend is None
    settings, ignored = resumed_settings(settings, record)
    warnings = [f"resume: {run / SESSION_FILE} keeps no backend, delay or product digest (written by an older "
                f"version): resuming with --backend {settings.backend} --delay {settings.delay_s:g} and the "
                "product as it is now"] if unrecorded else []
    if ignored:
        warnings.append(f"resume: ignoring {', '.join(ignored)} (a resume keeps the settings of {run / SESSION_FILE})")
    return settings, warnings


def _check_product(settings: SessionSettings, record: SessionFile, assembly: Assembly, run: Path) -> None:
    """Record the digest of the product as loaded now in ``record``; a resume whose product
    changed since the run started is refused (PlannerError): its journaled observations are
    of the product as it was."""
    digest = product_digest(assembly.folder)
    if settings.resume is not None and record.product not in (None, digest):
        raise PlannerError(f"--resume {run}: the product {assembly.folder} changed since the session started "
                           f"(digest {digest[:12]}, {run / SESSION_FILE} says {(record.product or '')[:12]}); its "
                           "journaled observations are of the product as it was: start a new session")
    record.product = digest


def _resume_line(settings: SessionSettings, record: SessionFile, run: Path, journal: Journal) -> str:
    """What a resume of ``run`` resumes, in one line."""
    magnitudes = msgspec.structs.asdict(record.cell.magnitudes)
    changed = [f"{name} {value:g}" for name, value in magnitudes.items()
               if value != getattr(DEFAULT_CELL.magnitudes, name)]
    return (f"resuming {run} (start {record.starts}): {len(journal.entries)} experiment(s) journaled; "
            f"assembly {record.assembly} (product digest {(record.product or '')[:12]}), policy {record.policy}, "
            f"seed {record.seed}, confirm {record.confirm}, backend {settings.backend}"
            + (f" (delay {settings.delay_s:g} s)" if settings.backend == "truth" else "")
            + f", cells: layer {record.cell.layer}, first cell seed {record.cell.cell_seed}"
            + (f", {', '.join(changed)}" if changed else ""))


def session_cell(settings: SessionSettings, record: SessionFile, run: Path, number: int, connect: list[str],
                 viewer_url: str | None) -> ServeSettings:
    """The settings of the session's cell ``c<number>`` (1, 2, ...) connecting to
    ``connect``: its recording ``RUN/c<k>[-<start>].rrd`` in the run's recording id, its
    cell seed (:func:`asp.session.cells.cell_seed`) and, for a sim cell, its ILC
    corrections kept in ``RUN/c<k>-ilc.json`` (a resume passes the same file, so the
    cell reloads what it learned)."""
    cell_id = f"c{number}"
    suffix = "" if record.starts == 1 else f"-{record.starts}"
    return ServeSettings(
        cell_id=cell_id, backend=settings.backend, backend_options=settings.backend_options,
        assembly=str(load_assembly(record.assembly).folder),
        connect=tuple(connect), delay_s=settings.delay_s, rrd=str(run / f"{cell_id}{suffix}.rrd"),
        recording_id=record.recording_id, zenoh_config=settings.zenoh_config, viewer_url=viewer_url,
        ilc_state=str(run / f"{cell_id}-ilc.json") if settings.backend == "sim" else None,
        cell=msgspec.structs.replace(record.cell, cell_seed=cell_seed(record.cell.cell_seed, number)))


def _run_locked(settings: SessionSettings, run: Path, record: SessionFile, started: float,
                viewer: Viewer) -> dict:
    """:func:`run_session` in the locked run folder ``run`` whose ``session.json`` is
    ``record`` (what is learned comes from there, and the cells' backend on a resume);
    ``started``: its ``time.perf_counter()`` [s] at the start."""
    settings, warnings = _resumed(settings, record, run) if settings.resume is not None else (settings, [])
    assembly = load_assembly(record.assembly)
    _check_product(settings, record, assembly, run)
    answers_from = {"sim": ("geometry.toml",), "franka": ("geometry.toml",),
                    "truth": ("geometry.toml", "sizes.lp")}.get(settings.backend, ())
    if settings.cells > 0 and answers_from and not any(assembly.has_file(name) for name in answers_from):
        raise PlannerError(f"{assembly.folder / answers_from[0]}: no such file; the cells a session starts (--backend "
                           f"{settings.backend}) answer from {' or '.join(answers_from)} (docs/backends.md); describe "
                           "the product, or use --cells 0 with cells of your own")
    parts, holes, truth, model = _sizes_domain(assembly, record.model)
    decided = ([] if record.size_prior is None
               else cad_prior(assembly, record.tolerance_m, tuple(parts), tuple(holes)))
    record.prior = None if record.size_prior is None else DecidedPrior(
        kind=record.size_prior, tolerance_m=record.tolerance_m, pairs=len(parts) * len(holes),
        decided=[(p, h, result) for (p, h), result in decided])
    by_hand = _placed_by_hand(assembly, settings.backend, truth, decided)
    against_orders, orders_statement = _against_cell_orders(
        assembly, [(part, hole) for part in parts for hole in holes], truth, [*decided, *by_hand])
    decided = [*decided, *by_hand, *against_orders]
    record.not_observed = [(part, hole, result) for (part, hole), result in (*by_hand, *against_orders)]
    not_observed = [pair for pair, _ in (*by_hand, *against_orders)]
    record.nominal_fits = _nominal_fits(assembly, settings.backend, parts, holes)
    stated_prior = "; ".join(statement for statement in (
        None if record.prior is None else prior_statement(record.prior),
        None if not by_hand else _by_hand_statement(assembly, settings.backend, by_hand),
        orders_statement,
        _near_miss_statement(assembly, settings.backend, by_hand),
        None if record.nominal_fits is None else _nominal_statement(record.nominal_fits))
        if statement is not None) or None
    # Every input file is read before any cell starts: bad input fails fast.
    demos, relation, prior = learn_for_assembly(assembly, None if record.demos is None else Path(record.demos))
    truth_relation = true_relation(assembly) if assembly.has_file("precedence.lp") else None
    if record.precedence == "explore":
        demos = explore_demos(demos, truth_relation, record.seed)
        relation = learn_must_precede(demos) if prior is None else learn_with_prior(
            demos, load_relation([prior], data=True), str(prior))
    if prior is not None:
        LOG.info("precedence: the geometric prior %s refined by %d demonstration(s)", prior, len(demos.sequences))
    options = LearningOptions(confirm=record.confirm, demonstrated=demos.placements(), model=model, prior=decided)
    learner = SizeLearner(parts, holes, record.policy, record.seed, options)
    required = None if truth_relation is None else set(truth_relation.pairs())
    run_id = record.recording_id
    listen, connect = _endpoints(settings)
    zenoh_config = None if settings.zenoh_config is None else Path(settings.zenoh_config)
    suffix = "" if record.starts == 1 else f"-{record.starts}"
    cell_ids = [f"c{k}" for k in range(1, settings.cells + 1)]
    journal = Journal(run)
    try:
        journal.check_ids(parts, holes)
    except PlannerError:
        journal.close()
        raise
    for warning in warnings:
        LOG.warning("%s", warning)
    if settings.resume is not None:
        LOG.info("%s", _resume_line(settings, record, run, journal))
    write_session_file(run, record)
    with ExitStack() as stack:
        stack.callback(journal.close)
        session = open_session(listen, connect, zenoh_config)
        stack.callback(session.close)
        listen = bound_endpoints(session, listen)  # the port its cells connect to, as bound
        directory = CellDirectory(session)
        stack.callback(directory.close)
        cells: list[CellProcess] = []
        stack.callback(lambda: stop_all(cells))
        for number in range(1, settings.cells + 1):  # they start up in parallel with each other and us
            cells.append(CellProcess(session_cell(settings, record, run, number, listen[:1], viewer.connect)))
        log = PlannerLog(run / f"planner{suffix}.rrd", record.recording_id, cell_ids, learner.knowledge, viewer)
        stack.callback(log.close)
        log.precedence(relation.parts, reduction(relation))
        abandoned = [event.experiment for event in journal.abandon_in_flight()]
        if abandoned:
            record.abandoned.extend(abandoned)
            LOG.warning("resume: experiment(s) %s were running when the session stopped; abandoned (their pairs "
                        "are asked again, under new numbers, if still needed)", ", ".join(map(str, abandoned)))
        # by default only its own cells
        allowed = cell_ids if settings.cells > 0 else (list(settings.allow_cells or ()) or None)
        processes = {cell.cell_id: cell for cell in cells}
        pool = CellPool(session, directory, PoolLimits(timeout=settings.timeout_s,
                                                       wait_for_cell=settings.wait_for_cell_s),
                        allowed=allowed,
                        exit_status=lambda cell: processes[cell].exit_code(CRASH_WAIT_S) if cell in processes else None)
        stack.callback(pool.close)
        oracle = ZenohOracle(pool, journal, run_id, record.seed)
        for cell in cells:
            cell.wait_for_line("ready", timeout=settings.wait_for_cell_s)
        try:
            directory.wait_for(max(1, len(cell_ids)), timeout=settings.wait_for_cell_s, among=allowed)
        except BridgeError as exc:
            raise PlannerError(f"cells: {exc}") from None
        if settings.cells == 0 and not settings.allow_cells:
            LOG.warning("--cells 0 without --allow-cells: using every cell that answers on the network (now: %s); "
                        "name the expected ones with --allow-cells", ", ".join(sorted(directory.alive())))
        timings = {"cells_ready_s": time.perf_counter() - started}
        LOG.info("assumes: %s", model.assumption())  # once every input was checked and the cells are up
        if stated_prior is not None:
            LOG.info("assumes: %s", stated_prior)
        try:
            sizes = _learn_sizes(oracle, learner, journal, log, timings)
        finally:
            for incident in pool.incidents:  # timeouts, conflicting replies, dropped cells
                LOG.warning("%s", incident)
        timings["learned_s"] = time.perf_counter() - started
        learned = run / "learned.lp"
        for change in sizes.model_changes:
            LOG.warning("model changed: %s", change)
        write_facts(learned, _learned_atoms(assembly, demo_facts(demos), relation, sizes, not_observed),
                    header=_learned_header(assembly, run, sizes, stated_prior))
        if record.precedence == "explore":
            started_explore = time.perf_counter()
            explored = _explore(session, cell_ids or sorted(set(directory.alive()) & set(allowed or directory.alive())),
                                learned, demos, prior, record, settings.timeout_s, cell_orders(assembly))
            relation = explored.learned.relation
            timings["precedence_s"] = time.perf_counter() - started_explore
            record.precedence_explored = explored.summary()
            write_facts(run / "precedence_support.lp", explored.learned.facts(),
                        header=f"Precedence learned by a session on {assembly.name} ({run}) from "
                               f"{len(demos.sequences)} demonstration(s), "
                               f"{'' if prior is None else 'the geometric precedence, '}"
                               f"{len(explored.trials)} experiment(s) (experiments.lp): support(A,B,S), S one of "
                               f"{', '.join(SUPPORTS)}; process_constraint(A,B): to confirm with the user.")
            write_trials(run / "experiments.lp", explored.trials)
            write_facts(learned, _learned_atoms(assembly, demo_facts(demos), relation, sizes, not_observed),
                        header=_learned_header(assembly, run, sizes, stated_prior))
            log.precedence(relation.parts, reduction(relation))
        unsolvable: UnsolvableAssembly | None = None
        try:
            assignment, found = _plans(learned, settings.plans)
        except UnsolvableAssembly as exc:
            assignment, found, unsolvable = {}, [], exc
        if unsolvable is None:
            write_facts(run / "assignment.lp", [fact("assigned", p, h) for p, h in assignment.items()],
                        header="A hole assignment of learned.lp (the paper's greedy one when it finds one, "
                               "else a matching; paper 2.2).")
            log.assignment(assignment)
        assembly_report = (_assemble(session, cell_ids, learned, found[0], record.seed, settings.timeout_s,
                                     cells[0] if cells else None, assembly.manual)
                           if settings.assemble and found else None)
    view_blueprint(run)
    fits = sorted(sizes.knowledge.fits)
    must_precede = relation.pairs()
    versus = _versus_truth(truth, required, fits, must_precede)
    known = [versus["sizes_equal"], versus["precedence_sound"]]
    matches = False if False in known else None if None in known else True
    record.run, record.experiments, record.fits = str(run), len(journal.entries), fits
    record.must_precede, record.plans, record.matches_truth = must_precede, [p.as_json() for p in found], matches
    record.model, record.assumption = sizes.model.name, sizes.model.assumption()
    record.model_changes, record.demonstrated = list(sizes.model_changes), list(sizes.demonstrated)
    record.status, record.truth, record.assignment, record.cells = "done", versus, assignment, cell_ids
    record.journal = [{"part": e.part, "hole": e.hole, "result": e.result, "cell": e.cell, "retest": e.retest}
                      for e in journal.entries]
    record.wall_s = round(time.perf_counter() - started, 3)
    record.timings = {k: round(v, 3) for k, v in timings.items()}
    result = {key: msgspec.to_builtins(getattr(record, key)) for key in RESULT_KEYS}
    if assembly_report is not None:
        record.assembly_run = assembly_report  # "assembly" in session.json names the assembly
        result["assembly"] = assembly_report
    if unsolvable is not None:
        record.error = result["error"] = str(unsolvable)
    write_session_file(run, record)
    return result
