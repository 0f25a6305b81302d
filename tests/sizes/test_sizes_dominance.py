"""Policies never worse than ``systematic``: exhaustive search on small sizes, Cranfield."""

from __future__ import annotations

import random

import numpy as np
import pytest

from asp.bench.dominance import (
    Relaxation,
    Search,
    add_answer,
    cranfield_search,
    policy_counts,
    reductions,
    systematic_counts,
)
from asp.sizes.biorders import all_biorders
from tests._sizes_helpers import consistent, experiments_per_truth, known_masks, systematic


@pytest.mark.parametrize("m, n", [(2, 3), (3, 3), (2, 4), (4, 2)])
def test_closure_is_what_every_consistent_biorder_agrees_on(m: int, n: int) -> None:
    biorders, rng = all_biorders(m, n), random.Random(m * 10 + n)
    for _ in range(100):
        truth, possible, fit, no_fit = int(rng.choice(biorders)), biorders, 0, 0
        for bit in rng.sample(range(m * n), m * n):
            if not ((fit | no_fit) >> bit) & 1:
                answer = bool((truth >> bit) & 1)
                fit, no_fit = add_answer(fit, no_fit, m, n, bit, answer)
                possible = consistent(possible, bit, answer)
                assert (fit, no_fit) == known_masks(possible, m * n)


def test_reduction_is_the_least_set_of_answers_entailing_the_truth() -> None:
    m, n = 3, 3
    truths = all_biorders(m, n)
    for truth, reduced in zip(truths.tolist(), reductions(truths, m, n).tolist()):
        bits = [b for b in range(m * n) if (reduced >> b) & 1]
        for left_out in [None, *bits]:
            fit = no_fit = 0
            for bit in bits:
                if bit != left_out:
                    fit, no_fit = add_answer(fit, no_fit, m, n, bit, bool((truth >> bit) & 1))
            assert (fit == truth and no_fit == ~truth & 511) == (left_out is None)


def test_systematic_counts_match_a_replay_over_all_biorders() -> None:
    m, n = 3, 4
    biorders = all_biorders(m, n)
    replayed = experiments_per_truth(m, n, systematic)
    assert systematic_counts(biorders, m, n).tolist() == [replayed[b] for b in biorders.tolist()]


@pytest.mark.parametrize("m, n, systematic_total, unconstrained", [
    (2, 3, 260, 258), (3, 2, 260, 258), (2, 4, 1082, 1070), (3, 3, 1876, 1832),
])
@pytest.mark.slow
def test_no_policy_beats_systematic_without_losing_somewhere(m: int, n: int, systematic_total: int,
                                                             unconstrained: int) -> None:
    """Least total over policies never worse than systematic on any m×n biorder = systematic's."""
    truths = all_biorders(m, n)
    budget = systematic_counts(truths, m, n)
    slack = (budget - np.bitwise_count(reductions(truths, m, n))).tolist()
    never_worse, free = Search(m, n, truths, slack), Search(m, n, truths, [None] * len(truths))
    assert int(budget.sum()) == never_worse.least_total() == systematic_total
    assert free.least_total() == unconstrained
    assert np.array_equal(policy_counts(never_worse), budget)
    assert policy_counts(free).sum() == unconstrained


@pytest.mark.slow
def test_cranfield_alone_does_not_force_systematic() -> None:
    """A policy never worse than systematic on all 900 Cranfield truths, of mean ≤ 18.8.

    Replayed here against all 329 462 5×5 biorders on a sample of the truths.
    """
    search = cranfield_search()
    budget = systematic_counts(search.truths, 5, 5)
    assert budget.sum() == 18480 and budget.max() == 25
    total = search.first_policy()
    counts = policy_counts(search)
    assert counts.sum() == total <= 18.8 * 900 and (counts <= budget).all() and counts.max() <= 21
    biorders, reduced = all_biorders(5, 5), reductions(search.truths, 5, 5)
    for i in range(0, 900, 45):
        truth, possible, alive, asked = int(search.truths[i]), biorders, search.root().alive, 0
        while len(possible) > 1:
            fit, no_fit = known_masks(possible, 25)
            if alive & (alive - 1):
                bit = search.choice[(fit, no_fit, asked)]
            else:
                bit = next(b for b in range(25) if (int(reduced[i]) >> b) & 1 and not ((fit | no_fit) >> b) & 1)
            answer = bool((truth >> bit) & 1)
            assert 0 < len(consistent(possible, bit, answer)) < len(possible), "asked an entailed pair"
            possible = consistent(possible, bit, answer)
            alive &= search.fit_sets[bit] if answer else ~search.fit_sets[bit]
            asked += 1
        assert asked == counts[i]


def test_relaxation_over_all_biorders_bounds_the_counted_total() -> None:
    """All counted: systematic's total (Pareto-minimal); some counted: a bound ≤ theirs."""
    m, n = 3, 3
    truths = all_biorders(m, n)
    budget = systematic_counts(truths, m, n)
    slack = budget - np.bitwise_count(reductions(truths, m, n))
    assert Relaxation(m, n, slack, np.ones(len(truths), dtype=bool)).least_total(10**6) == budget.sum()
    counted = np.arange(len(truths)) % 3 == 0
    bound = Relaxation(m, n, slack, counted).least_total(10**6)
    assert np.bitwise_count(reductions(truths[counted], m, n)).sum() < bound <= budget[counted].sum()
