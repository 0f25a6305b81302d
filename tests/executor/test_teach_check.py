"""Teaching checks its own result: a demonstration that does not reach its goal is
refused (one line naming the part, the hole and the end error; no skill written), and a
skill file is loaded only with the record of a teaching that reached its goal, so no
trial reports a fit from a skill that did not fit. ``--shapes`` teaches only the named
shapes and keeps the other stored skills byte for byte."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from executor import ExecutorError
from executor.skills.dmp import load_skill, skill_path
from executor.trial import Cell
from executor.world.geometry import load_geometry
from tests.conftest import error_lines


@pytest.fixture
def spare(tmp_path: Path, root: Path) -> Path:
    """A copy of the spare-hole plate (round pegs p1 p2, square peg p3; holes r1 r2 r3 s1)."""
    folder = tmp_path / "spare"
    shutil.copytree(root / "data" / "spare", folder, ignore=shutil.ignore_patterns("assets"))
    return folder


def _edit_record(folder: Path, change: dict | None) -> Path:
    """The square peg's skill file with its ``taught`` record updated by ``change`` (None: removed)."""
    path = skill_path(folder, "square_peg")
    data = json.loads(path.read_text())
    if change is None:
        del data["taught"]
    else:
        data["taught"].update(change)
    path.write_text(json.dumps(data))
    return path


def test_every_shipped_skill_records_a_teaching_in_its_demonstration_hole() -> None:
    for name in ("cranfield", "graded", "spare", "taskboard"):
        geometry = load_geometry(name)
        for part in geometry.parts.values():
            taught = load_skill(geometry.folder, part.shape).taught
            assert taught is not None and taught.reached
            taught_part = geometry.parts[taught.part]
            assert taught_part.shape == part.shape and taught.hole == taught_part.demo_hole
            assert (taught.part_kind, taught.part_sides) == (taught_part.kind, taught_part.sides)


def test_a_skill_never_taught_names_the_command_that_teaches_this_product(spare: Path) -> None:
    skill_path(spare, "square_peg").unlink()
    with pytest.raises(ExecutorError, match=f"part shape 'square_peg': no demonstration at .* run ./run.sh executor "
                       f"teach --assembly {spare}\\)$"):
        load_skill(spare, "square_peg")


def test_a_skill_file_without_its_record_is_refused(spare: Path) -> None:
    path = _edit_record(spare, None)
    with pytest.raises(ExecutorError, match="no record of its teaching") as refused:
        load_skill(spare, "square_peg")
    assert str(path) in str(refused.value) and "\n" not in str(refused.value)


@pytest.mark.parametrize("change", [{"end_error": 0.0249, "hole": "r1", "hole_kind": "round"},
                                    {"end_error": float("nan")}, {"end_error": "far"}, {"part_sides": [0.012]}])
def test_a_skill_whose_teaching_failed_or_whose_record_is_bad_is_refused(spare: Path, change: dict) -> None:
    path = _edit_record(spare, change)
    with pytest.raises(ExecutorError) as refused:
        load_skill(spare, "square_peg")
    message = str(refused.value)
    assert message.startswith(str(path)) and "\n" not in message
    if change.get("end_error") == 0.0249:
        assert "part p3 in hole r1: end error 24.9 mm, more than the 3.0 mm goal tolerance" in message


@pytest.mark.slow
def test_teaching_in_a_hole_the_part_cannot_pass_is_refused_and_keeps_the_skill(spare: Path, run_main) -> None:
    """The square peg (12 mm side, 17 mm diagonal) demonstrated in the round 13.3 mm hole r1
    stops on its entry: refused, the shipped skills untouched; the trial with them says
    what the physics does (no fit), and a trial with a skill recording such a teaching is
    refused."""
    geometry = spare / "geometry.toml"
    geometry.write_text(geometry.read_text().replace('demo_hole = "s1"', 'demo_hole = "r1"'))
    before = {path.name: path.read_bytes() for path in (spare / "demonstrations").iterdir()}
    done = run_main("executor", "teach", "--assembly", str(spare))
    assert done.returncode == 2, done.stdout + done.stderr
    lines = [line for line in done.stderr.splitlines() if not line.startswith("pybullet build time")]
    assert len(lines) == 1 and "teaching square_peg failed: part p3 in hole r1: end error" in lines[0], done.stderr
    error_mm = float(lines[0].split("end error ")[1].split(" mm")[0])
    assert error_mm > 20  # it stopped on the entry of the 25 mm deep hole
    assert {path.name: path.read_bytes() for path in (spare / "demonstrations").iterdir()} == before
    trial = run_main("executor", "trial", "--assembly", str(spare), "--part", "p3", "--hole", "r1", "--attempts", "1",
                     "--json")
    assert trial.returncode == 0, trial.stderr
    assert json.loads(trial.stdout)["summary"]["no_fit"] == 1
    path = _edit_record(spare, {"hole": "r1", "hole_kind": "round", "end_error": error_mm / 1000})  # as it was saved
    refused = run_main("executor", "trial", "--assembly", str(spare), "--part", "p3", "--hole", "r1")
    lines = [line for line in refused.stderr.splitlines() if not line.startswith("pybullet build time")]
    assert refused.returncode == 2 and len(lines) == 1 and not refused.stdout, refused.stdout + refused.stderr
    assert lines[0].startswith(f"error: {path}: its demonstration did not reach its goal (part p3 in hole r1")


def test_a_skill_moves_to_a_hole_s_bottom_from_the_depth_it_was_taught_at(spare: Path) -> None:
    """The goal follows the depth the record gives, not the product's ``demo_hole`` as it
    is now (which may have been edited since the teaching)."""
    skill = load_skill(spare, "square_peg")
    assert skill.taught is not None and skill.in_hole(skill.taught.depth) is skill
    deeper = skill.in_hole(skill.taught.depth + 0.005)
    assert deeper.end_position[2] == pytest.approx(skill.end_position[2] - 0.005, abs=1e-12)
    assert deeper.demo_goal[2] == pytest.approx(skill.demo_goal[2] - 0.005, abs=1e-12)
    assert deeper.taught == skill.taught


@pytest.mark.parametrize(("edit", "changed"), [
    (('size = 0.0120           # side [m]', 'size = 0.0110'), "part p3 square 12.00 x 12.00 mm, the product's p3 is "
                                                               "square 11.00 x 11.00 mm"),
    (('size = 0.0133           # side [m]', 'size = 0.0140'), "hole s1 square 13.30 x 13.30 mm, the product's s1 is "
                                                               "square 14.00 x 14.00 mm"),
    (('parts = ["p3"]', 'parts = ["p9"]'), "part p3, which the product no longer has")])
def test_a_skill_taught_on_a_section_the_product_no_longer_has_is_refused(spare: Path, edit: tuple[str, str],
                                                                         changed: str) -> None:
    """The square peg resized or renamed or its hole resized since the teaching: the cell
    refuses the skill, naming the file and the change, instead of running it."""
    geometry = spare / "geometry.toml"
    text = geometry.read_text()
    assert edit[0] in text
    geometry.write_text(text.replace(*edit))
    if edit[1].startswith("parts"):  # the part renamed in the product as well
        product = spare / "assembly.toml"
        product.write_text(product.read_text().replace("[parts.p3]", "[parts.p9]"))
    cell = Cell(str(spare))
    try:
        with pytest.raises(ExecutorError) as refused:
            cell.check_pair("p9" if "p9" in cell.geometry.parts else "p3", "s1")
    finally:
        cell.close()
    message = str(refused.value)
    assert message.startswith(f"{skill_path(spare, 'square_peg')}: taught on {changed}"), message
    assert "\n" not in message and message.endswith("run ./run.sh executor teach")


def test_a_skill_on_the_product_it_was_taught_on_is_used(spare: Path) -> None:
    cell = Cell(str(spare))
    try:
        assert cell.check_pair("p3", "s1").taught == load_skill(spare, "square_peg").taught
    finally:
        cell.close()


def test_teaching_the_named_shapes_keeps_the_other_stored_skills(spare: Path, run_main) -> None:
    """``executor teach --shapes round_peg`` on the sim backend writes the round peg's skill
    (its file removed first, so it must be written) and leaves the square peg's file byte for
    byte as it was (stored compact here, so a teaching of it would rewrite it indented)."""
    taught, kept = skill_path(spare, "round_peg"), skill_path(spare, "square_peg")
    taught.unlink()
    kept.write_text(json.dumps(json.loads(kept.read_text())))
    before = kept.read_bytes()
    done = run_main("executor", "teach", "--assembly", str(spare), "--shapes", "round_peg")
    assert done.returncode == 0, done.stdout + done.stderr
    assert f"wrote {taught}" in done.stdout.splitlines(), done.stdout
    assert f"wrote {kept}" not in done.stdout.splitlines(), done.stdout
    assert kept.read_bytes() == before
    record = load_skill(spare, "round_peg").taught
    assert record is not None and record.reached


@pytest.mark.parametrize(("shapes", "word"), [("round_peg,,square_peg", "expected comma-separated part shapes"),
                                              ("round_peg,hex_peg", "no part shape hex_peg in")])
def test_teaching_refuses_an_empty_or_unknown_shape_and_writes_nothing(spare: Path, run_main, shapes: str,
                                                                       word: str) -> None:
    """An empty item or a name not among geometry.toml's part shapes: one line, exit 2, no file written."""
    before = {path: path.read_bytes() for path in spare.rglob("*") if path.is_file()}
    done = run_main("executor", "teach", "--assembly", str(spare), "--shapes", shapes)
    lines = error_lines(done.stderr)
    assert done.returncode == 2 and len(lines) == 1 and word in lines[0] and not done.stdout, done.stdout + done.stderr
    if "no part shape" in word:
        assert str(spare / "geometry.toml") in lines[0]
    assert {path: path.read_bytes() for path in spare.rglob("*") if path.is_file()} == before
