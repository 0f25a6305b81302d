"""Parts simulated from their own meshes: a ``mesh`` entry of ``geometry.toml`` is checked
by the one loader (its file's digest, its convex pieces against that file), bad ones are
refused in one line naming the field and the file, and the cell builds such parts in
PyBullet (the base a static concave mesh, a moving part its convex pieces) where they
should rest."""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import pybullet as pb
import pytest
import trimesh

from assembly_constraints.cli import main
from bridge import BridgeError
from bridge.product import CONVEX_HEADER
from executor.assembly.product import load_product
from executor.assembly.world import AssemblyWorld
from executor.cad.assembled import part_meshes
from executor.cell_description import load_cell_description
from executor.world.assets import sources_digest
from executor.world.geometry import load_geometry, plate_obj_text
from executor.world.meshes import obj_text

REST_BOUND = 3e-4
"""A part at rest is within this of where it should be [m] (contact penetration and the
1 mm rounding of a hull's edges, not its margin: that would be 1 mm)."""
HOLE = (0.55, 0.0)
ASSEMBLY = f"""[parts.plate]
role = "base"
start = [0.3, -0.4]

[parts.peg]
role = "peg"
start = [0.25, 0.4]
shape = "square"

[holes.h1]
shape = "square"
position = [{HOLE[0]}, {HOLE[1]}]
"""


def _box(extents: tuple[float, float, float], centre: tuple[float, float, float]) -> trimesh.Trimesh:
    mesh = trimesh.creation.box(extents)
    mesh.apply_translation(centre)
    return mesh


def _write_obj(path: Path, meshes: list[trimesh.Trimesh], header: str) -> str:
    text = obj_text([(f"m{k}", m.vertices, m.faces) for k, m in enumerate(meshes)], header)
    path.write_text(text)
    return hashlib.sha256(text.encode()).hexdigest()


@pytest.fixture
def product(tmp_path: Path) -> Path:
    """A plate (100 x 100 x 20 mm, a 10.5 mm square hole 15 mm deep, a 10 mm high stop on
    one side) and a 10 mm square peg with a 16 mm flange on top, 40 mm long, as meshes:
    the plate in the cell frame, the peg in its part frame with its two boxes as pieces."""
    folder = tmp_path / "flanged"
    (folder / "meshes").mkdir(parents=True)
    x, y = HOLE
    stop = _box((0.01, 0.1, 0.01), (x + 0.045, y, 0.025))
    plate = trimesh.boolean.union([_box((0.1, 0.1, 0.02), (x, y, 0.01)), stop], engine="manifold")
    plate = trimesh.boolean.difference([plate, _box((0.0105, 0.0105, 0.015), (x, y, 0.0125 + 1e-6))],
                                       engine="manifold")
    plate_sha = _write_obj(folder / "meshes" / "plate.obj", [plate], "# the plate [m], cell frame")
    shaft, flange = _box((0.01, 0.01, 0.036), (0, 0, 0.018)), _box((0.016, 0.016, 0.004), (0, 0, 0.038))
    peg = trimesh.boolean.union([shaft, flange], engine="manifold")
    peg_sha = _write_obj(folder / "meshes" / "peg.obj", [peg], "# the peg [m], part frame")
    _write_obj(folder / "meshes" / "peg.convex.obj", [shaft, flange],
               CONVEX_HEADER.format(file="meshes/peg.obj", sha256=peg_sha))
    (folder / "assembly.toml").write_text(ASSEMBLY)
    (folder / "geometry.toml").write_text(f"""[plate]
top_z = 0.02
tile_size = 0.03
tile_thickness = 0.015
chamfer = 0.0002
polygon_sides = 24
base_size = [0.1, 0.1]
base_center = [{x}, {y}]
base_thickness = 0.005

[hole_shapes.h1]
holes = ["h1"]
kind = "square"
size = 0.0105

[part_shapes.peg]
parts = ["peg"]
kind = "square"
size = 0.01
length = 0.04
mass = {peg.volume * 2700:.6g}
demo_hole = "h1"
mesh = {{ file = "meshes/peg.obj", sha256 = "{peg_sha}", convex = "meshes/peg.convex.obj" }}

[base]
part = "plate"
tray = [{x}, {y}]
grip = [0.0, 0.0]
mass = 0.5
mesh = {{ file = "meshes/plate.obj", sha256 = "{plate_sha}" }}
""")
    return folder


def _edit(folder: Path, old: str, new: str) -> None:
    path = folder / "geometry.toml"
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new, 1))


def _refusal(folder: Path) -> str:
    with pytest.raises(BridgeError) as caught:
        load_geometry(str(folder))
    message = str(caught.value)
    assert "\n" not in message and message.startswith(f"{folder / 'geometry.toml'}: ")
    return message


def test_a_mesh_product_loads_with_its_meshes(product: Path) -> None:
    geometry = load_geometry(str(product))
    assert geometry.base_mesh == product / "meshes" / "plate.obj"
    mesh = geometry.parts["peg"].mesh
    assert mesh is not None and mesh.convex == "meshes/peg.convex.obj"


def test_an_edited_mesh_is_refused_naming_its_digest(product: Path) -> None:
    with (product / "meshes" / "peg.obj").open("a") as file:
        file.write("# edited\n")
    assert "[part_shapes.peg] mesh.sha256: expected the SHA-256 of meshes/peg.obj" in _refusal(product)


def test_stale_convex_pieces_are_refused(product: Path) -> None:
    # The mesh changed and geometry.toml was given its new digest, but the pieces were not made again.
    path = product / "meshes" / "peg.obj"
    before = hashlib.sha256(path.read_bytes()).hexdigest()
    path.write_text(path.read_text() + "# edited\n")
    _edit(product, before, hashlib.sha256(path.read_bytes()).hexdigest())
    message = _refusal(product)
    assert "[part_shapes.peg] mesh.convex: expected pieces made from meshes/peg.obj as it is" in message
    assert "stale pieces: import the product again" in message


def test_the_generated_assets_follow_an_edited_mesh(product: Path) -> None:
    """The mesh digests are among the assets' sources: a mesh edited (and its entry and
    pieces made again) makes the assets stale, so the cell regenerates them."""
    before = sources_digest(load_geometry(str(product)))
    path = product / "meshes" / "peg.obj"
    old = hashlib.sha256(path.read_bytes()).hexdigest()
    path.write_text(path.read_text() + "# edited\n")
    new = hashlib.sha256(path.read_bytes()).hexdigest()
    _edit(product, old, new)
    pieces = product / "meshes" / "peg.convex.obj"
    pieces.write_text(pieces.read_text().replace(old, new, 1))
    assert sources_digest(load_geometry(str(product))) != before


def test_a_base_of_its_own_mesh_has_no_bosses_so_a_pin_wider_than_the_tile_loads(product: Path) -> None:
    # A pin of the base (a 12-spline shaft d 40 in flynn_clutch) wider than the plate's
    # tile_size (its bolt holes' spacing): the cell collides the base's own mesh, so it
    # builds no boss about any hole or pin, none that the pin would not fit in.
    half = 0.02  # a 40 mm hexagon across its corners, beside the square hole
    outline = ", ".join(f"[{half * np.cos(k * np.pi / 3):.7f}, {half * np.sin(k * np.pi / 3):.7f}]" for k in range(6))
    with (product / "assembly.toml").open("a") as file:
        file.write(f'\n[holes.p1]\nshape = "polygon"\nposition = [{HOLE[0] - 0.025}, {HOLE[1]}]\n')
    _edit(product, "[part_shapes.peg]", f"""[hole_shapes.p1]
holes = ["p1"]
pin = true
kind = "polygon"
size = [{2 * half}, {2 * half * np.sin(np.pi / 3):.7f}]
outline = [{outline}]
top_z = 0.04
depth = 0.02

[part_shapes.peg]""")
    geometry = load_geometry(str(product))
    assert geometry.holes["p1"].pin and geometry.base_mesh is not None
    assert [line for line in plate_obj_text(geometry).splitlines() if not line.startswith("#")] == []


@pytest.mark.parametrize(("old", "new", "expected"), [
    ('file = "meshes/peg.obj"', 'file = "meshes/none.obj"', "[part_shapes.peg] mesh.file: {folder}/meshes/none.obj: "
     "no such mesh file (OBJ)"),
    ('file = "meshes/peg.obj"', 'file = "../peg.obj"', "[part_shapes.peg.mesh] file: expected a path of an .obj file "
     "inside the assembly folder"),
    ('file = "meshes/peg.obj"', 'file = "/tmp/peg.obj"', "[part_shapes.peg.mesh] file: expected a path of an .obj"),
    ('sha256 = "', 'sha256 = "x', "[part_shapes.peg.mesh] sha256: expected a SHA-256 digest (64 lower-case hex"),
    (', convex = "meshes/peg.convex.obj"', "", "[part_shapes.peg] mesh.convex: expected the convex pieces of "
     "meshes/peg.obj"),
    ('convex = "meshes/peg.convex.obj"', 'convex = "meshes/gone.obj"', "[part_shapes.peg] mesh.convex: "
     "{folder}/meshes/gone.obj: no such convex pieces file (OBJ)"),
    ('plate.obj", sha256', 'plate.obj", convex = "meshes/peg.convex.obj", sha256',
     "[base] mesh.convex: expected no convex pieces (the base and a part placed by hand are simulated as their "
     "static concave meshes)"),
    ('convex = "meshes/peg.convex.obj"', 'pieces = "meshes/peg.convex.obj"', "[part_shapes.peg.mesh] pieces: "
     "unknown key; expected one of file, sha256, convex"),
])
def test_a_bad_mesh_entry_is_one_line_naming_field_and_file(product: Path, old: str, new: str, expected: str) -> None:
    _edit(product, old, new)
    assert expected.format(folder=product) in _refusal(product)


@pytest.mark.slow
def test_the_command_line_refuses_a_bad_mesh_with_exit_2(product: Path, tmp_path: Path,
                                                        capsys: pytest.CaptureFixture[str]) -> None:
    _edit(product, 'file = "meshes/peg.obj"', 'file = "meshes/none.obj"')
    assert main(["executor", "sizes", "--assembly", str(product), "--out", str(tmp_path / "sizes.lp")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "[part_shapes.peg] mesh.file:" in err[0] and "meshes/none.obj" in err[0], err


@pytest.mark.slow
def test_mesh_parts_rest_where_they_should_in_the_cell(product: Path) -> None:
    """In PyBullet: the flanged peg on the tray floor stands at z = 0 (its pieces' hull
    margin taken off), and let go 1 mm above the hole's bottom it comes to rest on it
    (it passes the 10.5 mm opening of the concave plate mesh, its flange clear of the
    top), upright."""
    world = AssemblyWorld(load_product(str(product)), gains=load_cell_description(None).gains)
    try:
        assert (product / "assets" / "part_peg.convex.obj").is_file()
        world.settle(0.3)
        tray = world.position("peg")
        assert np.allclose(tray, [0.25, 0.4, 0.0], atol=REST_BOUND), tray
        world.set_peg_goal("peg", "h1")
        world.set_pose("peg", world.goals["peg"] + np.array([0.0, 0.0, 0.001]))
        pb.changeDynamics(world.frames["peg"].body, -1, activationState=pb.ACTIVATION_STATE_WAKE_UP,
                          physicsClientId=world.client)  # rest() put it to sleep
        world.settle(0.5)
        position, quat = world.pose("peg")
        assert world.goal_error("peg") < REST_BOUND, position
        assert abs(quat[3]) > np.cos(np.radians(1.0) / 2), quat  # tilted by less than 1 degree
    finally:
        world.close()


@pytest.mark.slow
def test_the_assembled_export_of_mesh_parts_is_their_meshes(product: Path) -> None:
    """``executor export --assembled`` (the meshes import reads) gives a mesh base as its
    mesh and a mesh peg as its mesh, placed in its hole."""
    meshes, base, _, _ = part_meshes(str(product))
    plate = trimesh.load(product / "meshes" / "plate.obj", force="mesh")
    peg = trimesh.load(product / "meshes" / "peg.obj", force="mesh")
    assert base == "plate" and isinstance(plate, trimesh.Trimesh) and isinstance(peg, trimesh.Trimesh)
    assert meshes["plate"].volume == pytest.approx(plate.volume, rel=1e-9)
    assert meshes["peg"].volume == pytest.approx(peg.volume, rel=1e-6)
    assert np.allclose(meshes["peg"].bounds[0], [HOLE[0] - 0.008, HOLE[1] - 0.008, 0.005], atol=1e-6)

