"""One process per cell id: a second process claiming a served cell id refuses to serve.

Every cell process holds the liveliness token ``cell/<id>/claim/<instance>`` (a random
instance name) and answers queries on that key with its age: the seconds since it
claimed the id, as decimal text. It follows the claims of its id; for every other
instance it sees, it asks that instance's age, and the younger of the two yields:

- at start (:meth:`CellClaim.check`, before the cell declares its ``alive`` token, so the
  planner never sees it) it raises :class:`ClaimLost`: the process exits with code 2;
- later (the two processes met only when a third peer connected them) it calls
  ``on_lost``: the cell stops after the experiment in progress and exits with code 2.

Ages within :data:`TIE_S` of each other (two processes started together) are decided by
instance name, the smaller keeping the id. An age is measured with a query's round trip
of error, so when that error is below :data:`TIE_S` the two processes never both yield.
A claim token whose process does not answer the age query is ignored.

Processes find each other only when Zenoh connects them (peers do not route for other
peers): on loopback every cell listens on a port of its own, and Zenoh's gossip then
connects the cells of one planner to each other (docs/decisions.md, duplicate cell ids).
"""

from __future__ import annotations

import functools
import math
import threading
import time
import uuid
from collections.abc import Callable

import zenoh

from bridge.keys import claim_key, claims_pattern, instance_of_claim_key
from executor import ExecutorError

STARTUP_CHECK_S = 0.5
"""How long a starting cell looks for an older claim of its id [s] (measured: peers
connected through one planner saw each other's tokens within 6 ms of opening)."""

TIE_S = 0.5
"""Ages closer than this [s] are a tie, decided by instance name."""

AGE_QUERY_TIMEOUT_S = 2.0
"""How long an age query waits for its answer [s]."""

_MAX_AGE_CHARS = 32


class ClaimLost(ExecutorError):
    """An older process serves this cell id."""


def _age(reply: zenoh.Reply) -> float | None:
    """The age [s] an answer states; None for an error or anything but a finite number >= 0."""
    if reply.ok is None:
        return None
    text = reply.ok.payload.to_bytes()[:_MAX_AGE_CHARS]
    try:
        age = float(text.decode("ascii"))
    except (UnicodeDecodeError, ValueError):
        return None
    return age if math.isfinite(age) and age >= 0 else None


class CellClaim:
    """This process's claim of ``cell_id`` on ``session`` (module doc). Close it with the
    session (the token and queryable go with it)."""

    def __init__(self, session: zenoh.Session, cell_id: str,
                 on_lost: Callable[[str], None] | None = None) -> None:
        self.cell_id = cell_id
        self.instance = uuid.uuid4().hex[:12]
        self.on_lost = on_lost
        self.lost: str | None = None
        """Why this process yields the id (None while it keeps it)."""
        self._session = session
        self._claimed = time.monotonic()
        self._decided = threading.Event()
        key = claim_key(cell_id, self.instance)
        self._held = (session.declare_queryable(key, self._answer),
                      session.liveliness().declare_token(key),
                      session.liveliness().declare_subscriber(claims_pattern(cell_id), self._on_claim,
                                                              history=True))

    def age(self) -> float:
        """Seconds since this process claimed the id."""
        return time.monotonic() - self._claimed

    def _answer(self, query: zenoh.Query) -> None:
        query.reply(query.key_expr, f"{self.age():.3f}".encode("ascii"))

    def _on_claim(self, sample: zenoh.Sample) -> None:
        """Zenoh thread: another process claims the id; ask its age (answer in :meth:`_compare`)."""
        other = instance_of_claim_key(str(sample.key_expr), self.cell_id)
        if sample.kind != zenoh.SampleKind.PUT or other is None or other == self.instance:
            return
        self._session.get(claim_key(self.cell_id, other), functools.partial(self._compare, other),
                          timeout=AGE_QUERY_TIMEOUT_S)

    def _compare(self, other: str, reply: zenoh.Reply) -> None:
        other_age = _age(reply)
        if other_age is None or self.lost is not None:
            return
        mine = self.age()
        older = other < self.instance if abs(other_age - mine) <= TIE_S else other_age > mine
        if not older:
            return
        self.lost = (f"cell id {self.cell_id} is already served by another process "
                     f"(instance {other}, up {other_age:.1f} s); this one (instance {self.instance}) "
                     "refuses to serve it twice")
        self._decided.set()
        if self.on_lost is not None:
            self.on_lost(self.lost)

    def check(self, wait_s: float = STARTUP_CHECK_S) -> None:
        """Look for an older claim for ``wait_s`` [s]; ClaimLost if there is one."""
        if self._decided.wait(wait_s):
            raise ClaimLost(str(self.lost))
