"""``./run.sh executor serve``: a cell node serving insertion experiments over Zenoh.

The node declares the queryable ``cell/<id>/insert`` and the liveliness token
``cell/<id>/alive/<instance>`` (and ``cell/<id>/ping``, which echoes its payload unread), then
serves until SIGTERM/SIGINT (or, with ``--lifeline``, until its stdin closes: the
supervising session died), then closes the Zenoh session cleanly. Before it declares
anything else it claims its cell id (:mod:`assembly_constraints.executor.claim`): when another process already
serves that id it exits with code 2 instead, and it stops the same way if it meets such a
process later.

- Every request is size-capped and validated (:mod:`assembly_constraints.bridge.messages`) in the Zenoh
  thread; a malformed, oversized or wrong-version request gets an ErrorReply at once and
  the cell keeps serving.
- Valid requests run one at a time in the main thread. Results are idempotent by
  request id: a repeated id gets the cached reply and never re-runs the experiment.
- Backends: ``sim`` runs the PyBullet :class:`assembly_constraints.executor.trial.Cell` (imported lazily)
  with the execution layer and uncertainty of its cell settings (``--layer``,
  ``--cell-seed``, ``--grasp-tilt-bias`` ...) and its ILC state in ``--ilc-state``;
  ``truth`` answers from the cell's geometry (cross-sections), or where the product has no
  ``geometry.toml`` from its ``sizes.lp``, without simulation, optionally
  after ``--delay`` seconds, to measure the bridge and test the protocol quickly;
  ``MODULE:CLASS`` loads a user's backend (:mod:`assembly_constraints.executor.backend_plugin`), e.g. a real robot.
- Plan steps (``cell/<id>/step``, :class:`assembly_constraints.bridge.messages.StepRequest`) run in the same
  queue: ``sim`` in the assembling world of :mod:`assembly_constraints.executor.assembly` (kept between the
  steps of one plan run), ``truth`` from the geometry; ``--block-hole H`` puts an obstacle
  in hole H (a fault to show the planner's recovery); ``--uncertainty cell`` gives the
  plan steps the cell's uncertainty, layer and ILC (default ``random``: their own errors).

Its settings are one :class:`assembly_constraints.bridge.cell_settings.ServeSettings`: ``--settings JSON|FILE``
(how a session starts its cells) or the options below, which build the same struct; the
node takes only the struct (:func:`serve`).

One line per event is printed to stdout (``ready``, ``start <id> <part> <hole>``,
``done <id> <result>``), flushed, so a supervisor can follow the node.
"""

from __future__ import annotations

import argparse
import os
import queue
import signal
import threading
import time
import uuid
from collections import OrderedDict
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import clingo
import zenoh

from assembly_constraints.bridge import BridgeError
from assembly_constraints.bridge.assembly import load_assembly
from assembly_constraints.bridge.cell_settings import (
    DEFAULT_CELL,
    CellSettings,
    ServeSettings,
    add_assembly_uncertainty_argument,
    add_cell_arguments,
    cell_settings_of,
    decode_settings,
)
from assembly_constraints.bridge.cli_types import (
    ArgumentParser,
    add_assembly_argument,
    finite_float,
    nonempty_path,
    path_setting,
)
from assembly_constraints.bridge.inputs import read_bytes
from assembly_constraints.bridge.keys import alive_key, check_cell_id, insert_key, ping_key, step_key
from assembly_constraints.bridge.messages import (
    MAX_ERROR_CHARS,
    MAX_MESSAGE_BYTES,
    ErrorCode,
    ErrorReply,
    Evidence,
    InsertReply,
    InsertRequest,
    MessageError,
    Result,
    StepEvidence,
    StepReply,
    StepRequest,
    decode_request,
    decode_step_request,
    encode,
)
from assembly_constraints.bridge.recording.sinks import NO_VIEWER, Viewer, add_viewer_arguments
from assembly_constraints.bridge.session import (
    DEFAULT_ENDPOINT,
    SIGNAL_POLL_S,
    add_endpoint_arguments,
    cell_listen,
    open_session,
)
from assembly_constraints.executor import ExecutorError
from assembly_constraints.executor.backend_plugin import (
    Backend,
    CellContext,
    InvalidStep,
    RunActive,
    StepOutcome,
    UnknownPair,
    backend_option,
    check_run,
    check_step,
    load_backend,
)
from assembly_constraints.executor.claim import CellClaim, ClaimLost
from assembly_constraints.executor.world.geometry import load_geometry, passes

if TYPE_CHECKING:
    from assembly_constraints.executor.assembly.step_backend import AssemblyRunner

CACHE_SIZE = 100_000
"""Replies kept for idempotency (oldest dropped first)."""

QUEUE_SIZE = 16
"""Requests that may wait for the cell; more are refused with ``busy``."""


def sizes_truth(path: Path) -> tuple[set[str], set[str], set[tuple[str, str]]]:
    """The pegs (``part/1``), holes (``hole/1``) and ``fits/2`` pairs of a product's
    ``sizes.lp`` (closed world); ExecutorError naming the file when it does not parse."""
    control = clingo.Control(["--warn=none"])
    try:
        control.add("base", [], read_bytes(path, "sizes (ASP facts)").decode("utf-8", "replace"))
        control.ground([("base", [])])
    except RuntimeError:
        raise ExecutorError(f"{path}: expected ASP facts part/1, hole/1, fits/2 (it does not parse)") from None
    atoms = [atom.symbol for atom in control.symbolic_atoms]
    pegs = {str(a.arguments[0]) for a in atoms if a.match("part", 1)}
    holes = {str(a.arguments[0]) for a in atoms if a.match("hole", 1)}
    return pegs, holes, {(str(a.arguments[0]), str(a.arguments[1])) for a in atoms if a.match("fits", 2)}


class TruthBackend:
    """Answers without simulation, after ``delay_s`` [s]: from the cell's geometry (a part
    passes a hole when its cross-section does,
    :func:`assembly_constraints.executor.world.geometry.passes`), or from the product's
    ``sizes.lp`` where it has no ``geometry.toml``; the parts ``geometry.toml`` places by
    hand answer from ``sizes.lp`` on its holes the geometry has not (the pins an
    imported part goes onto)."""

    def __init__(self, assembly: str, delay_s: float, cell_id: str,
                 recording_id: str | None, rrd: Path | None, viewer: Viewer = NO_VIEWER,
                 blocked: Sequence[str] = ()) -> None:
        try:
            assembly_of = load_assembly(assembly)
            if assembly_of.has_file("geometry.toml"):
                geometry = load_geometry(assembly)
                self._pegs, self._holes = set(geometry.parts), set(geometry.holes)
                self._manual: set[str] = set(geometry.tables.manual)
                self._fits = {(p, h) for p, part in geometry.parts.items() for h, hole in geometry.holes.items()
                              if passes(part, hole)}
                if assembly_of.has_file("sizes.lp"):  # parts placed by hand onto features the cell does not model
                    pegs, holes, fits = sizes_truth(assembly_of.file("sizes.lp"))
                    pegs &= self._manual
                    holes -= self._holes
                    self._pegs |= pegs
                    self._holes |= holes
                    self._fits |= {(p, h) for p, h in fits if p in pegs and h in holes}
            else:
                self._pegs, self._holes, self._fits = sizes_truth(assembly_of.file("sizes.lp"))
                self._manual = set()
        except BridgeError as exc:
            raise ExecutorError(f"truth backend: {exc}") from None
        self._delay_s = delay_s
        self._blocked = set(blocked)
        self._parts = tuple(assembly_of.part_ids)
        self._run: str | None = None  # the plan run whose product is being built
        self._placed: dict[str, float] = {}  # its placed parts
        self._log = None
        if rrd is not None or viewer != NO_VIEWER:
            from assembly_constraints.executor.rerun_log import open_recording

            self._log = open_recording(recording_id or str(uuid.uuid4()), rrd, viewer)
            self._entity = f"executor/{cell_id}/outcome"

    def run(self, request: InsertRequest) -> tuple[Result, Evidence | None]:
        if request.part not in self._pegs or request.hole not in self._holes:
            raise UnknownPair(f"unknown pair ({request.part},{request.hole}); expected a part "
                              f"of {tuple(sorted(self._pegs))} and a hole of {tuple(sorted(self._holes))}")
        if self._delay_s > 0:
            time.sleep(self._delay_s)  # stands in for the duration of a real insertion
        result: Result = "fit" if (request.part, request.hole) in self._fits else "no_fit"
        if self._log is not None:
            import rerun as rr

            if request.experiment:
                self._log.set_time("experiment", sequence=request.experiment)
            self._log.log(self._entity, rr.TextLog(f"{request.part}->{request.hole}: {result}"))
        return result, None

    def run_step(self, request: StepRequest) -> StepOutcome:
        """A peg fits when its cross-section passes the hole and the hole is not blocked;
        another part of the product is always placed (skill ``manual`` for one placed by
        hand). One plan run at a time; a step of another run, or one the product does not
        allow, is refused before anything changes
        (:func:`assembly_constraints.executor.backend_plugin.check_run`,
        :func:`assembly_constraints.executor.backend_plugin.check_step`)."""
        check_run(self._run, request.assembly, self._parts, self._placed)
        fresh = request.assembly != self._run
        check_step(request.part, request.hole, parts=self._parts, pegs=self._pegs, holes=self._holes,
                   placed=() if fresh else self._placed)
        if fresh:
            self._run, self._placed = request.assembly, {}
        placed = self._placed
        ok = request.hole is None or (request.hole not in self._blocked and (request.part, request.hole) in self._fits)
        if ok:
            placed[request.part] = 0.0
        skill = "manual" if request.part in self._manual else "truth"
        evidence = StepEvidence(skill=skill, attempts=1 if ok else 2, max_force_dev=0.0, max_torque_dev=0.0,
                                duration_s=0.0, sim_time_s=0.0, pose_error_mm=0.0)
        return ("fit" if ok else "no_fit"), evidence, dict(placed)

    def close(self) -> None:
        if self._log is not None:
            self._log.flush()


def _planner_numbered_logger() -> type:
    """AttemptLogger that logs a trial under the planner's experiment number, if given."""
    from assembly_constraints.executor.rerun_log import AttemptLogger

    class PlannerNumbered(AttemptLogger):
        planner_experiment: int | None = None

        def begin_attempt(self, part: str, hole: str, trial_seed: int, attempt: int,
                          experiment: int | None = None) -> None:
            super().begin_attempt(part, hole, trial_seed, attempt,
                                  experiment if experiment is not None else self.planner_experiment)

    return PlannerNumbered


class SimBackend:
    """The PyBullet cell (DIRECT mode); logs every attempt to Rerun if ``rrd`` is given."""

    def __init__(self, assembly: str, cell_id: str, recording_id: str | None,
                 rrd: Path | None, viewer: Viewer = NO_VIEWER, blocked: Sequence[str] = (),
                 cell: CellSettings = DEFAULT_CELL, ilc_state: Path | None = None) -> None:
        """``viewer``: also stream the recording live; ``blocked``: holes with an obstacle
        for plan steps; ``cell``: the Cell's settings (layer, uncertainty, cell seed; with
        ``uncertainty`` ``cell`` plan steps get the Cell's uncertainty (its systematic
        errors), layer and an ILC, with ``random`` their own); ``ilc_state``: the file its
        ILC corrections are loaded from and saved to, atomically after every update, so a
        resumed session's cell starts from them."""
        from assembly_constraints.executor.trial import Cell, cell_keywords

        _PlannerNumbered = _planner_numbered_logger()
        self._logger = (_PlannerNumbered(cell_id, recording_id=recording_id, rrd_path=rrd, viewer=viewer,
                                         send_blueprint=False)  # the planner sends it
                        if rrd is not None or viewer != NO_VIEWER else None)
        self._cell = Cell(assembly, gui=False, logger=self._logger, ilc_state=ilc_state, **cell_keywords(cell))
        self._assembly, self._blocked, self._cell_id = assembly, list(blocked), cell_id
        self._cell_uncertainty = cell.uncertainty == "cell"
        self._runner: AssemblyRunner | None = None

    def run_step(self, request: StepRequest) -> StepOutcome:
        from assembly_constraints.executor.assembly.step_backend import AssemblyRunner, step_evidence

        if self._runner is None:  # the assembling world is made on the first step
            from assembly_constraints.executor.assembly.recording import AssemblyRecorder

            recorder = None if self._logger is None else AssemblyRecorder(self._logger.rec, self._cell_id)
            cell = self._cell
            self._runner = (AssemblyRunner(self._assembly, self._blocked, recorder, uncertainty=cell.bias,
                                           layer=cell.layer)
                            if self._cell_uncertainty else AssemblyRunner(self._assembly, self._blocked, recorder))
        record, errors = self._runner.run_step(request)
        result: Result = "fit" if record.outcome == "fit" else "no_fit"
        return result, step_evidence(record), errors

    def run(self, request: InsertRequest) -> tuple[Result, Evidence | None]:
        try:
            self._cell.check_pair(request.part, request.hole)
        except ExecutorError as exc:
            raise UnknownPair(str(exc)) from None
        if self._logger is not None:
            self._logger.planner_experiment = request.experiment or None
        trial = self._cell.run_trial(request.part, request.hole, seed=request.seed).to_json()
        evidence = Evidence(attempts=int(trial["attempts"]),
                            max_force_dev=float(trial["max_force_dev"]),
                            max_torque_dev=float(trial["max_torque_dev"]),
                            end_error=float(trial["end_error"]),
                            duration_s=float(trial["duration_s"]))
        return trial["outcome"], evidence

    def close(self) -> None:
        self._cell.close()
        if self._runner is not None:
            self._runner.close()
        if self._logger is not None:
            self._logger.close()


@dataclass(frozen=True)
class _Work:
    """A valid request waiting for the cell, and when it arrived (``time.monotonic`` [s])."""

    query: zenoh.Query
    request: InsertRequest | StepRequest
    arrived: float


class CellNode:
    """Validates requests (Zenoh thread) and runs them one at a time (:meth:`serve`).

    Replies are cached by request id together with the whole request: the same request
    again gets the cached reply, the same id with anything else changed is refused
    (``id_reused``). At most ``queue_size`` requests wait; beyond that a request is refused
    (``busy``), and one that waited longer than its ``timeout_s`` is refused (``expired``)
    instead of being run for a client that has gone.
    """

    def __init__(self, cell_id: str, backend: Backend, queue_size: int = QUEUE_SIZE) -> None:
        self.cell_id = cell_id
        self._backend = backend
        self._work: queue.Queue[_Work | None] = queue.Queue(maxsize=queue_size)
        self._replies: OrderedDict[str, tuple[InsertRequest | StepRequest, bytes]] = OrderedDict()
        self._lock = threading.Lock()
        self._stopped = threading.Event()

    def _cached(self, query: zenoh.Query, request: InsertRequest | StepRequest) -> bytes | None:
        """The cached reply of this very request; refuses a reused id (then returns b"")."""
        with self._lock:
            cached = self._replies.get(request.id)
        if cached is None:
            return None
        if cached[0] != request:
            self._refuse(query, "id_reused", f"request id {request.id} was used for "
                         f"({cached[0].part},{cached[0].hole}); expected a new id", request.id)
            return b""
        return cached[1]

    def _refuse(self, query: zenoh.Query, code: ErrorCode, text: str,
                request_id: str | None = None) -> None:
        print(f"refused {code}: {text}", flush=True)
        reply = ErrorReply(cell=self.cell_id, code=code, error=text[:MAX_ERROR_CHARS], id=request_id)
        query.reply(query.key_expr, encode(reply))

    def on_query(self, query: zenoh.Query) -> None:
        """Zenoh-thread callback of ``insert``: refuse bad requests, answer repeats, queue new work."""
        self._accept(query, decode_request)

    def on_step_query(self, query: zenoh.Query) -> None:
        """Zenoh-thread callback of ``step``, as :meth:`on_query`."""
        self._accept(query, decode_step_request)

    def _accept(self, query: zenoh.Query, decode: Callable[[bytes], InsertRequest | StepRequest]) -> None:
        payload = query.payload.to_bytes() if query.payload is not None else b""
        try:
            request = decode(payload)
        except MessageError as exc:
            self._refuse(query, exc.code, str(exc))
            return
        cached = self._cached(query, request)
        if cached is not None:
            if cached:
                query.reply(query.key_expr, cached)
            return
        try:
            self._work.put_nowait(_Work(query, request, time.monotonic()))
        except queue.Full:
            self._refuse(query, "busy", f"{self._work.maxsize} requests are waiting; send it again later",
                         request.id)

    def _answer(self, request: InsertRequest | StepRequest, started: float) -> InsertReply | StepReply:
        """Run the request on the backend; the reply (an insert reply in the request's version)."""
        if isinstance(request, StepRequest):
            result, step_evidence, errors = self._backend.run_step(request)
            return StepReply(id=request.id, cell=self.cell_id, part=request.part, hole=request.hole, result=result,
                             evidence=step_evidence, pose_errors_mm=tuple(sorted(errors.items())),
                             wall_s=time.perf_counter() - started)
        outcome, evidence = self._backend.run(request)
        return InsertReply(id=request.id, cell=self.cell_id, part=request.part, hole=request.hole, result=outcome,
                           evidence=evidence, wall_s=time.perf_counter() - started, v=request.v)

    def stop(self) -> None:
        """Make :meth:`serve` return after the experiment in progress (any thread; never blocks)."""
        self._stopped.set()
        try:
            self._work.put_nowait(None)  # wakes serve() if it waits
        except queue.Full:
            pass  # serve() is busy and sees the flag next

    def serve(self) -> None:
        """Run queued requests until :meth:`stop` (or SIGTERM/SIGINT via SystemExit).

        The wait for work wakes every :data:`SIGNAL_POLL_S`; blocked without a timeout, the
        cell would wait out a SIGTERM one of Zenoh's threads took until it is killed."""
        while not self._stopped.is_set():
            try:
                work = self._work.get(timeout=SIGNAL_POLL_S)
            except queue.Empty:
                continue
            if work is None:
                break
            query, request = work.query, work.request
            waited = time.monotonic() - work.arrived
            cached = self._cached(query, request)
            if cached is None and request.timeout_s and waited > request.timeout_s:
                self._refuse(query, "expired", f"request {request.id} waited {waited:.1f} s, "
                             f"longer than its timeout_s {request.timeout_s:.1f} s", request.id)
            elif cached is None:
                cached = self._run(query, request)
            if cached:
                query.reply(query.key_expr, cached)
            query.drop()  # finalises the query: the planner need not wait for its timeout

    def _run(self, query: zenoh.Query, request: InsertRequest | StepRequest) -> bytes | None:
        number = request.experiment if isinstance(request, InsertRequest) else f"step {request.step}"
        print(f"start {request.id} {request.part} {request.hole} {number}", flush=True)
        started = time.perf_counter()
        try:
            message = self._answer(request, started)
        except ExecutorError as exc:
            code: ErrorCode = ("unknown_id" if isinstance(exc, UnknownPair) else "invalid_step"
                               if isinstance(exc, InvalidStep) else "run_active" if isinstance(exc, RunActive)
                               else "failed")
            self._refuse(query, code, str(exc), request.id)
            return None
        reply, result = encode(message), message.result
        with self._lock:
            self._replies[request.id] = (request, reply)
            while len(self._replies) > CACHE_SIZE:
                self._replies.popitem(last=False)
        print(f"done {request.id} {result}", flush=True)
        return reply


def _echo(query: zenoh.Query) -> None:
    """``cell/<id>/ping``: the payload back, unread; at most MAX_MESSAGE_BYTES of it."""
    payload = query.payload.to_bytes() if query.payload is not None else b""
    query.reply(query.key_expr, payload[:MAX_MESSAGE_BYTES])


def _exit_on_signal(signum: int, _frame: object) -> None:
    raise SystemExit(128 + signum)


def _stop_when_stdin_closes(node: CellNode) -> None:
    """Lifeline: the supervisor holds our stdin; when it dies, stdin reaches EOF."""
    while os.read(0, 4096):  # raw read: no interpreter lock held at shutdown
        pass
    node.stop()  # no print: the supervisor that read our stdout may be gone


SETTINGS_HELP = ("the cell's settings as one document: a JSON object (ServeSettings, docs/cell.md), or a file "
                 "holding one; instead of the other options (a session starts its cells so)")


def build_parser() -> argparse.ArgumentParser:
    parser = ArgumentParser(
        prog="executor serve", description="Serve insertion experiments over Zenoh "
        f"(default: listen on {DEFAULT_ENDPOINT}).")
    parser.add_argument("--settings", metavar="JSON|FILE", help=SETTINGS_HELP)
    parser.add_argument("--cell", default="c1", help="cell id (default c1)")
    parser.add_argument("--backend", default="sim", metavar="{sim,truth,MODULE:CLASS}",
                        help="sim: PyBullet cell; truth: answer from the geometry, no simulation; MODULE:CLASS: "
                             "your class driving a real cell (docs/backends.md) (default sim)")
    parser.add_argument("--backend-option", type=backend_option, action="append", default=[], metavar="KEY=VALUE",
                        help="an option for a MODULE:CLASS backend, e.g. journal=runs/x/journal.jsonl (repeatable)")
    add_assembly_argument(parser)
    parser.add_argument("--delay", type=finite_float(0, 3600), default=0.0, metavar="S",
                        help="truth backend: seconds each experiment takes (default 0)")
    parser.add_argument("--rrd", type=nonempty_path, help="save this cell's Rerun recording to FILE")
    parser.add_argument("--recording-id", help="Rerun recording id shared with the planner")
    add_viewer_arguments(parser, serve=False)  # a cell serves for as long as it runs: stream to a viewer
    parser.add_argument("--block-hole", action="append", default=[], metavar="H",
                        help="put an obstacle in hole H for plan steps (a fault injection; repeatable)")
    parser.add_argument("--lifeline", action="store_true",
                        help="exit when standard input closes (set by a supervising session)")
    parser.add_argument("--ilc-state", type=nonempty_path, metavar="FILE",
                        help="sim backend: load the cell's ILC corrections from FILE (if it exists) and "
                        "save them there after every update (a session passes <run>/<cell>-ilc.json)")
    add_cell_arguments(parser)
    add_assembly_uncertainty_argument(parser)
    add_endpoint_arguments(parser)
    return parser


def serve_settings_of(args: argparse.Namespace) -> ServeSettings:
    """The settings the options give: the ``--settings`` document, or the other options
    (the same struct); BridgeError when both are given or the document is not one."""
    settings = ServeSettings(
        cell_id=args.cell, backend=args.backend, backend_options=dict(args.backend_option), assembly=args.assembly,
        delay_s=args.delay, rrd=path_setting(args.rrd), recording_id=args.recording_id, viewer_url=args.rerun_connect,
        ilc_state=path_setting(args.ilc_state), block_holes=tuple(args.block_hole), lifeline=args.lifeline,
        listen=tuple(args.listen), connect=tuple(args.connect), zenoh_config=path_setting(args.zenoh_config),
        cell=cell_settings_of(args))
    if args.settings is None:
        return settings
    if settings != ServeSettings():
        raise BridgeError("--settings: expected the cell's settings either as one document or as options, not both")
    document = args.settings
    if document.lstrip().startswith("{"):
        return decode_settings(document, ServeSettings, "--settings")
    return decode_settings(read_bytes(document, "cell settings file (JSON)"), ServeSettings, document)


def _backend(settings: ServeSettings) -> Backend:
    """The backend ``settings.backend`` names: the simulator, the geometry's truth or a user class."""
    rrd = None if settings.rrd is None else Path(settings.rrd)
    viewer = Viewer(settings.viewer_url)
    if settings.backend == "truth":
        return TruthBackend(settings.assembly, settings.delay_s, settings.cell_id, settings.recording_id, rrd, viewer,
                            settings.block_holes)
    if settings.backend == "sim":
        return SimBackend(settings.assembly, settings.cell_id, settings.recording_id, rrd, viewer,
                          settings.block_holes, settings.cell,
                          None if settings.ilc_state is None else Path(settings.ilc_state))
    return load_backend(settings.backend, CellContext(settings.cell_id, settings.assembly, rrd,
                                                      settings.recording_id, settings.backend_options))


def main(argv: Sequence[str]) -> int:
    """``executor serve``: the settings of the options, then :func:`serve`."""
    return serve(serve_settings_of(build_parser().parse_args(list(argv))))


def serve(settings: ServeSettings) -> int:
    """Serve until SIGTERM/SIGINT; exit code 2 on bad settings, a damaged ``ilc_state`` or when another process
    serves this cell id (:mod:`assembly_constraints.executor.claim`)."""
    cell_id = check_cell_id(settings.cell_id)
    zenoh_config = None if settings.zenoh_config is None else Path(settings.zenoh_config)
    if settings.backend == "sim":
        from assembly_constraints.executor.trial import cell_keywords

        # Bad cell settings or description are refused here, before the session opens.
        description = cell_keywords(settings.cell)["description"]
        if settings.ilc_state is not None:
            from assembly_constraints.executor.control.ilc import offset_bound, read_state

            # So is a damaged state.
            read_state(Path(settings.ilc_state), description.ilc, offset_bound(description.admittance))
    elif settings.cell.description is not None:
        from assembly_constraints.executor.cell_description import load_cell_description

        # Not used by this backend, but a bad file is refused rather than silently ignored.
        load_cell_description(Path(settings.cell.description))
    listen = cell_listen(settings.listen, settings.connect, zenoh_config)
    connect = list(settings.connect)
    signal.signal(signal.SIGTERM, _exit_on_signal)
    signal.signal(signal.SIGINT, _exit_on_signal)
    session = open_session(listen, connect, zenoh_config)
    claim: CellClaim | None = None
    backend: Backend | None = None
    try:
        claim = CellClaim(session, cell_id)
        claim.check()  # before the backend starts: a refused cell loads nothing
        backend = _backend(settings)
        node = CellNode(cell_id, backend)
        claim.on_lost = lambda _why: node.stop()
        if claim.lost is not None:  # lost while the backend started
            raise ClaimLost(claim.lost)
        _declared = (session.declare_queryable(insert_key(cell_id), node.on_query),  # held
                     session.declare_queryable(step_key(cell_id), node.on_step_query),
                     session.declare_queryable(ping_key(cell_id), _echo),
                     session.liveliness().declare_token(alive_key(cell_id, claim.instance)))
        if settings.lifeline:
            threading.Thread(target=_stop_when_stdin_closes, args=(node,), daemon=True).start()
        print(f"ready cell {cell_id} backend {settings.backend} "
              f"listen {listen} connect {connect}", flush=True)
        node.serve()
    except SystemExit:
        pass  # SIGTERM/SIGINT: close below
    finally:
        session.close()
        if backend is not None:
            backend.close()
    if claim is not None and claim.lost is not None:
        raise ClaimLost(claim.lost)
    return 0
