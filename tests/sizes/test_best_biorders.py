"""Biorder enumeration, weights and sampling behind the ``best`` policy (asp/sizes/biorders.py)."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from asp.sizes.best import smaller_matrix
from asp.sizes.biorders import (
    all_biorder_orders,
    all_biorders,
    biorder_count,
    class_weights,
    consistent_index,
    mask_bits,
    sample_biorders,
    weighted_bit_sums,
)
from asp.sizes.learner import SizeLearner


def is_ferrers(fits: np.ndarray) -> bool:
    """Rows (sets of holes a part fits) form a chain under inclusion."""
    rows = [set(np.flatnonzero(r)) for r in fits]
    return all(a <= b or b <= a for a, b in itertools.combinations(rows, 2))


def as_matrices(masks: np.ndarray, m: int, n: int) -> np.ndarray:
    return mask_bits(masks, m * n).reshape(len(masks), m, n)


@pytest.mark.parametrize("m,n", [(1, 1), (2, 3), (3, 2), (3, 3), (2, 4)])
def test_enumeration_is_exactly_the_ferrers_relations(m: int, n: int) -> None:
    """Brute force over all 2^(m·n) relations finds the same set."""
    brute = [
        sum(1 << i for i, bit in enumerate(bits) if bit)
        for bits in itertools.product((0, 1), repeat=m * n)
        if is_ferrers(np.array(bits, dtype=bool).reshape(m, n))
    ]
    assert sorted(brute) == all_biorders(m, n).tolist()


@pytest.mark.parametrize("m,n", [(4, 4), (3, 5), (5, 3), (2, 6), (4, 5)])
def test_enumeration_count_is_poly_bernoulli_and_duplicate_free(m: int, n: int) -> None:
    masks = all_biorders(m, n)
    assert len(masks) == biorder_count(m, n) == len(np.unique(masks))
    assert all(is_ferrers(f) for f in as_matrices(masks[:: max(1, len(masks) // 300)], m, n))


@pytest.mark.parametrize("m,n", [(2, 2), (3, 4), (4, 4)])
def test_class_weights_count_the_orders_of_the_size_line(m: int, n: int) -> None:
    """Every order of the m+n items induces exactly one biorder."""
    masks = all_biorders(m, n)
    weights = class_weights(as_matrices(masks, m, n))
    assert weights.sum() == pytest.approx(math.factorial(m + n))
    assert np.allclose(all_biorder_orders(m, n), weights)


def test_weighted_bit_sums_equal_the_sums_over_expanded_bits() -> None:
    masks = all_biorders(4, 5)
    weights = np.rint(1000 * np.sqrt(all_biorder_orders(4, 5)))
    assert np.array_equal(weighted_bit_sums(masks, weights, 20), weights @ mask_bits(masks, 20))


def biorder_truths(max_side: int) -> st.SearchStrategy[np.ndarray]:
    """Random biorders with ties: integer sizes, a part fits a hole iff strictly smaller."""

    @st.composite
    def build(draw: st.DrawFn) -> np.ndarray:
        m = draw(st.integers(1, max_side))
        n = draw(st.integers(1, max_side))
        levels = draw(st.integers(1, m + n))
        parts = draw(st.lists(st.integers(0, levels), min_size=m, max_size=m))
        holes = draw(st.lists(st.integers(0, levels), min_size=n, max_size=n))
        return np.array(parts)[:, None] < np.array(holes)[None, :]

    return build()


def closure_after(truth: np.ndarray, observed: list[int]) -> SizeLearner:
    """A learner (ASP closure) that has seen the truth's answers for the flat pairs ``observed``."""
    m, n = truth.shape
    learner = SizeLearner([f"q{i}" for i in range(m)], [f"k{j}" for j in range(n)])
    for flat in observed:
        p, h = divmod(flat, n)
        pair = (learner.parts[p], learner.holes[h])
        if learner.knowledge.result(*pair) is None:
            learner.record(*pair, "fit" if truth[p, h] else "no_fit")
    return learner


@settings(max_examples=25, deadline=None)
@given(truth=biorder_truths(4), data=st.data())
def test_closure_entails_exactly_what_all_possible_biorders_agree_on(truth: np.ndarray, data: st.DataObject) -> None:
    """The closure (eqs. 2-5) is complete for biorders: unknown ⇔ the possible relations disagree."""
    m, n = truth.shape
    observed = data.draw(st.lists(st.integers(0, m * n - 1), max_size=m * n))
    knowledge = closure_after(truth, observed).knowledge
    masks = all_biorders(m, n)
    fit = sum(1 << (knowledge.parts.index(p) * n + knowledge.holes.index(h)) for p, h in knowledge.fits)
    no_fit = sum(1 << (knowledge.parts.index(p) * n + knowledge.holes.index(h)) for p, h in knowledge.no_fit)
    possible = as_matrices(masks[consistent_index(masks, fit, no_fit)], m, n)
    undecided = possible.any(axis=0) & ~possible.all(axis=0)
    unknown = {(knowledge.parts.index(p), knowledge.holes.index(h)) for p, h in knowledge.unknown}
    assert set(zip(*np.nonzero(undecided))) == unknown
    truth_mask = sum(1 << i for i, bit in enumerate(truth.ravel()) if bit)
    assert truth_mask in masks[consistent_index(masks, fit, no_fit)]


@settings(max_examples=25, deadline=None)
@given(truth=biorder_truths(3), data=st.data())
def test_samples_are_possible_biorders_and_cover_small_spaces(truth: np.ndarray, data: st.DataObject) -> None:
    m, n = truth.shape
    observed = data.draw(st.lists(st.integers(0, m * n - 1), max_size=m * n))
    known = np.zeros(m * n, dtype=bool)
    for flat in observed:
        known[flat] = True
    masks = all_biorders(m, n)
    observed_fit = sum(1 << int(i) for i in np.flatnonzero(known & truth.ravel()))
    observed_no_fit = sum(1 << int(i) for i in np.flatnonzero(known & ~truth.ravel()))
    possible = as_matrices(masks[consistent_index(masks, observed_fit, observed_no_fit)], m, n)
    # closed knowledge: what every possible relation agrees on
    fit = sum(1 << int(i) for i in np.flatnonzero(possible.all(axis=0).ravel()))
    no_fit = sum(1 << int(i) for i in np.flatnonzero(~possible.any(axis=0).ravel()))
    sample = sample_biorders(smaller_matrix(m, n, fit, no_fit), m, n, 20_000, np.random.default_rng(0))
    drawn, exact = {f.tobytes() for f in sample}, {f.tobytes() for f in possible}
    assert drawn <= exact
    if m + n <= 5:  # every possible relation occurs (3×3 has some too rare for a test)
        assert drawn == exact
