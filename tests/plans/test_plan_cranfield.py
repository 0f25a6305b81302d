"""Cranfield plans from its learned-facts equivalent (true precedence closed, Fig. 5
sizes): plans, optimal plans against brute force over every plan (also on random small
cells), the ``plan`` command and the plain clingo command lines of the docs. Every
plan goes through the checker."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import clingo
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from asp import PlannerError
from asp.plans.assign import LearnedFacts, all_assignments, load_learned_facts
from asp.plans.plans import PlanStep, check_plan, plans, travel_facts
from asp.precedence.relation import load_relation
from asp.solve import load_atoms, write_facts
from bridge.assembly import Assembly, Hole, Part, load_assembly
from tests.conftest import ROOT
from tests.plans.test_plan_cases import assemblies, brute_force_assignments, linear_extensions, random_facts

CRANFIELD = ROOT / "data" / "cranfield"


@pytest.fixture(scope="module")
def learned(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Cranfield's learned.lp as the learners would write it."""
    path = tmp_path_factory.mktemp("cranfield") / "learned.lp"
    closed = load_atoms([CRANFIELD / "precedence.lp"], encodings=["precedence_closure.lp"])
    write_facts(path, [*closed, *load_atoms([CRANFIELD / "sizes.lp"])])
    return path


@pytest.fixture(scope="module")
def facts(learned: Path) -> LearnedFacts:
    return load_learned_facts([learned])


def test_cranfield_plans_are_valid_and_distinct(facts: LearnedFacts) -> None:
    found = plans(facts, 40)
    assert len({plan.steps for plan in found}) == 40
    for plan in found:
        assert [step.part for step in plan.steps].count("bp") == 1
        assert check_plan(facts, plan.steps) == []


def _brute_force_optimum(
    facts: LearnedFacts, assembly: Assembly
) -> tuple[int, set[tuple[PlanStep, ...]]]:
    """Least total travel [mm] over every (order, assignment), straight from the
    assembly's positions (tool home at the origin), and the plans that reach it."""
    start = {part.id: part.start for part in assembly.parts if part.start is not None}
    at = {hole.id: hole.position for hole in assembly.holes if hole.position is not None}
    site = tuple(sum(c) / len(at) for c in zip(*at.values()))

    def leg(a: tuple[float, ...], b: tuple[float, ...]) -> int:
        return round(1000.0 * math.dist(a, b))

    best: float = math.inf
    winners: set[tuple[PlanStep, ...]] = set()
    for assignment in brute_force_assignments(facts):
        goal: dict[str, tuple[float, ...]] = {
            p: at[assignment[p]] if p in assignment else site for p in facts.parts
        }
        carry = sum(leg(start[p], goal[p]) for p in facts.parts)
        for order in linear_extensions(list(facts.parts), set(facts.must_precede)):
            tool: tuple[float, ...] = (0.0, 0.0)
            cost = carry
            for part in order:
                cost, tool = cost + leg(tool, start[part]), goal[part]
            cost += leg(tool, (0.0, 0.0))
            steps = tuple(PlanStep(p, assignment.get(p)) for p in order)
            if cost < best:
                best, winners = cost, {steps}
            elif cost == best:
                winners.add(steps)
    return int(best), winners


def test_cranfield_optimal_plans_match_brute_force(facts: LearnedFacts) -> None:
    travel = travel_facts(load_assembly("cranfield"), facts)
    found = plans(facts, 0, optimal=True, travel=travel)
    best, winners = _brute_force_optimum(facts, load_assembly("cranfield"))
    assert {plan.cost for plan in found} == {best}
    assert {plan.steps for plan in found} == winners
    for plan in found:
        assert check_plan(facts, plan.steps) == []


@settings(max_examples=20, deadline=None)
@given(assemblies, st.lists(st.tuples(st.integers(0, 800), st.integers(-500, 500)), min_size=7, max_size=7))
def test_optimal_plans_of_random_cells_match_brute_force(
    case: tuple[set, list[int], list[int]], spots_mm: list[tuple[int, int]]
) -> None:
    facts = random_facts(case)
    spots = [(x / 1000.0, y / 1000.0) for x, y in spots_mm]
    cell = Assembly(
        folder=ROOT, name="random cell",
        parts=tuple(Part(p, p, "peg", spot) for p, spot in zip(facts.parts, spots)),
        holes=tuple(Hole(h, h, "round", spot) for h, spot in zip(facts.holes, spots[4:])),
    )
    assume(brute_force_assignments(facts))
    found = plans(facts, 0, optimal=True, travel=travel_facts(cell, facts))
    best, winners = _brute_force_optimum(facts, cell)
    assert {plan.cost for plan in found} == {best} and {plan.steps for plan in found} == winners
    for plan in found:
        assert check_plan(facts, plan.steps) == []


def _steps(atoms: list[tuple[str, str, str]]) -> list[PlanStep]:
    return [PlanStep(p, None if h == "none" else h) for _, p, h in sorted(atoms, key=lambda a: int(a[0]))]


@pytest.mark.slow
def test_plan_command_json(learned: Path, facts: LearnedFacts, tmp_path: Path, run_main, run_python) -> None:
    done = run_main("plan", str(learned), "-n", "3", "--json")
    report = json.loads(done.stdout)
    assert done.returncode == 0 and list(report) == ["plans"] and len(report["plans"]) == 3
    for plan in report["plans"]:
        assert all(set(step) == {"part", "hole"} for step in plan)
        assert check_plan(facts, [PlanStep(s["part"], s["hole"]) for s in plan]) == []
    travel_file = tmp_path / "travel.lp"
    done = run_main("plan", str(learned), "--optimal", "--assembly", "cranfield",
                "--json", "--travel-out", str(travel_file))
    report = json.loads(done.stdout)
    assert report["cost"] == _brute_force_optimum(facts, load_assembly("cranfield"))[0] and len(report["plans"]) == 1
    assert check_plan(facts, [PlanStep(s["part"], s["hole"]) for s in report["plans"][0]]) == []
    # the same optimum from the plain clingo command line with the written travel facts
    done = run_python("clingo", str(ROOT / "asp/encodings/plans_optimal.lp"), str(learned),
                str(travel_file), "--opt-mode=opt", "--configuration=crafty")
    assert "OPTIMUM FOUND" in done.stdout
    assert re.findall(r"^Optimization: (\d+)$", done.stdout, re.M)[-1] == str(report["cost"])


@pytest.mark.slow
def test_plan_command_errors(learned: Path, tmp_path: Path, run_main) -> None:
    assert run_main("plan", "--help").returncode == 0
    no_geometry = run_main("plan", str(learned), "--optimal")
    assert no_geometry.returncode == 2 and "--assembly" in no_geometry.stderr
    too_slow = run_main("plan", str(learned), "--optimal", "--assembly", "cranfield",
                    "--time-limit", "0.001")
    assert too_slow.returncode == 2 and "did not finish within 0.001 s" in too_slow.stderr
    cyclic = tmp_path / "cyclic.lp"
    cyclic.write_text("part(a;b). must_precede(a,b). must_precede(b,a).\n")
    done = run_main("plan", str(cyclic))
    assert done.returncode == 2 and "must_precede has a cycle a < b < a" in done.stderr
    unsolvable = tmp_path / "unsolvable.lp"
    unsolvable.write_text("part(a;b). hole(h). fits(a,h). no_fit(b,h).\n")
    done = run_main("plan", str(unsolvable), "--json")
    assert done.returncode == 3 and json.loads(done.stdout)["part"] == "b"


def test_plain_clingo_answers_the_readme_questions(learned: Path, facts: LearnedFacts, run_python) -> None:
    five = run_python("clingo", str(ROOT / "asp/encodings/plans.lp"), str(learned), "5")
    answers = [line for line in five.stdout.splitlines() if "plan_step(" in line]
    assert len(answers) == 5
    for answer in answers:
        steps = _steps(re.findall(r"plan_step\((\d+),(\w+),(\w+)\)", answer))
        assert check_plan(facts, steps) == []
    brave = run_python("clingo", str(ROOT / "asp/encodings/assignments.lp"), str(learned),
                 "--enum-mode=brave")
    last = [line for line in brave.stdout.splitlines() if "assigned(" in line][-1]
    p3_holes = set(re.findall(r"assigned\(p3,(\w+)\)", last))
    assert p3_holes == {a["p3"] for a in all_assignments(facts)}
    assert p3_holes <= set(facts.holes_of("p3"))


@pytest.mark.parametrize("name", ["cranfield", "spare", "graded"])
def test_plans_of_shipped_files_respect_their_precedence_edges(name: str) -> None:
    """A shipped precedence.lp holds only precedence_edge/2 (the reduction): plans read
    its transitive closure, so every plan is a sequence the true constraints admit."""
    folder = ROOT / "data" / name
    truth = load_relation([folder / "precedence.lp"])
    facts = load_learned_facts([folder / "sizes.lp", folder / "precedence.lp"])
    assert facts.must_precede == frozenset(truth.pairs())
    for plan in plans(facts, 30):
        assert truth.admits([step.part for step in plan.steps])
        assert check_plan(facts, plan.steps) == []
    wrong = tuple(reversed(plans(facts, 1)[0].steps))
    assert any(error.startswith("wrong_order(") for error in check_plan(facts, wrong))


@pytest.mark.slow
def test_plan_command_reads_precedence_edges_and_mixed_forms(tmp_path: Path, run_main) -> None:
    truth = load_relation([CRANFIELD / "precedence.lp"])
    done = run_main("plan", str(CRANFIELD / "sizes.lp"), str(CRANFIELD / "precedence.lp"), "-n", "20", "--json")
    assert done.returncode == 0, done.stderr
    for plan in json.loads(done.stdout)["plans"]:
        assert truth.admits([step["part"] for step in plan])
    mixed = tmp_path / "mixed.lp"
    mixed.write_text("part(a;b;c). must_precede(a,b). precedence_edge(b,c).\n")
    done = run_main("plan", str(mixed), "-n", "0", "--json")
    assert done.returncode == 0, done.stderr
    assert [[step["part"] for step in plan] for plan in json.loads(done.stdout)["plans"]] == [["a", "b", "c"]]
    cyclic = tmp_path / "cyclic_edges.lp"
    cyclic.write_text("part(a;b). must_precede(a,b). precedence_edge(b,a).\n")
    done = run_main("plan", str(cyclic))
    assert done.returncode == 2 and "has a cycle a < b < a" in done.stderr
    unknown = tmp_path / "unknown.lp"
    unknown.write_text("part(a;b). precedence_edge(a,zz).\n")
    done = run_main("plan", str(unknown))
    assert done.returncode == 2 and "precedence_edge(a,zz): zz is not a part/1" in done.stderr


def test_ids_reach_clingo_as_symbols_never_as_program_text(facts: LearnedFacts) -> None:
    """An id holding ASP syntax is one constant: it adds no facts (the checker refuses the
    unknown hole) and no rules (the interval is never ground)."""
    plan = plans(facts, 1)[0]
    injected = [PlanStep(s.part, "r3). hole(zz). fits(p1,zz") if s.part == "p1" else s for s in plan.steps]
    assert any("p1" in error for error in check_plan(facts, injected))
    bomb = [PlanStep(s.part, "r3). bomb(1..50000000") if s.part == "p1" else s for s in plan.steps]
    assert any("p1" in error for error in check_plan(facts, bomb))
    atoms = load_atoms([], extra=[clingo.Function("part", [clingo.Function("a). part(b")])])
    assert [str(atom.arguments[0].name) for atom in atoms] == ["a). part(b"]


def test_a_fact_that_would_not_read_back_is_never_written(tmp_path: Path) -> None:
    path = tmp_path / "facts.lp"
    with pytest.raises(PlannerError, match="is not an ASP constant"):
        write_facts(path, [clingo.Function("hole", [clingo.Function("r3). bomb(1..5")])])
    with pytest.raises(PlannerError, match="'not' is not an ASP constant"):
        write_facts(path, [clingo.Function("part", [clingo.Function("not")])])
    assert not path.exists()
    write_facts(path, [clingo.Function("label", [clingo.String('a "quoted" ). string')]),
                       clingo.Function("n", [clingo.Number(-3)])])
    assert [str(atom) for atom in load_atoms([path])] == ['label("a \\"quoted\\" ). string")', "n(-3)"]
