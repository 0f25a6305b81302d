"""Confirmation re-tests of essential observations (``confirm``): noise the closure cannot see."""

from __future__ import annotations

import json

import clingo
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from asp import PlannerError
from asp.bench.sizes import main as bench_main
from asp.sizes.knowledge import Pair
from asp.sizes.learner import LearningOptions, SizeLearner, learn_sizes, run_learner
from asp.sizes.policies import policy_names
from asp.sizes.truth_oracle import TruthOracle
from asp.solve import encoding, fact, format_facts
from tests._sizes_helpers import biorders

CRANFIELD = TruthOracle.from_assembly("cranfield")


class LyingOracle:
    """Answers from a truth, but flips the answers of ``pair`` on its asks numbered ``lies`` (1-based)."""

    def __init__(self, truth: TruthOracle, pair: Pair, lies: tuple[int, ...] = (1,)) -> None:
        self.truth, self.pair, self.lies, self.asks = truth, pair, lies, 0

    def ask(self, part: str, hole: str) -> str:
        answer = self.truth.ask(part, hole)
        if (part, hole) != self.pair:
            return answer
        self.asks += 1
        return ("no_fit" if answer == "fit" else "fit") if self.asks in self.lies else answer


def _final_essentials(truth: TruthOracle, policy: str = "systematic") -> list[Pair]:
    learner = SizeLearner(truth.parts, truth.holes, policy, options=LearningOptions(confirm=1))
    run_learner(learner, truth)
    return learner.essential()


def test_essentials_of_a_hand_checked_chain() -> None:
    # a < x < b < y observed; a < y is entailed by the chain, so observing it adds nothing
    learner = SizeLearner(["a", "b"], ["x", "y"], options=LearningOptions(confirm=1))
    for part, hole, result in [("a", "x", "fit"), ("b", "x", "no_fit"), ("b", "y", "fit")]:
        learner.record(part, hole, result)
    assert learner.knowledge.complete
    assert learner.essential() == [("a", "x"), ("b", "x"), ("b", "y")]
    learner.record("a", "y", "fit")
    assert learner.essential() == [("a", "x"), ("b", "x"), ("b", "y")]


def _unknown_without(truth: TruthOracle, observed: list[Pair], removed: Pair) -> bool:
    """Brute force: is ``removed`` unknown given the other observations (closure alone)?"""
    atoms = [fact("part", p) for p in truth.parts] + [fact("hole", h) for h in truth.holes]
    atoms += [fact("observed", *pair, truth.ask(*pair)) for pair in observed if pair != removed]
    ctl = clingo.Control(["--warn=none"])
    ctl.add("base", [], format_facts(atoms))
    ctl.load(str(encoding("sizes_closure.lp")))
    ctl.ground([("base", [])])
    with ctl.solve(yield_=True) as handle:
        model = next(iter(handle))
        return model.contains(clingo.Function("unknown", [clingo.Function(x) for x in removed]))


@settings(max_examples=30, deadline=None)
@given(truth=biorders(max_parts=4, max_holes=4), data=st.data())
def test_essentials_are_the_observations_whose_pair_is_unknown_without_them(truth, data) -> None:
    pairs = [(p, h) for p in truth.parts for h in truth.holes]
    observed = data.draw(st.permutations(pairs).flatmap(lambda order: st.sampled_from(
        [order[:k] for k in range(1, len(order) + 1)])))
    learner = SizeLearner(truth.parts, truth.holes, options=LearningOptions(confirm=1))
    for pair in observed:
        learner.record(*pair, truth.ask(*pair))
    expected = [pair for pair in pairs if pair in observed and _unknown_without(truth, observed, pair)]
    assert learner.essential() == expected


@pytest.mark.slow
def test_confirm_1_undoes_a_lie_on_an_essential_pair_that_confirm_0_keeps() -> None:
    truth_fits = frozenset(CRANFIELD.fits)
    for pair in _final_essentials(CRANFIELD):
        plain = learn_sizes(CRANFIELD.parts, CRANFIELD.holes, LyingOracle(CRANFIELD, pair), "systematic")
        confirmed = learn_sizes(CRANFIELD.parts, CRANFIELD.holes, LyingOracle(CRANFIELD, pair),
                                "systematic", options=LearningOptions(confirm=1))
        assert plain.knowledge.fits != truth_fits, pair
        assert confirmed.knowledge.fits == truth_fits, pair


def test_a_disagreeing_retest_is_repeated_until_the_kept_result_leads_by_k_plus_1() -> None:
    pair = ("p3", "s1")  # essential; the truth is fit: answers fit, (lie) no_fit, fit, fit
    learner = SizeLearner(CRANFIELD.parts, CRANFIELD.holes, "systematic", options=LearningOptions(confirm=1))
    result = run_learner(learner, LyingOracle(CRANFIELD, pair, lies=(2,)))
    assert learner.answers[pair] == ["fit", "no_fit", "fit", "fit"]
    assert learner.lead(pair) == 2
    assert result.knowledge.fits == frozenset(CRANFIELD.fits)
    numbers = [e.number for e in result.experiments if (e.part, e.hole) == pair]
    assert numbers[1:] == list(range(numbers[1], numbers[1] + 3))  # re-asked at once


@pytest.mark.parametrize("policy", policy_names())
@pytest.mark.parametrize("confirm", [1, 2])
def test_without_noise_confirm_costs_k_experiments_per_essential_observation(policy, confirm) -> None:
    plain = learn_sizes(CRANFIELD.parts, CRANFIELD.holes, CRANFIELD, policy, seed=4)
    learner = SizeLearner(CRANFIELD.parts, CRANFIELD.holes, policy, seed=4, options=LearningOptions(confirm=confirm))
    result = run_learner(learner, CRANFIELD)
    assert result.count == plain.count + confirm * len(learner.essential())
    assert result.experiments[:plain.count] == plain.experiments
    assert all(e.retest for e in result.experiments[plain.count:])
    assert result.knowledge == plain.knowledge


@settings(max_examples=20, deadline=None)
@given(truth=biorders(max_parts=5, max_holes=5))
def test_without_noise_confirm_1_adds_one_experiment_per_essential_on_any_biorder(truth) -> None:
    plain = learn_sizes(truth.parts, truth.holes, truth, "systematic")
    learner = SizeLearner(truth.parts, truth.holes, "systematic", options=LearningOptions(confirm=1))
    assert run_learner(learner, truth).count == plain.count + len(learner.essential())


def _parallel(learner: SizeLearner, oracle, cells: int) -> list[list[Pair]]:
    """Run like the Zenoh session: keep ``cells`` busy with next_batch, oldest answer first."""
    running: list[Pair] = []
    batches = []
    while True:
        batch = learner.next_batch(cells - len(running), pending=running)
        if not batch and not running:
            return batches
        batches.append(batch)
        running += batch
        finished = running.pop(0)
        learner.record(*finished, oracle.ask(*finished))


@pytest.mark.parametrize("cells", [2, 3])
def test_batches_beside_pending_experiments_confirm_and_correct_a_lie(cells: int) -> None:
    pair = ("p3", "s1")
    learner = SizeLearner(CRANFIELD.parts, CRANFIELD.holes, "best", options=LearningOptions(confirm=1))
    batches = _parallel(learner, LyingOracle(CRANFIELD, pair), cells)
    assert learner.knowledge.fits == frozenset(CRANFIELD.fits)
    assert learner.essential() == _final_essentials(CRANFIELD)
    assert all(learner.lead(p) >= 2 for p in learner.essential())
    assert any(len(b) > 1 and all(p in learner.essential() for p in b) for b in batches)


def test_bad_confirm_settings_are_errors() -> None:
    with pytest.raises(PlannerError, match="confirm -1"):
        SizeLearner(["a"], ["x"], options=LearningOptions(confirm=-1))
    with pytest.raises(PlannerError, match="max_answers 2"):
        SizeLearner(["a"], ["x"], options=LearningOptions(max_answers=2, confirm=2))


@pytest.mark.slow
def test_cli_learn_and_evaluate_take_confirm_and_noise(run_main) -> None:
    done = run_main("sizes", "learn", "--assembly", "cranfield", "--policy", "systematic", "--confirm", "1", "--json")
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    assert {"policy", "experiments", "count", "fits"} <= set(report)
    assert report["count"] == 25 + 15  # Cranfield's 15 essential observations, each re-tested once
    done = run_main("sizes", "evaluate", "--assembly", "cranfield", "--policy", "systematic", "--relabelings", "6",
                "--noise", "0.1", "--confirm", "1", "--json")
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    assert (report["cases"], report["noise"], report["confirm"]) == (6, 0.1, 1)
    assert 0 <= report["wrong"] <= 6 and report["wrong_share"] == round(report["wrong"] / 6, 6)


@pytest.mark.parametrize("args", [
    ["sizes", "learn", "--assembly", "cranfield", "--confirm", "-1"],
    ["sizes", "learn", "--assembly", "cranfield", "--confirm", "one"],
    ["sizes", "evaluate", "--assembly", "cranfield", "--policy", "systematic", "--noise", "0.5"],
    ["bench", "sizes", "--noise", "0.1,x"],
    ["bench", "sizes", "--noise", "0.1", "--seeds", "0"],
])
def test_bad_confirm_or_noise_exits_2(args: list[str], run_main) -> None:
    done = run_main(*args)
    assert done.returncode == 2 and "Traceback" not in done.stderr and done.stderr.strip()


def test_bench_sizes_noise_mode_prints_one_row_per_setting(capsys) -> None:
    assert bench_main(["--noise", "0.05", "--confirm", "0,1", "--seeds", "4",
                       "--policies", "systematic", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)["noise"]
    assert [(r["policy"], r["confirm"], r["sessions"]) for r in rows] == [("systematic", 0, 4), ("systematic", 1, 4)]
    assert all(0 <= r["wrong_pct"] <= 100 and r["mean"] >= 15 for r in rows)
