"""Holes that take several parts (``capacity/2``: a bush and a gear onto one pin) and
holes the cell cannot put a part in (``out_of_reach/2``): assignments and plans against
brute force, the checker, the optimal plans, bad input, and a hand-written product
planned from its ``assembly.toml``."""

from __future__ import annotations

import json
import tempfile
from pathlib import Path

import clingo
import pytest
from clintest.assertion import Equals
from clintest.quantifier import Exact
from clintest.solver import Clingo
from clintest.test import Assert
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from asp.plans.assign import (
    LearnedFacts,
    UnsolvableAssembly,
    all_assignments,
    feasible_assignment,
    load_learned_facts,
    product_facts,
)
from asp.plans.plans import check_assignment, check_plan, plans, travel_facts
from bridge import BridgeError
from bridge.assembly import Assembly, Hole, Part, load_assembly
from tests.conftest import ROOT
from tests.plans.test_plan_cases import assemblies, brute_force_assignments, random_facts
from tests.plans.test_plan_cranfield import _brute_force_optimum

ENCODINGS = ROOT / "asp" / "encodings"

# capacities of up to 3 holes, and (part, hole) pairs out of the cell's reach
capacities = st.lists(st.integers(1, 3), max_size=3)
reach = st.sets(st.tuples(st.integers(0, 3), st.integers(0, 2)), max_size=3)


@settings(max_examples=40, deadline=None)
@given(assemblies, capacities, reach)
def test_assignments_and_plans_are_exactly_the_brute_force_ones(case, capacity: list[int],
                                                                 unreachable: set[tuple[int, int]]) -> None:
    """Every assignment and every plan, and the one ``session`` takes, are the brute
    force ones; "not solvable" only when brute force finds none."""
    facts = random_facts(case, capacity, unreachable)
    expected = brute_force_assignments(facts)
    try:
        chosen = feasible_assignment(facts)
    except UnsolvableAssembly as exc:
        assert expected == [] and set(exc.parts) <= set(facts.needs_hole)
        with pytest.raises(UnsolvableAssembly):
            plans(facts, 1)
        return
    assert chosen in expected and check_assignment(facts, chosen) == []
    assert all_assignments(facts) == sorted(expected, key=lambda a: sorted(a.items()))
    for plan in plans(facts, 0):
        assert check_plan(facts, plan.steps) == []
        assert {s.part: s.hole for s in plan.steps if s.hole} in expected


@settings(max_examples=15, deadline=None)
@given(assemblies, capacities, st.lists(st.tuples(st.integers(0, 800), st.integers(-500, 500)),
                                        min_size=7, max_size=7))
def test_optimal_plans_with_stacked_holes_match_brute_force(case, capacity: list[int],
                                                            spots_mm: list[tuple[int, int]]) -> None:
    """The travel cost pays the leg out of a hole once per part put in it."""
    facts = random_facts(case, capacity)
    spots = [(x / 1000.0, y / 1000.0) for x, y in spots_mm]
    cell = Assembly(folder=ROOT, name="random cell",
                    parts=tuple(Part(p, p, "peg", spot) for p, spot in zip(facts.parts, spots)),
                    holes=tuple(Hole(h, h, "round", spot) for h, spot in zip(facts.holes, spots[4:])))
    assume(brute_force_assignments(facts))
    found = plans(facts, 0, optimal=True, travel=travel_facts(cell, facts))
    best, winners = _brute_force_optimum(facts, cell)
    assert {plan.cost for plan in found} == {best} and {plan.steps for plan in found} == winners


STACK = "part(a;b;c). hole(h1;h2). fits(a,h1). fits(b,h1). fits(c,h1). fits(c,h2). capacity(h1,2).\n"
# name, the plan or assignment, the errors the checker must derive (exactly)
CHECK_CASES = [
    ("two ordered parts on a hole of capacity 2", "must_precede(a,b). assigned(a,h1). assigned(b,h1). "
                                                  "assigned(c,h2).", set()),
    ("three parts on a hole of capacity 2", "must_precede(a,b). must_precede(b,c). must_precede(a,c). "
                                            "assigned(a,h1). "
                                            "assigned(b,h1). assigned(c,h1).", {"error(over_capacity(h1))"}),
    ("two parts no precedence orders", "assigned(a,h1). assigned(b,h1). assigned(c,h2).",
     {"error(unordered(a,b,h1))"}),
    ("a hole out of the cell's reach", "out_of_reach(c,h2). must_precede(a,b). assigned(a,h1). "
                                       "assigned(b,h1). assigned(c,h2).", {"error(out_of_reach(c,h2))"}),
    ("a part held elsewhere in the CAD", "cad_hole(c,h1). must_precede(a,b). assigned(a,h1). "
                                         "assigned(b,h1). assigned(c,h2).", {"error(out_of_reach(c,h2))",
                                                                             "error(out_of_reach(a,h1))",
                                                                             "error(out_of_reach(b,h1))"}),
    ("a hole the CAD gives another part", "cad_hole(c,h2). must_precede(a,b). assigned(a,h1). assigned(b,h1). "
                                          "assigned(c,h2).", set()),
]


@pytest.mark.parametrize("name,given,errors", CHECK_CASES, ids=[c[0] for c in CHECK_CASES])
def test_checker_stacked_cases(name: str, given: str, errors: set[str]) -> None:
    test = Assert(Exact(1), Equals(set[clingo.Symbol | str](errors)))
    Clingo(program=STACK + given, files=[str(ENCODINGS / "check_plan.lp")]).solve(test)
    test.assert_()


def test_parts_no_precedence_orders_do_not_share_a_hole(tmp_path: Path, run_main) -> None:
    """Room enough, but their order along the pin is unknown: not solvable, named."""
    facts = tmp_path / "learned.lp"
    facts.write_text("part(a;b). hole(h). fits(a,h). fits(b,h). capacity(h,2).\n")
    done = run_main("plan", str(facts), "--json")
    assert done.returncode == 3 and json.loads(done.stdout)["parts"] == ["a", "b"]
    assert "no precedence orders onto one hole (e.g. a b on h)" in done.stderr
    facts.write_text("part(a;b). hole(h). fits(a,h). fits(b,h). capacity(h,2). must_precede(b,a).\n")
    assert run_main("plan", str(facts), "-n", "0").stdout == "b->h, a->h\n"


@pytest.mark.parametrize("atom", ["capacity(h,0)", "capacity(x,2)", "capacity(h,two)", "capacity(h,2). capacity(h,3)"])
def test_a_bad_capacity_is_refused_naming_it(tmp_path: Path, run_main, atom: str) -> None:
    facts = tmp_path / "learned.lp"
    facts.write_text(f"part(a). hole(h). fits(a,h). {atom}.\n")
    done = run_main("plan", str(facts))
    assert done.returncode == 2 and done.stderr.count("\n") == 1
    assert "expected capacity(H,C), H a hole/1" in done.stderr and str(facts) in done.stderr


def stacked_product(folder: Path) -> Path:
    """A base, a bush and a gear both onto one pin (the bush first), a peg into a hole:
    ``assembly.toml`` (the pin's capacity 2), ``sizes.lp``, ``precedence.lp``, ``demos.txt``."""
    folder.mkdir()
    parts = {"bp": ("base", 0.25), "bush": ("peg", 0.30), "gear": ("peg", 0.35), "peg": ("peg", 0.40)}
    lines = ['name = "stacked"']
    for pid, (role, x) in parts.items():
        lines += ["", f"[parts.{pid}]", f'name = "{pid}"', f'role = "{role}"', f"start = [{x}, 0.40]"]
    lines += ["", "[holes.pin]", 'name = "pin (bush, then gear)"', "position = [0.55, 0.0]", "capacity = 2",
              "", "[holes.hole]", 'name = "hole"', "position = [0.60, 0.0]"]
    (folder / "assembly.toml").write_text("\n".join(lines) + "\n")
    (folder / "sizes.lp").write_text("part(bush;gear;peg). hole(pin;hole).\n"
                                     "fits(bush,pin). fits(gear,pin). fits(peg,hole).\n")
    (folder / "precedence.lp").write_text("part(bp;bush;gear;peg).\n"
                                          "precedence_edge(bp,bush). precedence_edge(bp,peg). "
                                          "precedence_edge(bush,gear).\n")
    (folder / "demos.txt").write_text("bp bush gear peg\nbp peg bush gear\n")
    return folder


def test_a_product_stacking_two_parts_on_a_pin_plans_both_onto_it(tmp_path: Path, run_main) -> None:
    """The pin's capacity comes from ``assembly.toml`` (``--assembly``); without it the
    pin takes one part and the product is not solvable."""
    product = stacked_product(tmp_path / "stacked")
    sizes, precedence = str(product / "sizes.lp"), str(product / "precedence.lp")
    done = run_main("plan", sizes, precedence, "--assembly", str(product), "-n", "0", "--json")
    found = json.loads(done.stdout)["plans"]
    assert done.returncode == 0 and len(found) == 3
    for plan in found:
        order = [step["part"] for step in plan]
        assert {step["part"]: step["hole"] for step in plan} == {"bp": None, "bush": "pin", "gear": "pin",
                                                                 "peg": "hole"}
        assert order.index("bush") < order.index("gear")
    optimal = run_main("plan", sizes, precedence, "--assembly", str(product), "--optimal", "--json")
    assert optimal.returncode == 0 and json.loads(optimal.stdout)["cost"] > 0
    alone = run_main("plan", sizes, precedence)
    assert alone.returncode == 3 and "parts bush gear fit only 1 hole(s) between them (pin)" in alone.stderr


def test_a_part_the_cell_inserts_never_goes_into_a_hole_of_a_part_placed_by_hand() -> None:
    """A bolt fits a hole of the plate and one of a bracket placed by hand: the cell can
    only use the plate's (``out_of_reach/2`` from the product), so every plan takes it."""
    cell = Assembly(folder=ROOT, name="bracket", parts=(Part("plate", "plate", "base"), Part("bracket", "bracket"),
                                                          Part("bolt", "bolt", "peg")),
                    holes=(Hole("h1", "hole of the plate"), Hole("bracket_hole1", "hole of the bracket")),
                    manual={"bracket": "placed by hand"}, cell_holes=frozenset({"h1"}))
    assert product_facts(cell) == [clingo.parse_term("out_of_reach(bolt,bracket_hole1)")]
    facts_text = "part(plate;bracket;bolt). hole(h1;bracket_hole1). fits(bolt,h1). fits(bolt,bracket_hole1).\n"
    with_reach = _facts(facts_text, product_facts(cell))
    assert [plan.steps for plan in plans(with_reach, 0)] and all(
        {s.part: s.hole for s in plan.steps if s.hole} == {"bolt": "h1"} for plan in plans(with_reach, 0))
    assert check_assignment(with_reach, {"bolt": "bracket_hole1"}) == ["out_of_reach(bolt,bracket_hole1)"]
    assert {"bolt": "bracket_hole1"} in all_assignments(_facts(facts_text, []))
    only_bracket = _facts(facts_text.replace("fits(bolt,h1). ", ""), product_facts(cell))
    with pytest.raises(UnsolvableAssembly, match="part bolt fits no hole the cell can use"):
        feasible_assignment(only_bracket)


def _facts(text: str, product: list[clingo.Symbol]) -> LearnedFacts:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "learned.lp"
        path.write_text(text)
        return load_learned_facts([path], product)


def test_bad_capacity_in_assembly_toml_is_refused(tmp_path: Path) -> None:
    product = stacked_product(tmp_path / "stacked")
    toml = product / "assembly.toml"
    toml.write_text(toml.read_text().replace("capacity = 2", "capacity = 0"))
    with pytest.raises(BridgeError, match="capacity"):
        load_assembly(str(product))
