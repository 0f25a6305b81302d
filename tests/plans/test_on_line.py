"""Holes on one line (``on_line/3``, ``asp/encodings/plans/on_line.lp``): a bolt through a
bracket's flange hole into the plate's hole goes into the plate's hole, the bracket's being
no place of its own; it fits there only if it fits both; the bracket comes first. The
facts come from ``assembly.toml`` (``on_line``, ``owner``), which refuses a bad one."""

from __future__ import annotations

import tempfile
from pathlib import Path

import clingo
import pytest

from asp.plans.assign import (
    LearnedFacts,
    UnsolvableAssembly,
    all_assignments,
    feasible_assignment,
    load_learned_facts,
    product_facts,
)
from asp.plans.plans import PlanStep, check_assignment, check_plan, plans
from bridge import BridgeError
from bridge.assembly import load_assembly

# A plate (the base) with holes h1 and h2, a bracket whose flange hole lies on h1's line,
# two bolts: every bolt fits every hole.
FACTS = ("part(plate;bracket;bolt_a;bolt_b). hole(h1;h2;bracket_hole1).\n"
         "fits(bolt_a,h1). fits(bolt_a,h2). fits(bolt_a,bracket_hole1).\n"
         "fits(bolt_b,h1). fits(bolt_b,h2). fits(bolt_b,bracket_hole1).\n"
         "must_precede(plate,bracket). must_precede(plate,bolt_a). must_precede(plate,bolt_b).\n")
LINE = [clingo.parse_term("on_line(bracket_hole1,h1,bracket)")]


def _facts(text: str, product: list[clingo.Symbol]) -> LearnedFacts:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "learned.lp"
        path.write_text(text)
        return load_learned_facts([path], product)


def test_a_hole_on_another_s_line_is_no_place_of_its_own() -> None:
    """Without the fact the bracket's hole is a third place (a bolt planned into it, the
    wrong answer); with it the two bolts share the plate's two holes, every plan putting
    the bracket before the bolt in h1."""
    assert {"bolt_a": "bracket_hole1", "bolt_b": "h1"} in all_assignments(_facts(FACTS, []))
    facts = _facts(FACTS, LINE)
    assert all_assignments(facts) == [{"bolt_a": "h1", "bolt_b": "h2"}, {"bolt_a": "h2", "bolt_b": "h1"}]
    assert set(feasible_assignment(facts).values()) == {"h1", "h2"}
    found = plans(facts, 0)
    assert found
    for plan in found:
        order = [step.part for step in plan.steps]
        into_h1 = next(step.part for step in plan.steps if step.hole == "h1")
        assert order.index("bracket") < order.index(into_h1) and check_plan(facts, plan.steps) == []
    assert check_assignment(facts, {"bolt_a": "bracket_hole1", "bolt_b": "h1"}) == [
        "passed(bolt_a,bracket_hole1)"]


def test_a_part_fits_the_place_only_if_it_fits_every_hole_on_its_line() -> None:
    """bolt_a fits h1 but not the bracket's hole over it: h2 is its one place; with h2
    gone too, no hole, named."""
    facts = _facts(FACTS.replace("fits(bolt_a,bracket_hole1).", "no_fit(bolt_a,bracket_hole1)."), LINE)
    assert all_assignments(facts) == [{"bolt_a": "h2", "bolt_b": "h1"}]
    assert feasible_assignment(facts) == {"bolt_a": "h2", "bolt_b": "h1"}
    assert check_assignment(facts, {"bolt_a": "h1", "bolt_b": "h2"}) == ["not_fitting(bolt_a,bracket_hole1)"]
    alone = _facts(FACTS.replace("fits(bolt_a,bracket_hole1).", "").replace("fits(bolt_a,h2).", ""), LINE)
    with pytest.raises(UnsolvableAssembly, match=r"bolt_a fits no hole \(with every hole on its line: on_line/3\)"):
        feasible_assignment(alone)


def test_the_checker_names_a_plan_that_puts_the_bracket_after_its_bolt() -> None:
    facts = _facts(FACTS, LINE)
    steps = [PlanStep("plate", None), PlanStep("bolt_a", "h1"), PlanStep("bracket", None), PlanStep("bolt_b", "h2")]
    assert check_plan(facts, steps) == ["line_order(bracket,bolt_a)"]


def _product(folder: Path, hole: str) -> Path:
    folder.mkdir()
    (folder / "assembly.toml").write_text(
        'name = "bracket"\n'
        + "".join(f'\n[parts.{pid}]\nname = "{pid}"\nrole = "{role}"\n'
                  for pid, role in [("plate", "base"), ("bracket", "part"), ("bolt_a", "peg"), ("bolt_b", "peg")])
        + '\n[holes.h1]\nname = "h1"\nposition = [0.5, 0.0]\n\n[holes.h2]\nname = "h2"\nposition = [0.55, 0.0]\n'
        + f'\n[holes.bracket_hole1]\nname = "hole of bracket"\nposition = [0.5, 0.0]\n{hole}\n')
    return folder


def test_assembly_toml_gives_the_line_and_refuses_a_bad_one(tmp_path: Path) -> None:
    good = load_assembly(str(_product(tmp_path / "good", 'on_line = "h1"\nowner = "bracket"')))
    assert [atom for atom in product_facts(good) if atom.name == "on_line"] == LINE
    for name, hole, key in [("no_owner", 'on_line = "h1"', "owner"), ("no_hole", 'on_line = "h9"\nowner = "bracket"',
                                                                       "on_line"),
                            ("no_part", 'on_line = "h1"\nowner = "arm"', "owner")]:
        with pytest.raises(BridgeError, match=rf"\[holes.bracket_hole1\] {key}"):
            load_assembly(str(_product(tmp_path / name, hole)))
