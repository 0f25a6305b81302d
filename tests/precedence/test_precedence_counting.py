"""Counting, enumeration and sampling of admitted sequences, cross-checked with clingo."""

from __future__ import annotations

import random
from collections import Counter
from math import factorial

import clingo
import numpy as np
from hypothesis import given, settings
from scipy.stats import chisquare

from asp.precedence.batches import ExtensionBatches, positions_of
from asp.precedence.count import (
    UniformSampler,
    count_linear_extensions,
    exact_count,
    linear_extensions,
)
from asp.precedence.learn import intersect_orders
from asp.precedence.relation import Relation, true_relation
from asp.solve import encoding, fact
from bridge.assembly import load_assembly
from tests._precedence_helpers import closed_relation, posets


def clingo_sequences(relation: Relation) -> set[tuple[str, ...]]:
    """Every model of sequence.lp, as a sequence of part ids."""
    ctl = clingo.Control(["0"])
    ctl.load(str(encoding("sequences.lp")))
    facts = [fact("part", p) for p in relation.parts] + [fact("must_precede", a, b) for a, b in relation.pairs()]
    ctl.add("base", [], "".join(f"{atom}.\n" for atom in facts))
    ctl.ground([("base", [])])
    found: set[tuple[str, ...]] = set()

    def on_model(model: clingo.Model) -> None:
        steps = sorted((a.arguments[0].number, str(a.arguments[1])) for a in model.symbols(shown=True))
        found.add(tuple(part for _, part in steps))

    ctl.solve(on_model=on_model)
    return found


@settings(max_examples=40, deadline=None)
@given(posets(max_parts=6))
def test_count_enumeration_and_clingo_models_agree(relation: Relation) -> None:
    enumerated = list(linear_extensions(relation))
    assert len(enumerated) == len(set(enumerated))
    assert set(enumerated) == clingo_sequences(relation)
    assert count_linear_extensions(relation) == len(enumerated)
    assert all(relation.admits(s) for s in enumerated)


def test_cranfield_admits_5320_and_battery_truth_6() -> None:
    assert count_linear_extensions(true_relation(load_assembly("cranfield"))) == 5320
    assert count_linear_extensions(true_relation(load_assembly("battery"))) == 6


def test_counts_are_exact_big_integers_with_components_factored() -> None:
    free = Relation(tuple(f"q{i}" for i in range(40)), np.zeros((40, 40), dtype=bool))
    assert count_linear_extensions(free) == factorial(40)
    chains = closed_relation([f"q{i}" for i in range(30)],
                             [(i, i + 1) for i in range(9)] + [(i, i + 1) for i in range(10, 19)])
    assert exact_count(chains.matrix) == factorial(30) // (factorial(10) ** 2)


def test_base_first_cover_last_and_38_free_parts_count_and_sample_without_blowing_up() -> None:
    names = [f"q{i}" for i in range(40)]
    pairs = [("q0", x) for x in names[1:39]] + [(x, "q39") for x in names[1:39]]
    star = closed_relation(names, [(names.index(a), names.index(b)) for a, b in pairs])
    assert count_linear_extensions(star) == factorial(38)
    sequence = UniformSampler(star).sample(random.Random(2))
    assert sequence[0] == "q0" and sequence[-1] == "q39" and sorted(sequence) == sorted(names)


def test_a_cycle_admits_nothing() -> None:
    relation = Relation.from_pairs(["a", "b", "c"], [("a", "b"), ("b", "a")])
    assert count_linear_extensions(relation) == 0
    assert list(linear_extensions(relation)) == []


def test_sampler_is_uniform_over_the_admitted_sequences() -> None:
    # a before the chain b<c and before d; e free: series inside parallel, 15 sequences
    relation = closed_relation(list("abcde"), [(0, 1), (1, 2), (0, 3)])
    sampler, rng = UniformSampler(relation), random.Random(7)
    draws = Counter(sampler.sample(rng) for _ in range(4500))
    assert set(draws) == set(linear_extensions(relation))
    assert chisquare(list(draws.values())).pvalue > 1e-3


def test_batched_sampler_is_uniform_and_batched_counts_are_exact() -> None:
    truth = true_relation(load_assembly("battery"))
    batches = ExtensionBatches(truth)
    orders = batches.sample_orders(np.random.default_rng(3), 6000)
    draws = Counter(tuple(truth.parts[i] for i in row) for row in orders.tolist())
    assert set(draws) == set(linear_extensions(truth))
    assert chisquare(list(draws.values())).pvalue > 1e-3
    cranfield = true_relation(load_assembly("cranfield"))
    batches = ExtensionBatches(cranfield)
    orders = batches.sample_orders(np.random.default_rng(4), 200 * 4).reshape(200, 4, 10)
    learned = intersect_orders(positions_of(orders))
    expected = [count_linear_extensions(Relation(cranfield.parts, m)) for m in learned]
    assert batches.count(learned).tolist() == expected


def test_stepwise_generator_picks_a_placeable_part_uniformly_at_each_step() -> None:
    """a<b, c free: stepwise draws c first half the time (cab 1/2, abc 1/4, acb 1/4)."""
    relation = Relation.from_pairs(("a", "b", "c"), [("a", "b")])
    orders = ExtensionBatches(relation).sample_orders(np.random.default_rng(5), 8000, "stepwise")
    draws = Counter("".join(relation.parts[i] for i in row) for row in orders.tolist())
    assert set(draws) == {"abc", "acb", "cab"}
    assert chisquare([draws["cab"], draws["abc"], draws["acb"]], [4000, 2000, 2000]).pvalue > 1e-3
