"""Precedence by exploration in a session (``session --precedence explore``,
:func:`explore_precedence`), and the session's cells as the oracle of its precedence
experiments (:class:`CellOracle`): each experiment the planner
chooses (:class:`bridge.precedence.experiment.PrecedenceExperiment`, its steps without
holes) goes to a cell over Zenoh (``cell/<id>/precedence``), with the holes of the
session's assignment, and the cell's outcome comes back.

With ``by_hand`` (the default) the steps before the tested one, an order the planner
knows feasible, are not assembled: the cell sets those parts at their goals by hand (the
experiment's ``placed``) and assembles only the tested step, so an experiment costs one
step of physics (two in "B then A", the planner's experiments,
:func:`asp.precedence.explore.select.experiment_for`); the outcome is returned numbered as
for the whole sequence. A known state
that does not hold at the cell (a part set there does not stay) is a PlannerError naming
the cell's words: the planner believed that order feasible, so it is a conflict, never
read as evidence on the pair. A lost reply is sent again under the same id (the cell
answers it from its cache, never running it twice).
"""

from __future__ import annotations

import logging
import random
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import msgspec
import zenoh

from asp import PlannerError
from asp.precedence.count import UniformSampler
from asp.precedence.demos import Demonstrations
from asp.precedence.explore.knowledge import Evidence, Trial
from asp.precedence.explore.learner import Learned, geometric_reasons, learn_sources
from asp.precedence.explore.select import explore
from asp.precedence.explore.trials import load_trials, write_trials
from asp.precedence.relation import Pair, Relation, load_relation
from bridge import BridgeError
from bridge.client import CellRefused, CellTimeout, request_experiment
from bridge.precedence.experiment import ExperimentStep, PrecedenceExperiment, PrecedenceOutcome

LOG = logging.getLogger(__name__)
PRECEDENCE_JOURNAL = "precedence_experiments.lp"
"""``RUN/precedence_experiments.lp``: every precedence experiment of a session and its
outcome (:mod:`asp.precedence.explore.trials`), rewritten whole (atomically) after each."""
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

    def sent(self, experiment: PrecedenceExperiment) -> PrecedenceExperiment:
        """What goes to the cell for ``experiment``: every step with its hole, the steps before
        the tested one as ``placed`` when ``by_hand``."""
        steps = tuple(ExperimentStep(s.part, s.hole or self.holes.get(s.part)) for s in experiment.sequence)
        placed = tuple(ExperimentStep(s.part, s.hole or self.holes.get(s.part)) for s in experiment.placed)
        if self.by_hand:
            kept = 1 + int(experiment.then_first)
            placed, steps = placed + steps[:-kept], steps[-kept:]
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
        if outcome.outcome == "success" or outcome.failed_step is None:
            return outcome
        skipped = len(experiment.sequence) - len(sent.sequence)
        return msgspec.structs.replace(outcome, failed_step=outcome.failed_step + skipped)


MAX_DEMOS = 2
"""``session --precedence explore`` learns from at most this many demonstrations."""


def explore_demos(demos: Demonstrations, truth: Relation | None, seed: int) -> Demonstrations:
    """The demonstrations an exploring session starts from: the first :data:`MAX_DEMOS` of
    ``demos``; without any, :data:`MAX_DEMOS` drawn uniformly among the sequences ``truth``
    admits (a simulated teacher, seeded by ``seed``); PlannerError when there is neither."""
    if demos.sequences:
        keep = min(MAX_DEMOS, len(demos.sequences))
        return Demonstrations(demos.parts, demos.sequences[:keep], demos.origins[:keep], demos.holes[:keep])
    if truth is None:
        raise PlannerError("--precedence explore: the product has no demonstrations and no precedence.lp to "
                           "generate them from; expected a demos.txt or --demos FILE")
    sampler, rng = UniformSampler(truth), random.Random(seed)
    sequences = tuple(sampler.sample(rng) for _ in range(MAX_DEMOS))
    return Demonstrations(truth.parts, sequences, tuple(f"generated demonstration {k} (seed {seed})"
                                                        for k in range(1, MAX_DEMOS + 1)))


@dataclass(frozen=True)
class ExploredPrecedence:
    """What an exploring session learned (``learned``: the relation, each pair's support, the
    process constraints, :func:`asp.precedence.explore.learner.learn_sources`), the
    experiments' ``trials``, and the cell's ``sim_s`` and ``wall_s`` [s]."""

    learned: Learned
    trials: tuple[Trial, ...]
    sim_s: float
    wall_s: float

    def summary(self) -> dict[str, Any]:
        """What ``session.json`` keeps: ``experiments``, ``sim_s`` and ``wall_s`` [s], ``rests_on``
        (the learner's summary lines: the pairs by support), ``process`` (pairs), ``undecidable``
        (``[a, b, why]``: the pairs the cell's own orders leave undecidable)."""
        return {"experiments": len(self.trials), "sim_s": round(self.sim_s, 3), "wall_s": round(self.wall_s, 3),
                "rests_on": self.learned.summary().splitlines(), "process": [list(p) for p in self.learned.process],
                "undecidable": [[a, b, why] for (a, b), why in self.learned.cell_undecided]}


def explore_precedence(demos: Demonstrations, prior: Path | None, oracle: CellOracle,
                       policy: str = "informative", run_id: str = "explore",
                       journal: Path | None = None, cell_before: tuple[Pair, ...] = ()) -> ExploredPrecedence:
    """Learn the must-precede relation from ``demos``, the geometric precedence in ``prior``
    (None: no CAD) and the experiments the ASP ``policy`` chooses, run by ``oracle``
    (:func:`asp.precedence.explore.select.explore`), every one keeping the cell's own orders
    ``cell_before`` (the product's ``cell_order.lp``), until no pair is open but those these
    orders leave undecidable (reported, :attr:`asp.precedence.explore.learner.Learned.cell_undecided`);
    PlannerError when another is left open, PrecedenceConflict where the sources disagree. ``journal`` (a
    :data:`PRECEDENCE_JOURNAL`): the experiments it holds are evidence and never run again
    (a resumed session), and every new one is written there before it is learned from;
    ``sim_s`` and ``wall_s`` count this call's experiments only."""
    geometry = () if prior is None else tuple(load_relation([prior], data=True).pairs())
    evidence = Evidence(demos, geometry, str(prior or "the geometric precedence"),
                        geometric_reasons(None if prior is None else str(prior)), cell_before=cell_before)
    if journal is not None and journal.is_file():
        for trial in load_trials(journal, demos.parts):
            evidence = evidence.with_trial(trial)
        LOG.info("resumed: %d precedence experiment(s) from %s", len(evidence.trials), journal)
    for number, (_, trial) in enumerate(explore(evidence, oracle, policy, run_id), start=len(evidence.trials) + 1):
        LOG.info("precedence experiment %d on %s: %s; %.1f s simulated", number, oracle.cell, trial.describe(),
                 trial.outcome.sim_s)
        if journal is not None:
            write_trials(journal, (*evidence.trials, trial))
        evidence = evidence.with_trial(trial)
    learned = learn_sources(evidence)
    left = learned.knowledge.open - {pair for pair, _ in learned.cell_undecided}
    if left:
        raise PlannerError(f"precedence exploration ended with {len(left)} pair(s) open: "
                           f"{' '.join(f'{a}<{b}' for a, b in sorted(left))}")
    return ExploredPrecedence(learned, evidence.trials, oracle.sim_s, oracle.wall_s)
