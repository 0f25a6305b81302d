"""The next precedence experiment, chosen by ASP, and the exploration loop.

Policies (one encoding each): ``informative`` (``select_precedence_informative.lp``: the
candidate deciding the most open pairs whatever its outcome) and ``first``
(``select_precedence_first.lp``: the first candidate in part order, a systematic
baseline). The experiment on (a, b) places every part that precedes b in the upper bound
except a, in an order of the upper bound and of the cell's own orders together (the first
demonstration's where they allow), then b, then a ("B then A": a precedence the physics
shows only at a's step, once b is in, is seen too), or b alone where the cell's orders
keep a from going in after the parts then in place (:attr:`Knowledge.alone`). No
experiment breaks one of the cell's orders.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence

from asp import PlannerError
from asp.precedence.explore.knowledge import POLICIES, Evidence, Knowledge, Trial, broken_order, decisive, know
from asp.precedence.explore.oracle import Oracle
from asp.precedence.relation import Pair
from bridge.precedence.experiment import ExperimentStep, PrecedenceExperiment


def select_pair(knowledge: Knowledge, policy: str = "informative") -> Pair | None:
    """The pair the policy tests next; None when nothing is open."""
    if policy not in POLICIES:
        raise PlannerError(f"--policy {policy}: expected one of {', '.join(POLICIES)}")
    if not knowledge.candidates:
        return None
    if not knowledge.evidence.demos.sequences:
        raise PlannerError("precedence experiments need at least one demonstration (a feasible order to start "
                           "from); expected a demonstrations file")
    if knowledge.policy != policy:
        knowledge = know(knowledge.evidence, policy, knowledge.confirmed)
    if knowledge.selected is None:
        raise AssertionError(f"{POLICIES[policy]} selected no pair among {len(knowledge.candidates)} candidates")
    return knowledge.selected


def _set_up_order(knowledge: Knowledge, parts: Sequence[str]) -> list[str]:
    """``parts`` (a down-set of the upper bound but the tested pair's first part) in an order
    of the upper bound (known and open pairs) and of the cell's own orders among them, the
    first demonstration's where both leave it free (the candidates' encoding has checked that
    such an order exists)."""
    rank = knowledge.evidence.demos.sequences[0].index
    among = set(parts)
    edges = [(a, b) for a, b in (*knowledge.known, *knowledge.open, *knowledge.evidence.cell_before)
             if a in among and b in among]
    order: list[str] = []
    while among:
        ready = [p for p in among if not any(a in among and b == p for a, b in edges)]
        order.append(min(ready, key=rank))
        among.remove(order[-1])
    return order


def experiment_for(knowledge: Knowledge, pair: Pair, request_id: str) -> PrecedenceExperiment:
    """The experiment testing ``pair`` (a candidate of ``knowledge``): its set-up, then the
    pair's second part, then its first unless :attr:`Knowledge.alone`."""
    a, b = pair
    then = () if pair in knowledge.alone else (a,)
    steps = tuple(ExperimentStep(p) for p in (*_set_up_order(knowledge, knowledge.requires[pair]), b, *then))
    broken = broken_order([step.part for step in steps], knowledge.evidence.cell_before)
    if broken is not None:
        raise AssertionError(f"the experiment on {a}<{b} would place {broken[0]} after {broken[1]}, against the "
                             "cell's own order")
    return PrecedenceExperiment(id=request_id, pair=pair, sequence=steps)


def explore(evidence: Evidence, oracle: Oracle, policy: str = "informative", run_id: str = "explore",
            limit: int | None = None) -> Iterator[tuple[Knowledge, Trial]]:
    """Experiments until nothing is open (or ``limit`` of them): yields the knowledge each
    was chosen from and the trial (experiment and outcome); the last knowledge is
    :func:`know` of the evidence with every trial. PlannerError when the next experiment is
    one that already decided nothing (it would decide nothing again)."""
    knowledge = know(evidence, policy)
    count = 0
    while limit is None or count < limit:
        pair = select_pair(knowledge, policy)
        if pair is None:
            return
        count += 1
        experiment = experiment_for(knowledge, pair, f"{run_id}.{len(evidence.trials) + 1}")
        again = next((t for t in knowledge.undecided if t.experiment.pair == pair
                      and t.experiment.sequence == experiment.sequence), None)
        if again is not None:
            raise PlannerError(f"{again.describe()} decided nothing and would be run again: {pair[0]}<{pair[1]} "
                               "stays open (no experiment of this planner can decide it)")
        trial = Trial(experiment, oracle.run(experiment), "oracle")
        yield knowledge, trial
        evidence = evidence.with_trial(trial)
        confirmed = dict(knowledge.confirmed)
        if decisive(trial, knowledge.excluded, evidence.parts, evidence.cell_before):
            confirmed[len(evidence.trials)] = pair
        knowledge = know(evidence, policy, confirmed)
