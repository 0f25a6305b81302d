"""A hole entered sideways: the corpus's ``agh_hex_horizontal`` (real CAD: a hexagonal peg
going along -y through a hexagonal hole of a box, 0.433 mm of room all round) is imported
with its hole's axis and entry, taught, learned and assembled in physics by the same
skills as a hole entered from above, run in the hole's frame
(:mod:`executor.world.frames`)."""

from __future__ import annotations

import hashlib
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
import trimesh

from bridge import BridgeError
from bridge.product import load_product_description
from executor.cad.cli import ImportOptions, run_import
from executor.cad.derive import LEAVING
from executor.cad.operations.arm import SIDEWAYS_HOLE_REACH, SIDEWAYS_PIN_REACH
from executor.cad.sections import frame_of
from executor.cad.sweep import DIRECTIONS, opposite
from executor.trial import Cell
from executor.world.arm import ArmState, quat_to_matrix, tool_quat
from executor.world.frames import hole_frame, hole_rotation
from tests.cad.conftest import teach
from tests.conftest import assembled

CORPUS = Path(__file__).parent / "corpus" / "agh_hex_horizontal"
ENTRY = (0.56, 0.025, 0.03)
"""The hole's entry centre in the cell [m]: its +y face, 30 mm up, the box placed at x = 560 mm."""


def _import(out: Path) -> Path:
    run_import(CORPUS / "meshes", out, "mm", CORPUS / "import.toml")
    return out


@pytest.fixture(scope="module")
def taught(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The product imported and its peg's skill taught in its hole (``executor teach``, in
    this process)."""
    return teach(_import(tmp_path_factory.mktemp("sideways") / "out"))


@pytest.mark.parametrize("axis", ["-z", "+x", "-x", "+y", "-y"])
def test_the_hole_frame_has_the_axes_the_import_measures_sections_in(axis: str) -> None:
    rotation = hole_rotation(axis)
    out = np.array(DIRECTIONS[opposite(axis)])
    assert np.array_equal(rotation[:, 2], out)  # z out of the hole
    assert np.array_equal(rotation[:, :2].T, frame_of(out))  # x, y: the slice's axes of the section
    assert np.linalg.det(rotation) == pytest.approx(1.0)


def test_poses_and_readings_go_through_the_hole_frame() -> None:
    frame = hole_frame("-y", ENTRY)
    assert frame is not None and hole_frame("-z", ENTRY) is None
    # 2.5 mm above the entry, the tool pointing down the frame: 2.5 mm out along +y, pointing along -y.
    pos, quat = frame.pose_to_cell(np.array([0.56, 0.025, 0.0325]), tool_quat(0.0))
    assert pos == pytest.approx([0.56, 0.0275, 0.03], abs=1e-12)
    assert quat_to_matrix(quat)[:, 2] == pytest.approx([0.0, -1.0, 0.0], abs=1e-12)
    rng = np.random.default_rng(0)
    state = ArmState(rng.normal(size=7), rng.normal(size=7), pos, quat, *rng.normal(size=(2, 3)),
                     rng.normal(size=(6, 7)), np.array([0.0, 3.0, 0.0]), rng.normal(size=3))
    seen = frame.state_in(state)
    assert seen.tip_pos == pytest.approx([0.56, 0.025, 0.0325], abs=1e-12)
    assert quat_to_matrix(seen.tip_quat_xyzw) == pytest.approx(quat_to_matrix(tool_quat(0.0)), abs=1e-12)
    assert seen.force == pytest.approx([0.0, 0.0, 3.0])  # pushed back out of the hole: up in its frame
    for ours, theirs in ((seen.tip_vel, state.tip_vel), (seen.torque, state.torque)):
        assert frame.vector_to_cell(ours) == pytest.approx(theirs)
    assert frame.vector_to_cell(seen.jac[:3].T).T == pytest.approx(state.jac[:3])
    assert frame.points_in(frame.points_to_cell(np.array([0.1, 0.2, 0.3]))) == pytest.approx([0.1, 0.2, 0.3])


def test_a_sideways_hole_is_written_with_its_axis_and_entry_and_checked(tmp_path: Path) -> None:
    out = _import(tmp_path / "out")
    geometry = load_product_description(out).geometry
    assert geometry is not None and geometry.manual == {}
    hole = geometry.hole_shapes["h1"]
    assert (hole.axis, hole.top_z, hole.depth) == ("-y", 0.03, 0.075)  # the peg's tip 25 mm past the far face
    assert geometry.part_shapes["hex_peg"].length == pytest.approx(0.1)
    text = (out / "geometry.toml").read_text()
    for old, new, expected in [('axis = "-y"\ntop_z = 0.03\n', 'axis = "-y"\n', "top_z: expected the height of the "
                                "entry's centre [m] of a hole entered along -y, got nothing"),
                               ('axis = "-y"', 'axis = "+z"', "axis")]:
        (out / "geometry.toml").write_text(text.replace(old, new))
        with pytest.raises(BridgeError, match=re.escape(expected)) as caught:
            load_product_description(out)
        assert "\n" not in str(caught.value) and "[hole_shapes.h1]" in str(caught.value)


def _narrowed(folder: Path, out: Path, scale: float) -> Path:
    """A copy of the taught product whose box (its own mesh) is shrunk by ``scale`` across
    the hole's axis about that axis: the same nominal sections, a hole too narrow for the peg."""
    shutil.copytree(folder, out)
    mesh_file = out / "meshes" / "box.obj"
    box = trimesh.load(mesh_file, force="mesh")
    x, _, z = ENTRY
    box.apply_transform(trimesh.transformations.translation_matrix((x, 0.0, z))
                        @ np.diag([scale, 1.0, scale, 1.0])
                        @ trimesh.transformations.translation_matrix((-x, 0.0, -z)))
    box.export(mesh_file)
    old = hashlib.sha256((folder / "meshes" / "box.obj").read_bytes()).hexdigest()
    geometry = out / "geometry.toml"
    geometry.write_text(geometry.read_text().replace(old, hashlib.sha256(mesh_file.read_bytes()).hexdigest()))
    return out


@pytest.mark.slow  # teaches the peg (shared), then one attempt in physics (about 15 s under load)
def test_a_horizontal_insertion_too_narrow_is_refused_in_physics(taught: Path, tmp_path: Path) -> None:
    # The hole 3 % narrower (circumradius 19.9 mm, the peg's 20 mm): stopped at the entry.
    # The peg into the hole as drawn in physics: its step in the assembly below, and the
    # trial of a sim session in `bench corpus` (tests/cad/test_corpus_bench.py). One attempt:
    # the trial's second one after a no-fit is tests/executor/test_executor_cell.py's.
    narrow = Cell(str(_narrowed(taught, tmp_path / "narrow", 0.97)))
    try:
        refused = narrow.run_trial("hex_peg", "h1", 0, max_attempts=1)
    finally:
        narrow.close()
    assert refused.outcome == "no_fit" and refused.end_error > 0.02


@pytest.mark.slow  # teaches the peg (shared), then the box and the peg assembled in physics (about 40 s under load)
def test_a_horizontal_peg_is_assembled_within_2_mm(taught: Path) -> None:
    _, quat = assembled(taught, "box", "hex_peg", "h1")
    assert quat_to_matrix(quat)[:, 2] == pytest.approx([0.0, 1.0, 0.0], abs=0.02)  # lying along the hole's axis


def _turned(folder: Path, wall: float | None = None, faces: tuple[int, ...] = (1, -1)) -> Path:
    """The product's CAD (turned a quarter turn about z: its hole along x, the peg free both
    ways along it) or, with a ``wall`` [mm], as drawn with a 10 mm wall from each of its
    box's ``faces`` (+y: 1, -y: -1) the hole passes, beside the hole's entry there (x 25 to
    35 mm from its axis, as high as the box), reaching that far out, in ``folder``."""
    folder.mkdir()
    box = trimesh.load(CORPUS / "meshes" / "box.stl", force="mesh")
    peg = trimesh.load(CORPUS / "meshes" / "hex_peg.stl", force="mesh")
    if wall is not None:
        for face in faces:
            side = trimesh.creation.box((10.0, wall, 60.0))
            side.apply_translation((30.0, face * (25.0 + wall / 2), 30.0))
            box = trimesh.boolean.union([box, side], engine="manifold")
    else:
        for mesh in (box, peg):
            mesh.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, (0.0, 0.0, 1.0)))
    box.export(folder / "box.stl")
    peg.export(folder / "hex_peg.stl")
    return folder


def test_a_peg_into_a_sideways_hole_goes_by_hand_where_the_arm_was_not_measured_to_reach(tmp_path: Path) -> None:
    # Turned a quarter turn about z the peg is free both ways along x through its hole. Along
    # -x the assembling cell's transfer ends short of the approach (68.5 mm with the entry
    # 352.5 mm out, 75.9 mm at 452.5 mm: no IK solution within the joints' limits): never the
    # cell's, so the peg goes in along +x (the import chose -x, and the turned product's peg
    # went by hand: tests/cad/invariance.py, turn90); its entry 395 mm out is beyond the box
    # measured along +x.
    turned = _turned(tmp_path / "turned")
    for place, out, by_hand in (((0.56, 0.0), "default", False), ((0.42, 0.0), "near", True)):
        imported = run_import(turned, tmp_path / out, "mm", CORPUS / "import.toml", ImportOptions(place=place, turn=0))
        assert imported.derived.axis == {"hex_peg": "-x"}
        manual = load_product_description(tmp_path / out).geometry.manual  # type: ignore[union-attr]
        assert ("hex_peg" in manual) == by_hand, manual
        if by_hand:
            assert "goes into hole h1 along +x: its entry at (395.0, 0.0, 30.0) mm, out of the reach measured " \
                "along +x" in manual["hex_peg"].reason, manual
    # Along -y the entry 700 mm out along x: out of the box measured (docs/cell.md).
    run_import(CORPUS / "meshes", tmp_path / "far", "mm", CORPUS / "import.toml",
               ImportOptions(place=(0.70, 0.0), turn=0))
    manual = load_product_description(tmp_path / "far").geometry.manual  # type: ignore[union-attr]
    assert "its entry at (700.0, 25.0, 30.0) mm, out of the reach measured along -y (x 400-600 " in \
        manual["hex_peg"].reason, manual


@pytest.mark.parametrize(("wall", "meets"), [(60.0, True), (40.0, False)])
def test_a_peg_into_a_sideways_hole_goes_by_hand_where_the_wrist_would_meet_the_base(
        tmp_path: Path, wall: float, meets: bool) -> None:
    # The peg sticks 25 mm out of the entry, held 20 mm deep: the wrist starts 65 mm out,
    # a wall beside the entry must end 10 mm short of it. A wall beside both entries: the
    # product alike from either, the peg goes in along -y, the first the cell reaches.
    run_import(_turned(tmp_path / "cad", wall), tmp_path / "out", "mm", CORPUS / "import.toml")
    manual = load_product_description(tmp_path / "out").geometry.manual  # type: ignore[union-attr]
    assert ("hex_peg" in manual) == meets, manual
    if meets:
        assert manual["hex_peg"].reason == ("goes into hole h1 along -y, but the arm's wrist (60 mm about the "
                                          "tool's axis, 60 mm out from the grip) would meet 'box', 55.000 mm out "
                                          "from the grip within 60 mm of the axis"), manual


def test_a_peg_free_both_ways_alike_goes_in_from_the_side_away_from_a_wall(tmp_path: Path) -> None:
    # The peg sticks 25 mm out of either face: it leaves 75 mm either way. With a wall
    # beside the +y entry alone it went in along -y (the first axis the cell reaches),
    # past the wall, and by hand (its wrist would meet the wall); it goes in along +y, away
    # from the product's mass, and turned 180 deg from the same side.
    for turned, out in ((False, "-y"), (True, "+y")):
        cad = _turned(tmp_path / f"cad{turned}", 60.0, (1,))
        if turned:
            for stl in cad.iterdir():
                mesh = trimesh.load(stl, force="mesh")
                mesh.apply_transform(trimesh.transformations.rotation_matrix(np.pi, (0.0, 0.0, 1.0)))
                mesh.export(stl)
        imported = run_import(cad, tmp_path / f"out{turned}", "mm", CORPUS / "import.toml")
        assert imported.derived.axis == {"hex_peg": out}
        assert not load_product_description(tmp_path / f"out{turned}").geometry.manual  # type: ignore[union-attr]


def test_the_ways_out_chosen_first_are_those_whose_insertion_the_arm_reaches_sideways() -> None:
    horizontal = [d for d in LEAVING if d[1] != "z"]
    assert {opposite(d) for d in horizontal[:len(SIDEWAYS_HOLE_REACH)]} == set(SIDEWAYS_HOLE_REACH)
    assert set(SIDEWAYS_PIN_REACH) == set(SIDEWAYS_HOLE_REACH) and set(LEAVING) == set(DIRECTIONS)
