"""``import`` of products (meshes) whose holes are not at one level: a stepped housing
(entries at two heights, two depths) and a flat plate with a shallow and a deep hole. Each
gets a ``geometry.toml`` (the plate at one hole's level, the other hole with its own
``top_z`` or ``depth``) that the cell loads and builds; in physics each peg, taught in its
own hole, is inserted to the bottom of the other one."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import pytest
import trimesh

from assembly_constraints.cli import main
from executor.skills.teach import DEMO_CLEARANCE
from executor.trial import Cell
from executor.world.geometry import load_geometry
from executor.world.scene import Scene
from tests.cad.conftest import teach
from tests.cad.test_import import SIZE_BOUND, _box

LEVELS = {"stepped": ((0.020, 0.015), (0.030, 0.012)), "flat": ((0.020, 0.015), (0.020, 0.010))}
"""Product → (entry height, depth) [m] of its holes h1 (x 520 mm) and h2 (x 585 mm)."""
X = (520.0, 585.0)  # [mm] the holes' x, at y 0: 0.55 m in front of the arm


@pytest.fixture(scope="module")
def imported(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Each product of :data:`LEVELS` imported: a 120 × 60 mm base 20 mm high (the stepped
    one with a 50 mm wide step on it up to h2's entry), a 10.5 mm square blind hole at each
    level, a 10 mm square peg 40 mm long standing on the bottom of each [mm]."""
    out: dict[str, Path] = {}
    for name, levels in LEVELS.items():
        cad = tmp_path_factory.mktemp(name) / "cad"
        cad.mkdir()
        (low, _), (high, _) = ((1000 * top, 1000 * depth) for top, depth in levels)
        solids = [_box((120, 60, low), (550, 0, low / 2))]
        if high > low:
            solids.append(_box((50, 60, high - low), (585, 0, (low + high) / 2)))
        base = trimesh.boolean.union(solids, engine="manifold") if len(solids) > 1 else solids[0]
        holes = [_box((10.5, 10.5, 1000 * d), (x, 0, 1000 * (t - d / 2))) for x, (t, d) in zip(X, levels)]
        trimesh.boolean.difference([base, *holes], engine="manifold").export(cad / "housing.stl")
        for peg, x, (top, depth) in zip(("low", "high"), X, levels):
            _box((10, 10, 40), (x, 0, 1000 * (top - depth) + 20)).export(cad / f"{peg}.stl")
        assert main(["-q", "import", str(cad), "--out", str(cad.parent / "out")]) == 0
        out[name] = cad.parent / "out"
    return out


@pytest.mark.parametrize("name", sorted(LEVELS))
def test_holes_at_two_levels_get_a_geometry_the_cell_builds(imported: dict[str, Path], name: str) -> None:
    geometry = load_geometry(str(imported[name]))
    levels = {hid: (hole.top_z, hole.depth) for hid, hole in geometry.holes.items()}
    assert levels == {hid: pytest.approx(level, abs=SIZE_BOUND) for hid, level in zip(("h1", "h2"), LEVELS[name])}
    assert {geometry.parts[peg].demo_hole for peg in ("low", "high")} == {"h1", "h2"}  # each peg in its hole
    assert (geometry.plate.top_z, geometry.plate.tile_thickness) == pytest.approx(LEVELS[name][0], abs=SIZE_BOUND)
    shapes = tomllib.loads((imported[name] / "geometry.toml").read_text())["hole_shapes"]
    assert {"top_z", "depth"} & set(shapes["h1"]) == set()  # at the plate's level
    assert ("top_z" in shapes["h2"], "depth" in shapes["h2"]) == (name == "stepped", True)
    # a flat plate is one of primitives, the bosses on the plate under them; a step is no plate
    assert (geometry.base_mesh is None) == (name == "flat")
    Scene(geometry, geometry.parts["low"].shape).close()


@pytest.fixture(scope="module")
def taught(imported: dict[str, Path]) -> dict[str, Path]:
    """The imported products with their skills taught (each peg in its own hole)."""
    for folder in imported.values():
        teach(folder)
    return imported


@pytest.mark.slow
@pytest.mark.parametrize(("name", "part", "hole"), [("stepped", "low", "h2"), ("stepped", "high", "h1"),
                                                    ("flat", "high", "h1")])
def test_a_peg_taught_at_one_level_goes_to_the_bottom_of_the_other(taught: dict[str, Path], name: str, part: str,
                                                                   hole: str) -> None:
    cell = Cell(str(taught[name]))
    try:
        result = cell.run_trial(part, hole, seed=0)
        assert result.outcome == "fit", result.to_json()
        tip = cell.motion_for(part).controller.arm.read().tip_pos
        spec = cell.geometry.holes[hole]
        assert abs(tip[2] - spec.bottom_z) < DEMO_CLEARANCE, (tip, spec)
        assert math.dist(tip[:2], spec.position) < spec.size / 2
    finally:
        cell.close()
