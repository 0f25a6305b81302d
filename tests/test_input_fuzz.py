"""Fuzzing the readers of the planner's input files with hypothesis: the demonstrations
reader (text and ``demo/3`` facts) and the learned facts reader. Whatever the bytes, a
reader returns valid data or raises :class:`asp.PlannerError` with a short message: never
another exception, never unbounded work (each example has a deadline)."""

from __future__ import annotations

import re
import tempfile
from pathlib import Path

from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from asp import MAX_IDS, PlannerError
from asp.plans.assign import load_learned_facts
from asp.precedence.demos import MAX_DEMONSTRATIONS, load_demos
from asp.solve import load_atoms, pairs_by_name
from bridge.assembly import ID_PATTERN

FUZZ = settings(max_examples=100, deadline=2000, suppress_health_check=[HealthCheck.too_slow])
ID = re.compile(ID_PATTERN)
MAX_MESSAGE = 600  # characters: messages echo at most a short piece of the input

FRAGMENTS = [
    "demo(", "part(", "hole(", "fits(", "no_fit(", "must_precede(", "precedence_edge(", "needs_hole(", ")", "(",
    ",", ".", " ", "\n", "#", "%", "bp", "p1", "p2", "r1", "a", "b", "1", "2", "0", "-1", "2147483647",
    '"ä"', "ä", "X", "_", "\x00", "\xff", ":-", "not ", "{", "}", "x" * 1000,
    "demo(1,1,bp). ", "demo(1,2,p1). ", "demo(2,1,p1). ", "demo(1,2147483647,p1). ", "demo(1,99,p1). ",
    "part(a). ", "part(b). ", "hole(r1). ", "fits(a,r1). ", "no_fit(a,r1). ", "must_precede(a,b). ",
    "must_precede(b,a). ", "must_precede(a,b,c). ", "fits(a,r1,x). ", 'part("ä"). ', "part(3). ",
    "bp p1\n", "p1 bp\n", "bp, p1\n",
]
texts = st.one_of(st.text(max_size=300), st.lists(st.sampled_from(FRAGMENTS), max_size=30).map("".join))
contents = st.one_of(st.binary(max_size=300), texts.map(lambda text: text.encode("utf-8", "surrogatepass")))


def _file(folder: str, name: str, data: bytes) -> Path:
    path = Path(folder) / name
    path.write_bytes(data)
    return path


@FUZZ
@given(data=contents, suffix=st.sampled_from([".txt", ".lp"]), parts=st.sampled_from([None, ("bp", "p1")]))
@example(data=b",", suffix=".txt", parts=None)  # found by this test: a line of separators only
def test_demonstrations_reader_returns_valid_data_or_planner_error(data: bytes, suffix: str,
                                                                   parts: tuple[str, ...] | None) -> None:
    with tempfile.TemporaryDirectory() as folder:
        path = _file(folder, "demos" + suffix, data)
        try:
            demos = load_demos(path, parts)
        except PlannerError as exc:
            assert len(str(exc)) < MAX_MESSAGE + len(str(path))
            return
    assert 0 < len(demos.parts) <= MAX_IDS and all(ID.match(p) for p in demos.parts)
    assert 0 < len(demos.sequences) <= MAX_DEMONSTRATIONS
    assert all(sorted(sequence) == sorted(demos.parts) for sequence in demos.sequences)


@FUZZ
@given(data=contents)
def test_facts_reader_returns_valid_data_or_planner_error(data: bytes) -> None:
    with tempfile.TemporaryDirectory() as folder:
        path = _file(folder, "facts.lp", data)
        try:
            load_atoms([path])
            facts = load_learned_facts([path])
        except PlannerError as exc:
            assert len(str(exc)) < MAX_MESSAGE + len(str(path))
            return
    ids = [*facts.parts, *facts.holes, *(x for pair in facts.fits | facts.must_precede for x in pair)]
    assert 0 < len(facts.parts) <= MAX_IDS and all(ID.match(x) for x in ids)
    assert not facts.fits & set(pairs_by_name(facts.atoms, "no_fit"))
    assert all((b, a) not in facts.must_precede for a, b in facts.must_precede)
