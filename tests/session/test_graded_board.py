"""The graded-peg board (data/graded) is learned like Cranfield: its sizes by experiments
against its geometry, its precedence from its demonstrations."""

from __future__ import annotations

import pytest

from asp.precedence.demos import load_demos
from asp.precedence.learn import learn_must_precede
from asp.precedence.relation import true_relation
from asp.sizes.learner import learn_sizes
from asp.sizes.truth_oracle import TruthOracle
from bridge.assembly import load_assembly


def test_the_graded_board_is_learned_in_process() -> None:
    board = load_assembly("graded")
    truth = TruthOracle.from_assembly("graded")
    sizes = learn_sizes(truth.parts, truth.holes, truth, "best")
    assert sizes.knowledge.fits == truth.fits
    assert sizes.count < 6 * 7  # the staircase is inferred, not every pair tried
    learned = learn_must_precede(load_demos(board.file("demos.txt"), board.part_ids))
    assert set(learned.pairs()) == set(true_relation(board).pairs())


@pytest.mark.slow
def test_a_session_with_truth_cells_learns_the_graded_board(run_session, tmp_path) -> None:
    result = run_session("--assembly", "graded", "--out", str(tmp_path / "run"))
    assert result["matches_truth"] is True
    truth = true_relation(load_assembly("graded")).pairs()
    assert {tuple(pair) for pair in result["must_precede"]} == set(truth) and ("p6", "bar") in truth
    assert len(result["fits"]) == 24
