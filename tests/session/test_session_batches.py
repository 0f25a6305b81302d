"""Parallel experiments of the size learner: batches ordered by the policy, never wasted.

- k cells simulated in process (truth oracle, Cranfield and seeded relabelings), each
  finished experiment drawn at random among the running ones: every started pair is
  independent of every pair still running (all outcome combinations are possible
  biorders: checked by enumeration, not by the learner's ASP check), nothing is asked
  twice or asked while entailed, the relation learned is the truth, and ``best`` needs
  at most BEST_TWO_CELLS experiments with two cells (one cell: 19 on Cranfield);
- a real two-cell session on loopback (truth backend, fast): the same bound.
"""

from __future__ import annotations

import itertools
import random

import pytest

from asp.sizes.best import knowledge_masks
from asp.sizes.biorders import all_biorders, consistent_index
from asp.sizes.knowledge import Knowledge, Pair
from asp.sizes.learner import SizeLearner
from asp.sizes.truth_oracle import TruthOracle

TRUTH = TruthOracle.from_assembly("cranfield")
BEST_TWO_CELLS = 21
"""Most experiments ``best`` needs on Cranfield with two cells (measured: 18-21 over completion orders)."""


def independent(knowledge: Knowledge, pairs: list[Pair]) -> bool:
    """Every combination of outcomes of ``pairs`` is a possible Cranfield-sized biorder."""
    n = len(knowledge.holes)
    bits = [1 << (knowledge.parts.index(p) * n + knowledge.holes.index(h)) for p, h in pairs]
    fit_mask, no_fit_mask = knowledge_masks(knowledge)
    masks = all_biorders(len(knowledge.parts), n)
    for outcomes in itertools.product((True, False), repeat=len(bits)):
        fits = sum(bit for bit, fit in zip(bits, outcomes) if fit)
        if len(consistent_index(masks, fit_mask | fits, no_fit_mask | (sum(bits) - fits))) == 0:
            return False
    return True


def parallel_session(parts: list[str], holes: list[str], cells: int, policy: str, seed: int,
                     together: bool = False) -> int:
    """Learn with ``cells`` simulated cells finishing in a seeded random order; returns
    the number of experiments, asserting every batch is independent of what runs.
    ``together``: a random number of the running experiments finish at once and are
    recorded with one solve (``record_all``), as a session takes them."""
    learner = SizeLearner(parts, holes, policy)
    rng = random.Random(seed)
    running: list[Pair] = []
    asked: list[Pair] = []
    while True:
        batch = learner.next_batch(cells - len(running), pending=running)
        assert all(learner.knowledge.result(*pair) is None for pair in batch)
        assert not set(batch) & set(asked)
        running += batch
        asked += batch
        if not running:
            break
        assert independent(learner.knowledge, running), running
        if together:
            rng.shuffle(running)
            count = rng.randint(1, len(running))
            finished, running = running[:count], running[count:]
            learner.record_all([(*pair, TRUTH.ask(*pair)) for pair in finished])
        else:
            pair = running.pop(rng.randrange(len(running)))
            learner.record(*pair, TRUTH.ask(*pair))
    assert learner.knowledge.fits == TRUTH.fits
    return len(asked)


def relabelings(count: int) -> list[tuple[list[str], list[str]]]:
    """Cranfield in its own order, then ``count`` seeded random orders of parts and holes."""
    rng = random.Random(5)
    orders = [(list(TRUTH.parts), list(TRUTH.holes))]
    for _ in range(count):
        orders.append((rng.sample(TRUTH.parts, len(TRUTH.parts)), rng.sample(TRUTH.holes, len(TRUTH.holes))))
    return orders


@pytest.mark.parametrize("seed", range(3))
@pytest.mark.slow
def test_two_cells_with_best_need_few_experiments_and_never_waste_one(seed: int) -> None:
    counts = [parallel_session(parts, holes, 2, "best", seed) for parts, holes in relabelings(8)]
    assert max(counts) <= BEST_TWO_CELLS, counts


@pytest.mark.parametrize("policy", ["systematic", pytest.param("heuristic", marks=pytest.mark.slow),
                                    pytest.param("best", marks=pytest.mark.slow)])
def test_three_cells_keep_batches_independent_for_every_policy(policy: str) -> None:
    for parts, holes in relabelings(2):
        assert parallel_session(parts, holes, 3, policy, seed=1) <= 25


@pytest.mark.parametrize("policy", ["systematic", pytest.param("best", marks=pytest.mark.slow)])
def test_experiments_that_finish_together_are_recorded_at_once_and_batches_stay_independent(policy: str) -> None:
    counts = [parallel_session(parts, holes, 4, policy, seed, together=True)
              for seed, (parts, holes) in enumerate(relabelings(2))]
    assert max(counts) <= 25, counts


@pytest.mark.timeout(90)
@pytest.mark.slow
def test_a_two_cell_session_needs_no_more_experiments_than_measured(tmp_path, run_session) -> None:
    result = run_session("--cells", "2", "--out", str(tmp_path / "run"))
    assert result["matches_truth"] is True
    assert result["experiments"] <= BEST_TWO_CELLS
