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
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import clingo

from asp.precedence.explore.knowledge import Evidence, Knowledge, Trial, know
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
    """The learned relation, the support of each of its pairs, the process constraints and
    the failed experiments that confirmed nothing (another absent part may be the cause)."""

    knowledge: Knowledge
    relation: Relation
    support: dict[Pair, str]
    process: tuple[Pair, ...]
    undecided: tuple[Trial, ...]

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
        for trial in self.undecided:
            a, b = trial.experiment.pair
            cause = (f"{a} was not seen blocked by {b} alone: another part, or none seen, may be the cause"
                     if trial.outcome.failed_step == len(trial.experiment.sequence) and trial.experiment.then_first
                     else "another absent part may be the cause")
            lines.append(f"undecided: {trial.describe()}: {cause}")
        lines.append(f"open pairs left: {len(self.knowledge.open)}")
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
    return Learned(knowledge, relation, support, process, knowledge.undecided)
