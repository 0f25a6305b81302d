"""The precedence experiment encodings, with real clingo (clintest): what is known through
the closure, the decisive candidates and what each must place first, the two selection
policies, and the count of consistent relations."""

from __future__ import annotations

import clingo
import pytest
from clintest.assertion import Contains, Not, True_
from clintest.quantifier import All, Exact
from clintest.solver import Clingo
from clintest.test import And, Assert

from asp.solve import encoding, solve

KNOWLEDGE = str(encoding("precedence_knowledge.lp"))


def _index(*parts: str) -> str:
    return " ".join(f"part({p}). part_index({p},{i})." for i, p in enumerate(parts, 1)) + " "


def _demo(d: int, *parts: str) -> str:
    return " ".join(f"demo({d},{i},{p})." for i, p in enumerate(parts, 1)) + " "


CASES = [
    ("one demonstration leaves every kept pair open; b lies between a and c",
     _index("a", "b", "c") + _demo(1, "a", "b", "c"),
     {"open(a,b)", "open(a,c)", "open(b,c)", "candidate(a,b)", "candidate(b,c)", "requires(b,c,a)",
      "excluded(b,a)", "excluded(c,a)", "excluded(c,b)"}),
    ("a geometric pair is known and its pair is no candidate",
     _index("a", "b", "c") + _demo(1, "a", "b", "c") + " forced(a,b,geometry).",
     {"known(a,b)", "open(a,c)", "open(b,c)", "candidate(b,c)", "requires(b,c,a)"}),
    ("a success shows every absent part free of the placed ones",
     _index("a", "b", "c") + _demo(1, "a", "b", "c")
     + " experiment_step(1,1,a). experiment_step(1,2,c). experiment_success(1).",
     {"excluded(b,c)", "free(b,c,experiment(1))", "free(b,a,experiment(1))", "candidate(a,b)"}),
    ("a free pair excludes what the known pairs would chain into it",
     _index("a", "b", "c", "d") + " forced(a,b,geometry). forced(c,d,geometry). free(a,d,s).",
     {"excluded(b,c)", "excluded(b,d)", "excluded(a,c)", "excluded(a,d)", "known(a,b)", "known(c,d)",
      "open(c,a)", "open(d,b)"}),
    ("a demonstration against a forced pair is a conflict naming it",
     _index("a", "b") + _demo(1, "b", "a") + " forced(a,b,geometry).", {"conflict(a,b,demo(1))"}),
    ("forced pairs in a cycle", _index("a", "b") + _demo(1, "a", "b") + " forced(a,b,geometry). forced(b,a,x).",
     {"cycle(a)", "cycle(b)"}),
]


@pytest.mark.parametrize("name,program,expected", CASES, ids=[c[0] for c in CASES])
def test_knowledge_named_cases(name: str, program: str, expected: set[str]) -> None:
    test = And(Assert(Exact(1), Contains(next(iter(sorted(expected))))),
               *(Assert(All(), Contains(atom)) for atom in sorted(expected)))
    Clingo(program=program, files=[KNOWLEDGE]).solve(test)
    test.assert_()


def test_no_candidate_has_a_part_between_and_nothing_known_is_open() -> None:
    program = _index("a", "b", "c", "d") + _demo(1, "a", "b", "c", "d") + _demo(2, "a", "c", "b", "d")
    candidates = {"candidate(a,b)", "candidate(a,c)", "candidate(b,d)", "candidate(c,d)"}
    test = And(Assert(Exact(1), Contains("open(a,d)")), Assert(All(), Not(Contains("candidate(a,d)"))),
               *(Assert(All(), Contains(atom)) for atom in sorted(candidates)))
    Clingo(program=program, files=[KNOWLEDGE]).solve(test)
    test.assert_()


# "B then A" on (a,b) with c placed first: c, b, then a; a's step (3) is where it may fail
_THEN_A = (_index("a", "b", "c") + _demo(1, "c", "a", "b")
           + " experiment(1,a,b). experiment_step(1,1,c). experiment_step(1,2,b). experiment_step(1,3,a).")


@pytest.mark.parametrize("name,program,present,absent", [
    ("a blocked by b alone after b: a must precede b", _THEN_A + " experiment_failed(1,3,blocked). "
     "experiment_blocker(1,b).", {"blocked_first(1,a,b)", "known(a,b)"}, {"free(a,b,experiment(1))", "undecided(1)"}),
    ("a blocked by another part too: nothing decided", _THEN_A + " experiment_failed(1,3,blocked). "
     "experiment_blocker(1,b). experiment_blocker(1,c).", {"undecided(1)", "open(a,b)"},
     {"free(a,b,experiment(1))", "known(a,b)", "blocked_first(1,a,b)"}),
    ("a blocked with no part seen: nothing decided", _THEN_A + " experiment_failed(1,3,blocked).",
     {"undecided(1)", "open(a,b)"}, {"free(a,b,experiment(1))", "known(a,b)"}),
    ("a jammed touching b: not blocked, nothing decided", _THEN_A + " experiment_failed(1,3,jammed). "
     "experiment_blocker(1,b).", {"undecided(1)", "open(a,b)"}, {"known(a,b)"}),
    ("b then a both done: a need not precede b", _THEN_A + " experiment_success(1).",
     {"free(a,b,experiment(1))", "excluded(a,b)"}, {"undecided(1)", "known(a,b)"}),
])
def test_b_then_a_reads_a_failure_of_a_only_when_b_alone_blocked_it(name: str, program: str, present: set[str],
                                                                     absent: set[str]) -> None:
    test = And(Assert(Exact(1), True_()), *(Assert(All(), Contains(atom)) for atom in sorted(present)),
               *(Assert(All(), Not(Contains(atom))) for atom in sorted(absent)))
    Clingo(program=program, files=[KNOWLEDGE]).solve(test)
    test.assert_()


@pytest.mark.parametrize("entry,expected", [("select_precedence_informative.lp", "select(b,c)"),
                                            ("select_precedence_first.lp", "select(a,b)")])
def test_policies_choose_by_their_rule(entry: str, expected: str) -> None:
    # c<d known: a failure on (b,c) would confirm b<c and b<d, a success exclude b<c; (a,b)
    # decides a<b alone either way. The informative policy takes (b,c), the systematic one (a,b).
    program = _index("a", "b", "c", "d") + _demo(1, "a", "b", "c", "d") + " forced(c,d,geometry)."
    facts = [atom for text in program.split() for atom in [clingo.parse_term(text.rstrip("."))]]
    models: list[set[str]] = []
    solve([entry], facts, ["--opt-mode=opt"], lambda m: models.append({str(s) for s in m.symbols(shown=True)}))
    assert {atom for atom in models[-1] if atom.startswith("select(")} == {expected}


@pytest.mark.parametrize("program,count", [
    (_index("a", "b", "c") + _demo(1, "a", "b", "c"), 7),  # the naturally labelled posets on 3 parts
    (_index("a", "b", "c") + _demo(1, "a", "b", "c") + _demo(2, "a", "c", "b"), 4),  # {}, a<b, a<c, both
    (_index("a", "b", "c") + _demo(1, "a", "b", "c") + " forced(a,b,geometry). forced(b,c,geometry).", 1),
])
def test_orders_counts_the_consistent_relations(program: str, count: int) -> None:
    test = Assert(Exact(count), True_())
    Clingo(arguments=["0"], program=program, files=[str(encoding("precedence_orders.lp"))]).solve(test)
    test.assert_()
