"""``import``'s up axis: a product drawn with another axis than z up (``up = "+y"``,
``--up``) is turned by an exact signed permutation right after reading, so it gives the
same assembly facts as drawn z up; without ``up`` a product whose base lies on its side
with its holes opening sideways (standing on its edge, or the other parts set on one face),
is upside down (the other parts set on its bottom face, or left downwards), or is tilted
by another angle than quarter turns, is refused, naming the setting."""

from __future__ import annotations

import json
import subprocess
import sys
import tomllib
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import shapely
import trimesh

from executor import ExecutorError
from executor.cad.cli import Imported, ImportOptions, run_import
from executor.cad.upright import drawn_tilted
from tests.cad.test_corpus import _atoms
from tests.conftest import Runner, error_lines

CORPUS = Path(__file__).parent / "corpus"
DRAWN: dict[str, Callable[[np.ndarray], np.ndarray]] = {
    "+y": lambda v: np.column_stack([v[:, 0], v[:, 2], -v[:, 1]]),  # the cell's +z is the CAD's +y
    "-x": lambda v: np.column_stack([-v[:, 2], v[:, 1], v[:, 0]]),  # the cell's +z is the CAD's -x
    "-z": lambda v: np.column_stack([v[:, 0], -v[:, 1], -v[:, 2]]),  # upside down: the cell's +z is the CAD's -z
}
"""A z-up product's coordinates (n, 3) as drawn with another axis up: exact (permuted, negated)."""
FACTS = ("sizes.lp", "geometric_precedence.lp", "nominal_sizes.lp")


def _drawn(product: str, up: str, folder: Path) -> Path:
    """The corpus ``product``'s meshes written as drawn with ``up`` up, into ``folder/meshes``."""
    meshes = folder / "meshes"
    meshes.mkdir(parents=True)
    for path in sorted((CORPUS / product / "meshes").iterdir()):
        mesh = trimesh.load(path, force="mesh", process=False)
        mesh.vertices = DRAWN[up](np.asarray(mesh.vertices))
        mesh.export(meshes / path.name)
    return meshes


def _same(a: Any, b: Any, where: str = "") -> None:
    """``a`` and ``b`` (parsed TOML) alike: the same keys and strings, numbers within 1 nm
    (a mesh file's digest left out: the meshes are compared by :func:`_same_meshes`)."""
    if isinstance(a, dict):
        assert isinstance(b, dict) and a.keys() == b.keys(), where
        for key in a.keys() - {"sha256"}:
            _same(a[key], b[key], f"{where}.{key}")
    elif isinstance(a, list):
        assert isinstance(b, list) and len(a) == len(b), where
        for k, (x, y) in enumerate(zip(a, b, strict=True)):
            _same(x, y, f"{where}[{k}]")
    elif isinstance(a, float):
        assert b == pytest.approx(a, abs=1e-9), where
    else:
        assert a == b, where


def _same_meshes(one: Path, other: Path) -> None:
    """The meshes two imports wrote for the cell (``meshes/``) alike: the same files, their
    vertices within 1 nm and the same triangles."""
    names = sorted(path.name for path in (one / "meshes").glob("*.obj")) if (one / "meshes").is_dir() else []
    assert names == (sorted(path.name for path in (other / "meshes").glob("*.obj"))
                     if (other / "meshes").is_dir() else [])
    for name in names:
        a = trimesh.load(one / "meshes" / name, force="mesh", process=False)
        b = trimesh.load(other / "meshes" / name, force="mesh", process=False)
        assert np.array_equal(a.faces, b.faces), name
        assert np.allclose(a.vertices, b.vertices, rtol=0.0, atol=1e-9), name


def _same_import(first: Imported, second: Imported, one: Path, other: Path) -> None:
    """Two imports wrote the same assembly facts: parts, holes and trays, the fits, the
    precedence and the nominal rooms, each part's axis, the cell's geometry and meshes."""
    _same_meshes(one, other)
    for name in ("assembly.toml", "geometry.toml"):
        assert (one / name).is_file() == (other / name).is_file(), name
        if (one / name).is_file():
            _same(tomllib.loads((one / name).read_text()), tomllib.loads((other / name).read_text()), name)
    for name in FACTS:
        assert _atoms(one / name) == _atoms(other / name), name
    assert first.derived.axis == second.derived.axis
    assert {h: (f.axis, f.part) for h, f in first.derived.holes.items()} == \
        {h: (f.axis, f.part) for h, f in second.derived.holes.items()}


@pytest.fixture(scope="module")
def as_drawn(tmp_path_factory: pytest.TempPathFactory) -> Callable[[str], tuple[Imported, Path]]:
    """A corpus product imported z up as drawn, with its ``import.toml``: what the import
    derived and the folder it wrote, once per product for the module's tests."""
    done: dict[str, tuple[Imported, Path]] = {}

    def get(product: str) -> tuple[Imported, Path]:
        if product not in done:
            out = tmp_path_factory.mktemp(product) / "z_up"
            done[product] = run_import(CORPUS / product / "meshes", out, "mm", CORPUS / product / "import.toml"), out
        return done[product]

    return get


@pytest.mark.slow  # two imports of a five-part product (three for its first test)
@pytest.mark.parametrize(("product", "up", "words"), [
    ("agh_prism_array", "+y", ["the base box is thinnest along y", "4 of its 4 holes and pins open along y, the "
                               'other parts standing out of it along +y: the CAD may be drawn y up; set up = "+y" '
                               "or --up +y"]),
    ("factory_rect_pegs", "-x", ["the base hole_block is thinnest along x", "4 of its 4 holes and pins open along x",
                                 'along -x: the CAD may be drawn x up; set up = "-x" or --up=-x']),
    # upside down: the pegs hang 41 mm under the block through its holes
    ("factory_rect_pegs", "-z", ["the base hole_block is 8.992 mm tall and 4 of its 4 holes and pins open along z, "
                                 "the other parts standing out of it along -z (41.008 mm; at most 0.000 mm the other "
                                 'way and 0.000 mm across): the CAD may be drawn upside down (z down); set up = "-z" '
                                 "or --up=-z"]),
])
def test_a_product_drawn_with_another_axis_up_gives_the_same_facts(
        as_drawn: Callable[[str], tuple[Imported, Path]], tmp_path: Path, product: str, up: str,
        words: list[str]) -> None:
    config = CORPUS / product / "import.toml"
    first, z_up = as_drawn(product)
    meshes = _drawn(product, up, tmp_path / "drawn")
    turned = run_import(meshes, tmp_path / "turned", "mm", config, ImportOptions(up=up))
    _same_import(first, turned, z_up, tmp_path / "turned")
    assert f"the CAD's {up} is up (up): every part turned about" in turned.assumed[0]
    assert f"the CAD's {up} turned up" in (tmp_path / "turned" / "assembly.toml").read_text().splitlines()[0]
    # without up, the base stands on its edge with its holes opening sideways: refused, nothing written
    with pytest.raises(ExecutorError) as refused:
        run_import(meshes, tmp_path / "read_z_up", "mm", config)
    assert all(word in str(refused.value) for word in words), str(refused.value)
    assert not (tmp_path / "read_z_up").exists()


@pytest.mark.slow  # two imports
def test_up_in_the_settings_and_an_explicit_z_up(tmp_path: Path) -> None:
    meshes = _drawn("agh_prism_array", "+y", tmp_path / "drawn")
    (tmp_path / "up.toml").write_text('base = "box"\nup = "+y"\n')
    turned = run_import(meshes, tmp_path / "turned", "mm", tmp_path / "up.toml")
    assert {fit.axis for fit in turned.derived.holes.values()} == {"+z"}
    # z stated up is the user's word: the product is imported lying on its side, holes entered along -y
    (tmp_path / "z.toml").write_text('base = "box"\nup = "+z"\n')
    side = run_import(meshes, tmp_path / "side", "mm", tmp_path / "z.toml")
    assert {fit.axis for fit in side.derived.holes.values()} == {"+y"}
    assert side.assumed[0].startswith("the CAD's +z is up (up)")


@pytest.mark.parametrize(("argv", "setting", "words"), [
    (["--up", "y"], None, ["argument --up", "'y': expected one of +x, -x, +y, -y, +z, -z"]),
    (["--up", "-y"], None, ["argument --up: expected one argument"]),
    ([], 'up = "y+"\n', ["import.toml: up: expected one of +x, -x, +y, -y, +z, -z", "got 'y+'"]),
    ([], "up = 1\n", ["import.toml: up: expected one of", "got 1"]),
])
def test_a_bad_up_is_one_line(tmp_path: Path, run_main: Runner, argv: list[str], setting: str | None,
                              words: list[str]) -> None:
    (tmp_path / "cad").mkdir()
    trimesh.creation.box((0.05, 0.05, 0.01)).export(tmp_path / "cad" / "plate.stl")
    config = []
    if setting is not None:
        (tmp_path / "import.toml").write_text(setting)
        config = ["--config", "import.toml"]
    done = run_main("import", "cad", "--out", "out", "--units", "m", *config, *argv, cwd=tmp_path)
    lines = error_lines(done.stderr)
    assert done.returncode == 2 and len(lines) == 1 and "Traceback" not in done.stderr, done.stderr
    assert all(word in lines[0] for word in words), lines[0]
    assert not (tmp_path / "out").exists()


@pytest.mark.slow  # build123d in a process and two STEP imports
def test_a_step_product_drawn_y_up_keeps_its_exact_cylinders(tmp_path: Path) -> None:
    script = tmp_path / "make.py"
    script.write_text(
        "from build123d import *\n"
        "def product(turn):\n"
        "    plate = Box(100, 80, 12) + Pos(25, 0, 10) * Box(20, 20, 8)\n"  # a boss: the cell's base is its mesh
        "    plate = plate - Pos(-20, 0, 2) * Cylinder(6.65, 12) - Pos(25, 0, 12) * Cylinder(4.15, 8)\n"
        "    plate = turn * plate; plate.label = 'plate'\n"
        "    peg = turn * (Pos(-20, 0, 11) * Cylinder(6.0, 30)); peg.label = 'peg'\n"
        "    return Compound(label='product', children=[plate, peg])\n"
        f"export_step(product(Rot(0, 0, 0)), {str(tmp_path / 'z' / 'p.step')!r})\n"
        f"export_step(product(Rot(-90, 0, 0)), {str(tmp_path / 'y' / 'p.step')!r})\n")  # (x, y, z) -> (x, z, -y)
    (tmp_path / "z").mkdir()
    (tmp_path / "y").mkdir()
    subprocess.run([sys.executable, str(script)], check=True)
    first = run_import(tmp_path / "z" / "p.step", tmp_path / "z_up", "mm", None)
    turned = run_import(tmp_path / "y" / "p.step", tmp_path / "y_up", "mm", None, ImportOptions(up="+y"))
    _same_import(first, turned, tmp_path / "z_up", tmp_path / "y_up")
    # the base is simulated from its B-rep tessellated again for the cell, turned too
    assert (tmp_path / "y_up" / "meshes" / "plate.obj").is_file()
    fit = turned.derived.hole_of["peg"]
    assert fit.section is not None and fit.axis == "+z"
    # the B-rep's cylinders, turned with the mesh, give the round sizes exactly
    assert (fit.hole.a, fit.section.a) == pytest.approx((0.0133, 0.012), abs=1e-9)
    with pytest.raises(ExecutorError, match='thinnest along y .* 1 of its 1 holes and pins open along y, the other '
                       'parts standing out of it along \\+y: the CAD may be drawn y up; set up = "\\+y"'):
        run_import(tmp_path / "y" / "p.step", tmp_path / "read_z_up", "mm", None)


def _block_and_peg(folder: Path, peg_low: float, length: float = 100.0) -> Path:
    """A y-up block (60 x 50 x 60 mm: 50 mm tall along y) with a 29 mm square hole through
    it along y, and a 28.3 mm square peg ``length`` [mm] long in it from ``peg_low`` [mm] along y,
    written as STL into ``folder``: read z up, the block lies on a side only 1.2 times as
    tall as it is thick."""
    folder.mkdir()
    block = trimesh.creation.box((60.0, 50.0, 60.0))
    block.apply_translation((0.0, 25.0, 0.0))
    block = block.difference(trimesh.creation.box((29.0, 80.0, 29.0), trimesh.transformations.translation_matrix(
        (0.0, 25.0, 0.0))))
    block.export(folder / "block.stl")
    trimesh.creation.box((28.3, length, 28.3), trimesh.transformations.translation_matrix(
        (0.0, peg_low + length / 2, 0.0))).export(folder / "peg.stl")
    return folder


def test_a_base_lying_on_its_side_with_the_parts_set_on_one_face_is_refused(tmp_path: Path) -> None:
    cad = _block_and_peg(tmp_path / "cad", 0.0)  # the peg on the table through the block: out along +y only
    with pytest.raises(ExecutorError) as refused:
        run_import(cad, tmp_path / "read_z_up", "mm", None)
    assert ("the base block is thinnest along y (50.000 mm, 60.000 mm tall) and 1 of its 1 holes and pins open "
            "along y, the other parts standing out of it along +y (50.000 mm; at most 0.000 mm the other way and "
            '0.000 mm across): the CAD may be drawn y up; set up = "+y" or --up +y') in str(refused.value)
    assert not (tmp_path / "read_z_up").exists()
    turned = run_import(cad, tmp_path / "turned", "mm", None, ImportOptions(up="+y"))
    assert {fit.axis for fit in turned.derived.holes.values()} == {"+z"}
    # a stated +z is never doubted: the block is imported on its side, its hole entered sideways
    side = run_import(cad, tmp_path / "side", "mm", None, ImportOptions(up="+z"))
    assert {fit.axis[1] for fit in side.derived.holes.values()} == {"y"}


def test_a_horizontal_unit_whose_parts_stand_out_both_ways_is_imported_as_drawn(tmp_path: Path) -> None:
    # the peg through the block, 25 mm out of each face: a shaft through its housing, z up as drawn
    cad = _block_and_peg(tmp_path / "cad", -25.0)
    imported = run_import(cad, tmp_path / "out", "mm", None)
    assert {fit.axis[1] for fit in imported.derived.holes.values()} == {"y"}
    assert imported.assumed[0].startswith("the CAD's +z is up (set up")


def test_a_base_lying_on_its_side_with_the_parts_within_its_box_is_refused(tmp_path: Path) -> None:
    # the peg flush with the block's faces: nothing stands out, the one hole is left one way
    cad = _block_and_peg(tmp_path / "cad", 0.0, 50.0)
    with pytest.raises(ExecutorError, match="1 of its 1 holes and pins open along y, all of them left along "
                       "[+-]y and the other parts within 0.000 mm of its box: the CAD may be drawn y up"):
        run_import(cad, tmp_path / "read_z_up", "mm", None)
    assert not (tmp_path / "read_z_up").exists()


def _box(extents: tuple[float, float, float], centre: tuple[float, float, float]) -> trimesh.Trimesh:
    return trimesh.creation.box(extents, trimesh.transformations.translation_matrix(centre))


def _upside_down(folder: Path, below: float) -> Path:
    """A 60 x 60 x 30 mm block with a 29 mm square hole 20 mm deep into its bottom and a
    28.3 mm square peg up in it, standing ``below`` [mm] out of the block's bottom, as STL
    in ``folder``: a product drawn z down (its parts go up into the base from below)."""
    folder.mkdir()
    _box((60.0, 60.0, 30.0), (0.0, 0.0, 15.0)).difference(_box((29.0, 29.0, 40.0), (0.0, 0.0, 0.0))).export(
        folder / "block.stl")
    _box((28.3, 28.3, 20.0 + below), (0.0, 0.0, (20.0 - below) / 2)).export(folder / "peg.stl")
    return folder


@pytest.mark.parametrize(("below", "why"), [
    (30.0, "the other parts standing out of it along -z (30.000 mm; at most 0.000 mm the other way and 0.000 mm "
           "across)"),
    (0.0, "all of them left along -z and the other parts within 0.000 mm of its box"),  # flush with its bottom
])
def test_a_product_drawn_upside_down_is_refused_and_imported_with_up_minus_z(tmp_path: Path, below: float,
                                                                             why: str) -> None:
    cad = _upside_down(tmp_path / "cad", below)
    with pytest.raises(ExecutorError) as refused:
        run_import(cad, tmp_path / "read_z_up", "mm", None)
    assert (f"the base block is 30.000 mm tall and 1 of its 1 holes and pins open along z, {why}: the CAD may be "
            'drawn upside down (z down); set up = "-z" or --up=-z (up = "+z" or --up +z if z is up)') \
        in str(refused.value), str(refused.value)
    assert not (tmp_path / "read_z_up").exists()
    turned = run_import(cad, tmp_path / "turned", "mm", None, ImportOptions(up="-z"))
    assert {fit.axis for fit in turned.derived.holes.values()} == {"+z"}
    assert turned.derived.hole_of["peg"].depth == pytest.approx(0.02, abs=1e-9)
    assert turned.derived.axis["peg"] == "+z"


def test_a_screw_through_the_base_standing_out_under_it_is_no_product_drawn_upside_down(tmp_path: Path) -> None:
    # bd_warehouse's pillow block: its screws' heads in counterbores flush with the block's
    # top, their shanks 8 mm under it (into a part the example does not draw); they leave
    # along +z only
    cad = tmp_path / "cad"
    cad.mkdir()
    hole = trimesh.boolean.union([_box((10.0, 10.0, 40.0), (0.0, 0.0, 15.0)),
                                  _box((16.0, 16.0, 10.0), (0.0, 0.0, 30.0))],
                                 engine="manifold")
    _box((60.0, 60.0, 30.0), (0.0, 0.0, 15.0)).difference(hole).export(cad / "block.stl")
    trimesh.boolean.union([_box((9.6, 9.6, 33.0), (0.0, 0.0, 8.5)), _box((15.6, 15.6, 5.0), (0.0, 0.0, 27.5))],
                          engine="manifold").export(cad / "screw.stl")
    (tmp_path / "import.toml").write_text('base = "block"\n')
    done = run_import(cad, tmp_path / "read_z_up", "mm", tmp_path / "import.toml")
    assert done.derived.axis["screw"] == "+z"  # its removal: up out of the counterbore


def test_a_product_drawn_upside_down_with_more_parts_going_up_than_down_is_refused(tmp_path: Path) -> None:
    # Two pegs go up into holes in the block's bottom, standing 0.6 mm out of it below, one with
    # a flange 6 mm beyond the block across, and one down into a hole in its top, flush with it
    # (flynn_clutch drawn z down: four of its parts leave downwards, its plates 0.6 mm under the
    # holder and 5.5 mm beyond it across, one upwards)
    cad = tmp_path / "cad"
    cad.mkdir()
    block = _box((150.0, 60.0, 30.0), (0.0, 0.0, 15.0))
    for x, z in ((-45.0, 0.0), (0.0, 0.0), (45.0, 30.0)):
        block = block.difference(_box((29.0, 29.0, 40.0), (x, 0.0, z)))
    block.export(cad / "block.stl")
    for name, x, low, high in (("a", -45.0, -0.6, 20.0), ("b", 0.0, -0.6, 20.0), ("c", 45.0, 10.0, 30.0)):
        peg = _box((28.3, 28.3, high - low), (x, 0.0, (low + high) / 2))
        if name == "a":
            peg = trimesh.boolean.union([peg, _box((28.3, 72.0, 0.6), (x, 0.0, -0.3))], engine="manifold")
        peg.export(cad / f"{name}.stl")
    (tmp_path / "import.toml").write_text('base = "block"\n')
    with pytest.raises(ExecutorError) as refused:
        run_import(cad, tmp_path / "read_z_up", "mm", tmp_path / "import.toml")
    assert ("2 of the other parts left along -z (1 along +z) and standing out of it 0.600 mm below it, 0.000 mm above "
            'it: the CAD may be drawn upside down (z down); set up = "-z" or --up=-z') in str(refused.value), \
        str(refused.value)
    assert not (tmp_path / "read_z_up").exists()


@pytest.mark.slow  # two imports, one read with every other up (6 s)
def test_a_part_hanging_beyond_the_base_across_is_still_set_on_one_face(tmp_path: Path) -> None:
    # drawn y up: the peg's flange (100 x 30 x 80 mm) on the block's top face, 20 mm beyond it along x
    # and 10 mm along z: across, less far than it stands out along +y (30 mm)
    cad = _block_and_peg(tmp_path / "cad", 0.0, 50.0)
    trimesh.boolean.union([trimesh.load(cad / "peg.stl"), _box((100.0, 30.0, 80.0), (0.0, 65.0, 0.0))],
                          engine="manifold").export(cad / "peg.stl")
    (tmp_path / "import.toml").write_text('base = "block"\n')
    with pytest.raises(ExecutorError, match=r"1 of its 1 holes and pins open along y, the other parts standing out "
                       r"of it along \+y \(30.000 mm; at most 0.000 mm the other way and 20.000 mm across\): the CAD "
                       r'may be drawn y up; set up = "\+y" or --up \+y'):
        run_import(cad, tmp_path / "read_z_up", "mm", tmp_path / "import.toml")
    turned = run_import(cad, tmp_path / "turned", "mm", tmp_path / "import.toml", ImportOptions(up="+y"))
    assert {fit.axis for fit in turned.derived.holes.values()} == {"+z"}


def test_a_base_with_no_holes_or_pins_is_judged_by_the_products(tmp_path: Path) -> None:
    # drawn y up: a plate (2.5 times as tall as thick read z up), a bracket on it, a peg in the bracket's blind hole
    cad = tmp_path / "cad"
    cad.mkdir()
    _box((100.0, 20.0, 50.0), (0.0, 10.0, 0.0)).export(cad / "plate.stl")
    _box((40.0, 40.0, 40.0), (0.0, 40.0, 0.0)).difference(_box((20.5, 30.0, 20.5), (0.0, 50.0, 0.0))).export(
        cad / "bracket.stl")
    _box((20.0, 45.0, 20.0), (0.0, 57.5, 0.0)).export(cad / "peg.stl")
    with pytest.raises(ExecutorError, match=r"the base plate is thinnest along y \(20.000 mm, 50.000 mm tall\), has "
                       r"no holes or pins, and 1 of the product's 1 holes and pins open along y, the other parts "
                       r"standing out of it along \+y .*: the CAD may be drawn y up; set up = \"\+y\""):
        run_import(cad, tmp_path / "read_z_up", "mm", None)
    turned = run_import(cad, tmp_path / "turned", "mm", None, ImportOptions(up="+y"))
    assert {(fit.axis, fit.owner) for fit in turned.derived.part_holes.values()} == {("+z", "bracket")}


def _tilted(source: Path, folder: Path, degrees: float, about: tuple[float, float, float]) -> Path:
    """The meshes of ``source`` turned by ``degrees`` about the axis ``about`` (through the
    origin), written into ``folder``."""
    folder.mkdir()
    turn = trimesh.transformations.rotation_matrix(np.radians(degrees), about)
    for path in sorted(source.iterdir()):
        trimesh.load(path, force="mesh", process=False).apply_transform(turn).export(folder / path.name)
    return folder


@pytest.mark.parametrize(("degrees", "about", "facing"), [
    (30.0, (1.0, 0.0, 0.0), "(0.000, -0.500, 0.866), 30.0 deg"),
    (-12.5, (1.0, 1.0, 0.0), "(-0.153, 0.153, 0.976), 12.5 deg"),
    (60.0, (0.0, 1.0, 0.0), "(0.866, 0.000, 0.500), 60.0 deg"),
])
def test_a_product_tilted_by_another_angle_than_quarter_turns_is_refused_before_deriving(
        tmp_path: Path, degrees: float, about: tuple[float, float, float], facing: str) -> None:
    cad = _tilted(CORPUS / "factory_rect_pegs" / "meshes", tmp_path / "cad", degrees, about)
    with pytest.raises(ExecutorError) as refused:
        run_import(cad, tmp_path / "read_z_up", "mm", CORPUS / "factory_rect_pegs" / "import.toml")
    assert (f"cad: the base hole_block's largest flat faces (55 % of its surface) face {facing} from the z axis: the "
            "CAD may be drawn tilted; turn it in the CAD so that one of its axes points up (up turns by quarter turns "
            'only), or set up = "+z" or --up +z to import it as drawn') in str(refused.value), str(refused.value)
    assert not (tmp_path / "read_z_up").exists()


def test_a_product_turned_about_z_is_not_taken_for_tilted(tmp_path: Path) -> None:
    # a wall 20 mm thick, 80 mm tall, with a square peg down its top, yawed by 30 deg: its largest
    # faces, its sides, face the horizontal plane
    (tmp_path / "wall").mkdir()
    _box((20.0, 60.0, 80.0), (0.0, 0.0, 40.0)).difference(_box((10.5, 10.5, 40.0), (0.0, 0.0, 80.0))).export(
        tmp_path / "wall" / "wall.stl")
    _box((10.0, 10.0, 40.0), (0.0, 0.0, 80.0)).export(tmp_path / "wall" / "peg.stl")
    cad = _tilted(tmp_path / "wall", tmp_path / "cad", 30.0, (0.0, 0.0, 1.0))
    imported = run_import(cad, tmp_path / "out", "mm", None)
    assert {fit.axis for fit in imported.derived.holes.values()} == {"+z"}
    assert imported.assumed[0].startswith("the CAD's +z is up (set up")


def _one_peg_from_below(folder: Path) -> Path:
    """A 100 x 60 x 30 mm block at x = 560 mm with a 20.5 mm square hole 15 mm deep into its
    top (h1) and one into its bottom (h2), a 20 mm square peg 40 mm long down in h1 (25 mm
    out of the top) and a 15 mm one up in h2 (flush with the bottom), as STL in ``folder``:
    drawn z up, one part going into the base from below."""
    folder.mkdir()
    _box((100.0, 60.0, 30.0), (560.0, 0.0, 15.0)).difference(_box((20.5, 20.5, 30.0), (535.0, 0.0, 30.0))).difference(
        _box((20.5, 20.5, 30.0), (585.0, 0.0, 0.0))).export(folder / "block.stl")
    _box((20.0, 20.0, 40.0), (535.0, 0.0, 35.0)).export(folder / "down.stl")
    _box((20.0, 20.0, 15.0), (585.0, 0.0, 7.5)).export(folder / "up.stl")
    return folder


def test_a_part_going_into_the_base_from_below_is_placed_by_hand(tmp_path: Path, run_main: Runner) -> None:
    # the peg going up into h2 is no sign of a CAD drawn upside down (the other stands out above):
    # imported as drawn, that peg written to be placed by hand, its hole's entry on the floor
    _one_peg_from_below(tmp_path / "cad")
    done = run_main("import", "cad", "--out", "out", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert ("manual up: the cell has no operation for it, a plan's step places it by hand (goes into hole h2 along "
            "+z, from below)") in done.stdout, done.stdout
    assert "hole h2 entry at (585.000, 0.000, 0.000) mm, entered along +z" in done.stdout
    assert "no experiment of the PyBullet cell" not in done.stdout  # h2 is 15 mm deep, not taken for 0 mm
    holes = tomllib.loads((tmp_path / "out" / "assembly.toml").read_text())["holes"]
    assert holes["h2"]["position"] == pytest.approx([0.585, 0.0], abs=1e-9)
    manual = tomllib.loads((tmp_path / "out" / "geometry.toml").read_text())["manual"]
    assert set(manual) == {"up"} and manual["up"]["on"] == ["h2"]
    assert manual["up"]["goal"] == pytest.approx([0.585, 0.0, 0.0], abs=1e-6)  # where the CAD has it


def test_a_product_drawn_upside_down_imported_as_drawn_places_its_parts_by_hand(tmp_path: Path) -> None:
    # up = "+z" stated over the refusal: the peg goes up into the block's hole, which the cell
    # has no operation for; the product is still written (not a KeyError of the hole frame)
    cad = _upside_down(tmp_path / "cad", 30.0)
    imported = run_import(cad, tmp_path / "out", "mm", None, ImportOptions(up="+z"))
    assert imported.derived.axis["peg"] == "-z"
    assert imported.mapped.manual == {"peg": "goes into hole h1 along +z, from below"}
    assert (tmp_path / "out" / "geometry.toml").is_file()


@pytest.mark.slow  # teaches the peg going down, assembles the product in physics
def test_the_sim_cell_assembles_a_product_with_a_part_going_in_from_below(tmp_path: Path, run_main: Runner) -> None:
    _one_peg_from_below(tmp_path / "cad")
    assert run_main("import", "cad", "--out", "out", cwd=tmp_path).returncode == 0
    assert run_main("-q", "executor", "teach", "--assembly", "out", cwd=tmp_path).returncode == 0
    done = run_main("assemble", "out/sizes.lp", "out/geometric_precedence.lp", "--assembly", "out", "--json",
                    cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    steps = {step["part"]: step for step in report["steps"]}
    assert report["assembled"] and (steps["down"]["skill"], steps["up"]["skill"]) == ("insert", "manual")
    assert report["manual_reasons"] == {"up": "goes into hole h2 along +z, from below"}


def _bar(folder: Path, sides: int, roll: float) -> Path:
    """A regular ``sides``-gon bar 40 mm across its flats and 120 mm long along x, lying on
    a flat face turned by ``roll`` [deg] about its axis (on its lowest point at z = 0), a
    10.5 mm square hole down through it and a 10 mm square peg 50 mm long in it from the
    floor, as STL in ``folder``."""
    folder.mkdir()
    radius = 20.0 / np.cos(np.pi / sides)
    corners = [(radius * np.cos(np.pi / sides * (2 * k + 1)), radius * np.sin(np.pi / sides * (2 * k + 1)))
               for k in range(sides)]  # a flat face across +x, which the turn below sets down
    bar = trimesh.creation.extrude_polygon(shapely.Polygon(corners), 120.0)
    bar.apply_transform(trimesh.transformations.rotation_matrix(np.radians(roll), (1.0, 0.0, 0.0))
                        @ trimesh.transformations.rotation_matrix(np.pi / 2, (0.0, 1.0, 0.0)))
    low, high = bar.bounds
    bar.apply_translation((560.0 - (low[0] + high[0]) / 2, -(low[1] + high[1]) / 2, -low[2]))
    bar.difference(_box((10.5, 10.5, 100.0), (560.0, 0.0, 20.0))).export(folder / "bar.stl")
    _box((10.0, 10.0, 50.0), (560.0, 0.0, 25.0)).export(folder / "peg.stl")
    return folder


@pytest.mark.parametrize("sides", [6, 8])
def test_a_coarse_prism_lying_on_a_face_is_not_taken_for_tilted(tmp_path: Path, sides: int) -> None:
    # its largest flat faces, a pair at 60 or 45 deg (as large as its horizontal pair, less
    # the hole's), are tilted; it stands on its bottom face: imported as drawn
    imported = run_import(_bar(tmp_path / "cad", sides, 0.0), tmp_path / "out", "mm", None)
    assert {fit.axis for fit in imported.derived.holes.values()} == {"+z"}
    assert imported.derived.hole_of["peg"].id == "h1"


def test_a_coarse_prism_on_its_edge_is_tilted(tmp_path: Path) -> None:
    # the hexagonal bar turned 30 deg about its axis: on an edge, no face horizontal
    with pytest.raises(ExecutorError, match=r"the base bar's largest flat faces \(\d+ % of its surface\) face "
                       r"\(0.000, -?0.500, 0.866\), 30.0 deg from the z axis: the CAD may be drawn tilted"):
        run_import(_bar(tmp_path / "cad", 6, 30.0), tmp_path / "read_z_up", "mm", None)
    assert not (tmp_path / "read_z_up").exists()


@pytest.mark.parametrize(("turn", "tilted"), [(0.0, False), (180.0, True)])
def test_a_base_stands_on_horizontal_faces_only_from_its_lowest_point(turn: float, tilted: bool) -> None:
    # a wedge 20 mm wide along y, 27.5 mm high to its edge, 100 mm long: its flat face as large
    # as two thirds of each slanted face (20 deg from vertical), so its horizontal faces count;
    # lying on that face it stands on it, turned over about x onto its edge it is tilted
    wedge = trimesh.creation.extrude_polygon(shapely.Polygon([(0.0, -0.01), (0.0, 0.01), (-0.0275, 0.0)]), 0.1)
    wedge.apply_transform(trimesh.transformations.rotation_matrix(np.radians(turn), (1.0, 0.0, 0.0))
                          @ trimesh.transformations.rotation_matrix(np.pi / 2, (0.0, 1.0, 0.0)))
    why = drawn_tilted(wedge, "wedge")
    assert (why is not None) == tilted, why
