"""The planner's side of the bridge: discovering cells and sending them experiments.

- :class:`CellDirectory` follows the cells' liveliness tokens (``cell/*/alive``).
- :func:`send_insert` sends one request asynchronously; :func:`request_insert` waits for it.
- :class:`CellPool` runs a batch of requests over every alive cell at once: one request
  per cell, a cell that dies (token gone) or times out has its request re-sent to another
  cell (or the pool waits for one), and each request's outcome is delivered exactly once.
  Cells are idempotent by request id, so a re-sent request never runs twice on one cell.
"""

from __future__ import annotations

import itertools
import queue
import threading
import time
from collections import deque
from collections.abc import Callable, Iterable
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
    delivered = threading.Event()

    def deliver(outcome: Outcome) -> None:
        if not delivered.is_set():
            delivered.set()
            on_outcome(outcome)

    def on_reply(reply: zenoh.Reply) -> None:
        if reply.ok is None:
            deliver(CellTimeout(f"cell {cell}: query error: {reply.err.payload.to_string()}"))
            return
        try:
            message = decode_reply(reply.ok.payload.to_bytes())
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
    outcome = box.get(timeout=timeout + 5.0)
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
    """Runs batches of requests over every alive cell, with failover (see module doc).

    ``timeout`` [s] bounds one attempt at one cell; ``wait_for_cell`` [s] bounds how long
    a batch waits while no cell is alive; ``max_failures`` bounds the refused/failed
    attempts of one request before the batch gives up.
    """

    def __init__(self, session: zenoh.Session, directory: CellDirectory, *,
                 timeout: float = 60.0, wait_for_cell: float = 60.0, max_failures: int = 3) -> None:
        self._session = session
        self._directory = directory
        self.timeout = timeout
        self.wait_for_cell = wait_for_cell
        self.max_failures = max_failures
        self._attempts = itertools.count()

    def run(self, requests: Iterable[InsertRequest],
            on_reply: Callable[[InsertRequest, InsertReply], None]) -> dict[str, InsertReply]:
        """Run the requests (distinct ids), each on one alive cell, until all have replies.

        ``on_reply`` is called once per request, in the calling thread, as soon as its
        reply arrives. Raises BridgeError when no cell shows up for ``wait_for_cell`` s or
        a request fails ``max_failures`` times.
        """
        events: queue.SimpleQueue[tuple] = queue.SimpleQueue()

        def on_change(cell: str, alive: bool) -> None:
            events.put(("cell", cell, alive))

        alive = self._directory.listen(on_change)
        try:
            return self._loop(deque(requests), alive, events, on_reply)
        finally:
            self._directory.unlisten(on_change)

    def _loop(self, pending: deque[InsertRequest], alive: set[str], events: queue.SimpleQueue,
              on_reply: Callable[[InsertRequest, InsertReply], None]) -> dict[str, InsertReply]:
        done: dict[str, InsertReply] = {}
        busy: dict[str, _Sent] = {}
        slow: set[str] = set()
        failures: dict[str, int] = {}
        total = len(pending) + len(done)
        no_cell_since: float | None = None
        while len(done) < total:
            idle = sorted(alive - busy.keys(), key=lambda c: (c in slow, c))
            while pending and idle:
                cell = idle.pop(0)
                request = pending.popleft()
                attempt = next(self._attempts)
                cancel = send_insert(self._session, cell, request, self.timeout,
                                     lambda outcome, c=cell, a=attempt: events.put(("outcome", c, a, outcome)))
                busy[cell] = _Sent(attempt, request, cancel)
            if not busy and not alive:
                no_cell_since = no_cell_since or time.monotonic()
                remaining = no_cell_since + self.wait_for_cell - time.monotonic()
                if remaining <= 0:
                    raise CellTimeout(f"no cell alive for {self.wait_for_cell:.0f} s; "
                                      f"{len(pending)} experiment(s) still to run")
                try:
                    event = events.get(timeout=remaining)
                except queue.Empty:
                    continue
            else:
                no_cell_since = None
                event = events.get()
            if event[0] == "cell":
                _, cell, is_alive = event
                if is_alive:
                    alive.add(cell)
                    continue
                alive.discard(cell)
                sent = busy.pop(cell, None)
                if sent is not None:
                    sent.cancel.cancel()
                    pending.appendleft(sent.request)
                continue
            _, cell, attempt, outcome = event
            sent = busy.get(cell)
            if sent is None or sent.attempt != attempt:
                continue  # a cancelled or superseded attempt
            del busy[cell]
            request = sent.request
            if isinstance(outcome, InsertReply):
                slow.discard(cell)
                if request.id not in done:
                    done[request.id] = outcome
                    on_reply(request, outcome)
                continue
            if isinstance(outcome, CellTimeout):
                slow.add(cell)
            elif isinstance(outcome, CellRefused) and outcome.reply.code != "failed":
                raise outcome  # the request itself is bad: no cell will take it
            else:
                failures[request.id] = failures.get(request.id, 0) + 1
                if failures[request.id] >= self.max_failures:
                    raise BridgeError(f"request {request.id} ({request.part} into "
                                      f"{request.hole}) failed {self.max_failures} times; "
                                      f"last: {outcome}")
            pending.appendleft(request)
        return done
