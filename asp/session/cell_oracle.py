"""The session's cells as the oracle of precedence experiments: each experiment the planner
chooses (:class:`bridge.precedence.experiment.PrecedenceExperiment`, its steps without
holes) goes to a cell over Zenoh (``cell/<id>/precedence``), with the holes of the
session's assignment, and the cell's outcome comes back.

With ``by_hand`` (the default) the steps before the tested one, an order the planner
knows feasible, are not assembled: the cell sets those parts at their goals by hand (the
experiment's ``placed``) and assembles only the tested step, so an experiment costs one
step of physics; the outcome is returned numbered as for the whole sequence. A known state
that does not hold at the cell (a part set there does not stay) is a PlannerError naming
the cell's words: the planner believed that order feasible, so it is a conflict, never
read as evidence on the pair. A lost reply is sent again under the same id (the cell
answers it from its cache, never running it twice).
"""

from __future__ import annotations

from collections.abc import Mapping

import msgspec
import zenoh

from asp import PlannerError
from bridge import BridgeError
from bridge.client import CellRefused, CellTimeout, request_experiment
from bridge.precedence.experiment import ExperimentStep, PrecedenceExperiment, PrecedenceOutcome

SEND_ATTEMPTS = 3
"""An experiment whose reply is lost is sent this many times in all."""


class CellOracle:
    """Runs precedence experiments at cell ``cell`` of ``session``: pegs go into the holes of
    ``holes`` (part → hole), each experiment waits at most ``timeout_s`` [s] per send;
    ``seed`` seeds the cell's random errors. ``sim_s`` and ``wall_s`` add up what the cell
    reported spending [s]."""

    def __init__(self, session: zenoh.Session, cell: str, holes: Mapping[str, str], *, seed: int = 0,
                 timeout_s: float = 300.0, by_hand: bool = True) -> None:
        self.session, self.cell, self.holes = session, cell, dict(holes)
        self.seed, self.timeout_s, self.by_hand = seed, timeout_s, by_hand
        self.sim_s = 0.0
        self.wall_s = 0.0
        self.outcomes: list[PrecedenceOutcome] = []

    def sent(self, experiment: PrecedenceExperiment) -> PrecedenceExperiment:
        """What goes to the cell for ``experiment``: every step with its hole, the steps before
        the tested one as ``placed`` when ``by_hand``."""
        steps = tuple(ExperimentStep(s.part, s.hole or self.holes.get(s.part)) for s in experiment.sequence)
        placed = tuple(ExperimentStep(s.part, s.hole or self.holes.get(s.part)) for s in experiment.placed)
        if self.by_hand:
            placed, steps = placed + steps[:-1], steps[-1:]
        return msgspec.structs.replace(experiment, sequence=steps, placed=placed, seed=self.seed,
                                       timeout_s=self.timeout_s)

    def run(self, experiment: PrecedenceExperiment) -> PrecedenceOutcome:
        """The cell's outcome of ``experiment``, its failed step numbered in ``experiment.sequence``."""
        sent = self.sent(experiment)
        for attempt in range(1, SEND_ATTEMPTS + 1):
            try:
                outcome = request_experiment(self.session, self.cell, sent, self.timeout_s)
                break
            except CellTimeout as exc:
                if attempt == SEND_ATTEMPTS:
                    raise PlannerError(f"experiment {experiment.id} ({experiment.tested}): {exc}; gave up after "
                                       f"{attempt} sends") from None
            except CellRefused as exc:
                known_state = " (the known state, an order the evidence showed feasible)" \
                    if exc.reply.code == "invalid_step" else ""
                raise PlannerError(f"experiment {experiment.id} ({experiment.tested}){known_state}: {exc}") from None
            except BridgeError as exc:
                raise PlannerError(f"experiment {experiment.id} ({experiment.tested}): {exc}") from None
        self.sim_s += outcome.sim_s
        self.wall_s += outcome.wall_s
        if outcome.failed_step is not None:
            skipped = len(experiment.sequence) - len(sent.sequence)
            outcome = msgspec.structs.replace(outcome, failed_step=outcome.failed_step + skipped)
        self.outcomes.append(outcome)
        return outcome
