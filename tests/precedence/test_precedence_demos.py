"""Demonstrations files: formats, demo/3 facts, and bad input naming file:line."""

from __future__ import annotations

from pathlib import Path

import pytest

from asp import PlannerError
from asp.precedence.demos import demo_facts, load_demos, parse_demos
from asp.solve import write_facts


def test_spaces_commas_comments_and_blank_lines_give_the_same_sequences() -> None:
    text = "# battery\n\no r2 i2 r1 i1   # Fig. 3a\n o,r1, r2 ,i1,i2\n\n"
    demos = parse_demos(text, "demos.txt")
    assert demos.parts == ("o", "r2", "i2", "r1", "i1")
    assert demos.sequences == (("o", "r2", "i2", "r1", "i1"), ("o", "r1", "r2", "i1", "i2"))
    assert demos.origins == ("demos.txt:3", "demos.txt:4")


def test_assembly_parts_take_precedence_over_the_first_line() -> None:
    demos = parse_demos("b a\n", "d.txt", parts=["a", "b"])
    assert demos.parts == ("a", "b")
    with pytest.raises(PlannerError, match=r"d\.txt:1: unknown id 'c'"):
        parse_demos("a c\n", "d.txt", parts=["a", "b"])


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("a b c\na b x\n", r":2: unknown id 'x'"),
        ("a b c\na b b\n", r":2: id 'b' is repeated"),
        ("a b c\na b\n", r":2: missing id\(s\) c"),
        ("a b c\n\na b c a\n", r":3: id 'a' is repeated"),
        ("# only comments\n\n", r"empty, expected at least one sequence"),
        ("a B c\n", r":1: 'B' is not a part id"),
    ],
)
def test_bad_text_names_file_line_and_problem(tmp_path: Path, text: str, message: str) -> None:
    path = tmp_path / "demos.txt"
    path.write_text(text)
    with pytest.raises(PlannerError, match=message):
        load_demos(path)


def test_binary_garbage_is_rejected_with_its_line(tmp_path: Path) -> None:
    path = tmp_path / "demos.txt"
    path.write_bytes(b"a b c\n\xff\xfe\x00garbage\n")
    with pytest.raises(PlannerError, match=r"demos\.txt:2: binary data"):
        load_demos(path)
    for garbage in (b"a\x00b c", b"a \x01\x02 b c"):
        path.write_bytes(b"a b c\n" + garbage + b"\n")
        with pytest.raises(PlannerError, match=r"demos\.txt:2: binary data"):
            load_demos(path)


def test_demo_facts_round_trip(tmp_path: Path) -> None:
    demos = parse_demos("o r2 i2 r1 i1\no r1 r2 i1 i2\n", "d.txt")
    path = tmp_path / "demos.lp"
    write_facts(path, demo_facts(demos))
    again = load_demos(path)
    assert again.parts == demos.parts
    assert again.sequences == demos.sequences


def test_demo_facts_with_a_gap_or_a_repeat_are_rejected(tmp_path: Path) -> None:
    path = tmp_path / "demos.lp"
    path.write_text("part(a;b;c). demo(1,1,a). demo(1,3,b).\n")
    with pytest.raises(PlannerError, match=r"demonstration 1: no part at step 2"):
        load_demos(path)
    path.write_text("demo(1,1,a). demo(1,3,b).\n")  # two parts: no step 3
    with pytest.raises(PlannerError, match=r"demo\(1,3,b\): the step must be an integer from 1 to 2"):
        load_demos(path)
    path.write_text("part(a;b). demo(1,1,a). demo(1,2,a).\n")
    with pytest.raises(PlannerError, match=r"demonstration 1: id 'a' is repeated"):
        load_demos(path)


@pytest.mark.parametrize(
    ("content", "message"),
    [
        (b"bp p1 p2 p3 p4 sh sp pd ph fp\nbp p1 p2 p3 p4 sh sp pd ph zz\n", ":2: unknown id 'zz'"),
        (b"bp p1 p2 p3 p4 sh sp pd ph fp\nbp p1 p1 p3 p4 sh sp pd ph fp\n", ":2: id 'p1' is repeated"),
        (b"bp p1 p2 p3 p4 sh sp pd ph fp\nbp p1 p2 p3 p4 sh sp pd ph\n", ":2: missing id(s) fp"),
        (b"\n# nothing\n", "empty"),
        (b"\x89PNG\r\n\x1a\n\x00\x00", ":1: binary data"),
    ],
)
def test_cli_bad_input_exits_2_without_traceback(tmp_path: Path, content: bytes, message: str, run_cli) -> None:
    path = tmp_path / "demos.txt"
    path.write_bytes(content)
    result = run_cli("precedence", "learn", str(path), "--assembly", "cranfield")
    assert result.returncode == 2
    assert result.stderr.startswith(f"error: {path}")
    assert message in result.stderr
    assert "Traceback" not in result.stderr
