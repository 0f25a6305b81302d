"""The next precedence experiment, chosen by ASP, and the exploration loop.

Policies (one encoding each): ``informative`` (``select_precedence_informative.lp``: the
candidate deciding the most open pairs whatever its outcome) and ``first``
(``select_precedence_first.lp``: the first candidate in part order, a systematic
baseline). The experiment on (a, b) places every part that precedes b in the upper bound
except a, in the order of the first demonstration (a linear extension of the upper
bound), then b.
"""

from __future__ import annotations

from collections.abc import Iterator

import clingo

from asp import PlannerError
from asp.precedence.explore.knowledge import Evidence, Knowledge, Trial, know
from asp.precedence.explore.oracle import Oracle
from asp.precedence.relation import Pair
from asp.solve import solve
from bridge.precedence.experiment import ExperimentStep, PrecedenceExperiment

POLICIES = {"informative": "select_precedence_informative.lp", "first": "select_precedence_first.lp"}


def select_pair(knowledge: Knowledge, policy: str = "informative") -> Pair | None:
    """The pair the policy tests next; None when nothing is open."""
    if policy not in POLICIES:
        raise PlannerError(f"--policy {policy}: expected one of {', '.join(POLICIES)}")
    if not knowledge.candidates:
        return None
    if not knowledge.evidence.demos.sequences:
        raise PlannerError("precedence experiments need at least one demonstration (a feasible order to start "
                           "from); expected a demonstrations file")
    chosen: list[Pair] = []

    def on_model(model: clingo.Model) -> None:
        chosen[:] = [(str(s.arguments[0]), str(s.arguments[1])) for s in model.symbols(shown=True)
                     if s.name == "select"]

    solve([POLICIES[policy]], knowledge.facts, ["--opt-mode=opt"], on_model)
    if len(chosen) != 1:
        raise AssertionError(f"{POLICIES[policy]} selected {chosen}; expected one pair")
    return chosen[0]


def experiment_for(knowledge: Knowledge, pair: Pair, request_id: str) -> PrecedenceExperiment:
    """The experiment testing ``pair`` (a candidate of ``knowledge``)."""
    first_demo = knowledge.evidence.demos.sequences[0]
    before = sorted(knowledge.requires[pair], key=first_demo.index)
    steps = tuple(ExperimentStep(p) for p in (*before, pair[1]))
    return PrecedenceExperiment(id=request_id, pair=pair, sequence=steps)


def explore(evidence: Evidence, oracle: Oracle, policy: str = "informative", run_id: str = "explore",
            limit: int | None = None) -> Iterator[tuple[Knowledge, Trial]]:
    """Experiments until nothing is open (or ``limit`` of them): yields the knowledge each
    was chosen from and the trial (experiment and outcome); the last knowledge is
    :func:`know` of the evidence with every trial."""
    knowledge = know(evidence)
    count = 0
    while limit is None or count < limit:
        pair = select_pair(knowledge, policy)
        if pair is None:
            return
        count += 1
        experiment = experiment_for(knowledge, pair, f"{run_id}.{len(evidence.trials) + 1}")
        trial = Trial(experiment, oracle.run(experiment), "oracle")
        yield knowledge, trial
        evidence = evidence.with_trial(trial)
        knowledge = know(evidence)
