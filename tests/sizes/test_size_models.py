"""Size models on products of mixed cross-sections: sound entailment, weakening, matching.

The truths here come from the cross-sections, as the cell's truth backend answers
(``assembly_constraints.executor.world.geometry.passes``): a round peg d passes a round hole D when d < D,
a square hole S when d < S; a square peg s passes a square hole when s < S and a round
hole by its diagonal, s·√2 < D. Such relations are not one biorder, so the paper's one
line entails fits that do not exist; one line per cross-section does not.
"""

from __future__ import annotations

import itertools
import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from assembly_constraints.asp import PlannerError
from assembly_constraints.asp.plans.assign import LearnedFacts, UnsolvableAssembly, feasible_assignment
from assembly_constraints.asp.sizes.biorders import biorder_count
from assembly_constraints.asp.sizes.learner import LearningOptions, SizeLearner, learn_sizes
from assembly_constraints.asp.sizes.models import build_model, model_for
from assembly_constraints.asp.sizes.policies import policy_names
from assembly_constraints.asp.sizes.truth_oracle import TruthOracle, ferrers_violation
from assembly_constraints.asp.solve import fact
from assembly_constraints.executor.world.geometry import PartSpec, passes
from assembly_constraints.executor.world.geometry import Section as CrossSection

Section = tuple[str, float, float]
"""(kind, size [m], width [m]) of a peg's or a hole's cross-section: a rect is size x width
(size >= width), round and square have width 0."""


def _truth(pegs: list[Section], holes: list[Section],
           sections: list[str] | None = None) -> tuple[TruthOracle, dict[str, str]]:
    """The relation the cross-sections give, and each peg's section (default: its kind,
    a rect its own id; ``sections`` gives them, as a product's ``section`` labels do)."""
    part_ids = [f"p{i}" for i in range(1, len(pegs) + 1)]
    hole_ids = [f"h{j}" for j in range(1, len(holes) + 1)]
    specs = [PartSpec(p, kind, size, shape=kind, length=0.05, mass=0.05, start=(0.0, 0.0), demo_hole="h1",
                      width=width) for p, (kind, size, width) in zip(part_ids, pegs)]
    hole_specs = [CrossSection(h, kind, size, width=width)
                  for h, (kind, size, width) in zip(hole_ids, holes)]
    fits = {(p.id, h.id) for p in specs for h in hole_specs if passes(p, h)}
    if sections is None:
        sections = [p if kind == "rect" else kind for p, (kind, _, _) in zip(part_ids, pegs)]
    by_part = dict(zip(part_ids, sections))
    return TruthOracle(part_ids, hole_ids, fits, sections=by_part), by_part


def _example(pairs: int) -> tuple[TruthOracle, dict[str, str]]:
    """``pairs`` round and ``pairs`` square pegs 14, 13, 10, 9... mm, each with its own hole
    0.5 mm larger (the issue's four-peg example for 2, its sibling for 4)."""
    pegs: list[Section] = []
    holes: list[Section] = []
    for k in range(pairs):
        for kind, size in (("round", 0.014 - 0.004 * k), ("square", 0.013 - 0.004 * k)):
            pegs.append((kind, size, 0.0))
            holes.append((kind, size + 0.0005, 0.0))
    return _truth(pegs, holes)


@pytest.mark.parametrize("pairs", [2, 4])
@pytest.mark.parametrize("policy", policy_names())
def test_mixed_products_are_learned_exactly_by_every_policy(pairs: int, policy: str) -> None:
    truth, sections = _example(pairs)
    assert ferrers_violation(truth.parts, truth.holes, truth.fits) is not None  # not one line
    model = model_for(truth.parts, None, None, sections)
    assert model.name == "sections"
    result = learn_sizes(truth.parts, truth.holes, truth, policy, seed=3, options=LearningOptions(model=model))
    assert result.knowledge.fits == frozenset(truth.fits)
    assert result.knowledge.no_fit == frozenset(
        (p, h) for p in truth.parts for h in truth.holes if (p, h) not in truth.fits)
    assignment = feasible_assignment(_facts(truth.parts, truth.holes, result.knowledge.fits))
    assert sorted(assignment) == list(truth.parts) and len(set(assignment.values())) == len(truth.parts)
    assert all((p, h) in truth.fits for p, h in assignment.items())
    if pairs == 4 and policy == "best":
        assert result.count < len(truth.parts) * len(truth.holes)


def test_the_single_line_entails_a_fit_that_does_not_exist() -> None:
    """Why the model matters: on the four-peg example one line learns wrong facts."""
    truth, _ = _example(2)
    line = learn_sizes(truth.parts, truth.holes, truth, "heuristic",
                       options=LearningOptions(model=build_model("line", truth.parts)))
    assert line.knowledge.fits != frozenset(truth.fits)


def test_line_on_several_cross_sections_is_refused_unless_the_product_declares_it() -> None:
    truth, sections = _example(2)
    with pytest.raises(PlannerError, match=r"size model line puts parts of 2 cross-sections \(round: p1 p3; "
                                           r"square: p2 p4\)"):
        model_for(truth.parts, "line", None, sections)
    declared = model_for(truth.parts, "line", "line", sections)
    assert declared.name == "line" and "the product declares 2 cross-sections" in declared.assumption()


def test_information_bounds() -> None:
    """log2 of the number of relations a model allows: one 5x5 line 18.33 bits (the
    poly-Bernoulli number 329 462); two lines of 2 pegs x 4 holes 2 log2 146 = 14.4 bits."""
    assert biorder_count(5, 5) == 329_462 and biorder_count(2, 4) == 146
    parts = [f"p{i}" for i in range(5)]
    assert build_model("line", parts).information_bits(5) == pytest.approx(18.33, abs=0.005)
    truth, sections = _example(2)
    assert build_model("sections", truth.parts, sections).information_bits(4) == pytest.approx(
        2 * math.log2(146))
    assert build_model("pairs", truth.parts, sections).information_bits(4) == 16


def _facts(parts: list[str] | tuple[str, ...], holes: list[str] | tuple[str, ...],
           fits: frozenset[tuple[str, str]]) -> LearnedFacts:
    atoms = [fact("part", p) for p in parts] + [fact("hole", h) for h in holes]
    atoms += [fact("fits", p, h) for p, h in sorted(fits)] + [fact("needs_hole", p) for p in parts]
    return LearnedFacts(tuple(atoms), tuple(parts), tuple(holes), frozenset(fits), tuple(parts), frozenset())


@st.composite
def cross_section(draw, clearance: float = 0.0) -> Section:
    """Round, square or rect, sides 8..16 mm in 1 mm steps (ties likely), plus ``clearance`` [m]."""
    kind = draw(st.sampled_from(["round", "square", "rect"]))
    size = draw(st.integers(8, 16)) / 1000
    width = draw(st.integers(4, int(size * 1000))) / 1000 if kind == "rect" else 0.0
    return kind, size + clearance, width + clearance if width else 0.0


@st.composite
def products(draw, max_pegs: int = 5, max_holes: int = 5) -> tuple[TruthOracle, dict[str, str]]:
    """Random pegs and holes, round, square or rect; rect pegs of one aspect ratio share a
    section (they are scaled copies), others are their own."""
    pegs = draw(st.lists(cross_section(), min_size=1, max_size=max_pegs))
    holes = draw(st.lists(cross_section(0.0004), min_size=1, max_size=max_holes))
    sections = [f"rect_{round(1000 * size)}_{round(1000 * width)}" if kind == "rect" and draw(st.booleans())
                else kind if kind != "rect" else f"own{i}" for i, (kind, size, width) in enumerate(pegs)]
    # a shared label only for rects of one aspect ratio
    by_aspect: dict[float, str] = {}
    for i, (kind, size, width) in enumerate(pegs):
        if kind == "rect" and not sections[i].startswith("own"):
            sections[i] = by_aspect.setdefault(round(size / width, 9), sections[i])
    return _truth(pegs, holes, sections)


@settings(max_examples=60, deadline=None)
@given(products(), st.sampled_from(policy_names()), st.integers(0, 5))
def test_every_policy_learns_random_mixed_products_exactly(product, policy: str, seed: int) -> None:
    """Zero wrong facts; a complete assignment whenever one exists, else Hall's witness."""
    truth, sections = product
    model = model_for(truth.parts, None, None, sections)
    result = learn_sizes(truth.parts, truth.holes, truth, policy, seed, options=LearningOptions(model=model))
    assert result.knowledge.fits == frozenset(truth.fits)
    assert not result.model_changes
    facts = _facts(truth.parts, truth.holes, result.knowledge.fits)
    exists = any(all((p, h) in truth.fits for p, h in zip(truth.parts, chosen))
                 for chosen in itertools.permutations(truth.holes, len(truth.parts)))
    try:
        assignment = feasible_assignment(facts)
    except UnsolvableAssembly as exc:
        assert not exists
        assert len({h for p in exc.parts for h in facts.holes_of(p)}) < len(exc.parts)
        return
    assert exists and all((p, h) in truth.fits for p, h in assignment.items())
    assert len(set(assignment.values())) == len(assignment) == len(truth.parts)


def _allowed(rows: dict[str, frozenset[str]], sections: dict[str, str], holes: tuple[str, ...]) -> bool:
    """Whether the relation's rows of each section form a biorder."""
    groups: dict[str, list[str]] = {}
    for part, section in sections.items():
        groups.setdefault(section, []).append(part)
    fits = {(p, h) for p, row in rows.items() for h in row}
    return all(ferrers_violation(members, holes, fits) is None for members in groups.values())


@settings(max_examples=40, deadline=None)
@given(products(max_pegs=3, max_holes=3), st.sampled_from(["sections", "pairs"]),
       st.lists(st.tuples(st.integers(0, 2), st.integers(0, 2)), max_size=5))
def test_entailed_outcomes_hold_in_every_allowed_relation(product, name: str, asked) -> None:
    """Brute force: after some observations, an untried pair is entailed exactly when
    every relation of the model agreeing with the observations gives it one outcome."""
    truth, sections = product
    model = build_model(name, truth.parts, sections)
    learner = SizeLearner(truth.parts, truth.holes, "systematic", options=LearningOptions(model=model))
    observed: dict[tuple[str, str], str] = {}
    for i, j in asked:
        pair = (truth.parts[i % len(truth.parts)], truth.holes[j % len(truth.holes)])
        if learner.knowledge.result(*pair) is None:
            observed[pair] = truth.ask(*pair)
            learner.record(*pair, observed[pair])
    holes = truth.holes
    subsets = [frozenset(h for h, bit in zip(holes, bits) if bit)
               for bits in itertools.product((0, 1), repeat=len(holes))]
    agreeing = []
    for rows in itertools.product(subsets, repeat=len(truth.parts)):
        relation = dict(zip(truth.parts, rows))
        if all((h in relation[p]) == (r == "fit") for (p, h), r in observed.items()) and \
                _allowed(relation, dict(model.sections), holes):
            agreeing.append(relation)
    assert agreeing  # the truth itself agrees and is allowed
    for part in truth.parts:
        for hole in holes:
            outcomes = {hole in relation[part] for relation in agreeing}
            known = learner.knowledge.result(part, hole)
            if len(outcomes) == 1:
                assert known == ("fit" if outcomes.pop() else "no_fit"), (part, hole)
            else:
                assert known is None, (part, hole)


def test_a_contradicted_line_moves_to_sections_then_learns_the_truth() -> None:
    """Demonstrations that say where two pegs went and two answers contradict one line
    (the second arrives late, from a parallel cell, after the first entailed it): once
    re-tests reproduce them the learner names the observations, moves to one line per
    cross-section, and still learns the relation exactly."""
    truth, sections = _example(2)
    line = model_for(truth.parts, "line", "line", sections)  # declared by the product: allowed
    # p1 (round 14) in h1 (round 14.5) and p2 (square 13) in h2 (square 13.5): demonstrated;
    # p1 -> h2 no_fit and p2 -> h1 no_fit close a cycle on one line (p1 < h1 < p2 < h2 < p1).
    learner = SizeLearner(truth.parts, truth.holes, "systematic",
                          options=LearningOptions(demonstrated=[("p1", "h1"), ("p2", "h2")], model=line))
    learner.record("p1", "h2", truth.ask("p1", "h2"))
    assert learner.knowledge.result("p2", "h1") == "fit"  # p2 < h2 < p1 < h1 on one line: wrong
    learner.record("p2", "h1", truth.ask("p2", "h1"))
    assert learner.knowledge.conflicts
    while (pair := learner.next_experiment()) is not None:
        learner.record(*pair, truth.ask(*pair))
    result = learner.result()
    assert result.model.name == "sections" and len(result.model_changes) == 1
    assert "contradict size model line; now sections" in result.model_changes[0]
    assert result.knowledge.fits == frozenset(truth.fits)


@pytest.mark.parametrize("policy", policy_names())
def test_under_pairs_every_policy_tries_every_pair_and_learns_the_truth(policy: str) -> None:
    truth, sections = _example(2)
    result = learn_sizes(truth.parts, truth.holes, truth, policy,
                         options=LearningOptions(model=build_model("pairs", truth.parts, sections)))
    assert result.knowledge.fits == frozenset(truth.fits)
    assert result.count == len(truth.parts) * len(truth.holes)
    assert len({(e.part, e.hole) for e in result.experiments}) == result.count


@settings(max_examples=15, deadline=None)
@given(products(max_pegs=5, max_holes=5), st.sampled_from(policy_names()), st.integers(2, 4))
def test_parallel_batches_under_sections_never_conflict_and_learn_exactly(product, policy: str, cells: int) -> None:
    """Pairs handed out together are independent on their section's line: answered in
    any order they never contradict each other, and the relation is learned exactly."""
    truth, sections = product
    learner = SizeLearner(truth.parts, truth.holes, policy,
                          options=LearningOptions(model=model_for(truth.parts, None, None, sections)))
    while batch := learner.next_batch(cells):
        for pair in reversed(batch):
            learner.record(*pair, truth.ask(*pair))
            assert not learner.knowledge.conflicts
    assert learner.knowledge.fits == frozenset(truth.fits)
    assert not any(e.retest for e in learner.experiments)
