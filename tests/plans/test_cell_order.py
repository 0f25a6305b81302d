"""The cell's own orders (``cell_before/2``: the fingers' grip of a peg needs it in before
a part that would meet them, docs/cell.md#the-fingers-grip): every plan and every drawn
plan keeps them, the checker names a plan that breaks them, and a cycle with the
precedence is not solvable."""

from __future__ import annotations

from pathlib import Path

import pytest

from asp.bench.assemble_plans import draw_plans
from asp.plans.assign import UnsolvableAssembly, load_learned_facts
from asp.plans.plans import PlanStep, check_plan, plans
from assembly_constraints.cli import main

PRODUCT = "part(bp;peg;frame;pin). hole(h). fits(peg,h). must_precede(bp,peg). must_precede(bp,frame).\n"
"""A base plate, a peg, a frame the precedence lets be in place before the peg, a free part."""


def _facts(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "learned.lp"
    path.write_text(text)
    return path


def _before(order: list[str], first: str, then: str) -> bool:
    return order.index(first) < order.index(then)


def test_every_plan_puts_the_peg_in_before_the_frame(tmp_path: Path) -> None:
    alone = plans(load_learned_facts([_facts(tmp_path, PRODUCT)]), 0)
    assert any(not _before([s.part for s in p.steps], "peg", "frame") for p in alone)  # the precedence admits it
    facts = load_learned_facts([_facts(tmp_path, PRODUCT + "cell_before(peg,frame).\n")])
    found = plans(facts, 0)
    assert found and all(_before([s.part for s in p.steps], "peg", "frame") for p in found)
    assert len(found) == len(alone) // 2  # the peg and the frame are exchangeable: half the orders
    assert facts.must_precede == load_learned_facts([_facts(tmp_path, PRODUCT)]).must_precede  # not precedence
    drawn = draw_plans(facts, 40, seed=3)
    assert all(_before([s.part for s in p.steps], "peg", "frame") for p in drawn)
    frame_first = [PlanStep("bp", None), PlanStep("frame", None), PlanStep("peg", "h"), PlanStep("pin", None)]
    assert check_plan(facts, frame_first) == ["cell_order(peg,frame)"]
    assert check_plan(facts, [frame_first[0], frame_first[2], frame_first[1], frame_first[3]]) == []


def test_a_cell_order_against_the_precedence_is_not_solvable(tmp_path: Path,
                                                             capsys: pytest.CaptureFixture[str]) -> None:
    path = _facts(tmp_path, PRODUCT + "must_precede(frame,peg). cell_before(peg,frame).\n")
    with pytest.raises(UnsolvableAssembly, match="cell's own orders .* cycle through frame peg"):
        plans(load_learned_facts([path]), 1)
    assert main(["plan", str(path)]) == 3
    assert "cycle through frame peg" in capsys.readouterr().err


def test_a_cell_order_of_an_unknown_part_is_bad_input(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["plan", str(_facts(tmp_path, PRODUCT + "cell_before(peg,lid).\n"))]) == 2
    assert "cell_before(peg,lid): expected two part/1" in capsys.readouterr().err
