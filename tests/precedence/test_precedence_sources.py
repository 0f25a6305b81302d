"""One learner of demonstrations, geometry and experiments (truth oracle): the support of
each pair, process constraints, conflicts named with their evidence, the experiments file,
and exploration reaching the true relation with no wrong pair (property test)."""

from __future__ import annotations

import itertools
import re
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from asp import PlannerError
from asp.precedence.demos import Demonstrations, load_demos
from asp.precedence.explore.bound import Bound, enumerated_bound, information_bound
from asp.precedence.explore.knowledge import Evidence, PrecedenceConflict, Trial, know
from asp.precedence.explore.learner import geometric_reasons, learn_sources
from asp.precedence.explore.oracle import TruthOracle
from asp.precedence.explore.orders import count_orders
from asp.precedence.explore.select import explore
from asp.precedence.explore.trials import load_trials, write_trials
from asp.precedence.relation import Relation, close, true_relation
from bridge.assembly import load_assembly
from bridge.precedence.experiment import ExperimentStep, PrecedenceExperiment, PrecedenceOutcome
from tests._precedence_helpers import poset_with_demos

CRANFIELD_GEOMETRY = """% bp->p1: base
% sh->pd: locates
% pd->fp: supports
part(bp). part(p1). part(p2). part(p3). part(p4). part(sh). part(sp). part(pd). part(ph). part(fp).
must_precede(bp,p1). must_precede(sh,pd). must_precede(pd,fp). must_precede(sh,fp).
"""


def _explored(evidence: Evidence, truth: Relation, policy: str = "informative") -> Evidence:
    for _knowledge, trial in explore(evidence, TruthOracle(truth), policy):
        evidence = evidence.with_trial(trial)
    return evidence


def _trial(number: int, pair: tuple[str, str], parts: list[str], failed: int | None = None) -> Trial:
    experiment = PrecedenceExperiment(id=f"t.{number}", pair=pair, sequence=tuple(map(ExperimentStep, parts)))
    outcome = (PrecedenceOutcome(id=f"t.{number}", cell="c", pair=pair, outcome="success") if failed is None else
               PrecedenceOutcome(id=f"t.{number}", cell="c", pair=pair, outcome="failed", failed_step=failed,
                                 reason="jammed"))
    return Trial(experiment, outcome, f"x.lp:{number}")


def test_cranfield_from_demonstrations_geometry_and_experiments_each_pair_with_its_support(
        tmp_path: Path, root: Path) -> None:
    truth = true_relation(load_assembly("cranfield"))
    prior = tmp_path / "geometric_precedence.lp"
    prior.write_text(CRANFIELD_GEOMETRY)
    demos = load_demos(root / "data/cranfield/demos.txt", truth.parts)
    geometry = (("bp", "p1"), ("sh", "pd"), ("pd", "fp"), ("sh", "fp"))
    evidence = _explored(Evidence(demos, geometry, str(prior), geometric_reasons(str(prior))), truth)
    learned = learn_sources(evidence)
    assert learned.relation.same_as(truth)
    assert {p for p, s in learned.support.items() if s == "geometry"} == set(geometry)
    assert {p for p, s in learned.support.items() if s == "experiment"} == set(truth.pairs()) - set(geometry)
    assert not learned.process and not learned.undecided
    # the geometric pairs were never tested: every experiment was on another pair
    assert not {t.experiment.pair for t in evidence.trials} & set(geometry)
    assert "sh<pd (locates)" in learned.summary()


class _PhysicsOracle:
    """The truth, but for the pairs of ``late``, shown as the physics shows them: b goes in
    without a, and a, placed after b, is then blocked, touching the parts ``late[(a, b)]``."""

    def __init__(self, truth: Relation, late: dict[tuple[str, str], tuple[str, ...]]) -> None:
        self.truth, self.late = TruthOracle(truth), late

    def run(self, experiment: PrecedenceExperiment) -> PrecedenceOutcome:
        if experiment.pair not in self.late:
            return self.truth.run(experiment)
        if not experiment.then_first:
            return PrecedenceOutcome(id=experiment.id, cell="sim", pair=experiment.pair, outcome="success")
        return PrecedenceOutcome(id=experiment.id, cell="sim", pair=experiment.pair, outcome="failed",
                                 failed_step=len(experiment.sequence), reason="blocked",
                                 blocked_by=self.late[experiment.pair])


def _cranfield_two_demos(root: Path) -> tuple[Relation, Demonstrations]:
    truth = true_relation(load_assembly("cranfield"))
    demos = load_demos(root / "data/cranfield/demos.txt", truth.parts)
    return truth, Demonstrations(demos.parts, demos.sequences[:2], demos.origins[:2])


def test_a_precedence_shown_only_at_the_first_parts_step_is_learned_from_b_then_a(root: Path) -> None:
    # the sim Cranfield cell: fp goes in without sp, then sp is blocked by fp; pd goes in
    # without sh, then sh is blocked by pd
    truth, demos = _cranfield_two_demos(root)
    assert {("sp", "fp"), ("sh", "pd")} <= set(truth.pairs())
    oracle = _PhysicsOracle(truth, {("sp", "fp"): ("fp",), ("sh", "pd"): ("pd",)})
    evidence = Evidence(demos)
    for _knowledge, trial in explore(evidence, oracle):
        evidence = evidence.with_trial(trial)
    learned = learn_sources(evidence)
    assert learned.relation.same_as(truth) and not learned.undecided
    assert learned.support[("sp", "fp")] == learned.support[("sh", "pd")] == "experiment"
    late = [t for t in evidence.trials if t.experiment.pair in oracle.late]
    assert [t.experiment.sequence[-2:] for t in late] == [
        (ExperimentStep(b), ExperimentStep(a)) for a, b in (t.experiment.pair for t in late)]
    assert all("blocked by" in t.describe() for t in late)


@pytest.mark.parametrize("blocked_by", [("pd",), ("fp", "pd"), ()], ids=["another part", "two parts", "none seen"])
def test_a_failure_of_the_first_part_not_blamed_on_b_alone_decides_nothing(root: Path,
                                                                           blocked_by: tuple[str, ...]) -> None:
    truth, demos = _cranfield_two_demos(root)
    evidence = Evidence(demos)
    with pytest.raises(PlannerError, match=r"decided nothing and would be run again: sp<fp stays open"):
        for _knowledge, trial in explore(evidence, _PhysicsOracle(truth, {("sp", "fp"): blocked_by})):
            evidence = evidence.with_trial(trial)
    learned = learn_sources(evidence)
    assert ("sp", "fp") in learned.knowledge.open and ("fp", "sp") not in learned.relation.pairs()
    assert [t.experiment.pair for t in learned.undecided] == [("sp", "fp")]
    assert "sp was not seen blocked by fp alone" in learned.summary()
    assert not set(learned.relation.pairs()) - set(truth.pairs()) - {("sp", "fp")}


def test_without_experiments_open_pairs_are_demonstrated_only() -> None:
    truth = close(Relation.from_pairs(("a", "b", "c"), [("a", "b")]))
    learned = learn_sources(Evidence(Demonstrations(truth.parts, (("a", "b", "c"),), ("d:1",))))
    assert learned.support == {("a", "b"): "demonstrated", ("a", "c"): "demonstrated", ("b", "c"): "demonstrated"}


def test_a_demonstrated_order_the_physics_shows_free_is_a_process_constraint() -> None:
    truth = close(Relation.from_pairs(("a", "b", "c"), [("a", "b")]))
    demos = Demonstrations(truth.parts, (("a", "b", "c"), ("a", "b", "c")), ("d:1", "d:2"))
    learned = learn_sources(_explored(Evidence(demos), truth))
    assert learned.relation.same_as(truth) and learned.support == {("a", "b"): "experiment"}
    assert learned.process == (("a", "c"), ("b", "c"))
    assert "process constraints to confirm with the user" in learned.summary()


def test_a_demonstration_against_geometry_names_both() -> None:
    demos = Demonstrations(("a", "b", "c"), (("b", "a", "c"),), ("demos.txt:3",))
    with pytest.raises(PrecedenceConflict, match=re.escape("demonstration demos.txt:3 places b before a, but a must "
                                                           "precede b: a<b by geo.lp (blocks)")):
        know(Evidence(demos, (("a", "b"),), "geo.lp", {("a", "b"): "blocks"}))


def test_an_experiment_against_a_demonstration_names_both() -> None:
    demos = Demonstrations(("a", "b", "c"), (("b", "a", "c"),), ("demos.txt:1",))
    trial = _trial(1, ("a", "b"), ["c", "b"], failed=2)
    with pytest.raises(PrecedenceConflict, match=re.escape("demonstration demos.txt:1 places b before a, but a must "
                                                           "precede b: a<b by experiment t.1 (a<b: failed at step 2, "
                                                           "jammed, x.lp:1)")):
        know(Evidence(demos, trials=(trial,)))


def test_two_experiments_against_each_other_name_both() -> None:
    demos = Demonstrations(("a", "b", "c"), (("a", "b", "c"),), ("demos.txt:1",))
    failed = _trial(1, ("a", "b"), ["c", "b"], failed=2)
    success = _trial(2, ("a", "b"), ["b"])
    with pytest.raises(PrecedenceConflict, match=r"experiment t\.2 \(a<b: b placed before a.*experiment t\.1"):
        know(Evidence(demos, trials=(failed, success)))


def test_a_failure_before_the_tested_step_is_an_error() -> None:
    demos = Demonstrations(("a", "b", "c"), (("a", "b", "c"),), ("demos.txt:1",))
    with pytest.raises(PrecedenceConflict, match="step 1 placing c failed before the tested step 2"):
        know(Evidence(demos, trials=(_trial(1, ("a", "b"), ["c", "b"], failed=1),)))


def test_a_failure_another_absent_part_may_explain_confirms_nothing() -> None:
    demos = Demonstrations(("a", "b", "c"), (("a", "b", "c"),), ("demos.txt:1",))
    learned = learn_sources(Evidence(demos, trials=(_trial(1, ("b", "c"), ["c"], failed=1),)))
    assert [t.experiment.id for t in learned.undecided] == ["t.1"]
    assert learned.support[("b", "c")] == "demonstrated"  # a may be the part c needs


def test_experiments_file_round_trip_and_bad_files(tmp_path: Path) -> None:
    truth = close(Relation.from_pairs(("a", "b", "c"), [("a", "b")]))
    evidence = _explored(Evidence(Demonstrations(truth.parts, (("a", "b", "c"),), ("d:1",))), truth)
    path = tmp_path / "experiments.lp"
    write_trials(path, evidence.trials)
    loaded = load_trials(path, truth.parts)
    assert [(t.experiment, t.outcome.outcome, t.outcome.failed_step) for t in loaded] == [
        (t.experiment, t.outcome.outcome, t.outcome.failed_step) for t in evidence.trials]
    path.write_text('experiment(1,"x",a,b).\nexperiment_step(1,1,q).\nexperiment_success(1).\n')
    with pytest.raises(PlannerError, match=re.escape(f"{path}:2: q is not a part (a b c)")):
        load_trials(path, truth.parts)
    path.write_text('experiment(1,"x",a,b).\nexperiment_step(1,1,a).\nexperiment_step(1,2,b).\nexperiment_success(1).\n')
    with pytest.raises(PlannerError, match="expected pair\\[0\\] absent"):
        load_trials(path, truth.parts)


@settings(max_examples=12, deadline=None)
@given(poset_with_demos(max_parts=5, max_demos=2))
def test_exploration_reaches_the_true_relation_and_no_pair_is_wrong(case: tuple[Relation, list[tuple[str, ...]]]
                                                                     ) -> None:
    truth, sequences = case
    demos = Demonstrations(truth.parts, tuple(sequences), tuple(f"d:{i}" for i in range(len(sequences))))
    learned = learn_sources(_explored(Evidence(demos), truth, "first"))
    assert learned.relation.same_as(truth)
    assert set(learned.support.values()) <= {"experiment"}


def test_information_bound_counts_the_relations_left() -> None:
    demos = Demonstrations(("a", "b", "c"), (("a", "b", "c"),), ("d:1",))
    bound = information_bound(know(Evidence(demos)))
    assert (bound.relations, bound.complete) == (7, True)  # the naturally labelled posets on 3 parts
    truth = close(Relation.from_pairs(("a", "b", "c"), [("a", "b")]))
    settled = information_bound(know(_explored(Evidence(demos), truth)))
    assert (settled.relations, settled.bits) == (1, 0.0)


def _orders_by_brute_force(parts: list[str], lower: set[tuple[str, str]], upper: set[tuple[str, str]]) -> int:
    """The transitive, antisymmetric T with lower ⊆ T ⊆ upper, every subset of the free pairs tried."""
    free = sorted(upper - lower)
    found = 0
    for chosen in itertools.product((False, True), repeat=len(free)):
        t = lower | {pair for pair, keep in zip(free, chosen) if keep}
        found += all((a, c) in t for a, b in t for b2, c in t if b == b2) and not any((b, a) in t for a, b in t)
    return found


@settings(max_examples=40, deadline=None)
@given(st.data())
def test_the_exact_count_of_orders_is_that_of_every_relation_tried(data: st.DataObject) -> None:
    n = data.draw(st.integers(1, 14))
    parts = [f"p{i:02d}" for i in data.draw(st.permutations(range(n)))]  # the order is not the names'
    forward = [(parts[i], parts[j]) for i in range(n) for j in range(i + 1, n)]
    chosen = data.draw(st.lists(st.sampled_from(forward), max_size=40)) if forward else []
    lower = {(a, b) for a, b in close(Relation.from_pairs(parts, chosen[:len(chosen) // 2])).pairs()}
    free = sorted(set(chosen[len(chosen) // 2:]) - lower)[:8]
    upper = lower | set(free)
    assert count_orders(parts, lower, upper, 30.0) == _orders_by_brute_force(parts, lower, upper)


def test_the_exact_count_agrees_with_clingo_and_gives_up_where_it_cannot_count() -> None:
    truth = true_relation(load_assembly("cranfield"))
    demos = Demonstrations(truth.parts, (("bp", "p1", "p2", "p3", "p4", "sh", "sp", "ph", "pd", "fp"),
                                         ("bp", "sh", "ph", "pd", "p4", "p3", "sp", "p2", "p1", "fp")), ("a", "b"))
    geometry = tuple(truth.pairs())[:8]  # bp before the others forced: clingo enumerates the rest in a second
    knowledge = know(Evidence(demos, geometry))
    exact = information_bound(knowledge, 30.0)
    clingo_count = enumerated_bound(knowledge, 60.0)
    assert exact.complete and clingo_count.complete and exact.relations == clingo_count.relations > 10000
    assert count_orders(truth.parts, knowledge.known, knowledge.known | knowledge.open, 0.0) is None  # no time
    cycle = {("a", "b"), ("b", "a")}
    assert count_orders(("a", "b"), set(), cycle, 10.0) is None
    nothing_known = know(Evidence(Demonstrations(("a", "b", "c"), (), ())))  # no demonstration: every pair open
    assert information_bound(nothing_known, 10.0) == Bound(19, True)  # the labelled posets on 3 parts, by clingo
