"""A plate over two dowel pins of the base, each pin through its own bore: a base with two
d 8 pins 40 mm apart on a diagonal (30 deg from x) and a 70 x 24 x 8 mm plate with two
d 8.2 bores (0.1 mm of room per side) is imported with the plate one the cell puts onto
both pins (down its first, held as the CAD turns it, its second bore over the second pin),
taught and assembled in physics; with the second pin 1 mm farther from the first (the
bores' spacing wrong by 1 mm) the same skill stops it. A plate the cell cannot put onto
its pins stays placed by hand with the reason: too little room on one pin, or pins along a
horizontal axis."""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest
import shapely
import trimesh

from bridge.product import load_product_description
from executor.cad.cli import run_import
from executor.world.arm import quat_to_matrix
from tests.cad.conftest import teach, trial_on_edited_mesh
from tests.conftest import assembled

X_MM = 560.0
"""Where the product stands along x [mm]: within the simulated arm's reach."""
APART = 40.0
"""The distance between the two pins [mm]."""
TURN = 30.0
"""How far the product of the physics tests is turned about the vertical [deg]: its pins on a diagonal."""


def _import(tmp: Path, bores: tuple[float, float] = (8.2, 8.2), turn: float = 0.0, lying: bool = False) -> Path:
    """The base (100 x 60 x 10 mm) with two round d 8 pins (64-gons) standing 20 mm above its
    top at x 560 -/+ 20 mm, and the plate (70 x 24 x 8 mm) on that top with round ``bores``
    [mm] (128-gons) over the pins, all turned ``turn`` [deg] about the vertical through
    (560, 0), as STL files [mm], imported; with ``lying``, all turned a quarter turn about x
    instead (the pins along +y, 30 mm up, ``up = "+z"`` stated); the folder written."""
    cad = tmp / "cad"
    cad.mkdir(parents=True)
    base = trimesh.creation.box((100.0, 60.0, 10.0))
    base.apply_translation((X_MM, 0.0, 5.0))
    pins = [trimesh.creation.cylinder(radius=4.0, height=25.0, sections=64) for _ in range(2)]
    outline = shapely.box(-35.0, -12.0, 35.0, 12.0)
    for pin, bore, x in zip(pins, bores, (-APART / 2, APART / 2)):
        pin.apply_translation((X_MM + x, 0.0, 17.5))
        outline = outline.difference(shapely.Point(x, 0.0).buffer(bore / 2, quad_segs=32))
    plate = trimesh.creation.extrude_polygon(outline, 8.0)
    plate.apply_translation((X_MM, 0.0, 10.0))
    base = trimesh.boolean.union([base, *pins], engine="manifold")
    turned = (trimesh.transformations.rotation_matrix(-np.pi / 2, (1.0, 0.0, 0.0), (X_MM, 0.0, 30.0)) if lying else
              trimesh.transformations.rotation_matrix(np.radians(turn), (0.0, 0.0, 1.0), (X_MM, 0.0, 0.0)))
    base.apply_transform(turned)
    plate.apply_transform(turned)
    base.export(cad / "base.stl")
    plate.export(cad / "plate.stl")
    # lying, it is a product drawn z up on its side (the import would take it for one drawn y up): stated
    up = 'up = "+z"\n' if lying else ""
    (tmp / "import.toml").write_text(f'base = "base"\n{up}[parts.plate]\ntray = [0.30, 0.28]\n')
    run_import(cad, tmp / "out", "mm", tmp / "import.toml")
    return tmp / "out"


@pytest.fixture(scope="module")
def taught(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The plate with two d 8.2 bores over the pins on a diagonal imported and taught on its
    first pin (``executor teach``, in this process)."""
    return teach(_import(tmp_path_factory.mktemp("two_pins"), turn=TURN))


def _atoms(path: Path, name: str) -> set[str]:
    return {atom.strip() for line in path.read_text().splitlines() if not line.startswith("%")
            for atom in line.split(".") if atom.strip().startswith(f"{name}(")}


@pytest.mark.slow  # the import and the teaching: about 4 s of CPU
def test_a_plate_over_two_pins_is_one_the_cell_puts_onto_them(taught: Path) -> None:
    # both pairs are written for the learner, the truth backend and the prior; the cell has
    # the first pin as its hole (the plate's demo_hole) and no hole at the second, which the
    # plate takes: no plan puts the plate down the second pin with its first bore. Each pin
    # is measured alone: the other, on the diagonal, lies within the square about the first
    # that the plate reaches, but not within the circle
    product = load_product_description(taught)
    geometry = product.geometry
    assert geometry is not None and geometry.manual == {}
    assert _atoms(taught / "sizes.lp", "fits") == {"fits(plate,base_pin1)", "fits(plate,base_pin2)"}
    assert set(geometry.hole_shapes) == {"base_pin1"} and set(product.assembly.holes) == {"base_pin1", "base_pin2"}
    pin = geometry.hole_shapes["base_pin1"]
    assert pin.kind == "round" and pin.size == pytest.approx(0.008, abs=1e-6)
    plate = geometry.part_shapes["plate"]
    assert plate.bore and plate.demo_hole == "base_pin1"
    # its pieces: one layer, both bores regular polygons about their inscribed circles
    assert "each of its 2 bores a regular" in (taught / "meshes" / "plate.convex.obj").read_text().splitlines()[2]


@pytest.mark.slow  # teaches the plate (shared), then the base and the plate assembled in physics (about 5 s of CPU)
def test_a_plate_onto_two_pins_is_assembled_within_2_mm(taught: Path) -> None:
    step, quat = assembled(taught, "base", "plate", "base_pin1")
    assert step.skill == "insert", step
    # down on the base's top, so each bore is around its pin: turned as the CAD has it (the
    # part frame's), within what 0.1 mm of room per side leaves over 40 mm (0.29 deg)
    assert quat_to_matrix(quat)[:, 0] == pytest.approx([1.0, 0.0, 0.0], abs=0.005)


@pytest.mark.slow  # teaches the plate (shared), then one attempt in physics (about 5 s of CPU)
def test_a_second_pin_off_its_place_stops_the_plate_in_physics(taught: Path, tmp_path: Path) -> None:
    # The base (its own mesh) with its second pin 1 mm farther from the first, along the
    # diagonal: the plate's bores, 40 mm apart, no longer pass both pins. One attempt: the trial's second one after
    # a no-fit is tests/executor/test_executor_cell.py's.
    holes = load_product_description(taught).assembly.holes
    first, second = (np.array(holes[hid].position or (0.0, 0.0)) for hid in ("base_pin1", "base_pin2"))

    def moved(base: trimesh.Trimesh) -> None:
        vertices = base.vertices.copy()
        near = np.linalg.norm(vertices[:, :2] - second, axis=1) < 0.0045  # the pin and its foot's ring
        vertices[near, :2] += 0.001 * (second - first) / np.linalg.norm(second - first)
        base.vertices = vertices

    refused = trial_on_edited_mesh(taught, tmp_path / "moved", "base", moved, "plate", "base_pin1")
    assert refused.outcome == "no_fit" and refused.end_error > 0.01  # on the pins' tops, 20 mm above its goal


def test_a_plate_the_cell_cannot_put_onto_its_two_pins_is_placed_by_hand(tmp_path: Path) -> None:
    tight = tomllib.loads((_import(tmp_path / "tight", (8.2, 8.04)) / "geometry.toml").read_text())
    # the d 8.04 bore, a 128-gon, over the d 8 pin's 64-gon (its vertex circle)
    assert tight["manual"]["plate"]["reason"] == ("goes onto a pin (base_pin2) with +0.0187 mm of room per side, less "
                                                  "than the 0.025 mm the simulated cell resolves; the cell widens a "
                                                  "bore only for a part on one pin, its bore and every pin round")
    assert tight["manual"]["plate"]["on"] == ["base_pin1", "base_pin2"]
    lying = tomllib.loads((_import(tmp_path / "lying", lying=True) / "geometry.toml").read_text())
    assert lying["manual"]["plate"]["reason"] == (
        "goes onto 2 pins (base_pin1, base_pin2) along -y: the cell puts a part onto several pins only down onto "
        "pins standing up (+z)")
