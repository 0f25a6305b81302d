"""Named ASP cases for the closure, reduction and sequence encodings (clintest)."""

from __future__ import annotations

from clintest.assertion import Contains, Equals, Not
from clintest.quantifier import All, Exact
from clintest.solver import Clingo
from clintest.test import And, Assert

from asp.solve import encoding


def _solve(name: str, facts: str, test) -> None:
    Clingo(["0"], program=facts, files=[str(encoding(name))]).solve(test)
    test.assert_()


def test_closure_of_a_chain_with_a_branch() -> None:
    facts = "part(a;b;c;d). precedence_edge(a,b). precedence_edge(b,c). must_precede(a,d)."
    expected = {"part(a)", "part(b)", "part(c)", "part(d)", "must_precede(a,b)", "must_precede(b,c)",
                "must_precede(a,c)", "must_precede(a,d)"}
    _solve("precedence_closure.lp", facts, Assert(Exact(1), Equals(expected)))


def test_closure_reports_a_cycle() -> None:
    facts = "part(a;b). precedence_edge(a,b). precedence_edge(b,a)."
    both_cycle = And(Assert(All(), Contains("cycle(a)")), Assert(All(), Contains("cycle(b)")))
    _solve("precedence_closure.lp", facts, both_cycle)


def test_reduction_drops_implied_pairs() -> None:
    facts = "must_precede(a,b). must_precede(b,c). must_precede(a,c). must_precede(a,d)."
    expected = {"precedence_edge(a,b)", "precedence_edge(b,c)", "precedence_edge(a,d)"}
    _solve("precedence_reduction.lp", facts, Assert(Exact(1), Equals(expected)))


def test_sequence_enumerates_the_battery_relation_of_fig4() -> None:
    facts = ("part(o;r1;r2;i1;i2). must_precede(o,r1). must_precede(o,r2). must_precede(o,i1). "
             "must_precede(o,i2). must_precede(r1,i1). must_precede(r2,i1). must_precede(r2,i2).")
    test = And(
        Assert(Exact(5), Contains("sequence_step(1,o)")),
        Assert(All(), Not(Contains("sequence_step(5,r1)"))),
        Assert(Exact(1), Contains("sequence_step(3,i2)")),
    )
    _solve("sequences.lp", facts, test)
