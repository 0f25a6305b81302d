"""Who answers a precedence experiment: an :class:`Oracle`. The :class:`TruthOracle`
answers from a product's known relation (figures, tests); a cell answers over the bridge
(``cell/<id>/precedence``) with the same outcome type."""

from __future__ import annotations

from typing import Protocol

from asp.precedence.relation import Relation
from bridge.precedence.experiment import PrecedenceExperiment, PrecedenceOutcome


class Oracle(Protocol):
    """Runs a precedence experiment and reports its outcome."""

    def run(self, experiment: PrecedenceExperiment) -> PrecedenceOutcome: ...


class TruthOracle:
    """Answers from ``truth`` (closed): a step fails, ``blocked``, when a part that must
    precede its part is not yet placed. It spends no physics time."""

    def __init__(self, truth: Relation, cell: str = "truth") -> None:
        self.truth = truth
        self.cell = cell
        self._before = {p: {truth.parts[i] for i in truth.matrix[:, j].nonzero()[0]}
                        for j, p in enumerate(truth.parts)}

    def run(self, experiment: PrecedenceExperiment) -> PrecedenceOutcome:
        placed: set[str] = set()
        for number, step in enumerate(experiment.sequence, 1):
            missing = sorted(self._before[step.part] - placed)
            if missing:
                return PrecedenceOutcome(id=experiment.id, cell=self.cell, pair=experiment.pair, outcome="failed",
                                         failed_step=number, reason="blocked",
                                         detail=f"{step.part} needs {' '.join(missing)} placed first")
            placed.add(step.part)
        return PrecedenceOutcome(id=experiment.id, cell=self.cell, pair=experiment.pair, outcome="success")
