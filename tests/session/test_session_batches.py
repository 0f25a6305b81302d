"""Parallel experiments of the size learner: batches ordered by the policy, never wasted.

- k cells simulated in process (truth oracle, Cranfield and seeded relabelings), each
  finished experiment drawn at random among the running ones: every started pair is
  independent of every pair still running (all outcome combinations are possible
  biorders: checked by enumeration, not by the learner's ASP check), nothing is asked
  twice or asked while entailed, the relation learned is the truth, and ``best`` needs
  at most BEST_TWO_CELLS experiments with two cells (one cell: 19 on Cranfield); a real
  two-cell session on loopback keeps the same bound (``tests/session/test_session_cells.py``).
"""

from __future__ import annotations

import itertools
import json
import random

import pytest

from asp.bench.sizes import parallel_learning
from asp.sizes.best import knowledge_masks
from asp.sizes.biorders import all_biorders, consistent_index
from asp.sizes.knowledge import Knowledge, Pair
from asp.sizes.learner import SizeLearner
from asp.sizes.truth_oracle import TruthOracle

TRUTH = TruthOracle.from_assembly("cranfield")
BEST_TWO_CELLS = 21
"""Most experiments ``best`` needs on Cranfield with two cells (``./run.sh bench sizes --cells 2
--policies best --seeds 100``: 17-21 over relabelings and completion orders)."""


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
    """Learn with ``cells`` simulated cells (:func:`asp.bench.sizes.parallel_learning`);
    returns the number of experiments, asserting every batch is independent of what runs."""
    asked: list[Pair] = []

    def check(learner: SizeLearner, batch: list[Pair], running: list[Pair]) -> None:
        assert all(learner.knowledge.result(*pair) is None for pair in batch)
        assert not set(batch) & set(asked)
        asked.extend(batch)
        assert independent(learner.knowledge, running), running

    learner, count = parallel_learning(parts, holes, TRUTH, cells, policy, seed, together, watch=check)
    assert learner.knowledge.fits == TRUTH.fits and count == len(asked)
    return count


def relabelings(count: int) -> list[tuple[list[str], list[str]]]:
    """Cranfield in its own order, then ``count`` seeded random orders of parts and holes."""
    rng = random.Random(5)
    orders = [(list(TRUTH.parts), list(TRUTH.holes))]
    for _ in range(count):
        orders.append((rng.sample(TRUTH.parts, len(TRUTH.parts)), rng.sample(TRUTH.holes, len(TRUTH.holes))))
    return orders


@pytest.mark.slow
def test_two_cells_with_best_need_few_experiments_and_never_waste_one() -> None:
    """The bound over many relabelings and completion orders is measured by ``./run.sh bench
    sizes --cells 2 --policies best`` (docs/results/session.md)."""
    counts = [parallel_session(parts, holes, 2, "best", seed) for seed, (parts, holes) in enumerate(relabelings(2))]
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


def test_bench_sizes_counts_the_experiments_of_sessions_with_k_cells(run_main) -> None:
    """``bench sizes --cells K``: sessions on Cranfield relabelings, each learned right (a
    wrong relation is an error), their experiments counted."""
    done = run_main("bench", "sizes", "--cells", "2", "--policies", "best,systematic", "--seeds", "2", "--json")
    assert done.returncode == 0, done.stderr
    rows = json.loads(done.stdout)["parallel"]
    assert [(r["policy"], r["cells"], r["sessions"]) for r in rows] == [("best", 2, 2), ("systematic", 2, 2)]
    assert all(0 < r["min"] <= r["median"] <= r["max"] <= 25 for r in rows)
    assert rows[0]["max"] <= BEST_TWO_CELLS
