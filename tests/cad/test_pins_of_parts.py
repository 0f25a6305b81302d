"""A plate onto pins of several parts: a pin standing on a pad of the base and one on a
block placed by hand beside it (it lies on the base), the plate's two bores over both.
The import leaves the plate to the cell, naming the block as the owner of its further pin
(``pins_of``: the block stands at its goal in the plate's trials), a sim session learns its
fits in physics and assembles the plan; with the block's pin 1 mm off its place the same
skill stops the plate."""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest
import shapely
import trimesh

from tests.cad.conftest import import_on_base, learned_in_the_cell, manual_reasons, teach, trial_on_edited_mesh
from tests.conftest import Runner

X_MM = 560.0
"""Where the product stands along x [mm]: within the simulated arm's reach."""


def _prism(outline: shapely.Polygon, low: float, high: float) -> trimesh.Trimesh:
    """``outline`` [mm] extruded from ``low`` to ``high`` [mm] along z."""
    solid = trimesh.creation.extrude_polygon(outline, high - low)
    solid.apply_translation((0.0, 0.0, low))
    return solid


def _import(tmp: Path) -> Path:
    """The base (100 x 60 x 10 mm) with a 24 x 24 mm pad 10 mm high at x 540 mm and a d 8
    pin 20 mm above the pad; a block (24 x 24 x 10 mm) lying on the base at x 580 mm with a
    d 8 pin 20 mm above its top; a plate (70 x 24 x 8 mm: out of the product by more than the
    6 mm the fingers need) on the pad and the block with two d 8.2 bores over the pins; as
    STL files [mm], imported."""
    cad = tmp / "cad"
    cad.mkdir(parents=True)
    trimesh.boolean.union([_prism(shapely.box(X_MM - 50, -30, X_MM + 50, 30), 0, 10),
                           _prism(shapely.box(X_MM - 32, -12, X_MM - 8, 12), 5, 20),
                           _prism(shapely.Point(X_MM - 20, 0.0).buffer(4.0, quad_segs=32), 15, 40)],
                          engine="manifold").export(cad / "base.stl")
    trimesh.boolean.union([_prism(shapely.box(X_MM + 8, -12, X_MM + 32, 12), 10, 20),
                           _prism(shapely.Point(X_MM + 20, 0.0).buffer(4.0, quad_segs=32), 15, 40)],
                          engine="manifold").export(cad / "block.stl")
    plate = shapely.box(X_MM - 35, -12, X_MM + 35, 12)
    for x in (X_MM - 20, X_MM + 20):
        plate = plate.difference(shapely.Point(x, 0.0).buffer(4.1, quad_segs=64))
    _prism(plate, 20, 28).export(cad / "plate.stl")
    return import_on_base(cad, tmp, "base")


@pytest.fixture(scope="module")
def taught(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The product of :func:`_import` as drawn, imported and taught once for the module."""
    return teach(_import(tmp_path_factory.mktemp("pins_of")))



@pytest.mark.slow  # the import and the teaching: about 3 s of CPU
def test_a_plate_onto_pins_of_the_base_and_a_block_placed_by_hand_is_the_cell_s(taught: Path) -> None:
    geometry = tomllib.loads((taught / "geometry.toml").read_text())
    assert set(manual_reasons(taught)) == {"block"}  # no operation for it: it lies on the base
    plate = geometry["part_shapes"]["plate"]
    assert (plate["demo_hole"], plate["pins_of"]) == ("base_pin1", ["block"])
    assert "block_pin1" not in geometry["hole_shapes"]  # its further pin: no hole of the cell
    assert "must_precede(block,plate)." in (taught / "geometric_precedence.lp").read_text().split()


@pytest.mark.slow  # the plate taught (shared), a sim session with its assembly
def test_the_plate_is_learned_and_assembled_in_physics(run_main: Runner, taught: Path, tmp_path: Path) -> None:
    result, observed = learned_in_the_cell(run_main, taught, tmp_path / "run", exact=True)
    assert observed == {("plate", "base_pin1"): "fit"}
    cad = {atom for atom in (taught / "sizes.lp").read_text().replace(".", " ").split() if atom.startswith("fits(")}
    assert {f"fits({part},{hole})" for part, hole in result["fits"]} == cad == {
        "fits(plate,base_pin1)", "fits(plate,block_pin1)"}
    steps = {step["part"]: step for step in result["assembly"]["steps"]}
    assert result["assembly"]["assembled"] and steps["block"]["skill"] == "manual"
    assert (steps["plate"]["hole"], steps["plate"]["skill"]) == ("base_pin1", "insert")
    assert steps["plate"]["pose_error_mm"] <= 2.0, steps


@pytest.mark.slow  # teaches the plate (shared), then one attempt in physics (about 4 s of CPU)
def test_the_block_s_pin_off_its_place_stops_the_plate_in_physics(taught: Path, tmp_path: Path) -> None:
    # the block's pin 1 mm along x in its mesh: the plate's bores, 40 mm apart, no longer
    # pass both pins (the block at its goal in the trial's scene)
    def moved(block: trimesh.Trimesh) -> None:  # its frame's origin the centre of its bottom face
        vertices = block.vertices.copy()
        near = (np.linalg.norm(vertices[:, :2], axis=1) < 0.0045) & (vertices[:, 2] > 0.0095)  # above its top
        assert near.sum() >= 64
        vertices[near, 0] += 0.001
        block.vertices = vertices

    refused = trial_on_edited_mesh(taught, tmp_path / "moved", "block", moved, "plate", "base_pin1")
    assert refused.outcome == "no_fit" and refused.end_error > 0.01  # on the pins' tops, 20 mm above its goal
