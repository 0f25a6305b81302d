"""The product's pose on the table chosen for the arm's reach: :func:`executor.campaign.reach.pin_cad`'s
block drawn with its pin standing out along +x (its ring goes on along -x, along which no
reach was measured: placed by hand as drawn) is turned a quarter turn about z by the
import, so the cell puts the ring on; the answers (fits, precedence) are those of the
product as drawn, and a turn or place the user sets is kept."""

from __future__ import annotations

from pathlib import Path

import pytest

from assembly_constraints.corpus_truth import distance_to_axis
from bridge.product import load_product_description
from executor.cad.cli import ImportOptions, run_import
from executor.cad.operations.arm import Reach, best_pose
from executor.campaign.reach import pin_cad
from tests.conftest import assembled

from .conftest import teach


def _facts(out: Path, name: str) -> list[str]:
    """The facts of ``out/name`` (its comment lines left out), sorted."""
    return sorted(line for line in (out / name).read_text().splitlines() if line and not line.startswith("%"))


def _imported(tmp: Path, options: ImportOptions, settings: str = 'base = "block"\n') -> tuple[Path, int, list[str]]:
    """The ring on its pin along -x (the CAD turned three quarter turns) imported with
    ``options`` and ``settings``: its folder, the turn the import gave it and its assumptions."""
    cad = pin_cad(tmp / "cad", 10.2, turn=3)
    (tmp / "import.toml").write_text(settings)
    done = run_import(cad, tmp / "out", "mm", tmp / "import.toml", options)
    return tmp / "out", done.turn, done.assumed


def test_a_ring_on_a_pin_along_minus_x_goes_on_in_the_cell_once_the_product_is_turned(tmp_path: Path) -> None:
    drawn, turn, _ = _imported(tmp_path / "drawn", ImportOptions(turn=0))
    geometry = load_product_description(drawn).geometry
    assert geometry is not None and turn == 0 and geometry.hole_shapes["block_pin1"].axis == "-x"
    assert "measured to reach a horizontal pin along +x, +y, -y only" in geometry.manual["ring"].reason
    chosen, turn, assumed = _imported(tmp_path / "chosen", ImportOptions())
    geometry = load_product_description(chosen).geometry
    assert geometry is not None and geometry.manual == {}
    # one quarter turn (fewer than 180's two): the ring goes on along -y (90) or +y (270)
    assert (turn, geometry.hole_shapes["block_pin1"].axis) in ((90, "-y"), (270, "+y"))
    said = next(line for line in assumed if line.startswith(f"the product turned {turn} deg about z"))
    assert "so the arm reaches 1 more insertion(s) (ring; the cell inserts 1 of 1 moving parts)" in said
    assert said.endswith("set turn = 0 and place = [0.56, 0] to keep it as drawn")
    assert f"turned {turn} deg about z" in (chosen / "assembly.toml").read_text().splitlines()[0]
    for name in ("sizes.lp", "geometric_precedence.lp"):  # the answers do not turn with the product
        assert _facts(chosen, name) == _facts(drawn, name)


@pytest.mark.slow  # four imports (about 4 s of CPU, more beside other work)
def test_however_the_cad_is_turned_the_cell_puts_the_ring_on_and_the_answers_hold(tmp_path: Path) -> None:
    answers = []
    for quarter in range(4):  # the pin drawn along +y, -x, -y, +x
        cad = pin_cad(tmp_path / f"cad{quarter}", 10.2, turn=quarter)
        (tmp_path / f"import{quarter}.toml").write_text('base = "block"\n')
        out = tmp_path / f"out{quarter}"
        run_import(cad, out, "mm", tmp_path / f"import{quarter}.toml")
        geometry = load_product_description(out).geometry
        assert geometry is not None and geometry.manual == {}, quarter
        answers.append([_facts(out, name) for name in ("sizes.lp", "geometric_precedence.lp")])
    assert all(found == answers[0] for found in answers)


@pytest.mark.slow  # three imports (2 s); a turn set kept: the first test's turn = 0, best_pose's below
def test_a_turn_or_place_the_user_sets_is_kept(tmp_path: Path) -> None:
    out, turn, _ = _imported(tmp_path / "config", ImportOptions(), 'base = "block"\nturn = 0\n')
    geometry = load_product_description(out).geometry
    assert geometry is not None and turn == 0 and "ring" in geometry.manual
    out, turn, _ = _imported(tmp_path / "half", ImportOptions(turn=180))  # along +x: its end in the box 30 mm up
    geometry = load_product_description(out).geometry
    assert geometry is not None and turn == 180 and geometry.hole_shapes["block_pin1"].axis == "+x"
    assert geometry.manual == {}
    # placed where no turn brings the pin's end (60 mm out of the base's centre) into a box: as drawn
    out, turn, _ = _imported(tmp_path / "near", ImportOptions(place=(0.36, 0.0)))
    geometry = load_product_description(out).geometry
    assert geometry is not None and turn == 0 and "ring" in geometry.manual


def test_the_pose_ties_go_to_the_product_as_it_stands_then_the_fewest_quarter_turns() -> None:
    # A pin's free end 50 mm before the base's centre along x, 30 mm up, its part going on
    # along -x: turned 180 it goes on along +x in its box where it stands, turned 90 or 270
    # along -y or +y in theirs once moved 51 mm: one quarter turn before two.
    reach = Reach("ring", "-x", (0.51, 0.0, 0.03), True)
    def anywhere(xy: tuple[float, float]) -> bool:
        return True
    pose = best_pose([reach], {"ring"}, (0.56, 0.0), (None, None), anywhere)
    assert pose.turn in (90, 270) and pose.steps == 1
    assert best_pose([reach], {"ring"}, (0.56, 0.0), (0, None), anywhere).steps == 0  # turn set: nothing reaches
    assert best_pose([], {"ring"}, (0.56, 0.0), (None, None), anywhere) == best_pose(
        [], {"ring"}, (0.56, 0.0), (0, (0.56, 0.0)), anywhere)  # nothing to reach: as it stands


@pytest.mark.slow  # a truth session of the turned product with --assemble (~10 s)
def test_the_turned_product_is_learned_and_assembled_with_no_part_by_hand(tmp_path: Path, run_session) -> None:
    chosen, _, _ = _imported(tmp_path, ImportOptions())
    result = run_session("--assembly", str(chosen), "--out", str(tmp_path / "run"), "--assemble", timeout=120)
    assert result["assembly"]["manual"] == [] and result["assembly"]["assembled"]


@pytest.mark.slow  # the ring taught, then the block and the ring assembled in physics (~10 s)
def test_the_cell_puts_the_ring_on_the_turned_product_in_physics(tmp_path: Path) -> None:
    chosen, _, _ = _imported(tmp_path, ImportOptions())
    assembled(teach(chosen), "block", "ring", "block_pin1")


def test_a_turned_import_is_set_against_its_truth_in_the_cad_frame() -> None:
    # A point on a truth feature's axis (along x through (100, 20, 30) mm in the CAD),
    # turned 90 deg about z and moved by (500, 100, 0) mm: on the axis again.
    feature = {"axis": "+x", "axis_point": [100.0, 20.0, 30.0]}
    assert distance_to_axis([0.48, 0.25, 0.03], feature, (0.5, 0.1, 0.0), 90) == pytest.approx(0.0, abs=1e-9)
    assert distance_to_axis([0.48, 0.25, 0.03], feature, (0.5, 0.1, 0.0)) > 100
