"""The ``best`` policy: ASP and numpy paths agree; it learns any biorder, never asking a known pair."""

from __future__ import annotations

import itertools

import numpy as np
from hypothesis import example, given, settings
from hypothesis import strategies as st

from asp.sizes.best import batch_rank, choose, choose_bit, knowledge_masks, split_weights
from asp.sizes.biorders import all_biorders, consistent_index
from asp.sizes.learner import SizeLearner
from asp.sizes.policies import get_policy
from tests._best_reference import choose_by_asp, possible_relations_asp
from tests.sizes.test_best_biorders import biorder_truths, closure_after


@settings(max_examples=20, deadline=None)
@given(truth=biorder_truths(3), data=st.data())
def test_asp_path_enumerates_the_same_relations_and_chooses_the_same_pair(
    truth: np.ndarray, data: st.DataObject
) -> None:
    m, n = truth.shape
    observed = data.draw(st.lists(st.integers(0, m * n - 1), max_size=m * n // 2))
    knowledge = closure_after(truth, observed).knowledge
    if not knowledge.unknown:
        return
    masks, weights = possible_relations_asp(knowledge)
    everything = all_biorders(m, n)
    assert masks.tolist() == everything[consistent_index(everything, *knowledge_masks(knowledge))].tolist()
    assert weights.min() >= 1.0
    assert choose_by_asp(knowledge) == choose(knowledge, None)


def run_best(truth: np.ndarray) -> tuple[SizeLearner, int]:
    """Learn ``truth`` with ``best``; assert every proposed pair was unknown when proposed."""
    m, n = truth.shape
    learner = SizeLearner([f"q{i}" for i in range(m)], [f"k{j}" for j in range(n)], "best")
    while (pair := learner.next_experiment()) is not None:
        assert pair in learner.knowledge.unknown, f"{pair} was already entailed"
        p, h = learner.parts.index(pair[0]), learner.holes.index(pair[1])
        learner.record(*pair, "fit" if truth[p, h] else "no_fit")
    return learner, len(learner.experiments)


@settings(max_examples=4, deadline=None)
@given(truth=biorder_truths(8))
@example(truth=np.arange(8)[:, None] % 3 < np.arange(8)[None, :] % 4)
def test_best_learns_the_exact_relation_of_random_biorders(truth: np.ndarray) -> None:
    learner, count = run_best(truth)
    m, n = truth.shape
    learned = {(learner.parts.index(p), learner.holes.index(h)) for p, h in learner.knowledge.fits}
    assert learned == set(zip(*np.nonzero(truth)))
    assert count <= m * n


def test_registry_entry_resolves_to_the_best_policy() -> None:
    policy = get_policy("best")
    assert policy.name == "best" and policy.choose is choose and policy.deterministic


def test_sampled_path_is_deterministic_and_picks_an_unknown_pair_at_20x20() -> None:
    """Large instances: same knowledge, same choice (seeded by the knowledge), never a known pair."""
    m = n = 20
    truth = np.arange(m)[:, None] % 7 < np.arange(n)[None, :] % 5
    learner = closure_after(truth, [0, 21, 42, 63, 84, 105, 399, 210])
    fit, no_fit = knowledge_masks(learner.knowledge)
    first = choose_bit.__wrapped__(m, n, fit, no_fit)
    assert first == choose_bit.__wrapped__(m, n, fit, no_fit)
    assert not ((fit | no_fit) >> first) & 1


@settings(max_examples=20, deadline=None)
@given(truth=biorder_truths(4), data=st.data())
def test_batch_rank_is_the_lighter_outcome_summed_over_every_outcome_of_the_pending_pairs(
    truth: np.ndarray, data: st.DataObject
) -> None:
    """The grouped one-pass ranking equals the sum over all 2^k outcome combinations of the
    k pending pairs, each split computed on its own (the definition)."""
    m, n = truth.shape
    observed = data.draw(st.lists(st.integers(0, m * n - 1), max_size=m * n // 3))
    knowledge = closure_after(truth, observed).knowledge
    unknown = knowledge.unknown
    pending = data.draw(st.lists(st.sampled_from(unknown), unique=True, max_size=3)) if unknown else []
    index = {(p, h): i * n + j for i, p in enumerate(knowledge.parts) for j, h in enumerate(knowledge.holes)}
    fit_mask, no_fit_mask = knowledge_masks(knowledge)
    bits = [1 << index[pair] for pair in pending]
    score = np.zeros(m * n)
    for outcomes in itertools.product((True, False), repeat=len(bits)):
        fits = sum(bit for bit, fit in zip(bits, outcomes) if fit)
        fit_weight, total = split_weights(m, n, fit_mask | fits, no_fit_mask | (sum(bits) - fits))
        score += np.minimum(fit_weight, total - fit_weight)
    expected = sorted((pair for pair in unknown if pair not in pending), key=lambda p: (-score[index[p]], index[p]))
    assert batch_rank(knowledge, pending) == expected
