"""The information bound: log2 of the number of must-precede relations consistent with
what is known (transitive relations holding the known pairs and no excluded one). No
sequence of yes/no experiments decides the relation in fewer experiments in the worst case.

Counted exactly by :func:`asp.precedence.explore.orders.count_orders` within
``time_limit_s``; where that gives up (the known and open pairs in a cycle, as without any
demonstration, or the time is up), by clingo's enumeration (``precedence_orders.lp``) for
as long again: a count cut short is a lower bound of the count, hence of the bound (still
a valid lower bound of the experiments needed).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import clingo

from asp.precedence.explore.knowledge import Knowledge
from asp.precedence.explore.orders import count_orders
from asp.solve import add_facts, encoding


@dataclass(frozen=True)
class Bound:
    """``relations`` consistent with the knowledge (all of them when ``complete``)."""

    relations: int
    complete: bool

    @property
    def bits(self) -> float:
        """log2 of the count [bits]."""
        return math.log2(self.relations) if self.relations else 0.0

    def text(self) -> str:
        return f"{'' if self.complete else '>= '}{self.bits:.1f} bits ({self.relations} relations)"


def information_bound(knowledge: Knowledge, time_limit_s: float = 10.0) -> Bound:
    """Count the relations consistent with ``knowledge``: exactly within ``time_limit_s`` [s],
    else by :func:`enumerated_bound` within as long again (complete or a lower bound)."""
    exact = count_orders(knowledge.evidence.parts, knowledge.known, knowledge.known | knowledge.open, time_limit_s)
    if exact is not None:
        return Bound(exact, True)
    return enumerated_bound(knowledge, time_limit_s)


def enumerated_bound(knowledge: Knowledge, time_limit_s: float) -> Bound:
    """The relations consistent with ``knowledge`` that clingo enumerates within ``time_limit_s`` [s]."""
    ctl = clingo.Control(["--models=0"], logger=lambda _code, _msg: None)
    ctl.load(str(encoding("precedence_orders.lp")))
    add_facts(ctl, knowledge.facts)
    ctl.ground([("base", [])])
    with ctl.solve(async_=True) as handle:
        complete = handle.wait(time_limit_s)
        if not complete:
            handle.cancel()
    enumerated = int(ctl.statistics["summary"]["models"]["enumerated"])
    return Bound(enumerated, complete)
