"""Demonstrations files: formats, demo/3 facts, and bad input naming file:line."""

from __future__ import annotations

from pathlib import Path

import pytest

from asp import PlannerError
from asp.precedence.demos import demo_facts, load_demos, parse_demos
from asp.solve import atoms_by_name, load_atoms, write_facts
from bridge.assembly import load_assembly


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
def test_cli_bad_input_exits_2_without_traceback(tmp_path: Path, content: bytes, message: str, run_main) -> None:
    path = tmp_path / "demos.txt"
    path.write_bytes(content)
    result = run_main("precedence", "learn", str(path), "--assembly", "cranfield")
    assert result.returncode == 2
    assert result.stderr.startswith(f"error: {path}")
    assert message in result.stderr
    assert "Traceback" not in result.stderr


def test_placements_part_at_hole_are_read_from_text_and_facts_alike(tmp_path: Path) -> None:
    demos = parse_demos("o r1@x i1\no, i1, r1@y  # another hole\n", "d.txt", holes=["x", "y"])
    assert demos.sequences == (("o", "r1", "i1"), ("o", "i1", "r1"))
    assert demos.holes == ((None, "x", None), (None, None, "y"))
    assert demos.placements() == [("r1", "x"), ("r1", "y")]
    path = tmp_path / "demos.lp"
    write_facts(path, demo_facts(demos))
    assert "demo(1,2,r1,x)." in path.read_text() and "demo(1,1,o)." in path.read_text()
    again = load_demos(path, holes=["x", "y"])
    assert (again.sequences, again.holes) == (demos.sequences, demos.holes)
    assert parse_demos("o r1 i1\n", "d.txt").placements() == []


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("a b c\na b@z c\n", r"d\.txt:2: 'b@z': unknown hole 'z'; expected one of the assembly's holes: x y"),
        ("a@X b c\n", r"d\.txt:1: 'a@X': 'X' is not a hole id"),
        ("a@ b c\n", r"d\.txt:1: 'a@': '' is not a hole id"),
        ("a@x@y b c\n", r"d\.txt:1: 'a@x@y': 'x@y' is not a hole id"),
        ("a@x b@x c\n", r"d\.txt:1: 'b@x': hole x already holds a in this demonstration"),
        ("@x a b c\n", r"d\.txt:1: '' is not a part id"),
    ],
)
def test_a_bad_placement_names_file_line_and_the_hole(text: str, message: str) -> None:
    with pytest.raises(PlannerError, match=message):
        parse_demos(text, "d.txt", holes=["x", "y"])


def test_a_bad_placement_in_facts_names_the_atom(tmp_path: Path) -> None:
    path = tmp_path / "demos.lp"
    for text, message in [("demo(1,1,a,z). demo(1,2,b).", r"demos\.lp: demo\(1,1,a,z\): 'a@z': unknown hole 'z'"),
                          ("demo(1,1,a,3). demo(1,2,b).", r"'a@3': '3' is not a hole id"),
                          ("demo(1,1,a,x). demo(1,1,a). demo(1,2,b).", r"already places a at step 1")]:
        path.write_text(text + "\n")
        with pytest.raises(PlannerError, match=message):
            load_demos(path, holes=["x", "y"])


def test_cranfield_annotated_demonstrations_are_demos_txt_with_nine_fits() -> None:
    cranfield = load_assembly("cranfield")
    plain = load_demos(cranfield.file("demos.txt"), cranfield.part_ids, cranfield.hole_ids)
    annotated = load_demos(cranfield.folder / "demos_annotated.txt", cranfield.part_ids, cranfield.hole_ids)
    assert annotated.sequences == plain.sequences and plain.placements() == []
    truth = set(atoms_by_name(load_atoms([cranfield.file("sizes.lp")]), "fits", 2))
    assert len(annotated.placements()) == 9 and set(annotated.placements()) <= truth
