"""The information bound: log2 of the number of must-precede relations consistent with
what is known (``precedence_orders.lp``, counted by clingo's enumeration). No sequence
of yes/no experiments decides the relation in fewer experiments in the worst case.

Counting transitive relations is hard: the enumeration stops after ``time_limit_s``; a
count cut short is a lower bound of the count, hence of the bound (still a valid lower
bound of the experiments needed).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import clingo

from asp.precedence.explore.knowledge import Knowledge
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
    """Count the relations consistent with ``knowledge`` within ``time_limit_s`` [s]."""
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
