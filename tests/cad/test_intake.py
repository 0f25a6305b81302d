"""``import``'s intake of meshes and STEP files a user brings, and the files it owns.

Meshes: an OBJ that repeats its vertices once per normal (Blender's export) is one closed
surface; a closed mesh wound inconsistently is wound again (one shell) or named (several);
a coordinate that is not finite, a crack, a mesh beyond the bound of triangles and a STEP
file with a failing record are one line, exit code 2 (the STEP file's from the real
command as a process, the others from its ``main`` in this process). Files: import
removes only the files its manifest lists, keeps the user's, and refuses a folder holding
a product or a file it did not write unless given ``--replace``.
"""

from __future__ import annotations

import hashlib
import json
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import trimesh

from assembly_constraints.cli import main
from executor import ExecutorError
from executor.cad.parts import MAX_TRIANGLES, check_parts, load_meshes
from executor.cad.step import load_step
from tests.conftest import CLI_MODULE, Runner, child_env, error_lines, python_argv


def _box(extents: tuple[float, float, float], centre: tuple[float, float, float]) -> trimesh.Trimesh:
    mesh = trimesh.creation.box(extents)
    mesh.apply_translation(centre)
    return mesh


def _plate(folder: Path) -> trimesh.Trimesh:
    """``folder/plate.stl``: a 100 x 100 x 20 mm plate with a 10.5 mm square hole [mm];
    returns a 10 mm square peg standing in it (not written)."""
    folder.mkdir(parents=True)
    plate = trimesh.boolean.difference([_box((100, 100, 20), (0, 0, 0)), _box((10.5, 10.5, 30), (0, 0, 0))],
                                       engine="manifold")
    plate.export(folder / "plate.stl")
    return _box((10, 10, 40), (0, 0, 10))


def _product(folder: Path, peg: trimesh.Trimesh | None = None, name: str = "peg.stl") -> None:
    """``folder``: the plate (:func:`_plate`) and ``peg`` (default the square one) as ``name``."""
    square = _plate(folder)
    (square if peg is None else peg).export(folder / name)


def _tapered_peg() -> trimesh.Trimesh:
    """A 10 mm square peg whose top 10 mm narrow to 6 mm: convex, no prism (its own mesh) [mm]."""
    corners = [(x * s, y * s, z) for s, z in ((5, -10), (5, 20), (3, 30)) for x, y in ((-1, -1), (1, -1), (1, 1),
                                                                                          (-1, 1))]
    return trimesh.convex.convex_hull(np.array(corners, dtype=float))


def _blender_obj(mesh: trimesh.Trimesh) -> str:
    """``mesh`` as Blender exports it: each triangle its own three ``v`` and one ``vn``."""
    corners = mesh.vertices[mesh.faces].reshape(-1, 3)
    return "\n".join([*(f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in corners),
                      *(f"vn {x:.6f} {y:.6f} {z:.6f}" for x, y, z in mesh.face_normals),
                      *(f"f {3 * k + 1}//{k + 1} {3 * k + 2}//{k + 1} {3 * k + 3}//{k + 1}"
                        for k in range(len(mesh.faces)))]) + "\n"


def _fits(folder: Path) -> str:
    return (folder / "sizes.lp").read_text()


def test_an_obj_repeating_vertices_per_normal_is_one_closed_surface(tmp_path: Path) -> None:
    peg = _plate(tmp_path / "cad")
    (tmp_path / "cad" / "peg.obj").write_text(_blender_obj(peg))
    parts = load_meshes(tmp_path / "cad", "mm")
    assert [len(part.mesh.vertices) for part in parts if part.id == "peg"] == [8]
    assert main(["-q", "import", str(tmp_path / "cad"), "--out", str(tmp_path / "out")]) == 0
    assert "fits(peg,h1)." in _fits(tmp_path / "out")


def test_a_closed_mesh_wound_inconsistently_is_wound_again(tmp_path: Path) -> None:
    peg = _plate(tmp_path / "cad")
    faces = peg.faces.copy()
    faces[0] = faces[0][::-1]
    trimesh.Trimesh(peg.vertices, faces, process=False).export(tmp_path / "cad" / "peg.stl")
    parts = load_meshes(tmp_path / "cad", "mm")
    check_parts(parts, "mm")
    mesh = next(part.mesh for part in parts if part.id == "peg")
    assert mesh.is_winding_consistent and mesh.volume == pytest.approx(4e-6)  # 10 x 10 x 40 mm, outwards
    assert main(["-q", "import", str(tmp_path / "cad"), "--out", str(tmp_path / "out")]) == 0
    assert "fits(peg,h1)." in _fits(tmp_path / "out")


def _objects_obj(meshes: list[trimesh.Trimesh]) -> str:
    """``meshes`` as one OBJ, each its own object (``o``), as Blender writes a part modelled
    as several boxes (their names repeating, as in Blender files joined together)."""
    lines, base = [], 0
    for k, mesh in enumerate(meshes):
        lines += [f"o Cube.{k % 2:03d}", *(f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in mesh.vertices),
                  *(f"f {a + base + 1} {b + base + 1} {c + base + 1}" for a, b, c in mesh.faces)]
        base += len(mesh.vertices)
    return "\n".join(lines) + "\n"


def test_an_obj_of_closed_objects_that_touch_and_overlap_is_their_union(tmp_path: Path) -> None:
    # PEARL's peg-in-hole blocks (corpus pearl_peg_board) are Blender objects, each a closed
    # box: walls on a floor, edges of four faces and T-junctions where they meet, a digit's
    # strokes overlapping. As one mesh it is no manifold: it was refused as "an open mesh
    # (0 boundary edges, ... edges of more than two faces)".
    folder = tmp_path / "cad"
    folder.mkdir()
    walls = [_box((100, 45, 20), (0, 27.5, 10)), _box((100, 45, 20), (0, -27.5, 10)),
             _box((45, 10, 20), (27.5, 0, 10)), _box((45, 12, 20), (-27.5, 0, 10))]  # the last two overlap
    (folder / "plate.obj").write_text(_objects_obj([_box((100, 100, 10), (0, 0, -5)), *walls]))
    _box((9, 9, 30), (0, 0, 15)).export(folder / "peg.stl")
    parts = load_meshes(folder, "mm")
    check_parts(parts, "mm")
    plate = next(part.mesh for part in parts if part.id == "plate")
    assert plate.is_volume and plate.volume == pytest.approx((100 * 100 * 10 + 100 * 100 * 20 - 10 * 10 * 20) * 1e-9)
    assert main(["-q", "import", str(folder), "--out", str(tmp_path / "out")]) == 0
    assert "fits(peg,h1)." in _fits(tmp_path / "out")


def _nan_obj(tmp: Path) -> None:
    peg = _plate(tmp / "cad")
    peg.vertices[3, 1] = np.nan
    lines = trimesh.exchange.obj.export_obj(peg).splitlines()
    assert lines[4].startswith("v ") and "nan" in lines[4]  # the 4th vertex, line 5
    (tmp / "cad" / "peg.obj").write_text("\n".join(lines) + "\n")


def _inf_stl(tmp: Path) -> None:
    peg = _plate(tmp / "cad")
    vertices = peg.vertices.copy()
    vertices[peg.faces[0, 1], 2] = np.inf  # a corner of the first triangle
    with np.errstate(invalid="ignore"):  # its normal
        trimesh.Trimesh(vertices, peg.faces, process=False).export(tmp / "cad" / "peg.stl")


def _cracked(tmp: Path) -> None:
    peg = _plate(tmp / "cad")
    trimesh.Trimesh(peg.vertices, peg.faces[1:], process=False).export(tmp / "cad" / "peg.stl")


def _too_many(tmp: Path) -> None:
    """A binary STL whose header states one triangle more than the bound (a sparse file:
    the triangles are never read)."""
    _plate(tmp / "cad")
    count = MAX_TRIANGLES + 1
    with (tmp / "cad" / "peg.stl").open("wb") as file:
        file.write(bytes(80) + count.to_bytes(4, "little"))
        file.truncate(84 + 50 * count)


def _two_shells_wound_inconsistently(tmp: Path) -> None:
    """A hollow peg (a cavity: its inner shell faces inwards) with one outer triangle turned."""
    _plate(tmp / "cad")
    outer, inner = _box((10, 10, 40), (0, 0, 10)), _box((4, 4, 20), (0, 0, 10))
    inner.invert()
    hollow = trimesh.util.concatenate([outer, inner])
    faces = hollow.faces.copy()
    faces[0] = faces[0][::-1]
    trimesh.Trimesh(hollow.vertices, faces, process=False).export(tmp / "cad" / "peg.stl")


def _foreign_product(tmp: Path) -> None:
    _product(tmp / "cad")
    (tmp / "out").mkdir()
    (tmp / "out" / "assembly.toml").write_text('name = "mine"\n')


BAD = [
    ("non-finite-obj", _nan_obj, ["peg.obj:5: a coordinate that is not a finite number"]),
    ("non-finite-stl", _inf_stl, ["peg.stl: triangle 1: a coordinate that is not a finite number"]),
    ("crack", _cracked, ["part 'peg' is an open mesh (3 boundary edges", "one from (", ") mm"]),
    ("too-many-triangles", _too_many, [f"peg.stl: {MAX_TRIANGLES + 1} triangles, beyond the bound of {MAX_TRIANGLES}",
                                       "--max-triangles"]),
    ("two-shells-wound-inconsistently", _two_shells_wound_inconsistently,
     ["part 'peg' is a closed mesh of 2 shells whose triangles are wound inconsistently"]),
    ("foreign-product", _foreign_product, ["out: holds a product that import did not write", "(assembly.toml)",
                                           "--replace"]),
]


def _run_import(tmp: Path, *argv: str) -> tuple[int, str, str]:
    """``import`` as a process in ``tmp``: its exit code, standard output and error."""
    done = subprocess.run(python_argv(CLI_MODULE, "import", *argv), cwd=tmp, env=child_env(), capture_output=True,
                          text=True, timeout=120, stdin=subprocess.DEVNULL)
    return done.returncode, done.stdout, done.stderr


@pytest.mark.parametrize(("setup", "words"), [case[1:] for case in BAD], ids=[case[0] for case in BAD])
def test_bad_mesh_or_folder_is_one_line(tmp_path: Path, setup: Callable[[Path], None], words: list[str],
                                        run_main: Runner) -> None:
    # in this process (the real command's exit code 2 and one line: the corrupted STEP record below)
    setup(tmp_path)
    before = {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()}
    done = run_main("import", "cad", "--out", "out", cwd=tmp_path)
    lines = error_lines(done.stderr)
    assert "Traceback" not in done.stderr and done.returncode == 2, done.stderr[-3000:]
    assert len(lines) == 1 and lines[0].startswith("error: "), done.stderr[-3000:]
    assert all(word in lines[0] for word in words), lines[0]
    assert {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()} == before  # nothing written or lost


def test_the_crack_is_located_in_the_files_units(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _cracked(tmp_path)
    parts = load_meshes(tmp_path / "cad", "mm")
    with pytest.raises(ExecutorError) as caught:
        check_parts(parts, "mm")
    start, end = (np.array([float(v) for v in text.split(", ")])
                  for text in str(caught.value).split("one from (")[1].split(") mm")[0].split(") to ("))
    peg = _box((10, 10, 40), (0, 0, 10))
    dropped = peg.vertices[peg.faces[0]]  # the crack runs along the sides of the triangle left out
    assert any(np.allclose(start, a) and np.allclose(end, b) or np.allclose(start, b) and np.allclose(end, a)
               for a, b in zip(dropped, np.roll(dropped, -1, axis=0), strict=True))


def test_import_keeps_the_users_files_and_removes_only_its_own(tmp_path: Path) -> None:
    _product(tmp_path / "tapered", _tapered_peg())
    _product(tmp_path / "square")
    out = tmp_path / "out"
    (out / "meshes").mkdir(parents=True)
    mine = {out / "meshes" / "fixture.obj": b"# the user's own mesh\n", out / "notes.txt": b"mine\n"}
    for path, data in mine.items():
        path.write_bytes(data)
    assert main(["-q", "import", str(tmp_path / "tapered"), "--out", str(out)]) == 0
    assert (out / "meshes" / "peg.obj").is_file() and (out / "meshes" / "peg.convex.obj").is_file()
    assert main(["-q", "import", str(tmp_path / "square"), "--out", str(out)]) == 0  # a peg of primitives now
    assert not (out / "meshes" / "peg.obj").exists() and not (out / "meshes" / "peg.convex.obj").exists()
    assert all(path.read_bytes() == data for path, data in mine.items())
    # a file import wrote and the user changed since is theirs: refused, then replaced when told
    (out / "sizes.lp").write_text("fits(peg,h1). % checked by hand\n")
    assert main(["-q", "import", str(tmp_path / "square"), "--out", str(out)]) == 2
    assert (out / "sizes.lp").read_text() == "fits(peg,h1). % checked by hand\n"
    assert main(["-q", "import", str(tmp_path / "square"), "--out", str(out), "--replace"]) == 0
    assert "fits(peg,h1)." in _fits(out) and "by hand" not in _fits(out)
    assert all(path.read_bytes() == data for path, data in mine.items())


def test_a_source_mesh_in_the_out_folder_is_never_overwritten(tmp_path: Path) -> None:
    out = tmp_path / "out"
    _product(out / "meshes", _tapered_peg(), "peg.obj")
    before = (out / "meshes" / "peg.obj").read_bytes()
    assert main(["-q", "import", str(out / "meshes"), "--out", str(out)]) == 2
    assert (out / "meshes" / "peg.obj").read_bytes() == before
    assert sorted(p.name for p in out.rglob("*")) == ["meshes", "peg.obj", "plate.stl"]


@pytest.fixture(scope="module")
def step_files(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The folder of three STEP files written by build123d (one process): ``p.step``, a plate
    and a round peg placed 10 mm up in it; ``u.step``, a bracket assembly placed twice (as
    AS1 of the STEP test suite places its l-brackets), each copy's bolt named 'bolt';
    ``b.step``, the plate and two balls named 'ball' in one sub-assembly, resting on it."""
    folder = tmp_path_factory.mktemp("step")
    script = folder / "make.py"
    script.write_text(
        "from build123d import *\n"
        "plate = Box(100, 60, 20) - Pos(-20, 0, 2.5) * Cylinder(6.65, 15); plate.label = 'plate'\n"
        "peg = Pos(-20, 0, 10) * Cylinder(6.0, 30); peg.label = 'round peg'\n"
        f"export_step(Compound(label='pegs', children=[plate, peg]), {str(folder / 'p.step')!r})\n"
        "plate = Box(100, 60, 20); plate.label = 'plate'\n"
        "def side(x, label):\n"
        "    bolt = Pos(x, 0, 20) * Cylinder(5, 20); bolt.label = 'bolt'\n"
        "    return Compound(label=label, children=[bolt])\n"
        f"export_step(Compound(label='unit', children=[plate, side(-30, 'left'), side(30, 'right')]), "
        f"{str(folder / 'u.step')!r})\n"
        "def ball(x):\n"
        "    ball = Pos(x, 0, 25) * Sphere(5); ball.label = 'ball'\n"
        "    return ball\n"
        "bearing = Compound(label='bearing', children=[ball(-20), ball(20)])\n"
        f"export_step(Compound(label='balls', children=[plate, bearing]), {str(folder / 'b.step')!r})\n")
    subprocess.run([sys.executable, str(script)], check=True)
    return folder


CORRUPTED = [
    # the peg's placement (the first such point) no number: read on, the peg would stand 10 mm lower
    ("point", "CARTESIAN_POINT('',(-20.,0.,10.))", "CARTESIAN_POINT('',(-20.,0.,1O.))", "CARTESIAN_POINT: "),
    # an occurrence with a parameter missing: read on, the peg would be named after its parent
    ("usage", "'round peg','',#", "'round peg',#", "NEXT_ASSEMBLY_USAGE_OCCURRENCE: "),
    # a parenthesis missing: the reader names the line where it noticed (the next record's)
    ("syntax", "CARTESIAN_POINT('',(-20.,0.,10.))", "CARTESIAN_POINT('',(-20.,0.,10.)", "Incorrect syntax"),
]


def _corrupt(step: Path, old: str, new: str, folder: Path) -> tuple[Path, int]:
    """A copy of ``step`` in ``folder`` with the first ``old`` replaced by ``new``; its line."""
    text = step.read_text()
    bad = folder / "bad.step"
    bad.write_text(text.replace(old, new, 1))
    return bad, text[:text.index(old)].count("\n") + 1


@pytest.mark.slow  # build123d writes the STEP file (about 5 s)
def test_a_corrupted_step_record_is_refused_naming_it(step_files: Path, tmp_path: Path) -> None:
    step_file = step_files / "p.step"
    parts = {part.id: part for part in load_step(step_file)}
    assert parts["round_peg"].mesh.bounds[:, 2] == pytest.approx([-0.005, 0.025])  # placed 10 mm up
    for name, old, new, word in CORRUPTED:
        bad, line = _corrupt(step_file, old, new, tmp_path)
        lines = f"({line}|{line + 1})" if name == "syntax" else f"{line}"
        with pytest.raises(ExecutorError, match=f"bad.step:{lines}: .*{word}"):
            load_step(bad)
        if name == "point":  # the real command: one line, nothing from Open CASCADE on the output
            code, out, err = _run_import(tmp_path, "bad.step", "--out", "out")
            assert (code, out) == (2, ""), err
            assert err.startswith(f"error: {bad.name}:{line}: record #") and err.count("\n") == 1, err
            assert not (tmp_path / "out").exists()


def test_a_manifest_listing_other_files_is_refused(tmp_path: Path) -> None:
    _product(tmp_path / "cad")
    out = tmp_path / "out"
    assert main(["-q", "import", str(tmp_path / "cad"), "--out", str(out)]) == 0
    victim = tmp_path / "victim.txt"
    victim.write_text("not the import's\n")
    manifest = json.loads((out / ".import-manifest.json").read_text())
    manifest["files"]["../victim.txt"] = hashlib.sha256(victim.read_bytes()).hexdigest()
    (out / ".import-manifest.json").write_text(json.dumps(manifest))
    assert main(["-q", "import", str(tmp_path / "cad"), "--out", str(out)]) == 2
    assert main(["-q", "import", str(tmp_path / "cad"), "--out", str(out), "--replace"]) == 0
    assert victim.read_text() == "not the import's\n"


@pytest.mark.slow  # build123d writes the STEP files (shared, about 5 s)
def test_parts_of_one_name_in_two_sub_assemblies_are_told_apart_by_them(step_files: Path) -> None:
    parts = {part.id: part for part in load_step(step_files / "u.step")}
    assert sorted(parts) == ["left_bolt", "plate", "right_bolt"]
    assert parts["left_bolt"].mesh.centroid[0] == pytest.approx(-0.03, abs=1e-6)


@pytest.mark.slow  # build123d writes the STEP files (shared, about 5 s)
def test_balls_of_one_name_in_one_assembly_are_numbered_and_closed(step_files: Path) -> None:
    # A bearing's balls: one name in one sub-assembly, each a sphere whose poles Open
    # CASCADE tessellates as degenerate edges (triangles with two corners at one point).
    parts = {part.id: part for part in load_step(step_files / "b.step")}
    assert sorted(parts) == ["ball_1", "ball_2", "plate"]
    assert parts["ball_1"].mesh.centroid[0] == pytest.approx(-0.02, abs=1e-6)
    assert all(part.mesh.is_watertight for part in parts.values())
    check_parts(list(parts.values()), "mm")
