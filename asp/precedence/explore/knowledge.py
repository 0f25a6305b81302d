"""What is known of the true must-precede relation from demonstrations, geometry and
experiment outcomes (encodings ``precedence_knowledge.lp``: ``precedence/evidence.lp``,
``precedence/knowledge.lp``, ``precedence/experiment_candidates.lp``).

A failed experiment confirms its pair only when the pair's first part is the one absent
part that may precede the failing part: the others must be excluded. Exclusions grow with
the confirmed pairs, so the confirmed pairs are found by a fixpoint (each round one
solve; knowledge only grows). A "B then A" experiment whose A step, after B, the cell saw
blocked by B alone confirms its pair by ``precedence/evidence.lp`` (``blocked_first``);
failed there for another cause it decides nothing. A failure still undecided at the
fixpoint is kept and reported, never read as a confirmation. A failure before the tested step (the known
state was not reached) and every conflict between sources are errors naming their
evidence (:class:`PrecedenceConflict`).

The cell's own orders (``cell_before(P,Q)``, :attr:`Evidence.cell_before`: the fingers
holding P would meet Q in place) are kept by every experiment chosen; a failure of a step
placing P after such a Q (from a file) is the cell's and confirms nothing, and a pair
(P,Q) of them is confirmed only by Q failing without P, never shown free by the cell
(:attr:`Knowledge.cell_tried`, ``precedence/experiment_candidates.lp``).
"""

from __future__ import annotations

import re
from collections import deque
from collections.abc import Collection, Sequence
from dataclasses import dataclass, field, replace

import clingo

from asp import PlannerError
from asp.precedence.demos import Demonstrations
from asp.precedence.relation import Pair
from asp.solve import fact, solve
from bridge.precedence.experiment import PrecedenceExperiment, PrecedenceOutcome

GEOMETRY = "geometry"
POLICIES = {"informative": "select_precedence_informative.lp", "first": "select_precedence_first.lp"}
"""Experiment policies and their entry encodings (:mod:`asp.precedence.explore.select`)."""


class PrecedenceConflict(PlannerError):
    """Two sources of precedence disagree; the message names both and their evidence."""


@dataclass(frozen=True)
class Trial:
    """An experiment, its outcome and where the pair came from (a file:line, or the oracle)."""

    experiment: PrecedenceExperiment
    outcome: PrecedenceOutcome
    origin: str

    def describe(self) -> str:
        """E.g. ``experiment run.3 (sh<pd: failed at step 4, unsupported)``."""
        a, b = self.experiment.pair
        if self.outcome.outcome == "success":
            result = f"{b} placed before {a}" + (f", then {a}" if self.experiment.then_first else "")
        else:
            by = f" by {' '.join(self.outcome.blocked_by)}" if self.outcome.blocked_by else ""
            result = f"failed at step {self.outcome.failed_step}, {self.outcome.reason}{by}"
        where = "" if self.origin == "oracle" else f", {self.origin}"
        return f"experiment {self.experiment.id} ({self.experiment.tested}: {result}{where})"


@dataclass(frozen=True)
class Evidence:
    """Everything precedence is learned from. ``geometry``: the pairs the CAD forces (with
    ``geometry_reasons[pair]`` where the import named one); ``geometry_source``: its file."""

    demos: Demonstrations
    geometry: tuple[Pair, ...] = ()
    geometry_source: str = "the geometric precedence"
    geometry_reasons: dict[Pair, str] = field(default_factory=dict)
    trials: tuple[Trial, ...] = ()
    cell_before: tuple[Pair, ...] = ()
    """The cell's own orders (P, Q): the cell puts P in before Q (the product's ``cell_order.lp``)."""

    @property
    def parts(self) -> tuple[str, ...]:
        return self.demos.parts

    def with_trial(self, trial: Trial) -> Evidence:
        return replace(self, trials=(*self.trials, trial))

    def source_name(self, source: str) -> str:
        """The evidence a source (``demo(D)``, ``experiment(E)``, ``geometry``) stands for."""
        name, _, number = source.rstrip(")").partition("(")
        if name == "demo":
            return f"demonstration {self.demos.origins[int(number) - 1]}"
        if name == "experiment":
            return self.trials[int(number) - 1].describe()
        return self.geometry_source

    def facts(self) -> list[clingo.Symbol]:
        """``part/1``, ``part_index/2``, ``demo/3``, ``forced/3`` (geometry), ``cell_before/2`` and
        the experiments' ``experiment/3``, ``experiment_step/3``, ``experiment_success/1``,
        ``experiment_failed/3``, ``experiment_blocker/2`` (E: 1-based)."""
        atoms = [fact("part", p) for p in self.parts]
        atoms += [fact("cell_before", p, q) for p, q in self.cell_before]
        atoms += [fact("part_index", p, i) for i, p in enumerate(self.parts, 1)]
        atoms += [fact("demo", d, i, p) for d, sequence in enumerate(self.demos.sequences, 1)
                  for i, p in enumerate(sequence, 1)]
        atoms += [fact("forced", a, b, GEOMETRY) for a, b in self.geometry]
        for e, trial in enumerate(self.trials, 1):
            atoms.append(fact("experiment", e, *trial.experiment.pair))
            atoms += [fact("experiment_blocker", e, part) for part in trial.outcome.blocked_by]
            atoms += [fact("experiment_step", e, i, step.part) for i, step in enumerate(trial.experiment.sequence, 1)]
            if trial.outcome.outcome == "success":
                atoms.append(fact("experiment_success", e))
            else:
                assert trial.outcome.failed_step is not None and trial.outcome.reason is not None
                atoms.append(fact("experiment_failed", e, trial.outcome.failed_step, trial.outcome.reason))
        return atoms


@dataclass(frozen=True)
class Knowledge:
    """The knowledge state: ``known`` (closed), ``excluded``, ``open`` pairs; ``candidates``
    (experiments whose outcome decides their pair) with the parts each ``requires`` before its
    second part (every open pair no part lies between), ``alone`` those placing their second part
    without the first after it (the cell's orders); ``confirmed`` (pairs of failed
    experiments, by trial index); ``undecided`` (failed experiments that confirm nothing
    yet); ``cell_blocked`` and ``cell_tried``: the open pairs no part lies between that the
    cell's orders leave untested (their experiment would break one; their second part went
    in alone, the first never tried after it); ``facts`` (the solver's input); the pair
    ``selected`` by ``policy`` (None: no policy asked, or nothing open)."""

    evidence: Evidence
    known: frozenset[Pair]
    excluded: frozenset[Pair]
    open: frozenset[Pair]
    candidates: tuple[Pair, ...]
    requires: dict[Pair, tuple[str, ...]]
    confirmed: dict[int, Pair]
    undecided: tuple[Trial, ...]
    facts: tuple[clingo.Symbol, ...]
    alone: frozenset[Pair] = frozenset()
    cell_blocked: frozenset[Pair] = frozenset()
    cell_tried: frozenset[Pair] = frozenset()
    policy: str | None = None
    selected: Pair | None = None


_ATOM = re.compile(r"^([a-z_]\w*)\((.*)\)$")
_ARGUMENT = re.compile(r"[a-z_]\w*(?:\(\d+\))?|\d+")
Atoms = dict[str, list[tuple[str, ...]]]


def _solve_knowledge(facts: Sequence[clingo.Symbol], entry: str) -> Atoms:
    """The shown atoms of the last (optimal) model of ``entry`` by name, arguments as text
    (``demo(2)`` for a source): one string per symbol, as clingo's symbol accessors cost a
    foreign call each."""
    texts: list[str] = []

    def on_model(model: clingo.Model) -> None:
        texts[:] = [str(s) for s in model.symbols(shown=True)]

    solve([entry], facts, ["--opt-mode=opt"], on_model)
    atoms: Atoms = {}
    for text in texts:
        match = _ATOM.match(text)
        if match is not None:
            atoms.setdefault(match.group(1), []).append(tuple(_ARGUMENT.findall(match.group(2))))
    return atoms


def _pairs(atoms: Atoms, name: str) -> frozenset[Pair]:
    return frozenset((a[0], a[1]) for a in atoms.get(name, ()))


def _chain(start: str, goal: str, edges: dict[Pair, str]) -> list[Pair]:
    """A shortest path of forced edges from ``start`` to ``goal`` (breadth first; a cycle
    when they are the same part)."""
    came: dict[str, Pair] = {}
    queue = deque([start])
    while queue:
        node = queue.popleft()
        for a, b in sorted(edges):
            if a != node or b in came:
                continue
            came[b] = (a, b)
            if b == goal:
                path = [came[b]]
                while path[0][0] != start:
                    path.insert(0, came[path[0][0]])
                return path
            queue.append(b)
    raise AssertionError(f"no forced chain {start} < {goal}")


def _explain_forced(evidence: Evidence, edges: dict[Pair, str], start: str, goal: str) -> str:
    parts = []
    for a, b in _chain(start, goal, edges):
        source = edges[(a, b)]
        reason = evidence.geometry_reasons.get((a, b)) if source == GEOMETRY else None
        parts.append(f"{a}<{b} by {evidence.source_name(source)}" + (f" ({reason})" if reason else ""))
    return "; ".join(parts)


def _check_conflicts(evidence: Evidence, atoms: Atoms, edges: dict[Pair, str]) -> None:
    for (part,) in sorted(atoms.get("cycle", ())):
        raise PrecedenceConflict(f"conflict: the forced pairs chain {part} before itself: "
                                 f"{_explain_forced(evidence, edges, part, part)}")
    for a, b, source in sorted(atoms.get("conflict", ())):
        raise PrecedenceConflict(f"conflict on {a}<{b}: {evidence.source_name(source)} places {b} before "
                                     f"{a}, but {a} must precede {b}: {_explain_forced(evidence, edges, a, b)}")


def tested_step(experiment: PrecedenceExperiment) -> int:
    """The 1-based step placing the pair's second part (the last, or the one before it in
    "B then A")."""
    return len(experiment.sequence) - int(experiment.then_first)


def _check_tested_step(trial: Trial) -> None:
    failed = trial.outcome.failed_step
    tested = tested_step(trial.experiment)
    if failed is not None and failed < tested:
        step = trial.experiment.sequence[failed - 1]
        raise PrecedenceConflict(
            f"{trial.describe()}: step {failed} placing {step.part} failed before the tested step "
            f"{tested}, in an order the evidence showed feasible; expected the known state to be reached")


def broken_order(sequence: Sequence[str], cell_before: Collection[Pair]) -> Pair | None:
    """The first of the cell's orders (P, Q) that placing ``sequence`` in turn breaks (Q
    placed before P), None when it keeps them all."""
    for i, part in enumerate(sequence):
        for placed in sequence[:i]:
            if (part, placed) in cell_before:
                return part, placed
    return None


def decisive(trial: Trial, excluded: frozenset[Pair], parts: Sequence[str],
             cell_before: Collection[Pair] = ()) -> bool:
    """Whether a failure at the tested step (placing the pair's second part) confirms the
    pair: every absent part but its first is excluded from preceding its second, and the
    step breaks none of the cell's orders ``cell_before`` (the fingers meeting a part in
    place explain such a failure). (A failure of the first part's step in "B then A" is
    read by ``precedence/evidence.lp``.)"""
    a, b = trial.experiment.pair
    tested = tested_step(trial.experiment)
    placed = [step.part for step in trial.experiment.sequence[:tested]]
    return (trial.outcome.failed_step == tested and not any((b, q) in cell_before for q in placed[:-1])
            and all((x, b) in excluded for x in parts if x not in placed and x != a))


def know(evidence: Evidence, policy: str | None = None, confirmed: dict[int, Pair] | None = None) -> Knowledge:
    """The knowledge of ``evidence`` and, with a ``policy`` (:data:`POLICIES`), the pair it
    tests next; PrecedenceConflict naming the sources that disagree. ``confirmed``: failed
    trials (by 1-based index) already found decisive on earlier knowledge (it only grows,
    so they stay decisive): the fixpoint starts from them."""
    for trial in evidence.trials:
        _check_tested_step(trial)
        if trial.outcome.pair != trial.experiment.pair:
            raise PlannerError(f"{trial.describe()}: the outcome is for {'<'.join(trial.outcome.pair)}; "
                               "expected the experiment's pair")
    base = evidence.facts()
    confirmed = dict(confirmed or {})
    entry = POLICIES[policy] if policy is not None else "precedence_knowledge.lp"
    while True:
        facts = base + [clingo.Function("forced", [clingo.Function(a), clingo.Function(b),
                                                   clingo.Function("experiment", [clingo.Number(e)])])
                        for e, (a, b) in confirmed.items()]
        atoms = _solve_knowledge(facts, entry)
        confirmed.update({int(e): (a, b) for e, a, b in atoms.get("blocked_first", ())})
        edges = {(a, b): GEOMETRY for a, b in evidence.geometry}
        edges.update({pair: f"experiment({e})" for e, pair in confirmed.items()})
        _check_conflicts(evidence, atoms, edges)
        excluded = _pairs(atoms, "excluded")
        grown = dict(confirmed)
        grown.update({e: trial.experiment.pair for e, trial in enumerate(evidence.trials, 1)
                      if e not in confirmed
                      and decisive(trial, excluded, evidence.parts, evidence.cell_before)})
        if grown == confirmed:
            break
        confirmed = grown
    requires: dict[Pair, list[str]] = {}
    for a, b, x in atoms.get("requires", ()):
        requires.setdefault((a, b), []).append(x)
    candidates = sorted(_pairs(atoms, "candidate"))
    undecided = tuple(t for e, t in enumerate(evidence.trials, 1)
                      if t.outcome.outcome == "failed" and e not in confirmed)
    selected = sorted(_pairs(atoms, "select"))
    return Knowledge(evidence, _pairs(atoms, "known"), excluded, _pairs(atoms, "open"), tuple(candidates),
                     {pair: tuple(requires.get(pair, ())) for pair in _pairs(atoms, "covering")}, confirmed, undecided,
                     tuple(facts), _pairs(atoms, "alone"), _pairs(atoms, "cell_blocked"), _pairs(atoms, "cell_tried"),
                     policy, selected[0] if selected else None)
