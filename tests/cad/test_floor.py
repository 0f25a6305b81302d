"""``import`` stands a product on the cell's floor: the lowest point of all its parts goes to
z = 0 (a product drawn centred on the origin would otherwise be cut by the floor, one drawn
above it would float), unless ``place`` gives z; within ``FLOOR_TOLERANCE`` nothing moves."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest
import trimesh

from assembly_constraints.cli import main
from executor import ExecutorError
from executor.cad.cli import FLOOR_TOLERANCE, ImportOptions, run_import
from tests.cad.conftest import teach

HEIGHT_MM = 50.0
"""The box's height [mm]: its top stands this high in the cell when its bottom is on the floor."""


def _box(size: tuple[float, float, float], centre: tuple[float, float, float]) -> trimesh.Trimesh:
    box = trimesh.creation.box(extents=size)
    box.apply_translation(centre)
    return box


def _boxed_peg(folder: Path, bottom: float) -> Path:
    """A 60 x 60 x 50 mm box with its bottom at ``bottom`` [mm], a 10.5 mm square hole 30 mm
    deep from its top, and a 10 mm square peg 40 mm long down to the hole's bottom [mm]."""
    folder.mkdir()
    z = bottom + HEIGHT_MM / 2  # the box's centre
    body = trimesh.boolean.difference([_box((60, 60, HEIGHT_MM), (0, 0, z)), _box((10.5, 10.5, 32), (0, 0, z + 11))],
                                      engine="manifold")
    body.export(folder / "box.stl")
    _box((10, 10, 40), (0, 0, z + 15)).export(folder / "peg.stl")
    return folder


def _top_z(out: Path) -> float:
    """The plate's top in the cell [m], as geometry.toml states it."""
    return float(tomllib.loads((out / "geometry.toml").read_text())["plate"]["top_z"])


@pytest.mark.parametrize("bottom", [-HEIGHT_MM / 2, 30.0])  # centred on the origin (cut by the floor), floating
def test_a_product_stands_on_the_floor(tmp_path: Path, capsys: pytest.CaptureFixture[str], bottom: float) -> None:
    cad = _boxed_peg(tmp_path / "cad", bottom)
    assert main(["import", str(cad), "--out", str(tmp_path / "out")]) == 0
    printed = capsys.readouterr().out
    assert (f"the product's lowest point (of all its parts) on the cell's floor, z = 0 (set place = [x, y, z] or "
            f"--place X,Y,Z for another height), from z = {bottom:.3f} mm in the CAD") in printed
    assert f"every part moved by (560.000, 0.000, {-bottom:.3f}) mm from the CAD frame" in printed
    assert _top_z(tmp_path / "out") == pytest.approx(HEIGHT_MM / 1000, abs=1e-9)
    header = (tmp_path / "out" / "assembly.toml").read_text().splitlines()[0]
    assert f"moved by (560.000, 0.000, {-bottom:.3f}) mm from the CAD frame" in header


def test_place_sets_the_height_as_given(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    cad = _boxed_peg(tmp_path / "cad", -HEIGHT_MM / 2)
    assert main(["import", str(cad), "--out", str(tmp_path / "out"), "--place", "0.56,0,0.01"]) == 0
    assert "the product's lowest point (of all its parts) at z = 10.000 mm (place)" in capsys.readouterr().out
    assert _top_z(tmp_path / "out") == pytest.approx(0.06, abs=1e-9)
    config = tmp_path / "import.toml"
    config.write_text("place = [0.56, 0.0, -0.025]\n")  # as drawn: the floor cuts it, as asked
    done = run_import(cad, tmp_path / "as_drawn", "mm", config)
    assert done.offset == pytest.approx((0.56, 0.0, 0.0), abs=1e-12)
    assert _top_z(tmp_path / "as_drawn") == pytest.approx(0.025, abs=1e-9)


def test_a_rounding_below_the_floor_moves_nothing(tmp_path: Path) -> None:
    cad = _boxed_peg(tmp_path / "cad", -FLOOR_TOLERANCE * 1000 / 2)
    done = run_import(cad, tmp_path / "out", "mm", None, ImportOptions(place=(0.56, 0.0)))
    assert done.offset[2] == 0.0
    beyond = _boxed_peg(tmp_path / "beyond", -FLOOR_TOLERANCE * 1000 * 2)
    assert run_import(beyond, tmp_path / "out2", "mm", None).offset[2] == pytest.approx(2 * FLOOR_TOLERANCE, rel=1e-6)


@pytest.mark.slow  # two imports and two teachings (2 s); the import on the floor: the quick tests above
def test_the_peg_of_a_product_drawn_centred_on_the_origin_is_taught(tmp_path: Path) -> None:
    # Cut by the floor (its lowest point kept at z = -25 mm, as drawn), the floor stops the
    # peg 4.5 mm short of the hole's bottom; on the floor the teaching reaches it.
    cad = _boxed_peg(tmp_path / "cad", -HEIGHT_MM / 2)
    run_import(cad, tmp_path / "drawn", "mm", None, ImportOptions(place=(0.56, 0.0, -HEIGHT_MM / 2000)))
    with pytest.raises(ExecutorError, match="does not reach the bottom of its demo_hole"):
        teach(tmp_path / "drawn")
    run_import(cad, tmp_path / "stood", "mm", None)
    assert (teach(tmp_path / "stood") / "demonstrations" / "peg.json").is_file()
