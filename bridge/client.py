"""The planner's side of the bridge: discovering cells and sending them experiments.

- :class:`CellDirectory` follows the cells' liveliness tokens (``cell/*/alive``).
- :func:`send_insert` sends one request asynchronously; :func:`request_insert` waits for it;
  :func:`request_step` sends one plan step and waits for it, :func:`request_experiment` one
  precedence experiment.
- :class:`CellPool` keeps every alive cell busy with submitted requests: one request per
  cell, a cell that dies (token gone) or times out has its request re-sent to another
  cell (or the pool waits for one), and each request's reply is returned exactly once.
  Cells are idempotent by request id, so a re-sent request never runs twice on one cell.
"""

from __future__ import annotations

import functools
import itertools
import logging
import queue
import signal
import threading
import time
from collections import deque
from collections.abc import Callable, Collection
from dataclasses import dataclass

import msgspec
import zenoh

from bridge import BridgeError
from bridge.keys import ALIVE_PATTERN, cell_of_alive_key, insert_key, precedence_key, step_key
from bridge.messages import (
    ErrorReply,
    InsertReply,
    InsertRequest,
    MessageError,
    StepReply,
    StepRequest,
    decode_reply,
    encode,
)
from bridge.precedence.experiment import PrecedenceExperiment, PrecedenceOutcome, decode_outcome_reply

_LOG = logging.getLogger(__name__)

Request = InsertRequest | StepRequest | PrecedenceExperiment
"""What a planner asks a cell."""
Reply = InsertReply | StepReply | PrecedenceOutcome
"""What a cell answers a request it ran."""


class CellTimeout(BridgeError):
    """No valid reply from a cell within the request timeout."""


class CellRefused(BridgeError):
    """A cell answered a request with an :class:`ErrorReply`."""

    def __init__(self, reply: ErrorReply) -> None:
        super().__init__(f"cell {reply.cell} refused request {reply.id}: "
                         f"{reply.code}: {reply.error}")
        self.reply = reply


class CellConflict(BridgeError):
    """One query got different replies (two processes answer for one cell id)."""


class CellCrashed(BridgeError):
    """Every cell the pool may use has crashed, and work is left to do."""


def describe_exit(code: int) -> str:
    """A process's exit status in words: ``killed by signal SIGKILL``, ``exited with code 1``."""
    if code < 0:
        try:
            return f"killed by signal {signal.Signals(-code).name}"
        except ValueError:
            return f"killed by signal {-code}"
    return f"exited with code {code}"


Outcome = InsertReply | BridgeError
"""What one sent request ends with: a reply, or the error that ended it."""


class CellDirectory:
    """The set of alive cells, kept from liveliness tokens; listeners hear every change.

    Each cell process holds a token with its own instance name, so two processes claiming
    one cell id show as two tokens: such an id is *duplicated* and not alive (nothing is
    sent to it) until only one of them is left. A listener ``(cell_id, alive)`` is called
    from a Zenoh thread; keep it short.
    """

    def __init__(self, session: zenoh.Session) -> None:
        self._lock = threading.Condition()
        self._instances: dict[str, set[str]] = {}
        self._alive: set[str] = set()
        self.duplicated: set[str] = set()
        """Cell ids claimed by more than one process at some time (never cleared)."""
        self._listeners: list[Callable[[str, bool], None]] = []
        self._subscriber = session.liveliness().declare_subscriber(
            ALIVE_PATTERN, self._on_sample, history=True)

    def _on_sample(self, sample: zenoh.Sample) -> None:
        parsed = cell_of_alive_key(str(sample.key_expr))
        if parsed is None:
            return
        cell, instance = parsed
        with self._lock:
            instances = self._instances.setdefault(cell, set())
            (instances.add if sample.kind == zenoh.SampleKind.PUT else instances.discard)(instance)
            if len(instances) > 1:
                if cell not in self.duplicated:
                    _LOG.warning("%s", self._duplicate_text(cell))
                self.duplicated.add(cell)
            alive, was_alive = len(instances) == 1, cell in self._alive
            (self._alive.add if alive else self._alive.discard)(cell)
            listeners = list(self._listeners) if alive != was_alive else []
            self._lock.notify_all()
        for listener in listeners:
            listener(cell, alive)

    def _duplicate_text(self, cell: str) -> str:
        """Says that ``cell`` is claimed by several processes (call with the lock held)."""
        return (f"cell id {cell} is claimed by {len(self._instances[cell])} processes (liveliness tokens of "
                f"instances {', '.join(sorted(self._instances[cell]))}); nothing is sent to it until only one "
                "is left: stop the other process or give it another --cell-id")

    def alive(self) -> set[str]:
        """The cells whose token is currently seen."""
        with self._lock:
            return set(self._alive)

    def listen(self, listener: Callable[[str, bool], None]) -> set[str]:
        """Register a listener; returns the alive cells at that moment (no change is missed)."""
        with self._lock:
            self._listeners.append(listener)
            return set(self._alive)

    def unlisten(self, listener: Callable[[str, bool], None]) -> None:
        with self._lock:
            self._listeners.remove(listener)

    def wait_for(self, count: int, timeout: float, among: Collection[str] | None = None) -> set[str]:
        """Wait up to ``timeout`` [s] until at least ``count`` cells are alive, counting only
        those in ``among`` if given (a token of another id neither counts nor shortens the
        wait); the alive cells then (all of them). CellTimeout if not."""
        wanted = None if among is None else frozenset(among)
        deadline = time.monotonic() + timeout
        with self._lock:
            while len(self._alive if wanted is None else self._alive & wanted) < count:
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    duplicated = [self._duplicate_text(c) for c in sorted(self._instances)
                                  if len(self._instances[c]) > 1]
                    of = "" if wanted is None else f" of {', '.join(sorted(wanted))}"
                    raise CellTimeout(f"expected {count} alive cell(s){of} within {timeout:.1f} s, "
                                      f"saw {sorted(self._alive) or 'none'}" + "".join(f"; {d}" for d in duplicated))
                self._lock.wait(remaining)
            return set(self._alive)

    def close(self) -> None:
        self._subscriber.undeclare()


def send_insert(session: zenoh.Session, cell: str, request: InsertRequest, timeout: float,
                on_outcome: Callable[[Outcome], None]) -> zenoh.CancellationToken:
    """Send ``request`` to ``cell`` (see :func:`_send`)."""
    return _send(session, insert_key(cell), cell, request, timeout, on_outcome)  # type: ignore[arg-type]


def _send(session: zenoh.Session, key: str, cell: str, request: Request, timeout: float,
          on_outcome: Callable[[Reply | BridgeError], None]) -> zenoh.CancellationToken:
    """Send ``request`` to ``cell``; ``on_outcome`` is called exactly once (Zenoh thread),
    when the query ends (the cell finalises it after replying, or ``timeout`` [s] passes).

    The outcome is the InsertReply, or CellRefused for an ErrorReply, when every reply
    that validates and echoes the request (its id, part and hole, from ``cell``) is that
    same one; CellConflict when the query got different such replies; MessageError when
    replies came but none validated or echoed the request; CellTimeout when none came or
    the query was cancelled. Returns a token that cancels the query.
    """
    lock = threading.Lock()
    answers: list[Reply | ErrorReply] = []
    faults: list[BridgeError] = []
    sent = time.monotonic()

    def on_reply(reply: zenoh.Reply) -> None:
        ok, err = reply.ok, reply.err
        try:
            if ok is None:
                detail = err.payload.to_string() if err is not None else "neither a sample nor an error"
                raise CellTimeout(f"cell {cell}: query error: {detail}")
            payload = ok.payload.to_bytes()
            message = (decode_outcome_reply(payload) if isinstance(request, PrecedenceExperiment)
                       else decode_reply(payload))
            check_echo(message, cell, request)
        except BridgeError as exc:
            with lock:
                faults.append(exc)
            return
        with lock:
            answers.append(message)

    def on_end() -> None:
        with lock:
            distinct = list(dict.fromkeys(answers))
            fault = faults[0] if faults else None
        if len(distinct) > 1:
            on_outcome(CellConflict(f"cell {cell}: {len(distinct)} different replies to request {request.id}"))
        elif distinct:
            answer = distinct[0]
            on_outcome(CellRefused(answer) if isinstance(answer, ErrorReply) else answer)
        else:
            waited = time.monotonic() - sent
            # Zenoh also ends a query early when the cell's session goes away
            ended = (f"within {timeout:.1f} s" if waited >= 0.9 * timeout
                     else f"(the query ended after {waited:.1f} s of the {timeout:.1f} s allowed)")
            on_outcome(fault or CellTimeout(f"cell {cell}: no reply to request {request.id} {ended}"))

    cancel = zenoh.CancellationToken()
    session.get(key, zenoh.handlers.Callback(on_reply, on_end),
                payload=encode(request), timeout=timeout, cancellation_token=cancel,
                consolidation=zenoh.ConsolidationMode.NONE)
    return cancel


_ANSWERS: dict[type, type] = {InsertRequest: InsertReply, StepRequest: StepReply,
                              PrecedenceExperiment: PrecedenceOutcome}
"""The reply type of each request type."""


def _asked(message: Request | Reply) -> tuple:
    """What a reply echoes of its request: part and hole, or a precedence experiment's pair."""
    if isinstance(message, (PrecedenceExperiment, PrecedenceOutcome)):
        return (message.pair,)
    return message.part, message.hole


def check_echo(message: Reply | ErrorReply, cell: str, request: Request) -> None:
    """MessageError unless ``message`` comes from ``cell`` and answers ``request`` (a reply of
    the request's kind)."""
    asked = (cell, request.id, *_asked(request))
    if isinstance(message, ErrorReply):
        answered = (message.cell, message.id or request.id, *_asked(request))
    else:
        if not isinstance(message, _ANSWERS[type(request)]):
            raise MessageError("malformed", f"a {type(message).__name__} does not answer a {type(request).__name__}")
        answered = (message.cell, message.id, *_asked(message))
    if answered != asked:
        raise MessageError("malformed", f"reply {answered} does not echo the request {asked}")


def request_insert(session: zenoh.Session, cell: str, request: InsertRequest,
                   timeout: float) -> InsertReply:
    """Send ``request`` to ``cell`` and wait; raises CellTimeout, CellRefused, MessageError."""
    box: queue.SimpleQueue[Outcome] = queue.SimpleQueue()
    send_insert(session, cell, request, timeout, box.put)
    try:
        outcome = box.get(timeout=timeout + 5.0)  # Zenoh ends the query at its timeout
    except queue.Empty:
        raise CellTimeout(f"cell {cell}: query {request.id} never ended") from None
    if isinstance(outcome, BridgeError):
        raise outcome
    return outcome


def _request(session: zenoh.Session, key: str, cell: str, request: Request, timeout: float) -> Reply:
    """Send ``request`` on ``key`` to ``cell`` and wait; raises CellTimeout, CellRefused, MessageError."""
    box: queue.SimpleQueue[Reply | BridgeError] = queue.SimpleQueue()
    _send(session, key, cell, request, timeout, box.put)
    try:
        outcome = box.get(timeout=timeout + 5.0)
    except queue.Empty:
        raise CellTimeout(f"cell {cell}: query {request.id} never ended") from None
    if isinstance(outcome, BridgeError):
        raise outcome
    return outcome


def request_step(session: zenoh.Session, cell: str, request: StepRequest, timeout: float) -> StepReply:
    """Send a plan step to ``cell`` and wait; raises CellTimeout, CellRefused, MessageError."""
    outcome = _request(session, step_key(cell), cell, request, timeout)
    assert isinstance(outcome, StepReply)  # check_echo let only a StepReply through
    return outcome


def request_experiment(session: zenoh.Session, cell: str, experiment: PrecedenceExperiment,
                       timeout: float) -> PrecedenceOutcome:
    """Send a precedence experiment to ``cell`` and wait; raises CellTimeout, CellRefused, MessageError."""
    outcome = _request(session, precedence_key(cell), cell, experiment, timeout)
    assert isinstance(outcome, PrecedenceOutcome)  # check_echo let only a PrecedenceOutcome through
    return outcome


@dataclass(frozen=True)
class _Sent:
    """One attempt of a request at a cell."""

    attempt: int
    request: InsertRequest
    cancel: zenoh.CancellationToken


@dataclass(frozen=True)
class PoolLimits:
    """How long a :class:`CellPool` waits and how often it retries: ``timeout`` [s] bounds
    one attempt at one cell; ``wait_for_cell`` [s] bounds a wait while no usable cell is
    alive; ``max_failures`` bounds the failed attempts of one request; a cell that misses
    ``max_misses`` replies in a row is dropped for the rest of the pool's life."""

    timeout: float = 60.0
    wait_for_cell: float = 60.0
    max_failures: int = 3
    max_misses: int = 2


class CellPool:
    """Keeps every alive cell busy with submitted requests, with failover (module doc).

    :meth:`submit` queues a request (distinct ids); :meth:`next_reply` dispatches queued
    requests to idle alive cells and returns the next finished request and its reply;
    each submitted request is returned exactly once, within ``limits``
    (:class:`PoolLimits`). Only the
    cells in ``allowed`` are used (None: any cell that shows a token). ``exit_status(cell)``
    gives the exit status of a cell's process when this planner started it and it has
    ended (None otherwise; it may wait a moment for a process whose links just closed, and
    is asked only when a cell's token goes or an attempt fails): such a cell is *crashed*,
    its request is sent to another cell at once, it is never used again, and when every
    allowed cell has crashed the pool fails with :class:`CellCrashed` naming them instead
    of waiting. ``incidents`` lists what went wrong on the way (timeouts, conflicts,
    crashed and dropped cells).
    ``on_dispatch(cell, request)``, if set, is called (in the thread of :meth:`next_reply`)
    just before each request is sent to a cell, also when it is re-sent to another; an
    exception it raises propagates from :meth:`next_reply` and the request is not sent.
    Close it when done.
    """

    def __init__(self, session: zenoh.Session, directory: CellDirectory, limits: PoolLimits = PoolLimits(), *,
                 allowed: Collection[str] | None = None,
                 exit_status: Callable[[str], int | None] | None = None) -> None:
        self._session = session
        self._directory = directory
        self.timeout = limits.timeout
        self.wait_for_cell = limits.wait_for_cell
        self.max_failures = limits.max_failures
        self.max_misses = limits.max_misses
        self._allowed = None if allowed is None else frozenset(allowed)
        self._attempts = itertools.count()
        self._events: queue.SimpleQueue[tuple] = queue.SimpleQueue()
        self._pending: deque[InsertRequest] = deque()
        self._busy: dict[str, _Sent] = {}
        self._slow: set[str] = set()
        self._failures: dict[str, int] = {}
        self._misses: dict[str, int] = {}
        self._dropped: set[str] = set()
        self._exit_status = exit_status
        self._gone: set[str] = set()
        """Cells whose token disappeared (since last seen alive)."""
        self.crashed: dict[str, str] = {}
        """Cells whose process ended: cell id -> how (``killed by signal SIGKILL``)."""
        self.incidents: list[str] = []
        self._alive = {cell for cell in directory.listen(self._on_change) if self._usable(cell)}
        self.on_dispatch: Callable[[str, InsertRequest], None] | None = None

    def usable_alive(self) -> set[str]:
        """The cells whose token is seen now and that the pool may use (in ``allowed``, not
        dropped): how many requests can run at once. A token of any other id (a cell of
        another planner, a rogue process) is not counted, so it cannot change how much work
        the planner hands out at a time."""
        return {cell for cell in self._directory.alive() if self._usable(cell)}

    def _usable(self, cell: str) -> bool:
        return (self._allowed is None or cell in self._allowed) and cell not in self._dropped

    def _on_change(self, cell: str, alive: bool) -> None:
        self._events.put(("cell", cell, alive))

    @property
    def unfinished(self) -> int:
        """Submitted requests not yet returned by :meth:`next_reply`."""
        return len(self._pending) + len(self._busy)

    def submit(self, request: InsertRequest) -> None:
        """Queue a request; it is sent as soon as a cell is idle."""
        self._pending.append(request)

    def close(self) -> None:
        self._directory.unlisten(self._on_change)

    def dispatch(self) -> None:
        """Send queued requests to the idle alive cells now (:meth:`next_reply` does too)."""
        self._dispatch()

    def _dispatch(self) -> None:
        idle = sorted(self._alive - self._busy.keys(), key=lambda c: (c in self._slow, c))
        while self._pending and idle:
            cell, request = idle[0], self._pending[0]
            if self.on_dispatch is not None:
                self.on_dispatch(cell, request)
            idle.pop(0)
            self._pending.popleft()
            attempt = next(self._attempts)
            sent = msgspec.structs.replace(request, timeout_s=self.timeout)  # the cell drops it after that
            cancel = send_insert(self._session, cell, sent, self.timeout,
                                 functools.partial(self._on_outcome, cell, attempt))
            self._busy[cell] = _Sent(attempt, request, cancel)

    def _on_outcome(self, cell: str, attempt: int, outcome: Outcome) -> None:
        """Zenoh thread: queue the outcome of ``attempt`` sent to ``cell``."""
        self._events.put(("outcome", cell, attempt, outcome))

    def _next_event(self, wait: bool) -> tuple | None:
        """The next event; without ``wait``, None when none has come yet."""
        if not wait:
            try:
                return self._events.get_nowait()
            except queue.Empty:
                return None
        if self._busy or self._alive:
            return self._events.get()
        for cell in sorted(self._gone - self._dropped):
            self._ended(cell)  # a crash seen only now: its links closed before its process was reaped
        crashed = "; ".join(f"cell {cell} crashed ({how})" for cell, how in sorted(self.crashed.items()))
        if self._allowed is not None and self._allowed <= self.crashed.keys():
            raise CellCrashed(f"{crashed}; no other cell left, {len(self._pending)} experiment(s) still to run")
        try:
            return self._events.get(timeout=self.wait_for_cell)
        except queue.Empty:
            raise CellTimeout(f"no cell alive for {self.wait_for_cell:.0f} s"
                              f"{f' ({crashed})' if crashed else ''}; "
                              f"{len(self._pending)} experiment(s) still to run") from None

    def _ended(self, cell: str) -> bool:
        """Whether ``cell``'s process (one this planner started) has ended; the first time,
        it is dropped and named in :attr:`crashed` and the incidents."""
        if cell in self.crashed:
            return True
        code = None if self._exit_status is None else self._exit_status(cell)
        if code is None:
            return False
        self.crashed[cell] = describe_exit(code)
        self._dropped.add(cell)
        self._alive.discard(cell)
        running = self._busy.get(cell)
        during = "" if running is None else (f" during request {running.request.id} ({running.request.part} "
                                             f"into {running.request.hole}), sent again to another cell")
        self.incidents.append(f"cell {cell} crashed ({self.crashed[cell]}){during}")
        return True

    def next_reply(self) -> tuple[InsertRequest, InsertReply]:
        """The next finished request and its reply; BridgeError if none can finish."""
        if not self.unfinished:
            raise BridgeError("next_reply: no request submitted")
        found = self._next_reply(wait=True)
        assert found is not None  # waiting ends with a reply or an error
        return found

    def finished_reply(self) -> tuple[InsertRequest, InsertReply] | None:
        """A request that has already finished and its reply, without waiting (None if
        none has); what came in meanwhile (cells, failures) is handled as by :meth:`next_reply`."""
        return self._next_reply(wait=False) if self.unfinished else None

    def _next_reply(self, wait: bool) -> tuple[InsertRequest, InsertReply] | None:
        while True:
            self._dispatch()
            event = self._next_event(wait)
            if event is None:
                return None
            if event[0] == "cell":
                _, cell, alive = event
                if alive:
                    self._gone.discard(cell)
                    if self._usable(cell):
                        self._alive.add(cell)
                    continue
                self._gone.add(cell)
                self._ended(cell)
                self._alive.discard(cell)
                sent = self._busy.pop(cell, None)
                if sent is not None:  # it died mid-experiment: re-send elsewhere
                    sent.cancel.cancel()
                    self._pending.appendleft(sent.request)
                continue
            _, cell, attempt, outcome = event
            sent = self._busy.get(cell)
            if sent is None or sent.attempt != attempt:
                continue  # a cancelled or superseded attempt
            if isinstance(outcome, InsertReply):
                del self._busy[cell]
                self._slow.discard(cell)
                self._misses[cell] = 0
                return sent.request, outcome
            if self._ended(cell):  # no reply because the process is gone: not a miss
                del self._busy[cell]
                self._pending.appendleft(sent.request)
                continue
            del self._busy[cell]
            self.incidents.append(str(outcome))
            self._failed(cell, sent.request, outcome)

    def _failed(self, cell: str, request: InsertRequest, outcome: BridgeError) -> None:
        if isinstance(outcome, CellTimeout):
            self._slow.add(cell)
            self._misses[cell] = self._misses.get(cell, 0) + 1
            if self._misses[cell] >= self.max_misses:
                self._dropped.add(cell)
                self._alive.discard(cell)
                self.incidents.append(f"cell {cell} dropped after {self._misses[cell]} missed replies")
        elif isinstance(outcome, CellRefused) and outcome.reply.code in ("busy", "expired"):
            self._slow.add(cell)
        elif isinstance(outcome, CellRefused) and outcome.reply.code != "failed":
            raise outcome  # the request itself is bad: no cell will take it
        else:
            self._failures[request.id] = self._failures.get(request.id, 0) + 1
            if self._failures[request.id] >= self.max_failures:
                raise BridgeError(f"request {request.id} ({request.part} into {request.hole}) "
                                  f"failed {self.max_failures} times; last: {outcome}")
        self._pending.appendleft(request)
