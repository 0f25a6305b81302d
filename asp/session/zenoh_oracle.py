"""The size learner's oracle over Zenoh: experiments run on every alive cell at once.

:class:`ZenohOracle` satisfies :class:`asp.sizes.truth_oracle.Oracle`
(``ask(part, hole)``) and adds a pipelined interface: :meth:`~ZenohOracle.submit` an experiment, get finished ones
with :meth:`~ZenohOracle.next_result`. The session submits only experiments that the
size learner put in one batch with everything still running (none of their outcomes
can entail another's), so parallel work is never wasted. Underneath,
:class:`bridge.client.CellPool` sends one request per alive cell and re-sends the
request of a cell that dies mid-experiment to another cell (or waits for one).

Request ids are ``<run>.<part>.<hole>.<n>`` for the n-th time the pair is started in
the run (an experiment abandoned by a killed planner counts, so a resumed session never
sends an old id again; ``retest`` marks a deliberate re-test of a pair already tried).
Experiments are numbered in the order they are submitted, after the highest number the
journal ever saw started. Each request is journaled as started (fsynced) just before it
is sent to a cell. Cells are idempotent by id, so a re-sent request never runs twice on
a cell that finished it; every reply is journaled (fsynced) exactly once, before its
result is returned.
"""

from __future__ import annotations

import zlib
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass

from asp import PlannerError
from asp.session.journal import Journal, JournalEntry
from asp.sizes.truth_oracle import Result
from bridge import BridgeError
from bridge.client import CellPool
from bridge.messages import InsertReply, InsertRequest

Pair = tuple[str, str]


@dataclass(frozen=True)
class Finished:
    """A finished experiment: ``cell`` inserted ``part`` into ``hole`` with ``result``."""

    part: str
    hole: str
    result: Result
    cell: str
    experiment: int
    """Its number in the order experiments were started (Rerun timeline ``experiment``)."""
    attempts: int | None = None
    """Insertion attempts the cell made (None when it reported no evidence)."""
    wall_s: float = 0.0
    """The cell's wall-clock time for the experiment [s]."""


class ZenohOracle:
    """Runs experiments on the cells of ``pool``; journals each finished one."""

    def __init__(self, pool: CellPool, journal: Journal, run_id: str, seed: int = 0) -> None:
        self._pool = pool
        self._journal = journal
        self._run_id = run_id
        self._seed = seed
        self._tried: Counter[Pair] = Counter((e.part, e.hole) for e in journal.entries)
        started = {(e.part, e.hole, e.experiment) for e in journal.events}
        started |= {(e.part, e.hole, e.experiment or -k) for k, e in enumerate(journal.entries, start=1)}
        self._asked: Counter[Pair] = Counter((part, hole) for part, hole, _ in started)
        self._started = journal.highest_started
        pool.on_dispatch = self._on_dispatch

    def alive_cells(self) -> int:
        """How many cells the pool may use are alive now (how many experiments can run at
        once); a token of a cell the session does not use is not counted, so the batches,
        and thus the experiments chosen, do not depend on it."""
        return len(self._pool.usable_alive())

    def submit(self, part: str, hole: str) -> None:
        """Queue one experiment under the next number; it starts as soon as a cell is idle."""
        self._asked[(part, hole)] += 1
        key = f"{self._run_id}.{part}.{hole}.{self._asked[(part, hole)]}"
        retest = self._tried[(part, hole)] > 0
        self._tried[(part, hole)] += 1
        self._started += 1
        self._pool.submit(InsertRequest(id=key, part=part, hole=hole, retest=retest,
                                        seed=zlib.crc32(f"{self._seed}.{key}".encode()),
                                        experiment=self._started))

    def dispatch(self) -> None:
        """Start the submitted experiments on the idle cells now, before other work of the
        planner's thread (:meth:`next_result` would start them too)."""
        self._pool.dispatch()

    def _on_dispatch(self, cell: str, request: InsertRequest) -> None:
        self._journal.started(request.experiment, request.id, request.part, request.hole, cell)

    def next_result(self) -> Finished:
        """Wait for the next finished experiment, journal it durably, return it.

        PlannerError when the cells cannot finish the submitted experiments (no cell for
        the wait limit, or a request refused by every cell).
        """
        finished = self._finish(self._pool.next_reply)
        assert finished is not None  # next_reply waits until one finishes or raises
        return finished

    def finished_result(self) -> Finished | None:
        """An experiment that has already finished, journaled, without waiting (None if
        none has): the session takes every one of them before it plans again."""
        return self._finish(self._pool.finished_reply)

    def _finish(self, reply_of: Callable[[], tuple[InsertRequest, InsertReply] | None]) -> Finished | None:
        try:
            found = reply_of()
        except BridgeError as exc:
            raise PlannerError(f"experiments over Zenoh failed: {exc}") from None
        if found is None:
            return None
        request, reply = found
        self._journal.append(JournalEntry(
            id=request.id, part=request.part, hole=request.hole, result=reply.result,
            cell=reply.cell, retest=request.retest, evidence=reply.evidence, wall_s=reply.wall_s,
            experiment=request.experiment))
        return Finished(request.part, request.hole, reply.result, reply.cell, request.experiment,
                        None if reply.evidence is None else reply.evidence.attempts, reply.wall_s)

    def ask(self, part: str, hole: str) -> Result:
        """One experiment, waited for (Oracle protocol); nothing else may be running."""
        if self._pool.unfinished:
            raise PlannerError("ask: other experiments are still running; use next_result")
        self.submit(part, hole)
        return self.next_result().result
