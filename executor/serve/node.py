"""The cell node: claims its cell id, declares its queryables and liveliness token, and
serves requests one at a time until SIGTERM/SIGINT (or, with ``lifeline``, until its stdin
closes), then closes the Zenoh session cleanly (:func:`serve`).

Every request is size-capped and validated in the Zenoh thread (:class:`CellNode`); a
malformed, oversized or wrong-version request gets an ErrorReply at once and the cell keeps
serving. Valid requests run one at a time in the main thread; results are idempotent by
request id; a request whose backend raises gets an ErrorReply ``failed`` naming the
exception, and the cell keeps serving. One line per event is printed to stdout (``ready``, ``start <id> <part> <hole>``,
``done <id> <result>``; a precedence experiment's ``<part> <hole>`` is ``placed <parts>
sequence <parts>``), flushed, so a supervisor can follow the node.
"""

from __future__ import annotations

import os
import queue
import signal
import sys
import threading
import time
import traceback
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import zenoh

from bridge.cell_settings import ServeSettings
from bridge.client import Reply, Request
from bridge.keys import alive_key, check_cell_id, insert_key, ping_key, precedence_key, step_key
from bridge.messages import (
    MAX_ERROR_CHARS,
    MAX_MESSAGE_BYTES,
    ErrorCode,
    ErrorReply,
    InsertReply,
    InsertRequest,
    MessageError,
    StepReply,
    StepRequest,
    decode_request,
    decode_step_request,
    encode,
)
from bridge.precedence.experiment import PrecedenceExperiment, PrecedenceOutcome, decode_experiment
from bridge.session import SIGNAL_POLL_S, bound_endpoints, cell_listen, open_session
from executor import ExecutorError
from executor.backend_plugin import Backend, InvalidStep, RunActive, UnknownPair
from executor.claim import CellClaim, ClaimLost
from executor.serve.backends import backend_starter

CACHE_SIZE = 100_000
"""Replies kept for idempotency (oldest dropped first)."""

QUEUE_SIZE = 16
"""Requests that may wait for the cell; more are refused with ``busy``."""



_SAID = threading.Lock()


def say(line: str) -> None:
    """Print ``line`` whole on stdout, flushed: the zenoh callbacks' refusals and the worker's
    start and done lines come from different threads, and ``print`` writes a line's text and
    its newline apart, so two lines could be glued (the planner reads them by their start)."""
    with _SAID:
        sys.stdout.write(line + "\n")
        sys.stdout.flush()

@dataclass(frozen=True)
class _Work:
    """A valid request waiting for the cell, and when it arrived (``time.monotonic`` [s])."""

    query: zenoh.Query
    request: Request
    arrived: float


def _what(request: Request) -> str:
    """What a request asks, for a log line: ``part hole``, or a precedence experiment's
    ``a<b placed p,q sequence r,b``."""
    if isinstance(request, PrecedenceExperiment):
        return (f"{request.tested} placed {','.join(s.part for s in request.placed) or '-'} "
                f"sequence {','.join(s.part for s in request.sequence)}")
    return f"{request.part} {request.hole}"


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
        self._replies: OrderedDict[str, tuple[Request, bytes]] = OrderedDict()
        self._lock = threading.Lock()
        self._stopped = threading.Event()

    def _cached(self, query: zenoh.Query, request: Request) -> bytes | None:
        """The cached reply of this very request; refuses a reused id (then returns b"")."""
        with self._lock:
            cached = self._replies.get(request.id)
        if cached is None:
            return None
        if cached[0] != request:
            self._refuse(query, "id_reused", f"request id {request.id} was used for ({_what(cached[0])}); "
                         "expected a new id", request.id)
            return b""
        return cached[1]

    def _refuse(self, query: zenoh.Query, code: ErrorCode, text: str,
                request_id: str | None = None) -> None:
        say(f"refused {code}: {text}")
        reply = ErrorReply(cell=self.cell_id, code=code, error=text[:MAX_ERROR_CHARS], id=request_id)
        query.reply(query.key_expr, encode(reply))

    def on_query(self, query: zenoh.Query) -> None:
        """Zenoh-thread callback of ``insert``: refuse bad requests, answer repeats, queue new work."""
        self._accept(query, decode_request)

    def on_step_query(self, query: zenoh.Query) -> None:
        """Zenoh-thread callback of ``step``, as :meth:`on_query`."""
        self._accept(query, decode_step_request)

    def on_precedence_query(self, query: zenoh.Query) -> None:
        """Zenoh-thread callback of ``precedence``, as :meth:`on_query`."""
        self._accept(query, decode_experiment)

    def _accept(self, query: zenoh.Query, decode: Callable[[bytes], Request]) -> None:
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

    def _answer(self, request: Request, started: float) -> Reply:
        """Run the request on the backend; the reply (in the request's version). A backend
        without ``run_precedence`` fails a precedence experiment."""
        if isinstance(request, PrecedenceExperiment):
            run_precedence = getattr(self._backend, "run_precedence", None)
            if run_precedence is None:
                raise ExecutorError(f"this cell's backend ({type(self._backend).__name__}) runs no precedence "
                                    "experiments")
            run = run_precedence(request)
            return PrecedenceOutcome(id=request.id, cell=self.cell_id, pair=request.pair,
                                     outcome="success" if run.failed_step is None else "failed",
                                     failed_step=run.failed_step, reason=run.reason, blocked_by=run.blocked_by,
                                     detail=run.detail[:MAX_ERROR_CHARS], sim_s=run.sim_s,
                                     wall_s=time.perf_counter() - started)
        if isinstance(request, StepRequest):
            result, step_evidence, errors = self._backend.run_step(request)
            return StepReply(id=request.id, cell=self.cell_id, part=request.part, hole=request.hole, result=result,
                             evidence=step_evidence, pose_errors_mm=tuple(sorted(errors.items())),
                             wall_s=time.perf_counter() - started, v=request.v)
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

    def _run(self, query: zenoh.Query, request: Request) -> bytes | None:
        number = (request.experiment if isinstance(request, InsertRequest) else
                  f"step {request.step}" if isinstance(request, StepRequest) else "experiment")
        say(f"start {request.id} {_what(request)} {number}")
        started = time.perf_counter()
        try:
            message = self._answer(request, started)
        except ExecutorError as exc:
            code: ErrorCode = ("unknown_id" if isinstance(exc, UnknownPair) else "invalid_step"
                               if isinstance(exc, InvalidStep) else "run_active" if isinstance(exc, RunActive)
                               else "failed")
            self._refuse(query, code, str(exc), request.id)
            return None
        except Exception as exc:  # a bug of the backend: this request fails, the cell keeps serving
            where = traceback.extract_tb(exc.__traceback__)[-1]
            self._refuse(query, "failed", f"the backend raised {type(exc).__name__}: {str(exc)[:200]} "
                         f"(at {Path(where.filename).name}:{where.lineno})", request.id)
            return None
        reply = encode(message)
        result = message.outcome if isinstance(message, PrecedenceOutcome) else message.result
        with self._lock:
            self._replies[request.id] = (request, reply)
            while len(self._replies) > CACHE_SIZE:
                self._replies.popitem(last=False)
        say(f"done {request.id} {result}")
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


def serve(settings: ServeSettings) -> int:
    """Serve until SIGTERM/SIGINT; exit code 2 on bad settings, a damaged ``ilc_state`` or when another process
    serves this cell id (:mod:`executor.claim`)."""
    cell_id = check_cell_id(settings.cell_id)
    zenoh_config = None if settings.zenoh_config is None else Path(settings.zenoh_config)
    start_backend = backend_starter(settings)  # bad settings are refused here, before the session opens
    listen = cell_listen(settings.listen, settings.connect, zenoh_config)
    connect = list(settings.connect)
    signal.signal(signal.SIGTERM, _exit_on_signal)
    signal.signal(signal.SIGINT, _exit_on_signal)
    session = open_session(listen, connect, zenoh_config)
    claim: CellClaim | None = None
    backend: Backend | None = None
    try:
        listen = bound_endpoints(session, listen)  # reported as bound (port 0: the port it took)
        claim = CellClaim(session, cell_id)
        claim.check()  # before the backend starts: a refused cell loads nothing
        backend = start_backend()
        node = CellNode(cell_id, backend)
        claim.on_lost = lambda _why: node.stop()
        if claim.lost is not None:  # lost while the backend started
            raise ClaimLost(claim.lost)
        _declared = (session.declare_queryable(insert_key(cell_id), node.on_query),  # held
                     session.declare_queryable(step_key(cell_id), node.on_step_query),
                     session.declare_queryable(precedence_key(cell_id), node.on_precedence_query),
                     session.declare_queryable(ping_key(cell_id), _echo),
                     session.liveliness().declare_token(alive_key(cell_id, claim.instance)))
        if settings.lifeline:
            threading.Thread(target=_stop_when_stdin_closes, args=(node,), daemon=True).start()
        say(f"ready cell {cell_id} backend {settings.backend} listen {listen} connect {connect}")
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
