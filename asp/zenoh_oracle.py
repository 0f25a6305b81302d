"""The size learner's oracle over Zenoh: experiments run on every alive cell at once.

:class:`ZenohOracle` satisfies :class:`asp.oracle.Oracle` (``ask(part, hole)``) and adds
:meth:`ZenohOracle.ask_batch`, which runs a batch of experiments (the learner's
:meth:`~asp.size_learner.SizeLearner.next_batch`: none of their outcomes can entail
another's) in parallel, one per alive cell, through :class:`bridge.client.CellPool`. A
cell dying mid-experiment has its request re-sent to another cell (or waits for one).

Request ids are ``<run>.<part>.<hole>.<n>`` for the n-th time the pair is asked in the
run (n > 1: a deliberate re-test). Cells are idempotent by id, so a re-sent request
never runs twice on a cell that finished it, and every reply is journaled (fsynced)
exactly once before its result is returned.
"""

from __future__ import annotations

import zlib
from collections import Counter
from collections.abc import Sequence

from asp import PlannerError
from asp.journal import Journal, JournalEntry
from asp.oracle import Result
from bridge import BridgeError
from bridge.client import CellDirectory, CellPool
from bridge.messages import InsertReply, InsertRequest

Pair = tuple[str, str]


class ZenohOracle:
    """Runs experiments on the cells of ``directory``; journals each finished one."""

    def __init__(self, pool: CellPool, directory: CellDirectory, journal: Journal,
                 run_id: str, seed: int = 0) -> None:
        self._pool = pool
        self._directory = directory
        self._journal = journal
        self._run_id = run_id
        self._seed = seed
        self._asked: Counter[Pair] = Counter((e.part, e.hole) for e in journal.entries)

    def alive_cells(self) -> int:
        """How many cells are alive now (the useful batch size)."""
        return len(self._directory.alive())

    def ask(self, part: str, hole: str) -> Result:
        """One experiment (Oracle protocol)."""
        return self.ask_batch([(part, hole)])[0]

    def ask_batch(self, pairs: Sequence[Pair]) -> list[Result]:
        """Run the experiments in parallel; results in the order of ``pairs``.

        PlannerError when the cells cannot finish them (no cell for the wait limit, or a
        request refused by every cell).
        """
        requests = [self._request(part, hole) for part, hole in pairs]

        def journal(request: InsertRequest, reply: InsertReply) -> None:
            self._journal.append(JournalEntry(
                id=request.id, part=request.part, hole=request.hole, result=reply.result,
                cell=reply.cell, retest=request.retest, evidence=reply.evidence,
                wall_s=reply.wall_s))

        try:
            replies = self._pool.run(requests, journal)
        except BridgeError as exc:
            raise PlannerError(f"experiments over Zenoh failed: {exc}") from None
        return [replies[request.id].result for request in requests]

    def _request(self, part: str, hole: str) -> InsertRequest:
        self._asked[(part, hole)] += 1
        n = self._asked[(part, hole)]
        key = f"{self._run_id}.{part}.{hole}.{n}"
        return InsertRequest(id=key, part=part, hole=hole, retest=n > 1,
                             seed=zlib.crc32(f"{self._seed}.{key}".encode()))
