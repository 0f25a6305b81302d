"""The size learner: exact relation, no entailed pair asked, conflicts, batches."""

from __future__ import annotations

import itertools

import networkx as nx
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from assembly_constraints.asp import PlannerError
from assembly_constraints.asp.sizes import learner as learner_module
from assembly_constraints.asp.sizes.learner import LearningOptions, SizeLearner, learn_sizes
from assembly_constraints.asp.sizes.models import build_model
from assembly_constraints.asp.sizes.truth_oracle import TruthOracle
from tests._sizes_helpers import CheckingOracle, biorders
from tests.conftest import ROOT


@pytest.mark.parametrize("policy", ["systematic", "random", pytest.param("heuristic", marks=pytest.mark.slow)])
@settings(max_examples=12, deadline=None)
@given(truth=biorders())
def test_every_policy_learns_the_exact_relation_asking_no_entailed_pair(policy, truth) -> None:
    oracle = CheckingOracle(truth)
    result = learn_sizes(truth.parts, truth.holes, oracle, policy, seed=7, on_experiment=oracle.observe)
    assert result.knowledge.fits == frozenset(truth.fits)
    assert result.knowledge.complete
    assert len(oracle.asked) == result.count <= len(truth.parts) * len(truth.holes)


def test_cranfield_relation_is_learned_and_written_as_facts() -> None:
    truth = TruthOracle.from_assembly("cranfield")
    result = learn_sizes(truth.parts, truth.holes, truth, "heuristic")
    assert result.knowledge.fits == frozenset(truth.fits)
    names = {str(s) for s in result.facts()}
    assert "fits(sh,br)" in names and "no_fit(sh,s1)" in names and "smaller(p1,p3)" in names
    assert sum(1 for s in result.facts() if s.name == "tried") == result.count


def _cycle_learner() -> SizeLearner:
    """a < x < b < y observed, so a < y is entailed; then a late answer says a does not fit y."""
    learner = SizeLearner(["a", "b"], ["x", "y"])
    learner.record("a", "x", "fit")
    learner.record("b", "x", "no_fit")
    learner.record("b", "y", "fit")
    assert learner.knowledge.result("a", "y") == "fit"
    learner.record("a", "y", "no_fit")
    return learner


def test_a_cyclic_closure_names_the_conflicting_experiments_and_queues_retests() -> None:
    learner = _cycle_learner()
    assert [e.number for e in learner.conflicting_experiments()] == [1, 2, 3, 4]
    assert sorted(learner.retests) == [("a", "x"), ("a", "y"), ("b", "x"), ("b", "y")]
    assert learner.next_experiment() in learner.retests


def test_retests_resolve_the_conflict_and_keep_a_consistent_relation() -> None:
    learner = _cycle_learner()
    truth = TruthOracle(["a", "b"], ["x", "y"], {("a", "x"), ("a", "y"), ("b", "y")})
    while (pair := learner.next_experiment()) is not None:
        learner.record(*pair, truth.ask(*pair))
    assert not learner.knowledge.conflicts
    assert learner.knowledge.fits == frozenset(truth.fits)
    assert [e.retest for e in learner.experiments].count(True) >= 1


def test_reproduced_conflicting_observations_move_to_a_weaker_model_and_learn_the_truth() -> None:
    # a fits x and b fits y only: not a biorder, so the line model is wrong, and re-tests
    # that reproduce every answer on the cycle are no noise.
    learner = _cycle_learner()
    truth = TruthOracle(["a", "b"], ["x", "y"], {("a", "x"), ("b", "y")},
                        sections={"a": "a", "b": "b"})
    while (pair := learner.next_experiment()) is not None:
        learner.record(*pair, truth.ask(*pair))
    result = learner.result()
    assert result.model.name == "pairs"
    assert result.model_changes == ("observations a->x fit, a->y no_fit, b->x no_fit, b->y fit "
                                    "contradict size model line; now pairs",)
    assert learner.knowledge.fits == frozenset(truth.fits) and not learner.knowledge.conflicts
    assert "size_model(pairs)" in {str(s) for s in result.facts()}


def _entails(graph: nx.DiGraph, pair: tuple[str, str]) -> bool:
    part, hole = pair
    return nx.has_path(graph, part, hole) or nx.has_path(graph, hole, part)


@settings(max_examples=10, deadline=None)
@given(truth=biorders(max_parts=5, max_holes=5))
def test_a_batch_holds_pairs_no_outcomes_of_the_others_can_entail(truth) -> None:
    learner = SizeLearner(truth.parts, truth.holes, "systematic")
    for pair in learner.next_batch(2):  # learn a little first
        learner.record(*pair, truth.ask(*pair))
    batch = learner.next_batch(3)
    assert bool(batch) == (not learner.knowledge.complete)
    assume(batch)
    assert len(set(batch)) == len(batch)
    assert batch[0] == learner.next_experiment()
    known = nx.DiGraph()
    known.add_nodes_from([*truth.parts, *truth.holes])
    known.add_edges_from(learner.knowledge.smaller)
    for index, target in enumerate(batch):
        assert learner.knowledge.result(*target) is None
        others = batch[:index] + batch[index + 1:]
        for outcomes in itertools.product([True, False], repeat=len(others)):
            graph = known.copy()
            graph.add_edges_from((p, h) if fit else (h, p) for (p, h), fit in zip(others, outcomes))
            assert not _entails(graph, target)


@settings(max_examples=15, deadline=None)
@given(truth=biorders(max_parts=4, max_holes=4), data=st.data())
def test_answers_recorded_at_once_give_the_closure_of_recording_them_one_by_one(truth, data) -> None:
    """record_all: the same knowledge and experiments as record, in the order given, with
    noise too (a flipped answer is a conflict either way)."""
    pairs = [(p, h) for p in truth.parts for h in truth.holes]
    chosen = data.draw(st.lists(st.sampled_from(pairs), min_size=1, max_size=6))
    flips = data.draw(st.lists(st.booleans(), min_size=len(chosen), max_size=len(chosen)))
    answers = [(p, h, {"fit": "no_fit", "no_fit": "fit"}[truth.ask(p, h)] if flip else truth.ask(p, h))
               for (p, h), flip in zip(chosen, flips)]
    one_by_one, at_once = (SizeLearner(truth.parts, truth.holes, "systematic") for _ in range(2))
    for answer in answers:
        one_by_one.record(*answer)
    recorded = at_once.record_all(answers)
    assert recorded == one_by_one.experiments == at_once.experiments
    assert at_once.answers == one_by_one.answers
    assert at_once.knowledge.fits == one_by_one.knowledge.fits
    assert at_once.knowledge.no_fit == one_by_one.knowledge.no_fit
    assert at_once.knowledge.conflicts == one_by_one.knowledge.conflicts


def test_a_batch_recorded_at_once_cannot_be_undone_but_a_single_record_can() -> None:
    learner = SizeLearner(["a", "b"], ["x", "y"])
    learner.record_all([("a", "x", "fit"), ("b", "x", "no_fit")])
    with pytest.raises(PlannerError, match="nothing to take back"):
        learner.undo()
    learner.record_all([("a", "y", "fit")])
    learner.undo()
    assert len(learner.experiments) == 2 and learner.knowledge.result("a", "y") is None


def test_a_batch_avoids_pairs_pending_at_other_cells() -> None:
    learner = SizeLearner(["a", "b"], ["x", "y"])
    learner.record("a", "x", "fit")
    learner.record("b", "x", "no_fit")  # a < x < b
    # (a,y) and (b,y) are not independent: a not fitting y entails b not fitting y
    assert learner.next_batch(2) == [("a", "y")]
    assert learner.next_batch(2, pending=[("a", "y")]) == []


def test_the_learner_starts_from_demonstrated_fits_and_what_they_entail_with_experiments() -> None:
    learner = SizeLearner(["a", "b"], ["x", "y"], options=LearningOptions(demonstrated=[("a", "x")]))
    assert learner.knowledge.result("a", "x") == "fit" and learner.experiments == []
    assert learner.next_experiment() != ("a", "x")
    learner.record("b", "x", "no_fit")  # x < b, and a < x from the demonstration: a < b
    learner.record("b", "y", "fit")  # a < x < b < y: a fits y, never asked
    assert learner.knowledge.result("a", "y") == "fit" and learner.knowledge.complete
    without = SizeLearner(["a", "b"], ["x", "y"])
    without.record("b", "x", "no_fit")
    without.record("b", "y", "fit")
    assert without.knowledge.result("a", "y") is None  # the demonstration made the difference
    names = {str(s) for s in learner.result().facts()}
    assert "demonstrated(a,x)" in names and not any(s.startswith("tried(") and ",a,x," in s for s in names)
    learner.reset()
    assert learner.knowledge.result("a", "x") == "fit"  # a fresh session keeps what was demonstrated
    with pytest.raises(PlannerError, match=r"demonstrated placement\(s\) a@z"):
        SizeLearner(["a", "b"], ["x", "y"], options=LearningOptions(demonstrated=[("a", "z")]))


@pytest.mark.parametrize("policy", ["systematic", "heuristic", "best"])
def test_annotated_cranfield_demonstrations_save_experiments(policy: str) -> None:
    from assembly_constraints.asp.sizes.cli import demonstrated_fits

    truth = TruthOracle.from_assembly("cranfield")
    shown = demonstrated_fits(str(ROOT / "data" / "cranfield" / "demos_annotated.txt"), "cranfield")
    plain = learn_sizes(truth.parts, truth.holes, truth, policy)
    oracle = CheckingOracle(truth)
    annotated = learn_sizes(truth.parts, truth.holes, oracle, policy, on_experiment=oracle.observe,
                            options=LearningOptions(demonstrated=shown))
    assert annotated.knowledge.fits == frozenset(truth.fits)
    assert not set(oracle.asked) & set(shown)
    assert annotated.count <= plain.count - 5


@pytest.mark.parametrize("policy", ["systematic", pytest.param("heuristic", marks=pytest.mark.slow)])
def test_grounding_once_and_per_decision_make_the_same_session(policy, monkeypatch) -> None:
    # 8 parts on two sections, 6 holes, one wrong answer confirmed away: both ways the learner solves
    parts, holes = [f"p{i}" for i in range(1, 9)], [f"h{j}" for j in range(1, 7)]
    sizes = {name: (5 * k) % 11 for k, name in enumerate(parts + holes)}
    fits = {(p, h) for p in parts for h in holes if sizes[p] < sizes[h]}
    model = build_model("sections", parts, {p: "round" if i % 2 else "square" for i, p in enumerate(parts)})
    sessions = []
    for limit in (0, 10_000):
        monkeypatch.setattr(learner_module, "GROUND_ONCE_PAIRS", limit)
        learner = SizeLearner(parts, holes, policy, options=LearningOptions(confirm=1, model=model))
        flipped = False
        while (pair := learner.next_experiment()) is not None:
            result = "fit" if pair in fits else "no_fit"
            if not flipped and len(learner.experiments) == 4:
                result, flipped = ("no_fit" if result == "fit" else "fit"), True
            learner.record(*pair, result)
        sessions.append(([(e.part, e.hole, e.result) for e in learner.experiments], learner.knowledge.fits))
    assert sessions[0] == sessions[1]
    assert sessions[0][1] == frozenset(fits)
