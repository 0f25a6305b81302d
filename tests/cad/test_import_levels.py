"""``import`` of a stepped housing (meshes): holes at two entry heights and of two depths
get a ``geometry.toml`` (the plate at one hole's level, the other hole with its own
``top_z`` and ``depth``) that the cell loads and builds; in physics each peg, taught in its
own hole, is inserted to the bottom of the other one."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import pytest
import trimesh

from assembly_constraints.cli import main
from assembly_constraints.executor.skills.teach import DEMO_CLEARANCE, teach_all
from assembly_constraints.executor.trial import Cell
from assembly_constraints.executor.world.geometry import load_geometry
from assembly_constraints.executor.world.scene import Scene
from tests.cad.test_import import SIZE_BOUND, _box

LOW = (0.020, 0.015)  # [m] entry height and depth of the hole in the low part of the housing
HIGH = (0.030, 0.012)  # [m] of the hole in its 10 mm step


@pytest.fixture(scope="module")
def imported(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A 120 × 60 × 20 mm housing with a 50 mm wide step 10 mm high, a 10.5 mm square blind
    hole in each part, a 10 mm square peg standing on the bottom of each [mm, 0.55 m in
    front of the arm], imported."""
    tmp = tmp_path_factory.mktemp("stepped")
    cad = tmp / "cad"
    cad.mkdir()
    (low_top, low_depth), (high_top, high_depth) = ((1000 * t, 1000 * d) for t, d in (LOW, HIGH))
    housing = trimesh.boolean.union([_box((120, 60, low_top), (550, 0, low_top / 2)),
                                     _box((50, 60, high_top - low_top), (585, 0, (low_top + high_top) / 2))],
                                    engine="manifold")
    housing = trimesh.boolean.difference([housing, _box((10.5, 10.5, low_depth), (520, 0, low_top - low_depth / 2)),
                                          _box((10.5, 10.5, high_depth), (585, 0, high_top - high_depth / 2))],
                                         engine="manifold")
    housing.export(cad / "housing.stl")
    _box((10, 10, 40), (520, 0, low_top - low_depth + 20)).export(cad / "low.stl")
    _box((10, 10, 40), (585, 0, high_top - high_depth + 20)).export(cad / "high.stl")
    assert main(["-q", "import", str(cad), "--out", str(tmp / "out")]) == 0
    return tmp / "out"


def test_holes_at_two_levels_get_a_geometry_the_cell_builds(imported: Path) -> None:
    geometry = load_geometry(str(imported))
    levels = {fit: (hole.top_z, hole.depth) for fit, hole in geometry.holes.items()}
    assert levels == {"h1": pytest.approx(LOW, abs=SIZE_BOUND), "h2": pytest.approx(HIGH, abs=SIZE_BOUND)}
    assert (geometry.plate.top_z, geometry.plate.tile_thickness) == pytest.approx(LOW, abs=SIZE_BOUND)
    shapes = tomllib.loads((imported / "geometry.toml").read_text())["hole_shapes"]
    assert {"top_z", "depth"} & set(shapes["h1"]) == set() and {"top_z", "depth"} <= set(shapes["h2"])
    assert geometry.base_mesh is not None  # a stepped housing is no plate of primitives
    scene = Scene(geometry, geometry.parts["low"].shape)
    scene.close()


@pytest.fixture(scope="module")
def taught(imported: Path) -> Path:
    """The imported product with its skills taught (each peg in its own hole)."""
    teach_all(str(imported))
    return imported


@pytest.mark.slow
@pytest.mark.parametrize(("part", "hole"), [("low", "h2"), ("high", "h1")])
def test_a_peg_taught_at_one_level_goes_to_the_bottom_of_the_other(taught: Path, part: str, hole: str) -> None:
    cell = Cell(str(taught))
    try:
        result = cell.run_trial(part, hole, seed=0)
        assert result.outcome == "fit", result.to_json()
        tip = cell.motion_for(part).controller.arm.read().tip_pos
        spec = cell.geometry.holes[hole]
        assert abs(tip[2] - spec.bottom_z) < DEMO_CLEARANCE, (tip, spec)
        assert math.dist(tip[:2], spec.position) < spec.size / 2
    finally:
        cell.close()
