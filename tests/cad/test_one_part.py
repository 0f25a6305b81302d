"""``import``'s ``one_part`` (and ``--one-part``): a STEP sub-assembly named by id or
pattern is one part, its leaves' meshes joined and their cylinders kept.

The product (build123d): an 80 x 80 x 10 mm plate with a d 32.4 bore, a ``bearing``
sub-assembly in it (an outer ring d 32 x 28, an inner ring d 20 x 12, three d 3.6 balls
between them) and a d 11.6 shaft through the inner ring. Read as its leaves, the bearing
is five parts; with ``one_part`` it is one, in the plate's bore, the shaft in its bore. A
name that matches no sub-assembly, the setting on a mesh folder and a setting that is no
list of names are one line naming the setting, exit code 2.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
import trimesh

from executor.cad.cli import run_import
from executor.cad.step import load_step
from tests.conftest import Runner, error_lines

BALLS = 3


@pytest.fixture(scope="module")
def bearing_step(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The product's STEP file, written by build123d in a process of its own."""
    folder = tmp_path_factory.mktemp("bearing")
    path = folder / "unit.step"
    script = folder / "make.py"
    script.write_text(
        "import math\n"
        "from build123d import *\n"
        "plate = Box(80, 80, 10) - Cylinder(16.2, 10); plate.label = 'plate'\n"
        "outer = Cylinder(16, 10) - Cylinder(14, 10); outer.label = 'outer ring'\n"
        "inner = Cylinder(10, 10) - Cylinder(6, 10); inner.label = 'inner ring'\n"
        "def ball(k):\n"
        f"    turn = 2 * math.pi * k / {BALLS}\n"
        "    ball = Pos(12 * math.cos(turn), 12 * math.sin(turn), 0) * Sphere(1.8); ball.label = 'ball'\n"
        "    return ball\n"
        f"balls = [ball(k) for k in range({BALLS})]\n"
        "bearing = Compound(label='bearing', children=[outer, inner, *balls])\n"
        "shaft = Pos(0, 0, 10) * Cylinder(5.8, 40); shaft.label = 'shaft'\n"
        f"export_step(Compound(label='unit', children=[plate, bearing, shaft]), {str(path)!r})\n")
    subprocess.run([sys.executable, str(script)], check=True)
    return path


@pytest.mark.slow  # build123d writes the STEP file (about 5 s)
def test_a_sub_assembly_is_read_as_its_leaves_unless_named_one_part(bearing_step: Path) -> None:
    leaves = sorted(part.id for part in load_step(bearing_step))
    assert leaves == ["ball_1", "ball_2", "ball_3", "inner_ring", "outer_ring", "plate", "shaft"]
    offered: list[dict[str, int]] = []

    def whole(solids: dict[str, int]) -> set[str]:
        offered.append(solids)
        return {"bearing"}

    parts = {part.id: part for part in load_step(bearing_step, whole=whole)}
    assert offered == [{"bearing": 2 + BALLS}] and sorted(parts) == ["bearing", "plate", "shaft"]
    bearing = parts["bearing"]
    assert bearing.mesh.is_watertight and len(bearing.mesh.split(only_watertight=False)) == 2 + BALLS
    radii = sorted({round(cylinder.radius, 6) for cylinder in bearing.cylinders})
    assert radii == [0.006, 0.01, 0.014, 0.016]  # both rings' bores and outsides


@pytest.mark.slow  # build123d writes the STEP file, the import derives the product's fits
def test_the_bearing_one_part_sits_in_the_bore_with_the_shaft_in_its_own(bearing_step: Path, tmp_path: Path) -> None:
    (tmp_path / "import.toml").write_text('base = "plate"\none_part = ["bear*"]\n')
    done = run_import(bearing_step, tmp_path / "out", "mm", tmp_path / "import.toml")
    derived = done.derived
    assert sorted(derived.parts) == ["bearing", "plate", "shaft"]
    bore = derived.in_holes["bearing"]
    assert bore.owner is None and bore.hole.kind == "round" and bore.hole.a == pytest.approx(0.0324, abs=1e-6)
    assert derived.in_holes["shaft"].hole.a == pytest.approx(0.012, abs=1e-6)
    assert (f"STEP sub-assemblies imported as one part as set (one_part in {tmp_path / 'import.toml'}): "
            f"bearing ({2 + BALLS} solids)") in "; ".join(done.assumed)


def _one_line(done: subprocess.CompletedProcess[str]) -> str:
    """The single error line of a refused import (exit code 2, no traceback)."""
    lines = error_lines(done.stderr)
    assert "Traceback" not in done.stderr and done.returncode == 2, done.stderr[-3000:]
    assert len(lines) == 1 and lines[0].startswith("error: "), done.stderr[-3000:]
    return lines[0]


BAD = [
    ('one_part = ["motor"]\n', ["import.toml: one_part: ", "'motor' matches no sub-assembly", "bearing)"]),
    ('one_part = ["plate"]\n', ["import.toml: one_part: ", "'plate' matches no sub-assembly"]),  # a leaf
    ('one_part = "bearing"\n', ["import.toml", "one_part: expected a list of sub-assembly ids or patterns"]),
]


@pytest.mark.slow  # build123d writes the STEP file (about 5 s)
@pytest.mark.parametrize(("settings", "words"), BAD, ids=["no-match", "a-leaf", "not-a-list"])
def test_a_bad_one_part_is_one_line_naming_it(bearing_step: Path, tmp_path: Path, run_main: Runner, settings: str,
                                              words: list[str]) -> None:
    (tmp_path / "import.toml").write_text(settings)
    line = _one_line(run_main("import", str(bearing_step), "--out", "out", "--config", "import.toml", cwd=tmp_path))
    assert all(word in line for word in words), line
    assert not (tmp_path / "out").exists()


def test_one_part_on_a_mesh_folder_is_one_line_naming_it(tmp_path: Path, run_main: Runner) -> None:
    (tmp_path / "cad").mkdir()
    trimesh.creation.box((100, 100, 20)).export(tmp_path / "cad" / "plate.stl")
    line = _one_line(run_main("import", "cad", "--out", "out", "--one-part", "bearing", cwd=tmp_path))
    assert "--one-part: cad is a folder of meshes, each file one part already" in line


@pytest.mark.slow  # build123d writes the STEP file (about 5 s)
def test_the_flag_is_over_the_setting_and_named_in_its_errors(bearing_step: Path, tmp_path: Path,
                                                              run_main: Runner) -> None:
    (tmp_path / "import.toml").write_text('one_part = ["bearing"]\n')
    line = _one_line(run_main("import", str(bearing_step), "--out", "out", "--config", "import.toml",
                              "--one-part", "bearing,motor*", cwd=tmp_path))
    assert "--one-part: 'motor*' matches no sub-assembly" in line
