"""Hole assignment: named ASP cases for assign.lp, the greedy assignment against brute
force on random biorders, Cranfield, and the ``assign`` command."""

from __future__ import annotations

import itertools
import json
import tempfile
from pathlib import Path

import pytest
from clintest.assertion import Equals, Or, True_
from clintest.quantifier import All, Exact
from clintest.solver import Clingo
from clintest.test import And, Assert
from hypothesis import given, settings
from hypothesis import strategies as st

from asp.plans.assign import (
    LearnedFacts,
    UnsolvableAssembly,
    all_assignments,
    feasible_assignment,
    greedy_assignment,
    load_learned_facts,
)
from asp.plans.plans import check_assignment
from asp.solve import encoding, fact, write_facts
from tests.conftest import ROOT

ASSIGNMENTS_LP = str(encoding("assignments.lp"))
CRANFIELD_SIZES = ROOT / "data" / "cranfield" / "sizes.lp"

# name, facts, expected models (each the set of assigned/2 atoms); [] = unsatisfiable
ASSIGN_CASES = [
    ("one part one hole", "part(a). hole(h). fits(a,h).", [{"assigned(a,h)"}]),
    ("nested sizes leave one choice",
     "part(a;b). hole(h1;h2). fits(a,h1). fits(a,h2). fits(b,h2).",
     [{"assigned(a,h1)", "assigned(b,h2)"}]),
    ("equal parts swap holes",
     "part(a;b). hole(h1;h2). fits(a,h1). fits(a,h2). fits(b,h1). fits(b,h2).",
     [{"assigned(a,h1)", "assigned(b,h2)"}, {"assigned(a,h2)", "assigned(b,h1)"}]),
    ("a part without sizes needs no hole", "part(a;x). hole(h). fits(a,h).",
     [{"assigned(a,h)"}]),
    ("spare hole", "part(a). hole(h1;h2). fits(a,h2). no_fit(a,h1).", [{"assigned(a,h2)"}]),
    ("part fitting nothing is unsat", "part(a). hole(h). no_fit(a,h).", []),
    ("declared needs_hole without sizes is unsat", "part(a). hole(h). needs_hole(a).", []),
    ("a part pressed in by hand needs no hole",
     "part(a;b). hole(h1;h2). fits(a,h1). no_fit(a,h2). no_fit(b,h1). no_fit(b,h2). cad_hole(b,h2). pressed(b).",
     [{"assigned(a,h1)"}]),
    ("a part not pressed into a CAD hole it fits none of is unsat",
     "part(a;b). hole(h1;h2). fits(a,h1). no_fit(a,h2). no_fit(b,h1). no_fit(b,h2). cad_hole(b,h2).", []),
    ("two parts one hole is unsat",
     "part(a;b). hole(h1;h2). fits(a,h1). fits(b,h1). no_fit(a,h2). no_fit(b,h2).", []),
]


@pytest.mark.parametrize("name,facts,expected", ASSIGN_CASES, ids=[c[0] for c in ASSIGN_CASES])
def test_assign_encoding_named_cases(name: str, facts: str, expected: list[set[str]]) -> None:
    test: Assert | And = Assert(Exact(len(expected)), True_())
    if expected:
        test = And(test, Assert(All(), Or(*(Equals(set(model)) for model in expected))))
    Clingo(arguments=["0"], program=facts, files=[ASSIGNMENTS_LP]).solve(test)
    test.assert_()


def _facts_file(tmp_path: Path, fits: dict[str, list[str]], holes: list[str]) -> Path:
    atoms = [fact("part", p) for p in fits] + [fact("hole", h) for h in holes]
    for part, fitting in fits.items():
        atoms += [fact("fits" if h in fitting else "no_fit", part, h) for h in holes]
    path = tmp_path / "learned.lp"
    write_facts(path, atoms)
    return path


def _learned(fits: dict[str, list[str]], holes: list[str]) -> LearnedFacts:
    with tempfile.TemporaryDirectory() as tmp:
        return load_learned_facts([_facts_file(Path(tmp), fits, holes)])


def _brute_force(facts: LearnedFacts) -> list[dict[str, str]]:
    """Every injective part -> fitting hole map, by trying all hole permutations."""
    parts = list(facts.needs_hole)
    found = {
        tuple(zip(parts, holes))
        for holes in itertools.permutations(facts.holes, len(parts))
        if all((p, h) in facts.fits for p, h in zip(parts, holes))
    }
    return sorted((dict(a) for a in found), key=lambda a: sorted(a.items()))


def test_cranfield_assignments_are_all_feasible_ones_and_greedy_is_one() -> None:
    facts = load_learned_facts([CRANFIELD_SIZES])
    assignments = all_assignments(facts)
    assert assignments == _brute_force(facts)
    assert greedy_assignment(facts) in assignments
    assert all(check_assignment(facts, a) == [] for a in assignments)


biorders = st.integers(1, 5).flatmap(
    lambda n_parts: st.tuples(
        st.lists(st.integers(0, 6), min_size=n_parts, max_size=n_parts),
        st.lists(st.integers(0, 6), min_size=1, max_size=5),
    )
)


@settings(max_examples=40, deadline=None)
@given(biorders)
def test_greedy_solves_exactly_the_solvable_biorders(sizes: tuple[list[int], list[int]]) -> None:
    """Sizes on a line (fits = part smaller than hole): greedy finds an assignment iff
    one exists; when none does, the named part and the parts at least as big as it
    outnumber the holes they fit."""
    part_sizes, hole_sizes = sizes
    parts = [f"p{i}" for i in range(len(part_sizes))]
    holes = [f"h{i}" for i in range(len(hole_sizes))]
    fits = {p: [h for h, hs in zip(holes, hole_sizes) if ps < hs] for p, ps in zip(parts, part_sizes)}
    facts = _learned(fits, holes)
    expected = _brute_force(facts)
    try:
        greedy = greedy_assignment(facts)
    except UnsolvableAssembly as exc:
        assert expected == []
        at_least_as_big = [p for p in parts if set(fits[p]) <= set(fits[exc.part])]
        assert len(at_least_as_big) > len(fits[exc.part])
        with pytest.raises(UnsolvableAssembly):
            all_assignments(facts)
        return
    assert check_assignment(facts, greedy) == []
    assert all_assignments(facts) == expected


relations = st.tuples(st.integers(1, 4), st.integers(1, 4)).flatmap(
    lambda size: st.lists(
        st.lists(st.booleans(), min_size=size[1], max_size=size[1]), min_size=size[0], max_size=size[0]
    )
)


@settings(max_examples=40, deadline=None)
@given(relations)
def test_feasible_assignment_exists_whenever_one_does(table: list[list[bool]]) -> None:
    """Any fits/2 table, not only biorders: an assignment iff brute force finds one."""
    holes = [f"h{i}" for i in range(len(table[0]))]
    fits = {f"p{i}": [h for h, ok in zip(holes, row) if ok] for i, row in enumerate(table)}
    facts = _learned(fits, holes)
    expected = _brute_force(facts)
    try:
        assignment = feasible_assignment(facts)
    except UnsolvableAssembly as exc:
        # Hall's condition fails for the named parts: fewer holes between them than parts.
        assert expected == [] and set(exc.parts) <= set(fits)
        assert len({h for p in exc.parts for h in fits[p]}) < len(exc.parts)
        with pytest.raises(UnsolvableAssembly):
            all_assignments(facts)
        return
    assert assignment in expected and check_assignment(facts, assignment) == []


def test_feasible_assignment_when_greedy_gets_stuck() -> None:
    """Not a biorder: greedy puts p0 into h2 and p1 into h1, leaving p2 nothing."""
    fits = {"p0": ["h2", "h3"], "p1": ["h1", "h3"], "p2": ["h1", "h2"]}
    facts = _learned(fits, ["h1", "h2", "h3"])
    with pytest.raises(UnsolvableAssembly):
        greedy_assignment(facts)
    assignment = feasible_assignment(facts)
    assert assignment in _brute_force(facts) and check_assignment(facts, assignment) == []


def test_assign_command_json(tmp_path: Path, run_main) -> None:
    greedy = json.loads(run_main("assign", str(CRANFIELD_SIZES), "--json").stdout)
    every = json.loads(run_main("assign", str(CRANFIELD_SIZES), "--all", "--json").stdout)
    facts = load_learned_facts([CRANFIELD_SIZES])
    assert list(greedy) == ["assignments"] and len(greedy["assignments"]) == 1
    assert greedy["assignments"][0] in every["assignments"]
    assert every["assignments"] == all_assignments(facts)


def test_assign_command_names_the_part_without_hole(tmp_path: Path, run_main) -> None:
    path = _facts_file(tmp_path, {"a": ["h1", "h2"], "b": ["h2"], "c": ["h2"]}, ["h1", "h2"])
    for extra in ([], ["--all"]):
        done = run_main("assign", str(path), "--json", *extra)
        assert done.returncode == 3
        report = json.loads(done.stdout)
        assert report["assignments"] == [] and report["parts"] == ["b", "c"]
        assert "parts b c fit only 1 hole(s) between them (h2)" in done.stderr


def test_assign_command_bad_input(tmp_path: Path, run_main) -> None:
    broken = tmp_path / "broken.lp"
    broken.write_text("part(a). fits(a,\n")
    unknown = tmp_path / "unknown.lp"
    unknown.write_text("part(a). hole(h). fits(a,zz).\n")
    reserved = tmp_path / "reserved.lp"
    reserved.write_text("part(a). hole(none). fits(a,none).\n")
    for path, word in ((broken, "parse"), (unknown, "zz"), (reserved, "reserved")):
        done = run_main("assign", str(path))
        assert done.returncode == 2 and word in done.stderr
    assert run_main("assign", "--help").returncode == 0
