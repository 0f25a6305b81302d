"""Fuzzing the readers of the planner's input files with hypothesis: the demonstrations
reader (text and ``demo/3`` facts), the learned facts reader, the plan JSON reader, the
session journal reader and the product description loader (``assembly.toml``). Whatever
the bytes, a reader returns valid data or raises its package's error
(:class:`asp.PlannerError`, :class:`bridge.BridgeError`) with a
short message: never another exception, never unbounded work (each example has a deadline)."""

from __future__ import annotations

import re
import tempfile
from pathlib import Path

from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from asp import MAX_IDS, PlannerError
from asp.assemble.inputs import read_plan_json
from asp.plans.assign import load_learned_facts
from asp.precedence.demos import MAX_DEMONSTRATIONS, load_demos
from asp.session.journal import read_journal
from asp.solve import load_atoms, pairs_by_name
from bridge import BridgeError
from bridge.assembly import ID_PATTERN, load_assembly

FUZZ = settings(max_examples=100, deadline=2000, suppress_health_check=[HealthCheck.too_slow])
ID = re.compile(ID_PATTERN)
MAX_MESSAGE = 600  # characters: messages echo at most a short piece of the input

FRAGMENTS = [
    "demo(", "part(", "hole(", "fits(", "no_fit(", "must_precede(", "precedence_edge(", "needs_hole(", ")", "(",
    ",", ".", " ", "\n", "#", "%", "bp", "p1", "p2", "r1", "a", "b", "1", "2", "0", "-1", "2147483647",
    '"ä"', "ä", "X", "_", "\x00", "\xff", ":-", "not ", "{", "}", "x" * 1000,
    "demo(1,1,bp). ", "demo(1,2,p1). ", "demo(2,1,p1). ", "demo(1,2147483647,p1). ", "demo(1,99,p1). ",
    "part(a). ", "part(b). ", "hole(r1). ", "fits(a,r1). ", "no_fit(a,r1). ", "must_precede(a,b). ",
    "must_precede(b,a). ", "precedence_edge(b,a). ", "precedence_edge(a,zz). ", "must_precede(a,b,c). ",
    "fits(a,r1,x). ", 'part("ä"). ', "part(3). ",
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


PLAN_FRAGMENTS = [
    "[", "]", "{", "}", ",", ":", '"part"', '"hole"', '"plan"', '"plans"', '"cost"', "null", "1", "-1", "true",
    '"bp"', '"p1"', '"r1"', '"not"', '"p\\u00e91"', '"p\\ud800"', '"r3). bomb(1..5"', '"p1\\n"', '"zz"', " ",
    '{"part": "bp", "hole": null}', '{"part": "p1", "hole": "r1"}', '{"part": "p1", "part": "p2"}',
]
plan_texts = st.one_of(st.text(max_size=200), st.lists(st.sampled_from(PLAN_FRAGMENTS), max_size=40).map("".join))


@FUZZ
@given(data=st.one_of(st.binary(max_size=200), plan_texts.map(lambda text: text.encode("utf-8", "surrogatepass"))),
       k=st.integers(1, 3))
@example(data=b'[{"part": "bp", "hole": "r3). hole(zz). fits(p1,zz"}]', k=1)
@example(data=b"[" * 5000 + b"]" * 5000, k=1)
def test_plan_json_reader_returns_a_plan_of_ids_or_planner_error(data: bytes, k: int) -> None:
    with tempfile.TemporaryDirectory() as folder:
        path = _file(folder, "plan.json", data)
        try:
            plan = read_plan_json(path, k)
        except PlannerError as exc:
            assert len(str(exc)) < MAX_MESSAGE + len(str(path))
            return
    assert plan.steps and all(ID.match(s.part) and (s.hole is None or ID.match(s.hole)) for s in plan.steps)
    assert not any(s.part == "not" or s.hole == "not" for s in plan.steps)


JOURNAL_FRAGMENTS = [
    '{"id":"a","part":"p1","hole":"br","result":"fit","cell":"c1"}\n',
    '{"id":"b","part":"p1","hole":"br","result":"no_fit","cell":"c1"}\n',
    '{"id":"c","part":"p1","hole":"br","result":"no_fit","cell":"c1","retest":true}\n',
    '{"id":"d","part":"p2","hole":"r1","result":"fit","cell":"c1","experiment":-1}\n',
    '{"event":"started","experiment":1,"id":"a","part":"p1","hole":"br"}\n',
    '{"event":"abandoned","experiment":0,"id":"a","part":"p1","hole":"br"}\n',
    '{"id":"e","part":"not","hole":"br","result":"fit","cell":"c1"}\n', "\n", "{", "}", '"id"', "[",
]


@FUZZ
@given(lines=st.lists(st.sampled_from(JOURNAL_FRAGMENTS), max_size=12))
def test_journal_reader_returns_a_consistent_journal_or_an_error_naming_the_line(lines: list[str]) -> None:
    with tempfile.TemporaryDirectory() as folder:
        path = _file(folder, "journal.jsonl", "".join(lines).encode())
        try:
            entries = read_journal(path)
        except PlannerError as exc:
            assert re.match(rf"{re.escape(str(path))}:\d+: ", str(exc)) and len(str(exc)) < MAX_MESSAGE + len(str(path))
            return
    assert len({e.id for e in entries}) == len(entries)
    first: set[tuple[str, str]] = set()
    for entry in entries:
        assert entry.experiment >= 0 and ((entry.part, entry.hole) not in first or entry.retest)
        first.add((entry.part, entry.hole))


ASSEMBLY_FRAGMENTS = [
    "[parts.a]\n", "[parts.not]\n", "[parts.P1]\n", "[holes.h1]\n", "[holes.h1]\n", "[parts]\n", 'name = "x"\n',
    'role = "peg"\n', "start = [0.1, 0.2]\n", "start = [1e999, 0]\n", 'start = "x"\n', "position = [0, 0]\n",
    "shape = 3\n", "name = 5\n", "[parts.a.b]\n", "x = 1\n", "[[parts]]\n", "parts = 1\n", "holes = []\n", "=\n",
    '"\n', "[" * 50 + "\n", 'role = ["peg"]\n', '[parts."p\\u00e91"]\n', '[parts."a\\n"]\n',
]


@FUZZ
@given(text=st.one_of(st.text(max_size=200), st.lists(st.sampled_from(ASSEMBLY_FRAGMENTS), max_size=20).map("".join)))
def test_product_description_loader_returns_an_assembly_of_ids_or_bridge_error(text: str) -> None:
    with tempfile.TemporaryDirectory() as folder:
        _file(folder, "assembly.toml", text.encode("utf-8", "surrogatepass"))
        try:
            assembly = load_assembly(folder)
        except BridgeError as exc:
            assert len(str(exc)) < MAX_MESSAGE + len(folder) * 2
            return
    ids = [*assembly.part_ids, *assembly.hole_ids]
    assert all(ID.match(x) for x in ids) and len(set(assembly.part_ids)) == len(assembly.part_ids)
