"""``import``'s up axis read by gravity: without ``up``, a product that as read could not
rest on the floor as assembled (its centre of mass outside what it stands on, its base
free to slide down the parts under it) is refused, and the up a refusal names is one whose
reading is not refused itself (docs/import.md, "The up axis")."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh

from executor import ExecutorError
from executor.cad.cli import ImportOptions, run_import
from executor.cad.upright.gravity import turned_facts
from executor.campaign.import_bench import write_shafts


def _box(extents: tuple[float, float, float], centre: tuple[float, float, float]) -> trimesh.Trimesh:
    return trimesh.creation.box(extents, trimesh.transformations.translation_matrix(centre))


def _y_up(mesh: trimesh.Trimesh) -> trimesh.Trimesh:
    """A z-up part as drawn y up: (x, y, z) -> (x, z, -y), exact."""
    v = np.asarray(mesh.vertices)
    mesh.vertices = np.column_stack([v[:, 0], v[:, 2], -v[:, 1]])
    return mesh


def _write(folder: Path, parts: dict[str, trimesh.Trimesh], base: str) -> Path:
    """``parts`` (z up, mm) written drawn y up as STL into ``folder``, with ``base`` the
    fixture in ``folder/import.toml``."""
    folder.mkdir()
    for name, mesh in parts.items():
        _y_up(mesh).export(folder / f"{name}.stl")
    (folder / "import.toml").write_text(f'base = "{base}"\n')
    return folder


def test_a_shaft_through_its_housing_drawn_y_up_is_refused_naming_y(tmp_path: Path) -> None:
    # z up: an 80 x 50 x 60 mm housing with a 29 mm square bore along y, a 28.3 mm shaft
    # through it 25 mm out of each face. Drawn y up and read z up, the shaft stands
    # upright through the housing, which nothing keeps from sliding down it to the floor
    housing = _box((80.0, 50.0, 60.0), (0.0, 0.0, 30.0)).difference(_box((29.0, 80.0, 29.0), (0.0, 0.0, 30.0)))
    cad = _write(tmp_path / "cad", {"housing": housing, "shaft": _box((28.3, 100.0, 28.3), (0.0, 0.0, 30.0))},
                 "housing")
    with pytest.raises(ExecutorError) as refused:
        run_import(cad, tmp_path / "read_z_up", "mm", cad / "import.toml")
    assert ("the base housing stands 25.000 mm above the product's lowest point and no part keeps it from going "
            'down: it would slide down shaft; read with up = "+y" or "-y" standing steadiest (39.8 deg from tipping '
            'over): the CAD may be drawn y up; set up = "+y" or "-y" (--up +y or --up=-y)') in str(refused.value), \
        str(refused.value)
    assert not (tmp_path / "read_z_up").exists()
    turned = run_import(cad, tmp_path / "turned", "mm", cad / "import.toml", ImportOptions(up="+y"))
    assert {fit.axis[1] for fit in turned.derived.holes.values()} == {"y"}


def test_a_product_whose_arm_stands_beside_its_base_drawn_y_up_is_refused_as_falling_over(tmp_path: Path) -> None:
    # z up: a 200 x 40 x 20 mm bar, an arm 150 mm long lying on it across, reaching 130 mm
    # beyond it, held by a peg through it into the bar. Drawn y up and read z up, the arm
    # hangs 130 mm under the bar, the product on the arm's end, its centre of mass beside it
    bar = _box((200.0, 40.0, 20.0), (0.0, 0.0, 10.0)).difference(_box((10.6, 10.6, 20.0), (80.0, 0.0, 20.0)))
    arm = _box((30.0, 150.0, 10.0), (80.0, 55.0, 25.0)).difference(_box((10.6, 10.6, 20.0), (80.0, 0.0, 25.0)))
    cad = _write(tmp_path / "cad", {"bar": bar, "arm": arm, "peg": _box((10.0, 10.0, 30.0), (80.0, 0.0, 25.0))},
                 "bar")
    with pytest.raises(ExecutorError) as refused:
        run_import(cad, tmp_path / "read_z_up", "mm", cad / "import.toml")
    assert ("the product's centre of mass lies 47.671 mm outside what it stands on (22.0 deg past its edge): it "
            'would fall over; read with up = "+y" standing steadiest (30.8 deg from tipping over): the CAD may be '
            'drawn y up; set up = "+y" or --up +y') in str(refused.value), str(refused.value)
    imported = run_import(cad, tmp_path / "turned", "mm", cad / "import.toml", ImportOptions(up="+y"))
    assert imported.derived.axis["peg"] == "+z"


@pytest.mark.slow  # a 20-part import
def test_the_shaft_unit_drawn_y_up_is_refused_naming_y_not_the_axis_of_its_bores(tmp_path: Path) -> None:
    # the bench's 20-part unit (two shafts along x through housings on a floor plate 200 mm
    # long) drawn y up stands read z up on the plate's 60 x 65 mm end, 200 mm tall, its bores
    # along x; read with x up its shafts would stand upright under the housings, the base
    # 35 mm above the floor, its lids and pulleys free to drop; read -y up the base would stand 5 mm up on its lids
    z_up = tmp_path / "z_up"
    z_up.mkdir()
    write_shafts(z_up, 20, 13)
    parts = {path.stem: trimesh.load(path, force="mesh", process=False) for path in sorted(z_up.glob("*.stl"))}
    cad = _write(tmp_path / "cad", parts, "base")
    with pytest.raises(ExecutorError) as refused:
        run_import(cad, tmp_path / "read_z_up", "mm", cad / "import.toml")
    assert "the base base is thinnest along x" in str(refused.value)
    assert ('the other parts standing out of it along -x: the CAD may be drawn y up; set up = "+y" or --up +y '
            '(up = "+z"') in str(refused.value), str(refused.value)


def test_a_product_assembled_wholly_from_below_is_refused_as_upside_down(tmp_path: Path) -> None:
    # z up: a screw through a 60 x 60 x 30 mm block from above, its head in a counterbore
    # flush with the top, its shank 8 mm under the block (bd_warehouse's pillow block).
    # Drawn z down, the screw goes in from below, its shank 8 mm above the block
    cad = tmp_path / "cad"
    cad.mkdir()
    hole = trimesh.boolean.union([_box((10.0, 10.0, 40.0), (0.0, 0.0, 15.0)),
                                  _box((16.0, 16.0, 10.0), (0.0, 0.0, 30.0))], engine="manifold")
    upside_down = np.diag([1.0, -1.0, -1.0, 1.0])  # about x by 180 deg, exact
    _box((60.0, 60.0, 30.0), (0.0, 0.0, 15.0)).difference(hole).apply_transform(upside_down).export(cad / "block.stl")
    trimesh.boolean.union([_box((9.6, 9.6, 33.0), (0.0, 0.0, 8.5)), _box((15.6, 15.6, 5.0), (0.0, 0.0, 27.5))],
                          engine="manifold").apply_transform(upside_down).export(cad / "screw.stl")
    (tmp_path / "import.toml").write_text('base = "block"\n')
    with pytest.raises(ExecutorError) as refused:
        run_import(cad, tmp_path / "read_z_up", "mm", tmp_path / "import.toml")
    assert ("every one of the 1 other parts goes in from below (leaves the product along -z only): the CAD may be "
            'drawn upside down (z down); set up = "-z" or --up=-z') in str(refused.value), str(refused.value)
    turned = run_import(cad, tmp_path / "turned", "mm", tmp_path / "import.toml", ImportOptions(up="-z"))
    assert turned.derived.axis["screw"] == "+z"


def test_a_base_held_off_the_floor_where_another_up_rests_it_steadier_is_refused(tmp_path: Path) -> None:
    # z up: the housing and shaft above, the shaft's shoulder against the housing's +y face
    # and a collar on the shaft against its -y face. Drawn y up and read z up, the shoulder
    # holds the housing 25 mm up on the upright shaft (nothing would drop: the shaft stands
    # on the floor, the collar on the housing); read y up the housing rests on the floor,
    # steadier
    housing = _box((80.0, 50.0, 60.0), (0.0, 0.0, 30.0)).difference(_box((29.0, 80.0, 29.0), (0.0, 0.0, 30.0)))
    shaft = trimesh.boolean.union([_box((28.3, 100.0, 28.3), (0.0, 0.0, 30.0)),
                                   _box((50.0, 10.0, 50.0), (0.0, 30.0, 30.0))], engine="manifold")
    collar = _box((50.0, 10.0, 50.0), (0.0, -30.0, 30.0)).difference(_box((29.0, 20.0, 29.0), (0.0, -30.0, 30.0)))
    cad = _write(tmp_path / "cad", {"housing": housing, "shaft": shaft, "collar": collar}, "housing")
    with pytest.raises(ExecutorError) as refused:
        run_import(cad, tmp_path / "read_z_up", "mm", cad / "import.toml")
    assert ("the base housing stands 25.000 mm above the product's lowest point on the parts under it, the "
            "product 15.8 deg from tipping over, where 4 other up(s) would rest the base on the floor steadier (up to "
            '39.8 deg); read with up = "+y" or "-y" standing steadiest (39.8 deg from tipping over): the CAD may be '
            'drawn y up; set up = "+y" or "-y" (--up +y or --up=-y)') in str(refused.value), str(refused.value)


def test_facts_turned_as_an_up_turns_them_are_those_an_import_with_that_up_derives(tmp_path: Path) -> None:
    # what the up check reads other ups by (and tests.cad.up_readings evaluates it by); the
    # shaft's flange against the housing's face: it leaves one way only (a part free both
    # ways keeps the way its import chose, where an import with the other up picks the cell's)
    housing = _box((80.0, 50.0, 60.0), (0.0, 0.0, 30.0)).difference(_box((29.0, 80.0, 29.0), (0.0, 0.0, 30.0)))
    shaft = trimesh.boolean.union([_box((28.3, 60.0, 28.3), (0.0, 5.0, 30.0)),
                                   _box((50.0, 10.0, 50.0), (0.0, 40.0, 30.0))], engine="manifold")
    cad = _write(tmp_path / "cad", {"housing": housing, "shaft": shaft}, "housing")
    as_drawn = run_import(cad, tmp_path / "z", "mm", cad / "import.toml", ImportOptions(up="+z"))
    turned = turned_facts(as_drawn.derived, "+y")
    imported = run_import(cad, tmp_path / "y", "mm", cad / "import.toml", ImportOptions(up="+y"))
    assert turned.axis == imported.derived.axis == {"shaft": "+y"}
    assert {h: f.axis for h, f in turned.holes.items()} == {h: f.axis for h, f in imported.derived.holes.items()}
    assert turned.blockers == imported.derived.blockers
    corner = {name: d.parts["housing"].mesh.bounds[0] for name, d in (("turned", turned), ("y", imported.derived))}
    for pid, part in imported.derived.parts.items():  # the same up to where each import placed it
        assert np.allclose(turned.parts[pid].mesh.bounds - corner["turned"], part.mesh.bounds - corner["y"],
                           rtol=0.0, atol=1e-9), pid
