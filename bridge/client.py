"""The planner's side of the bridge: discovering cells and sending them experiments.

- :class:`CellDirectory` follows the cells' liveliness tokens (``cell/*/alive``).
- :func:`send_insert` sends one request asynchronously; :func:`request_insert` waits for it.
- :class:`CellPool` keeps every alive cell busy with submitted requests: one request per
  cell, a cell that dies (token gone) or times out has its request re-sent to another
  cell (or the pool waits for one), and each request's reply is returned exactly once.
  Cells are idempotent by request id, so a re-sent request never runs twice on one cell.
"""

from __future__ import annotations

import functools
import itertools
import queue
import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass

import zenoh

from bridge import BridgeError
from bridge.keys import ALIVE_PATTERN, cell_of_alive_key, insert_key
from bridge.messages import ErrorReply, InsertReply, InsertRequest, MessageError, decode_reply, encode


class CellTimeout(BridgeError):
    """No valid reply from a cell within the request timeout."""


class CellRefused(BridgeError):
    """A cell answered a request with an :class:`ErrorReply`."""

    def __init__(self, reply: ErrorReply) -> None:
        super().__init__(f"cell {reply.cell} refused request {reply.id}: "
                         f"{reply.code}: {reply.error}")
        self.reply = reply


Outcome = InsertReply | BridgeError
"""What one sent request ends with: a reply, or the error that ended it."""


class CellDirectory:
    """The set of alive cells, kept from liveliness tokens; listeners hear every change.

    A listener ``(cell_id, alive)`` is called from a Zenoh thread; keep it short.
    """

    def __init__(self, session: zenoh.Session) -> None:
        self._lock = threading.Condition()
        self._alive: set[str] = set()
        self._listeners: list[Callable[[str, bool], None]] = []
        self._subscriber = session.liveliness().declare_subscriber(
            ALIVE_PATTERN, self._on_sample, history=True)

    def _on_sample(self, sample: zenoh.Sample) -> None:
        cell = cell_of_alive_key(str(sample.key_expr))
        if cell is None:
            return
        alive = sample.kind == zenoh.SampleKind.PUT
        with self._lock:
            (self._alive.add if alive else self._alive.discard)(cell)
            listeners = list(self._listeners)
            self._lock.notify_all()
        for listener in listeners:
            listener(cell, alive)

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

    def wait_for(self, count: int, timeout: float) -> set[str]:
        """Wait up to ``timeout`` [s] until at least ``count`` cells are alive; CellTimeout if not."""
        deadline = time.monotonic() + timeout
        with self._lock:
            while len(self._alive) < count:
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    raise CellTimeout(f"expected {count} alive cell(s) within {timeout:.1f} s, "
                                      f"saw {sorted(self._alive) or 'none'}")
                self._lock.wait(remaining)
            return set(self._alive)

    def close(self) -> None:
        self._subscriber.undeclare()


def send_insert(session: zenoh.Session, cell: str, request: InsertRequest, timeout: float,
                on_outcome: Callable[[Outcome], None]) -> zenoh.CancellationToken:
    """Send ``request`` to ``cell``; ``on_outcome`` is called exactly once (Zenoh thread).

    The outcome is the InsertReply, CellRefused for an ErrorReply, CellTimeout when no
    valid reply came within ``timeout`` [s] or the query was cancelled, or MessageError
    for a reply that does not validate. Returns a token that cancels the query.
    """
    lock = threading.Lock()
    delivered = False

    def deliver(outcome: Outcome) -> None:
        nonlocal delivered
        with lock:  # replies and the query's end may come on different threads
            first, delivered = not delivered, True
        if first:
            on_outcome(outcome)

    def on_reply(reply: zenoh.Reply) -> None:
        ok, err = reply.ok, reply.err
        if ok is None:
            detail = err.payload.to_string() if err is not None else "neither a sample nor an error"
            deliver(CellTimeout(f"cell {cell}: query error: {detail}"))
            return
        try:
            message = decode_reply(ok.payload.to_bytes())
        except MessageError as exc:
            deliver(exc)
            return
        deliver(message if isinstance(message, InsertReply) else CellRefused(message))

    def on_end() -> None:
        deliver(CellTimeout(f"cell {cell}: no reply to request {request.id} "
                            f"within {timeout:.1f} s"))

    cancel = zenoh.CancellationToken()
    session.get(insert_key(cell), zenoh.handlers.Callback(on_reply, on_end),
                payload=encode(request), timeout=timeout, cancellation_token=cancel,
                consolidation=zenoh.ConsolidationMode.NONE)
    return cancel


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


@dataclass(frozen=True)
class _Sent:
    """One attempt of a request at a cell."""

    attempt: int
    request: InsertRequest
    cancel: zenoh.CancellationToken


class CellPool:
    """Keeps every alive cell busy with submitted requests, with failover (module doc).

    :meth:`submit` queues a request (distinct ids); :meth:`next_reply` dispatches queued
    requests to idle alive cells and returns the next finished request and its reply;
    each submitted request is returned exactly once. ``timeout`` [s] bounds one attempt
    at one cell; ``wait_for_cell`` [s] bounds a wait while no cell is alive;
    ``max_failures`` bounds the failed attempts of one request. ``on_dispatch(cell,
    request)``, if set, is called (in the thread of :meth:`next_reply`) just before each
    request is sent to a cell, also when it is re-sent to another; an exception it raises
    propagates from :meth:`next_reply` and the request is not sent. Close it when done.
    """

    def __init__(self, session: zenoh.Session, directory: CellDirectory, *,
                 timeout: float = 60.0, wait_for_cell: float = 60.0, max_failures: int = 3) -> None:
        self._session = session
        self._directory = directory
        self.timeout = timeout
        self.wait_for_cell = wait_for_cell
        self.max_failures = max_failures
        self._attempts = itertools.count()
        self._events: queue.SimpleQueue[tuple] = queue.SimpleQueue()
        self._pending: deque[InsertRequest] = deque()
        self._busy: dict[str, _Sent] = {}
        self._slow: set[str] = set()
        self._failures: dict[str, int] = {}
        self._alive = directory.listen(self._on_change)
        self.on_dispatch: Callable[[str, InsertRequest], None] | None = None

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

    def _dispatch(self) -> None:
        idle = sorted(self._alive - self._busy.keys(), key=lambda c: (c in self._slow, c))
        while self._pending and idle:
            cell, request = idle[0], self._pending[0]
            if self.on_dispatch is not None:
                self.on_dispatch(cell, request)
            idle.pop(0)
            self._pending.popleft()
            attempt = next(self._attempts)
            cancel = send_insert(self._session, cell, request, self.timeout,
                                 functools.partial(self._on_outcome, cell, attempt))
            self._busy[cell] = _Sent(attempt, request, cancel)

    def _on_outcome(self, cell: str, attempt: int, outcome: Outcome) -> None:
        """Zenoh thread: queue the outcome of ``attempt`` sent to ``cell``."""
        self._events.put(("outcome", cell, attempt, outcome))

    def _next_event(self) -> tuple:
        if self._busy or self._alive:
            return self._events.get()
        try:
            return self._events.get(timeout=self.wait_for_cell)
        except queue.Empty:
            raise CellTimeout(f"no cell alive for {self.wait_for_cell:.0f} s; "
                              f"{len(self._pending)} experiment(s) still to run") from None

    def next_reply(self) -> tuple[InsertRequest, InsertReply]:
        """The next finished request and its reply; BridgeError if none can finish."""
        if not self.unfinished:
            raise BridgeError("next_reply: no request submitted")
        while True:
            self._dispatch()
            event = self._next_event()
            if event[0] == "cell":
                _, cell, alive = event
                if alive:
                    self._alive.add(cell)
                    continue
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
            del self._busy[cell]
            if isinstance(outcome, InsertReply):
                self._slow.discard(cell)
                return sent.request, outcome
            self._failed(cell, sent.request, outcome)

    def _failed(self, cell: str, request: InsertRequest, outcome: BridgeError) -> None:
        if isinstance(outcome, CellTimeout):
            self._slow.add(cell)
        elif isinstance(outcome, CellRefused) and outcome.reply.code != "failed":
            raise outcome  # the request itself is bad: no cell will take it
        else:
            self._failures[request.id] = self._failures.get(request.id, 0) + 1
            if self._failures[request.id] >= self.max_failures:
                raise BridgeError(f"request {request.id} ({request.part} into {request.hole}) "
                                  f"failed {self.max_failures} times; last: {outcome}")
        self._pending.appendleft(request)
