"""Who answers a precedence experiment: an :class:`Oracle`. The :class:`TruthOracle`
answers from a product's known relation (figures, tests); a cell answers over the bridge
(``cell/<id>/precedence``) with the same outcome type."""

from __future__ import annotations

from typing import Protocol

from asp.precedence.relation import Relation
from bridge.precedence.experiment import PrecedenceExperiment, PrecedenceOutcome, first_missing


class Oracle(Protocol):
    """Runs a precedence experiment and reports its outcome."""

    def run(self, experiment: PrecedenceExperiment) -> PrecedenceOutcome: ...


class TruthOracle:
    """Answers from ``truth`` (closed) as a ``truth`` cell does: a step fails, ``precedence``,
    when a part that must precede its part is not yet placed
    (:func:`bridge.precedence.experiment.first_missing`); nothing is ever ``blocked_by`` a
    part. It spends no physics time."""

    def __init__(self, truth: Relation, cell: str = "truth") -> None:
        self.truth = truth
        self.cell = cell
        self._before = {p: {truth.parts[i] for i in truth.matrix[:, j].nonzero()[0]}
                        for j, p in enumerate(truth.parts)}

    def run(self, experiment: PrecedenceExperiment) -> PrecedenceOutcome:
        first = first_missing(experiment, self._before)
        if first is None:
            return PrecedenceOutcome(id=experiment.id, cell=self.cell, pair=experiment.pair, outcome="success")
        number, part, missing = first
        return PrecedenceOutcome(id=experiment.id, cell=self.cell, pair=experiment.pair, outcome="failed",
                                 failed_step=number, reason="precedence",
                                 detail=f"{part} precedence (without {' '.join(missing)}; the known relation)")
