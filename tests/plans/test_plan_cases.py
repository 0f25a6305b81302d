"""Named ASP cases for plans.lp and the checker (check_plan.lp), and the plans of random
small assemblies against brute force, every plan through the checker."""

from __future__ import annotations

import itertools
import tempfile
from collections.abc import Collection, Iterator, Sequence
from pathlib import Path

import clingo
import pytest
from clintest.assertion import Assertion, Equals, Or, True_
from clintest.quantifier import All, Exact
from clintest.solver import Clingo
from clintest.test import And, Assert
from hypothesis import given, settings
from hypothesis import strategies as st

from asp.plans.assign import LearnedFacts, UnsolvableAssembly, load_learned_facts
from asp.plans.plans import PlanStep, check_plan, plans
from asp.solve import fact, write_facts
from tests.conftest import ROOT

ENCODINGS = ROOT / "asp" / "encodings"

# name, facts, expected models (their plan_step/3 atoms); [] = unsatisfiable
PLAN_CASES = [
    ("precedence and a hole", "part(a;b). hole(h). fits(a,h). must_precede(a,b).",
     [{"plan_step(1,a,h)", "plan_step(2,b,none)"}]),
    ("no constraints, no holes", "part(a;b).",
     [{"plan_step(1,a,none)", "plan_step(2,b,none)"},
      {"plan_step(1,b,none)", "plan_step(2,a,none)"}]),
    ("two holes, fixed order", "part(a;b). hole(h1;h2). fits(a,h1). fits(a,h2). must_precede(b,a).",
     [{"plan_step(1,b,none)", "plan_step(2,a,h1)"}, {"plan_step(1,b,none)", "plan_step(2,a,h2)"}]),
    ("chain not closed transitively",
     "part(a;b;c). must_precede(c,b). must_precede(b,a).",
     [{"plan_step(1,c,none)", "plan_step(2,b,none)", "plan_step(3,a,none)"}]),
    ("two independent pairs", "part(a;b;c;d). must_precede(a,b). must_precede(c,d).",
     [{f"plan_step({t},{p},none)" for t, p in enumerate(order, start=1)}
      for order in ("abcd", "acbd", "acdb", "cabd", "cadb", "cdab")]),
    ("cyclic precedence is unsat", "part(a;b). must_precede(a,b). must_precede(b,a).", []),
    ("part without a hole is unsat", "part(a;b). hole(h). fits(a,h). fits(b,h).", []),
]


class PlanStepsEqual(Assertion):
    """Holds for a model whose plan_step/3 atoms are exactly ``steps``."""

    def __init__(self, steps: set[str]) -> None:
        self.steps = {clingo.parse_term(step) for step in steps}

    def holds_for(self, model: clingo.Model) -> bool:
        return {a for a in model.symbols(shown=True) if a.match("plan_step", 3)} == self.steps


@pytest.mark.parametrize("name,facts,expected", PLAN_CASES, ids=[c[0] for c in PLAN_CASES])
def test_plan_encoding_named_cases(name: str, facts: str, expected: list[set[str]]) -> None:
    """Exactly the expected plans (clingo never repeats a model, and a plan determines
    the sequence and the assignment that plans.lp also shows)."""
    test: Assert | And = Assert(Exact(len(expected)), True_())
    if expected:
        test = And(test, Assert(All(), Or(*(PlanStepsEqual(model) for model in expected))))
    Clingo(arguments=["0"], program=facts, files=[str(ENCODINGS / "plans.lp")]).solve(test)
    test.assert_()


CHECK_FACTS = "part(a;b;c). hole(h1;h2). fits(a,h1). fits(b,h1). fits(b,h2). must_precede(a,b).\n"
# name, the plan or assignment, the errors the checker must derive (exactly)
CHECK_CASES = [
    ("valid plan", "plan_step(1,a,h1). plan_step(2,b,h2). plan_step(3,c,none).", set()),
    ("valid assignment", "assigned(a,h1). assigned(b,h2).", set()),
    ("wrong order", "plan_step(1,b,h2). plan_step(2,a,h1). plan_step(3,c,none).",
     {"error(wrong_order(a,b))"}),
    ("part missing", "plan_step(1,a,h1). plan_step(2,b,h2).", {"error(missing(c))"}),
    ("part repeated", "plan_step(1,a,h1). plan_step(2,b,h2). plan_step(3,c,none). plan_step(4,c,none).",
     {"error(repeated(c))", "error(bad_step(4))"}),
    ("two parts at one step", "plan_step(1,a,h1). plan_step(1,c,none). plan_step(2,b,h2).",
     {"error(step_twice(1))"}),
    ("hole not fitting", "plan_step(1,a,h2). plan_step(2,b,h1). plan_step(3,c,none).",
     {"error(not_fitting(a,h2))"}),
    ("hole used twice", "plan_step(1,a,h1). plan_step(2,b,h1). plan_step(3,c,none).",
     {"error(over_capacity(h1))"}),
    ("part without its hole", "plan_step(1,a,none). plan_step(2,b,h2). plan_step(3,c,none).",
     {"error(no_hole(a))"}),
    ("unknown part", "plan_step(1,a,h1). plan_step(2,b,h2). plan_step(3,c,none). plan_step(4,x,none).",
     {"error(unknown_part(x))", "error(bad_step(4))"}),
    ("assignment misses a part", "assigned(a,h1).", {"error(no_hole(b))"}),
    ("assignment gives two holes", "assigned(a,h1). assigned(b,h1). assigned(b,h2).",
     {"error(two_holes(b))", "error(over_capacity(h1))"}),
]


@pytest.mark.parametrize("name,given,errors", CHECK_CASES, ids=[c[0] for c in CHECK_CASES])
def test_checker_named_cases(name: str, given: str, errors: set[str]) -> None:
    test = Assert(Exact(1), Equals(set[clingo.Symbol | str](errors)))
    Clingo(program=CHECK_FACTS + given, files=[str(ENCODINGS / "check_plan.lp")]).solve(test)
    test.assert_()


def linear_extensions(parts: list[str], before: set[tuple[str, str]]) -> Iterator[tuple[str, ...]]:
    """Every order of ``parts`` in which a comes before b for each (a, b) in ``before``."""
    if not parts:
        yield ()
    for part in parts:
        if not any((other, part) in before for other in parts):
            rest = [other for other in parts if other != part]
            for tail in linear_extensions(rest, before):
                yield (part, *tail)


assemblies = st.integers(1, 4).flatmap(
    lambda n: st.tuples(
        st.sets(st.tuples(st.integers(0, n - 1), st.integers(0, n - 1)).filter(lambda e: e[0] < e[1])),
        st.lists(st.integers(0, 3), min_size=n, max_size=n),  # part sizes, 0 = needs no hole
        st.lists(st.integers(1, 4), min_size=1, max_size=3),  # hole sizes
    )
)


def random_facts(case: tuple[set, list[int], list[int]], capacities: Sequence[int] = (),
                 out_of_reach: Collection[tuple[int, int]] = ()) -> LearnedFacts:
    """Learned facts of a drawn assembly: edges (i, j) i < j are must_precede, a part of
    size 0 needs no hole, another fits the holes of a larger size; hole k takes
    ``capacities[k]`` parts (default 1), the cell cannot put part i into hole k for each
    (i, k) of ``out_of_reach``."""
    edges, part_sizes, hole_sizes = case
    parts = [f"p{i}" for i in range(len(part_sizes))]
    holes = [f"h{i}" for i in range(len(hole_sizes))]
    atoms = [fact("part", p) for p in parts] + [fact("hole", h) for h in holes]
    atoms += [fact("must_precede", parts[a], parts[b]) for a, b in edges]
    atoms += [
        fact("fits" if ps < hs else "no_fit", p, h)
        for p, ps in zip(parts, part_sizes) if ps > 0
        for h, hs in zip(holes, hole_sizes)
    ]
    atoms += [fact("capacity", h, c) for h, c in zip(holes, capacities)]
    atoms += [fact("out_of_reach", parts[i], holes[k]) for i, k in out_of_reach
              if i < len(parts) and k < len(holes)]
    with tempfile.TemporaryDirectory() as tmp:
        write_facts(Path(tmp) / "learned.lp", atoms)
        return load_learned_facts([Path(tmp) / "learned.lp"])


def brute_force_assignments(facts: LearnedFacts) -> list[dict[str, str]]:
    """Every map of the parts that need a hole to holes they fit and the cell can put
    them in, no hole holding more parts than its capacity, parts sharing a hole ordered
    by must_precede."""
    found = []
    for chosen in itertools.product(facts.holes, repeat=len(facts.needs_hole)):
        pairs = list(zip(facts.needs_hole, chosen))
        if (all((p, h) in facts.fits and (p, h) not in facts.out_of_reach for p, h in pairs)
                and all(chosen.count(h) <= facts.capacity.get(h, 1) for h in chosen)
                and all((a, b) in facts.must_precede or (b, a) in facts.must_precede
                        for (a, h), (b, k) in itertools.combinations(pairs, 2) if h == k)):
            found.append(dict(pairs))
    return found


@settings(max_examples=30, deadline=None)
@given(assemblies)
def test_plans_are_exactly_the_brute_force_ones(case: tuple[set, list[int], list[int]]) -> None:
    facts = random_facts(case)
    assignments = brute_force_assignments(facts)
    expected = {
        tuple(PlanStep(p, a.get(p)) for p in order)
        for order in linear_extensions(list(facts.parts), set(facts.must_precede))
        for a in assignments
    }
    try:
        found = plans(facts, 0)
    except UnsolvableAssembly as exc:
        assert not assignments and exc.part in facts.needs_hole
        return
    assert {plan.steps for plan in found} == expected and len(found) == len(expected)
    for plan in found:
        assert check_plan(facts, plan.steps) == []
