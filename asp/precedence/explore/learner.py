"""One learner for three sources: demonstrations, the geometric precedence and experiment
outcomes. Each learned pair carries its support:

- ``geometry``: forced by the CAD's geometric precedence (its closure);
- ``experiment``: confirmed by a failed experiment (with geometry, through the closure);
- ``demonstrated``: every demonstration keeps the order and nothing decided it (Algorithm 1);
- ``assumed``: implied through the closure by demonstrated pairs, though itself shown free
  (kept so the relation admits only orders whose every pair the evidence allows).

The learned relation is the closure of the known and open pairs: every sequence it admits
respects the true relation (paper eq. 10). Without demonstrations it is the known pairs
alone (as a prior alone). Pairs that every demonstration keeps but an experiment shows free
are *process constraints*: not physics, perhaps the user's process; reported, to confirm
with the user, never silently dropped. Conflicts between the sources are errors
(:class:`asp.precedence.explore.knowledge.PrecedenceConflict`).

The cell's own orders (``cell_before(P,Q)``, the fingers' grip) leave some pairs open: the
cell never places P after Q, so it cannot show P<Q free, and an experiment that would
break one is never run. Such pairs are *undecidable by this cell*
(:attr:`Learned.cell_undecided`, each with its reason): kept in the relation as the
demonstrations have them (the cell's plans put P first anyway), never guessed.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import clingo

from asp.precedence.explore.knowledge import Evidence, Knowledge, Trial, broken_order, know
from asp.precedence.learn import learn_must_precede
from asp.precedence.relation import Pair, Relation, close, precedence_facts
from asp.solve import fact
from bridge.inputs import read_bytes

SUPPORTS = ("geometry", "experiment", "demonstrated", "assumed")
_REASON = re.compile(r"^% ([a-z]\w*)->([a-z]\w*): ([a-z]+)$", re.MULTILINE)


def geometric_reasons(path: str | None) -> dict[Pair, str]:
    """The reason of each direct pair of a ``geometric_precedence.lp`` (its ``% a->b: reason``
    comments, as ``import`` writes them: blocks, base, feature, supports, locates); {} without a file."""
    if path is None:
        return {}
    text = read_bytes(Path(path), "geometric precedence").decode("utf-8", errors="replace")
    return {(a, b): reason for a, b, reason in _REASON.findall(text)}


@dataclass(frozen=True)
class Learned:
    """The learned relation, the support of each of its pairs, the process constraints, the
    failed experiments that confirmed nothing (another absent part, or the cell's order, may
    be the cause) and the open pairs the cell's own orders leave undecidable, each with why."""

    knowledge: Knowledge
    relation: Relation
    support: dict[Pair, str]
    process: tuple[Pair, ...]
    undecided: tuple[Trial, ...]
    cell_undecided: tuple[tuple[Pair, str], ...] = ()

    def facts(self) -> list[clingo.Symbol]:
        """``part/1``, ``must_precede/2``, ``precedence_edge/2``, ``support(A,B,S)`` and
        ``process_constraint(A,B)``."""
        return (precedence_facts(self.relation)
                + [fact("support", a, b, s) for (a, b), s in sorted(self.support.items())]
                + [fact("process_constraint", a, b) for a, b in self.process])

    def summary(self) -> str:
        """The pairs by support, the process constraints and the undecided experiments, as text."""
        counts = {s: sum(1 for v in self.support.values() if v == s) for s in SUPPORTS}
        lines = [f"learned {len(self.support)} pairs: " + ", ".join(f"{n} {s}" for s, n in counts.items())]
        reasons = self.knowledge.evidence.geometry_reasons
        for s in SUPPORTS:
            pairs = [f"{a}<{b}" + (f" ({reasons[(a, b)]})" if (a, b) in reasons and s == "geometry" else "")
                     for (a, b), v in sorted(self.support.items()) if v == s]
            if pairs:
                lines.append(f"  {s}: {' '.join(pairs)}")
        if self.process:
            lines.append("process constraints to confirm with the user (every demonstration keeps the order, "
                         "experiments show it free): " + " ".join(f"{a}<{b}" for a, b in self.process))
        cell_before = self.knowledge.evidence.cell_before
        for trial in self.undecided:
            a, b = trial.experiment.pair
            failed = [step.part for step in trial.experiment.sequence[:trial.outcome.failed_step]]
            broken = broken_order(failed, cell_before)
            cause = (f"the cell's own order explains it: the fingers holding {broken[0]} meet {broken[1]} in place"
                     if broken is not None and broken[0] == failed[-1] else
                     f"{a} was not seen blocked by {b} alone: another part, or none seen, may be the cause"
                     if trial.outcome.failed_step == len(trial.experiment.sequence) and trial.experiment.then_first
                     else "another absent part may be the cause")
            lines.append(f"undecided: {trial.describe()}: {cause}")
        for (a, b), why in self.cell_undecided:
            lines.append(f"undecidable by this cell: {a}<{b}: {why}")
        lines.append(f"open pairs left: {len(self.knowledge.open)}"
                     + (f" ({len(self.cell_undecided)} undecidable by this cell, kept as the demonstrations "
                        "have them)" if self.cell_undecided else ""))
        if cell_before:
            lines.append("assumes: the cell's own orders (cell_order.lp: "
                         + " ".join(f"{p}<{q}" for p, q in cell_before) + ") hold in every experiment: "
                         "a pair of them is confirmed only by its second part failing without its first, "
                         "never shown free (the cell never places the first after the second)")
        return "\n".join(lines)


def learn_sources(evidence: Evidence) -> Learned:
    """Learn from every source of ``evidence``; PrecedenceConflict where they disagree."""
    knowledge = know(evidence)
    parts = evidence.parts
    geometric = set(close(Relation.from_pairs(parts, evidence.geometry)).pairs())
    has_demos = bool(evidence.demos.sequences)
    upper = knowledge.known | (knowledge.open if has_demos else frozenset())
    relation = close(Relation.from_pairs(parts, upper), source="the learned precedence")
    support: dict[Pair, str] = {}
    for pair in relation.pairs():
        if pair in geometric:
            support[pair] = "geometry"
        elif pair in knowledge.known:
            support[pair] = "experiment"
        elif pair in knowledge.open:
            support[pair] = "demonstrated"
        else:
            support[pair] = "assumed"
    demonstrated = learn_must_precede(evidence.demos).pairs() if has_demos else []
    process = tuple(sorted(p for p in demonstrated if p in knowledge.excluded))
    return Learned(knowledge, relation, support, process, knowledge.undecided, cell_undecided(knowledge))


def _tried_alone(knowledge: Knowledge, pair: Pair) -> str:
    a, b = pair
    trial = next(t for t in reversed(knowledge.evidence.trials) if t.experiment.pair == pair
                 and t.outcome.outcome == "success" and not t.experiment.then_first)
    placed = [step.part for step in trial.experiment.sequence]
    orders = " ".join(f"{a}<{q}" for q in placed if (a, q) in knowledge.evidence.cell_before)
    return (f"{b} went in without {a} ({trial.describe()}), and the cell never places {a} after it "
            f"(its own order {orders}): whether {a} can go in after {b} is not observed")


def _blocked(knowledge: Knowledge, pair: Pair) -> str:
    a, b = pair
    set_up = knowledge.requires.get(pair, ())
    orders = [(p, q) for p, q in knowledge.evidence.cell_before
              if (p == b and q in set_up) or (p in set_up and q in set_up)]
    return (f"its experiment ({b} without {a}, after {' '.join(set_up)}) would break the cell's own order "
            + " ".join(f"{p}<{q}" for p, q in orders))


def cell_undecided(knowledge: Knowledge) -> tuple[tuple[Pair, str], ...]:
    """The open pairs the cell's own orders leave undecidable, each with why: its second part
    went in alone and the cell never places its first after it, its experiment would break
    one of the orders, or it lies over such pairs (no experiment separates the two parts);
    () without those orders or while a candidate is left."""
    if not knowledge.evidence.cell_before or knowledge.candidates:
        return ()
    upper = knowledge.known | knowledge.open
    after: dict[str, set[str]] = {p: {p} for p in knowledge.evidence.parts}
    for start, reached in after.items():  # the parts at or after each in the upper bound
        frontier = [start]
        while frontier:
            part = frontier.pop()
            for a, b in upper:
                if a == part and b not in reached:
                    reached.add(b)
                    frontier.append(b)
    untested = knowledge.cell_tried | knowledge.cell_blocked
    reasons = []
    for a, b in sorted(knowledge.open):
        if (a, b) in knowledge.cell_tried:
            reasons.append(((a, b), _tried_alone(knowledge, (a, b))))
        elif (a, b) in knowledge.cell_blocked:
            reasons.append(((a, b), _blocked(knowledge, (a, b))))
        else:
            over = [f"{x}<{y}" for x, y in sorted(untested) if x in after[a] and b in after[y]]
            reasons.append(((a, b), "a part may lie between them, over " + " ".join(over)
                            + ", which this cell cannot decide: no experiment of it separates the two"))
    return tuple(reasons)
