"""Algorithm 1: the paper's battery example, Cranfield, properties, wrong demonstrations."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings

from asp.precedence.count import count_linear_extensions, linear_extensions
from asp.precedence.demos import Demonstrations, load_demos, parse_demos
from asp.precedence.learn import learn_must_precede, pair_evidence, suspects
from asp.precedence.relation import Relation, reduction, true_relation
from bridge.assembly import load_assembly
from tests._precedence_helpers import poset_with_demos


def test_battery_fig3_gives_fig4_and_the_five_listed_sequences() -> None:
    battery = load_assembly("battery")
    learned = learn_must_precede(load_demos(battery.file("demos.txt"), battery.part_ids))
    assert set(learned.pairs()) == {
        ("o", "r1"), ("o", "r2"), ("o", "i1"), ("o", "i2"), ("r1", "i1"), ("r2", "i1"), ("r2", "i2"),
    }
    assert set(reduction(learned)) == {("o", "r1"), ("o", "r2"), ("r1", "i1"), ("r2", "i1"), ("r2", "i2")}
    listed = {  # paper 2.1: the two demonstrations and the three further sequences
        "o r2 i2 r1 i1", "o r1 r2 i1 i2", "o r1 r2 i2 i1", "o r2 r1 i1 i2", "o r2 r1 i2 i1",
    }
    assert {" ".join(s) for s in linear_extensions(learned)} == listed
    assert count_linear_extensions(learned) == 5


def test_one_demonstration_admits_only_itself_and_none_admits_nothing() -> None:
    demos = parse_demos("c a b\n", "d.txt")
    learned = learn_must_precede(demos)
    assert list(linear_extensions(learned)) == [("c", "a", "b")]
    no_demos = Demonstrations(("a", "b"), (), ())
    assert count_linear_extensions(learn_must_precede(no_demos)) == 0  # paper: all ones


def test_cranfield_demonstrations_learn_the_true_relation_exactly() -> None:
    cranfield = load_assembly("cranfield")
    learned = learn_must_precede(load_demos(cranfield.file("demos.txt"), cranfield.part_ids))
    assert learned.same_as(true_relation(cranfield))
    assert count_linear_extensions(learned) == 5320


def test_cranfield_demonstrations_hold_two_realizers_and_no_suspect() -> None:
    cranfield = load_assembly("cranfield")
    demos = load_demos(cranfield.file("demos.txt"), cranfield.part_ids)
    assert suspects(demos) == []
    by_line = {origin.rsplit(":", 1)[1]: s for origin, s in zip(demos.origins, demos.sequences)}
    for lines in (("7", "9"), ("8", "10")):  # as the file's comment says
        pair = Demonstrations(demos.parts, tuple(by_line[n] for n in lines), lines)
        assert learn_must_precede(pair).same_as(true_relation(cranfield))


@settings(max_examples=60, deadline=None)
@given(poset_with_demos())
def test_learned_contains_truth_admits_demos_and_only_feasible_sequences(case: tuple[Relation, list]) -> None:
    truth, sequences = case
    learned = learn_must_precede(Demonstrations(truth.parts, tuple(sequences), tuple("x" * len(sequences))))
    assert np.all(learned.matrix >= truth.matrix)  # paper eq. 10
    assert all(learned.admits(s) for s in sequences)
    admitted = list(linear_extensions(learned))
    assert all(truth.admits(s) for s in admitted)
    assert len(admitted) == count_linear_extensions(learned)


def _battery_with_a_wrong_demo() -> Demonstrations:
    # Four feasible demonstrations (each free pair seen twice both ways) and a wrong one
    # that inserts i1 before removing r1.
    text = "o r1 i1 r2 i2\no r2 i2 r1 i1\no r1 i1 r2 i2\no r2 i2 r1 i1\no i1 r1 r2 i2  # wrong\n"
    return parse_demos(text, "demos.txt")


def test_a_wrong_demonstration_is_flagged_and_min_support_keeps_the_constraint() -> None:
    demos = _battery_with_a_wrong_demo()
    plain = learn_must_precede(demos)
    assert ("r1", "i1") not in plain.pairs()  # intersection silently drops a true constraint
    flagged = suspects(demos)
    assert [s.origin for s in flagged] == ["demos.txt:5"]
    assert ("r1", "i1") in flagged[0].removes
    robust = learn_must_precede(demos, min_support=2)
    assert set(robust.pairs()) == {("o", "r1"), ("o", "r2"), ("o", "i1"), ("o", "i2"), ("r1", "i1"), ("r2", "i2")}
    evidence = {tuple(e["pair"]): (e["support"], e["contradict"]) for e in pair_evidence(demos)}
    assert evidence[("r1", "i1")] == (4, 1)
    assert evidence[("r1", "r2")] == (3, 2)


def test_learned_relation_facts_are_queryable_by_plain_clingo(tmp_path, run_python) -> None:
    from asp.precedence.relation import precedence_facts
    from asp.solve import encoding, write_facts

    learned = learn_must_precede(parse_demos("o r2 i2 r1 i1\no r1 r2 i1 i2\n", "d.txt"))
    path = tmp_path / "learned.lp"
    write_facts(path, precedence_facts(learned))
    result = run_python("clingo", str(encoding("sequences.lp")), str(path), "0", "--quiet=2", timeout=60)
    assert "Models       : 5" in result.stdout
