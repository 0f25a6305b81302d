"""``session --precedence explore``: precedence and sizes in one session from at most 2
demonstrations and precedence experiments at the session's own cell (the session in the
test's process, ``executor serve`` a process of its own, Zenoh on loopback); a resumed
exploration runs no journaled experiment again."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import pytest

from asp import PlannerError
from asp.plans.assign import load_learned_facts
from asp.precedence.demos import Demonstrations, load_demos
from asp.precedence.explore.oracle import TruthOracle
from asp.precedence.explore.trials import load_trials
from asp.precedence.relation import Relation, true_relation
from asp.session.precedence import PRECEDENCE_JOURNAL, explore_precedence
from asp.session.run import _against_cell_orders
from asp.sizes.truth_oracle import TruthOracle as SizesTruth
from bridge.assembly import load_assembly
from bridge.precedence.experiment import PrecedenceExperiment, PrecedenceOutcome
from tests.conftest import TRUTH_SESSION, Runner
from tests.precedence.test_precedence_cell_order import CRANFIELD_ORDERS, breaks
from tests.session import exact_cell
from tests.session.test_session_resume import cranfield_copy


def _learned_exactly_the_truth(run: Path, assembly: str) -> None:
    """learned.lp holds exactly the product's precedence closure, and precedence_support.lp
    says what each learned pair rests on: here every one on the experiments."""
    truth = set(true_relation(load_assembly(assembly)).pairs())
    assert set(load_learned_facts([run / "learned.lp"]).must_precede) == truth
    support = (run / "precedence_support.lp").read_text()
    for a, b in truth:
        assert f"support({a},{b},experiment)." in support


class _Cell:
    """A cell answering from ``truth`` (:class:`TruthOracle`) that records the pairs it ran and,
    after ``dies_after`` of them, fails as a session killed in the middle would stop."""

    def __init__(self, truth: Relation, dies_after: int | None = None) -> None:
        self.truth, self.dies_after = TruthOracle(truth), dies_after
        self.cell, self.sim_s, self.wall_s = "c1", 0.0, 0.0
        self.ran: list[tuple[str, str]] = []

    def run(self, experiment: PrecedenceExperiment) -> PrecedenceOutcome:
        if len(self.ran) == self.dies_after:
            raise PlannerError("the session was killed")
        self.ran.append(experiment.pair)
        return self.truth.run(experiment)


def test_a_resumed_exploration_runs_no_journaled_experiment_again(tmp_path: Path, root: Path) -> None:
    truth = true_relation(load_assembly("cranfield"))
    every = load_demos(root / "data/cranfield/demos.txt", truth.parts)
    demos = Demonstrations(every.parts, every.sequences[:2], every.origins[:2])
    journal = tmp_path / PRECEDENCE_JOURNAL
    killed = _Cell(truth, dies_after=3)
    with pytest.raises(PlannerError, match="killed"):
        explore_precedence(demos, None, killed, journal=journal)
    assert [t.experiment.pair for t in load_trials(journal, truth.parts)] == killed.ran
    cell = _Cell(truth)
    resumed = explore_precedence(demos, None, cell, journal=journal)
    ran = killed.ran + cell.ran
    assert len(set(ran)) == len(ran) == len(resumed.trials)  # no pair run twice
    assert resumed.learned.relation.same_as(truth)
    assert [t.experiment.pair for t in load_trials(journal, truth.parts)] == ran


@pytest.mark.slow
@pytest.mark.timeout(180)
def test_truth_cell_session_explores_cranfield_to_its_exact_relation(tmp_path: Path, run_main: Runner) -> None:
    run = tmp_path / "run"
    done = run_main(*TRUTH_SESSION, "--precedence", "explore", "--out", str(run), timeout=150)
    assert done.returncode == 0, done.stderr
    result = json.loads(done.stdout)
    assert result["matches_truth"] is True
    _learned_exactly_the_truth(run, "cranfield")
    explored = json.loads((run / "session.json").read_text())["precedence_explored"]
    # Cranfield's demos.txt: its first two demonstrations order p2 before p1 and p3 before p4,
    # which the experiments show free: process constraints, not learned
    assert explored["process"] == [["p2", "p1"], ["p3", "p4"]]
    assert 1 <= explored["experiments"] <= 20 and explored["sim_s"] == 0.0
    assert explored["rests_on"][0] == "learned 20 pairs: 0 geometry, 20 experiment, 0 demonstrated, 0 assumed"


@pytest.mark.slow
@pytest.mark.timeout(400)
def test_sim_cell_session_explores_a_small_product_in_physics_with_the_layer_it_was_given(
        tmp_path: Path, run_main: Runner) -> None:
    """``--layer pi_phase_stop`` (no ILC) and a cell without pose errors (its sizes'
    experiments the shorter: :func:`tests.session.exact_cell`) reach the cell: it learns
    nothing across executions, so no ILC state appears in the run folder (the default layer
    writes one at the first fit: ``tests/session/test_session_sim.py``)."""
    run = tmp_path / "run"
    done = run_main("session", "--json", "--assembly", "spare", "--precedence", "explore", "--layer", "pi_phase_stop",
                    *exact_cell(tmp_path), "--out", str(run), timeout=360)
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["matches_truth"] is True
    _learned_exactly_the_truth(run, "spare")
    cell = json.loads((run / "session.json").read_text())["cell"]
    assert cell["layer"] == "pi_phase_stop" and cell["magnitudes"]["vision_sigma"] == 0.0
    assert not (run / "c1-ilc.json").exists()
    explored = json.loads((run / "session.json").read_text())["precedence_explored"]
    assert explored["experiments"] == 3 and explored["sim_s"] > 0.0  # bp<p1, bp<p2, bp<p3, each in physics
    assert (run / "experiments.lp").read_text().count(",1,unsupported).") == 3  # each peg fell: no plate


@pytest.mark.slow
@pytest.mark.timeout(180)
def test_truth_cell_session_keeps_the_cells_own_orders_and_reports_what_they_leave_undecided(
        tmp_path: Path, root: Path, run_main: Runner) -> None:
    """Cranfield with the six orders its import writes (the pegs before the front plate and
    the square ones before the spacer, all true precedence) and p2 before p1 (free in the
    product): no experiment breaks one, every true pair is learned, and p2<p1, which the cell
    can show only by p1 going in without p2 (never p2 after it), is reported undecidable by
    the cell and kept, not taken for a process constraint."""
    orders = (*CRANFIELD_ORDERS, ("p2", "p1"))
    product, run = cranfield_copy(root, tmp_path / "product"), tmp_path / "run"
    (product / "cell_order.lp").write_text("".join(f"cell_before({p},{q}).\n" for p, q in orders))
    done = run_main(*TRUTH_SESSION, "--precedence", "explore", "--assembly", str(product), "--out", str(run),
                    timeout=150)
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["matches_truth"] is True  # every true pair learned, the sizes equal
    trials = load_trials(run / "experiments.lp", true_relation(load_assembly(str(product))).parts)
    assert trials and not [t.experiment.id for t in trials if breaks([s.part for s in t.experiment.sequence], orders)]
    explored = json.loads((run / "session.json").read_text())["precedence_explored"]
    assert explored["process"] == [["p3", "p4"]]
    assert [pair[:2] for pair in explored["undecidable"]] == [["bp", "p1"], ["p2", "fp"], ["p2", "p1"]]
    assert any(line.startswith("undecidable by this cell: p2<p1: p1 went in without p2")
               for line in explored["rests_on"])
    assert ("p2", "p1") in load_learned_facts([run / "learned.lp"]).must_precede


def test_a_size_trial_that_would_break_a_cells_order_is_taken_from_sizes_lp(tmp_path: Path, root: Path) -> None:
    """A trial stands the owner of the pin it tries at its goal (``Scene.feature``): were s1
    a pin of the spacer, p3's trial onto it would put p3 in after sp, against the order
    p3 before sp; that pair is no experiment, its outcome the CAD's, stated."""
    product = cranfield_copy(root, tmp_path / "product")
    (product / "cell_order.lp").write_text("cell_before(p3,sp).\n")
    assembly = replace(load_assembly(str(product)), hole_owners={"s1": "sp"})
    truth = SizesTruth.from_assembly(str(product))
    pairs = [(p, h) for p in truth.parts for h in truth.holes]
    taken, statement = _against_cell_orders(assembly, pairs, truth, [])
    assert taken == [(("p3", "s1"), "fit")]
    assert statement is not None and "1 pairs whose trial would stand a part the cell puts in after the one tried" \
        in statement and "p3->s1 (sp in place)" in statement
    assert _against_cell_orders(assembly, pairs, truth, [(("p3", "s1"), "fit")]) == ([], None)  # decided already
    assert _against_cell_orders(replace(assembly, hole_owners={}), pairs, truth, []) == ([], None)
