"""A round peg at a room the cell does not resolve (here room 0) in a round hole of a base
that is its own mesh (a block with a bore along y, entered sideways): the cell cannot widen
the hole, so it narrows the peg by ``NOMINAL_FIT_ROOM`` per side, the peg's section as it
reads it and the convex pieces the import writes (``executor.cad.operations.resolution.narrows_peg``,
``executor.world.meshes.narrowed``), and only where no other hole's answer would change."""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest
import trimesh

from bridge.assembly import load_assembly
from bridge.product.nominal import NOMINAL_FIT_ROOM
from executor import ExecutorError
from executor.cad.cli import run_import
from executor.world.geometry import HoleSpec, PartSpec, _with_widened_fits, load_geometry
from executor.world.meshes import narrowed, read_objects
from tests.cad.conftest import teach
from tests.conftest import assembled

_UP = trimesh.transformations.rotation_matrix(-np.pi / 2, [1, 0, 0])  # a cylinder's z turned to +y


def _along_y(radius: float, low: float, high: float, x: float = 0.0) -> trimesh.Trimesh:
    """A 64-sided cylinder [mm] of ``radius`` along y from ``low`` to ``high``, its axis at (x, z 30)."""
    return trimesh.creation.cylinder(radius=radius, height=high - low, sections=64, transform=(
        trimesh.transformations.translation_matrix([x, (low + high) / 2, 30]) @ _UP))


def _import(folder: Path, bores: dict[float, float]) -> Path:
    """A block with a through bore along y of each diameter [mm] of ``bores`` (at x 0, 40,
    ...) and in each a peg of the diameter it maps to: a shank along the bore, its head d 30
    outside the block's +y face (it goes in along -y); imported, the block the base."""
    cad = folder / "cad"
    cad.mkdir()
    block = trimesh.creation.box([60 + 40 * (len(bores) - 1), 50, 60],
                                 trimesh.transformations.translation_matrix([20 * (len(bores) - 1), 0, 30]))
    for k, (bore, peg) in enumerate(bores.items()):
        block = block.difference(_along_y(bore / 2, -40, 40, 40 * k))
        trimesh.boolean.union([_along_y(peg / 2, -45, 26, 40 * k), _along_y(15, 25, 35, 40 * k)]).export(
            cad / f"peg{k + 1}.stl")
    block.export(cad / "block.stl")
    (folder / "import.toml").write_text('base = "block"\n')
    run_import(cad, folder / "out", "mm", folder / "import.toml")
    return folder / "out"


@pytest.fixture(scope="module")
def imported(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The block with a d 20 bore and its d 20 peg, room 0, imported."""
    return _import(tmp_path_factory.mktemp("narrowed"), {20.0: 20.0})


def test_a_zero_clearance_peg_in_a_mesh_base_is_narrowed_by_the_cell(imported: Path) -> None:
    geometry = tomllib.loads((imported / "geometry.toml").read_text())
    assert "manual" not in geometry  # the cell inserts it (it was placed by hand: room 0 in the base's own mesh)
    assert geometry["hole_shapes"]["h1"]["widened"] == ["peg1"]
    assert geometry["part_shapes"]["peg1"]["size"] == pytest.approx(0.02)  # the CAD's section, as written
    # The cell reads it 0.15 mm narrower per side, and its pieces are so about its axis (z
    # in its part frame): the shank's 0.15 mm inside the d 20 circle, the head d 30 likewise.
    assert load_geometry(str(imported)).parts["peg1"].size == pytest.approx(0.02 - 2 * NOMINAL_FIT_ROOM)
    pieces = read_objects(imported / "meshes" / "peg1.convex.obj")
    reach = sorted(float(np.hypot(p[:, 0], p[:, 1]).max()) for p in pieces)
    assert reach[0] == pytest.approx(0.01 - NOMINAL_FIT_ROOM, abs=2e-6)
    assert reach[-1] == pytest.approx(0.015 - NOMINAL_FIT_ROOM, abs=2e-6)
    # Its pair is an experiment of the sim cell, reported with the CAD's room.
    assembly = load_assembly(str(imported))
    assert assembly.widened == {("peg1", "h1"): 0.0}
    assert not assembly.tried_by_hand("peg1", "h1", "sim")


@pytest.mark.slow  # an import (2 s); the cell's refusal of that peg: the quick test after it
def test_a_peg_the_narrowing_would_let_into_another_hole_is_placed_by_hand(tmp_path: Path) -> None:
    # peg1 d 20 at room 0 in its d 20 bore; beside it a d 19.8 bore (with its d 19.6 peg):
    # peg1 misses it by 0.1 mm per side, and 0.15 mm narrower would pass it.
    out = _import(tmp_path, {20.0: 20.0, 19.8: 19.6})
    geometry = tomllib.loads((out / "geometry.toml").read_text())
    assert set(geometry["manual"]) == {"peg1"}, geometry.get("manual")
    assert geometry["manual"]["peg1"]["reason"].startswith(
        "goes into hole h1 with +0.0000 mm of room per side, less than the 0.025 mm the simulated cell resolves; its "
        "section 0.15 mm narrower per side would pass hole h2 (-0.1"), geometry["manual"]["peg1"]["reason"]
    assert not any("widened" in shape for shape in geometry["hole_shapes"].values())


def test_the_cell_reads_a_peg_narrowed_and_refuses_one_that_would_then_pass_another_hole() -> None:
    peg = PartSpec("peg", "round", 0.020, shape="peg", length=0.07, mass=0.05, start=(0.3, 0.3), demo_hole="h1")
    hole = HoleSpec("h1", "round", 0.020, (0.5, 0.0), top_z=0.04, depth=0.03, zero_clearance=("peg",),
                    widened=("peg",))
    loose = HoleSpec("h2", "round", 0.021, (0.55, 0.0), top_z=0.04, depth=0.03)
    assert _with_widened_fits(peg, {"h1": hole, "h2": loose}).size == pytest.approx(0.0197)
    assert _with_widened_fits(peg, {"h2": loose}) == peg  # no narrowed peg stated: as read
    tight = HoleSpec("h2", "round", 0.0198, (0.55, 0.0), top_z=0.04, depth=0.03)  # -0.1 mm per side; +0.05 narrowed
    with pytest.raises(ExecutorError, match=r"its section 0\.15 mm narrower per side, and in hole 'h2' "
                                            r"\(-0\.1000 mm per side\) it would then fit"):
        _with_widened_fits(peg, {"h1": hole, "h2": tight})


def test_a_piece_is_narrowed_across_z_only() -> None:
    box = trimesh.creation.box([0.02, 0.01, 0.05])
    cut = narrowed(box.vertices, 0.001)
    assert cut is not None
    assert cut.extents == pytest.approx([0.018, 0.008, 0.05])  # its ends where they were
    slanted = trimesh.convex.convex_hull(np.array([[0, 0, 0], [0.01, 0, 0], [0, 0.01, 0], [0, 0, 0.01]]))
    assert narrowed(slanted.vertices, 0.01) is None  # nothing left


@pytest.mark.slow  # teaches the peg, then the block and the peg assembled in physics (about 30 s under load)
def test_a_zero_clearance_peg_narrowed_goes_into_a_mesh_base_in_physics(imported: Path) -> None:
    step, quat = assembled(teach(imported), "block", "peg1", "h1")
    assert step.attempts == 1, step
    assert trimesh.transformations.quaternion_matrix(np.roll(quat, 1))[:3, 2] == pytest.approx([0, 1, 0], abs=0.02)
