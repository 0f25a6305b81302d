"""Named ASP cases for the size closure and the selection encodings (clintest)."""

from __future__ import annotations

import itertools

import clingo
import networkx as nx
import pytest
from clintest.assertion import Contains, Equals, SupersetOf
from clintest.quantifier import Exact, Last
from clintest.solver import Clingo
from clintest.test import And, Assert
from hypothesis import given, settings
from hypothesis import strategies as st

from asp.solve import encoding, fact, format_facts

TWO_BY_TWO = "part(a;b). hole(x;y). part_index(a,1). part_index(b,2). hole_index(x,1). hole_index(y,2). "


def _solve(files: list[str], facts: str, test, arguments: list[str] | None = None) -> None:
    paths = [str(encoding(f)) for f in files]
    Clingo(["0", *(arguments or [])], program=facts, files=paths).solve(test)
    test.assert_()


def _closure_model(facts: str) -> set[str]:
    models: list[set[str]] = []
    ctl = clingo.Control(["--warn=none"])
    ctl.load(str(encoding("sizes_closure.lp")))
    ctl.add("base", [], facts)
    ctl.ground([("base", [])])
    ctl.solve(on_model=lambda m: models.append({str(s) for s in m.symbols(shown=True)}))
    assert len(models) == 1
    return models[0]


def test_a_fit_and_a_no_fit_give_eq2_and_the_rest_unknown() -> None:
    facts = TWO_BY_TWO + "tried(1,a,x,fit). tried(2,b,x,no_fit)."
    expected = {"smaller(a,x)", "smaller(x,b)", "smaller(a,b)", "fits(a,x)", "no_fit(b,x)",
                "unknown(a,y)", "unknown(b,y)"}
    _solve(["sizes_closure.lp"], facts, Assert(Exact(1), Equals(expected)))


def test_eq3_orders_holes_and_eq4_entails_a_fit() -> None:
    # x < a < y (eq. 3: x < y); b < x (so b < a, eq. 2); eq. 4 then gives b < y.
    facts = TWO_BY_TWO + "tried(1,a,x,no_fit). tried(2,a,y,fit). tried(3,b,x,fit)."
    test = And(
        Assert(Exact(1), Contains("smaller(x,y)")),
        Assert(Exact(1), Contains("fits(b,y)")),
        Assert(Exact(1), SupersetOf({"smaller(b,a)", "smaller(b,y)"})),
    )
    _solve(["sizes_closure.lp"], facts, test)


def test_eq5_entails_a_no_fit_of_a_bigger_part() -> None:
    # a < y < b gives a < b (eq. 2); x < a then gives x < b (eq. 5): b does not fit x.
    facts = TWO_BY_TWO + "tried(1,a,y,fit). tried(2,b,y,no_fit). tried(3,a,x,no_fit)."
    _solve(["sizes_closure.lp"], facts, Assert(Exact(1), SupersetOf({"no_fit(b,x)", "smaller(x,b)"})))


def test_a_cycle_names_every_experiment_on_it() -> None:
    # a < x < b < y < a: four observations on one cycle, all in conflict.
    facts = TWO_BY_TWO + "tried(1,a,x,fit). tried(2,b,x,no_fit). tried(3,b,y,fit). tried(4,a,y,no_fit)."
    expected = {"conflict_experiment(1,a,x,fit)", "conflict_experiment(2,b,x,no_fit)",
                "conflict_experiment(3,b,y,fit)", "conflict_experiment(4,a,y,no_fit)"}
    _solve(["sizes_closure.lp"], facts, Assert(Exact(1), SupersetOf(expected)))


CONSISTENCY_CASES = {
    "same pair both ways": ("tried(1,a,x,fit). tried(2,a,x,no_fit).", 0),
    "four-cycle": ("tried(1,a,x,fit). tried(2,b,x,no_fit). tried(3,b,y,fit). tried(4,a,y,no_fit).", 0),
    "consistent": ("tried(1,a,x,fit). tried(2,b,x,no_fit).", 1),
}


@pytest.mark.parametrize("case", CONSISTENCY_CASES)
def test_require_consistent_makes_conflicts_unsat(case: str) -> None:
    observations, models = CONSISTENCY_CASES[case]
    _solve(["sizes_closure.lp"], TWO_BY_TWO + observations, Assert(Exact(models), Contains("fits(a,x)")),
           ["-c", "require_consistent=1"])


def test_systematic_takes_lowest_part_then_lowest_hole() -> None:
    facts = TWO_BY_TWO + "tried(1,a,x,fit). tried(2,a,y,fit)."
    _solve(["select_systematic.lp"], facts, Assert(Exact(1), Contains("select(b,x)")))


def test_systematic_selects_nothing_once_all_is_known() -> None:
    facts = TWO_BY_TWO + "tried(1,a,x,fit). tried(2,a,y,fit). tried(3,b,x,no_fit). tried(4,b,y,no_fit)."
    test = Assert(Exact(1), Equals({"smaller(a,x)", "smaller(a,y)", "smaller(x,b)", "smaller(y,b)",
                                    "smaller(a,b)", "fits(a,x)", "fits(a,y)", "no_fit(b,x)",
                                    "no_fit(b,y)"}))
    _solve(["select_systematic.lp"], facts, test)


def test_random_takes_the_least_priority_among_unknown_pairs() -> None:
    facts = TWO_BY_TWO + ("priority(a,x,2). priority(a,y,0). priority(b,x,3). priority(b,y,1). "
                          "tried(1,a,y,fit).")
    _solve(["select_random.lp"], facts, Assert(Exact(1), Contains("select(b,y)")))


def test_heuristic_prefers_the_template_of_fig7() -> None:
    # a < b < c are known parts (b fits y but c does not; a fits x but b does not);
    # (b,z) matches Fig. 7 with Pi = a and Pk = c: both unknown with hole z.
    facts = ("part(a;b;c). hole(x;y;z). part_index(a,1). part_index(b,2). part_index(c,3). "
             "hole_index(x,1). hole_index(y,2). hole_index(z,3). "
             "tried(1,a,x,fit). tried(2,b,x,no_fit). tried(3,b,y,fit). tried(4,c,y,no_fit).")
    _solve(["select_heuristic.lp"], facts, Assert(Last(), Contains("select(b,z)")))


OBSERVATIONS = st.lists(
    st.tuples(st.integers(0, 3), st.integers(0, 3), st.sampled_from(["fit", "no_fit"])),
    max_size=8,
)


@settings(max_examples=40, deadline=None)
@given(OBSERVATIONS)
def test_closure_equals_the_transitive_closure(observations) -> None:
    parts, holes = [f"p{i}" for i in range(4)], [f"h{j}" for j in range(4)]
    graph = nx.DiGraph()
    graph.add_nodes_from(parts + holes)
    atoms = [fact("part", p) for p in parts] + [fact("hole", h) for h in holes]
    for e, (i, j, r) in enumerate(observations, 1):
        atoms.append(fact("tried", e, parts[i], holes[j], r))
        graph.add_edge(*((parts[i], holes[j]) if r == "fit" else (holes[j], parts[i])))
    closure = nx.transitive_closure(graph, reflexive=False)
    model = _closure_model(format_facts(atoms))
    assert {s for s in model if s.startswith("smaller(")} == {f"smaller({x},{y})" for x, y in closure.edges}
    for p, h in itertools.product(parts, holes):
        known = closure.has_edge(p, h) or closure.has_edge(h, p)
        assert (f"unknown({p},{h})" in model) == (not known)
