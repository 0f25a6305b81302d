"""The suction cup: a part too short for the fingers whose flat top takes the cup is held by
its top (``tool = "suction"``), learned and assembled in the cell; a top that is not flat, or
smaller than the cup, leaves the part placed by hand with why; a part pulled off the cup
beyond its holding force drops and is reported (docs/cell.md#the-suction-tool)."""

from __future__ import annotations

import shutil
import tomllib
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import trimesh

from assembly_constraints.cli import main
from assembly_constraints.corpus_truth import CorpusImport, feature_holes, import_product
from executor.assembly.product import load_product
from executor.assembly.step import Assembler
from executor.cad.operations.tools import flat_top
from executor.cell_description import CellDescription
from executor.trial import Cell
from executor.world.arm import Dropped, tool_quat
from executor.world.geometry import load_geometry
from tests.cad.conftest import CORPUS, corpus_copy, learned_in_the_cell, teach
from tests.cad.test_covers import _pegs_and_plate
from tests.cad.test_mesh_import import _box
from tests.conftest import Runner


def test_a_flat_top_is_its_face_and_a_pointed_top_has_none() -> None:
    box = trimesh.creation.box((0.04, 0.03, 0.005))
    assert flat_top(box).area == pytest.approx(0.04 * 0.03, rel=1e-9)
    cone = trimesh.creation.cone(0.02, 0.01)  # its top a point: no face up there
    assert flat_top(cone).is_empty


def test_a_short_peg_with_a_pointed_top_stays_by_hand(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # peg2, 18 mm long (the fingers hold 20), its 12 mm square body ends in a pyramid.
    _pegs_and_plate(tmp_path / "cad", (560.0, 0.0))
    corners = [(560.0 + 25 + sx * 6, sy * 6, z) for sx in (-1, 1) for sy in (-1, 1) for z in (5.0, 19.0)]
    trimesh.convex.convex_hull([*corners, (585.0, 0.0, 23.0)]).export(tmp_path / "cad" / "peg2.stl")
    assert main(["-q", "import", str(tmp_path / "cad"), "--out", str(tmp_path / "out")]) == 0
    assert ("manual peg2: the cell has no operation for it, a plan's step places it by hand (part 'peg2' is "
            "18.000 mm long, no longer than the gripper's grasp depth (20 mm), and its top is not flat for the "
            "suction cup)") in capsys.readouterr().out


def test_a_cup_larger_than_the_top_leaves_the_part_by_hand(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # peg2, 18 mm long (the fingers hold 20), its flat top a 12 mm square: the 30 mm cup
    # does not lie whole on it (a 12 mm square is 20.4 % of the cup's disc).
    _pegs_and_plate(tmp_path / "cad", (560.0, 0.0))
    _box((12, 12, 18), (585.0, 0.0, 14.0)).export(tmp_path / "cad" / "peg2.stl")
    assert main(["-q", "import", str(tmp_path / "cad"), "--out", str(tmp_path / "out")]) == 0
    assert ("manual peg2: the cell has no operation for it, a plan's step places it by hand (part 'peg2' is "
            "18.000 mm long, no longer than the gripper's grasp depth (20 mm), and the suction cup (30 mm) does not "
            "lie whole on its flat top (20.4% of the cup on it))") in capsys.readouterr().out


@pytest.mark.slow  # imports the product (shared with test_corpus.py's on a worker: about 10 s under load)
def test_a_2_mm_plate_goes_on_the_suction_cup_into_its_recess_at_the_ledge_it_rests_on(
        corpus_import: Callable[[str], CorpusImport]) -> None:
    # nop_printed_box's base: a 2 mm plate, the cell's hull margin twice: it collides as
    # itself within what the cell resolves (executor/world/meshes.py), so it is inserted, not
    # placed by hand; it rests on the ledge 2.99 mm under the recess's rim, where the cell's
    # goal is, not on the case's top 43 mm down the recess's centre line. So shallow a
    # recess cannot tell a plate in it from one on its rim: the fit is no experiment.
    geometry = tomllib.loads((corpus_import("nop_printed_box").out / "geometry.toml").read_text())
    assert "manual" not in geometry
    assert geometry["part_shapes"]["smooth_box_base"]["tool"] == "suction"
    (hole,) = geometry["hole_shapes"].values()
    assert hole["depth"] == pytest.approx(0.045 - 0.0420078, abs=1e-6)
    assert hole["near_miss"] == ["smooth_box_base"]


@pytest.mark.slow  # imports, teaches, learns 3 pairs in physics and assembles (about 60 s under load)
@pytest.mark.timeout(900)
def test_a_gridfinity_bin_base_is_learned_on_the_suction_cup_and_assembled_within_2_mm(
        run_main: Runner, tmp_path: Path) -> None:
    # gridfinity_bases with one of its two bin bases (the other the same foot, a shape of its
    # own): its three pockets tried in physics, the bin base held by its top, and assembled.
    folder = Path(shutil.copytree(CORPUS / "gridfinity_bases", tmp_path / "cad",
                                  ignore=shutil.ignore_patterns("bin_base_b.stl")))
    done = import_product(folder, tmp_path / "out")
    geometry = tomllib.loads((done.out / "geometry.toml").read_text())
    assert "manual" not in geometry
    assert {pid: shape["tool"] for pid, shape in geometry["part_shapes"].items()} == {"bin_base_a": "suction"}
    result, outcomes = learned_in_the_cell(run_main, teach(done.out), tmp_path / "run", exact=True)
    holes = feature_holes(done)
    truth = {(row["part"], holes[row["feature"]]): "fit" if row["fits"] else "no_fit" for row in done.truth["fits"]
             if row["part"] == "bin_base_a"}
    assert len(truth) == 3 and {pair: outcomes.get(pair) for pair in truth} == truth
    assembly = result["assembly"]
    assert assembly["assembled"] is True and assembly["manual"] == []
    assert {step["part"] for step in assembly["steps"]} == {"baseplate", "bin_base_a"}
    assert max(assembly["final_pose_error_mm"].values()) <= 2.0


@pytest.mark.slow  # imports the product (shared), a trial's cell and an assembling cell (about 25 s under load)
def test_a_part_pulled_off_the_cup_beyond_its_holding_force_drops(
        corpus_import: Callable[[str], CorpusImport], tmp_path: Path) -> None:
    # A holding force below the bin base's weight (18.5 g: 0.18 N): hanging on the cup is
    # already too much, the cell reports the drop.
    done = corpus_copy(corpus_import("gridfinity_bases"), tmp_path / "out")
    assert load_geometry(str(done.out)).parts["bin_base_a"].tool == "suction"
    _hang(done.out)  # the cell's 20 N holds it
    text = done.out / "geometry.toml"
    text.write_text(text.read_text().replace("cup_force = 20.0", "cup_force = 0.1"))
    with pytest.raises(Dropped, match=r"more than its holding force \(0.1 N\); the part dropped"):
        _hang(done.out)
    # The assembling cell: the base set on its fixture, then the pick of a bin base.
    assembler = Assembler(load_product(str(done.out)), description=CellDescription())
    try:
        assert assembler.run_step("baseplate", None, 0).outcome == "fit"
        with pytest.raises(Dropped, match=r"more than its holding force \(0.1 N\); the part dropped"):
            assembler.run_step("bin_base_a", "h1", 0)
    finally:
        assembler.close()


def _hang(folder: Path) -> None:
    """Hold bin_base_a on the cup, the tool pointing down 50 mm above h1, for the settle time."""
    cell = Cell(str(folder))
    try:
        motion = cell.motion_for("bin_base_a")
        hole = cell.geometry.holes["h1"]
        cell.hold_at(motion, np.array([*hole.position, hole.top_z + 0.05]), tool_quat(0.0))
    finally:
        cell.close()
