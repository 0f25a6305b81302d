"""``import``'s ``leave_out`` (and ``--leave-out``): parts of the CAD named by id or pattern
are dropped as read, before the bound of triangles and every check.

The product: a 100 x 100 x 20 mm plate with a square hole, a square peg in it, and a
``hopper`` ball sunk 10 mm into the plate's corner (5120 triangles): refused as it is
(the overlap), imported with the hopper left out (absent from every file written, the
assumption printed and written in ``assembly.toml``), within a bound of triangles the
hopper alone passes; a name that matches no part, the base left out and a setting that
is no list of names are one line naming the setting, exit code 2.
"""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest
import trimesh

from executor.cad.parts import MAX_TRIANGLES
from tests.conftest import Runner, error_lines


def _product(folder: Path) -> None:
    """``folder``: ``plate.stl`` (100 x 100 x 20 mm, a 10.5 mm square hole), ``peg.stl``
    (10 x 10 x 40 mm, standing in it) and ``hopper.stl`` (a 30 mm ball whose centre is 5 mm
    into the plate's top at a corner: overlapping the plate) [mm]."""
    folder.mkdir(parents=True)
    plate = trimesh.boolean.difference([trimesh.creation.box((100, 100, 20)), trimesh.creation.box((10.5, 10.5, 30))],
                                       engine="manifold")
    plate.export(folder / "plate.stl")
    peg = trimesh.creation.box((10, 10, 40))
    peg.apply_translation((0, 0, 10))
    peg.export(folder / "peg.stl")
    hopper = trimesh.creation.icosphere(subdivisions=4, radius=15)
    hopper.apply_translation((35, 35, 5))
    hopper.export(folder / "hopper.stl")


def _one_line(done: subprocess.CompletedProcess[str]) -> str:
    """The single error line of a refused import (exit code 2, no traceback)."""
    lines = error_lines(done.stderr)
    assert "Traceback" not in done.stderr and done.returncode == 2, done.stderr[-3000:]
    assert len(lines) == 1 and lines[0].startswith("error: "), done.stderr[-3000:]
    return lines[0]


def test_the_product_with_the_overlapping_part_is_refused(tmp_path: Path, run_main: Runner) -> None:
    _product(tmp_path / "cad")
    line = _one_line(run_main("import", "cad", "--out", "out", cwd=tmp_path))
    assert "'hopper'" in line and "overlap" in line


@pytest.mark.parametrize("how", ["config", "flag"])
def test_a_part_left_out_is_in_no_file_written(tmp_path: Path, run_main: Runner, how: str) -> None:
    _product(tmp_path / "cad")
    (tmp_path / "import.toml").write_text('leave_out = ["hop*"]\n' if how == "config" else 'leave_out = ["peg"]\n')
    argv = ("--config", "import.toml") if how == "config" else ("--config", "import.toml", "--leave-out", "hopper")
    done = run_main("import", "cad", "--out", "out", *argv, cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-3000:]
    setting = "leave_out in import.toml" if how == "config" else "--leave-out"  # the flag over the file's
    assert f"parts left out as set ({setting}): hopper (1 part;" in done.stdout
    written = [p for p in (tmp_path / "out").rglob("*") if p.is_file()]
    assert not any("hopper" in p.name for p in written)
    holding = [p.name for p in written if p.name != "assembly.toml" and "hopper" in p.read_text()]
    assert holding == []
    assembly = (tmp_path / "out" / "assembly.toml").read_text()
    assert "[parts.hopper]" not in assembly and "[parts.peg]" in assembly
    assert f"# Parts of cad left out as set ({setting}): hopper." in assembly


def test_the_bound_of_triangles_counts_the_parts_kept(tmp_path: Path, run_main: Runner) -> None:
    _product(tmp_path / "cad")
    bound = "2000"  # the hopper alone is 5120 triangles; the plate and the peg far fewer
    line = _one_line(run_main("import", "cad", "--out", "out", "--max-triangles", bound, cwd=tmp_path))
    assert "hopper.stl" in line and "--max-triangles" in line
    done = run_main("import", "cad", "--out", "out", "--max-triangles", bound, "--leave-out", "hopper", cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-3000:]
    assert int(bound) < MAX_TRIANGLES


BAD = [
    ('leave_out = ["funnel", "hopper"]\n',
     ["import.toml: leave_out: ", "'funnel' matches no part", "hopper, peg, plate"]),
    ('base = "plate"\nleave_out = ["pl*"]\n', ["import.toml: leave_out: ", "the base 'plate' cannot be left out"]),
    ('leave_out = ["*"]\n', ["import.toml: leave_out: ", "every part left out"]),
    ('leave_out = "hopper"\n', ["import.toml", "leave_out: expected a list of part ids or patterns"]),
]


@pytest.mark.parametrize(("settings", "words"), BAD, ids=["no-match", "base", "every-part", "not-a-list"])
def test_a_bad_leave_out_is_one_line_naming_it(tmp_path: Path, run_main: Runner, settings: str,
                                               words: list[str]) -> None:
    _product(tmp_path / "cad")
    (tmp_path / "import.toml").write_text(settings)
    line = _one_line(run_main("import", "cad", "--out", "out", "--config", "import.toml", cwd=tmp_path))
    assert all(word in line for word in words), line
    assert not (tmp_path / "out").exists()


def test_an_unmatched_flag_names_the_flag(tmp_path: Path, run_main: Runner) -> None:
    _product(tmp_path / "cad")
    line = _one_line(run_main("import", "cad", "--out", "out", "--leave-out", "hopper,screw_*", cwd=tmp_path))
    assert "--leave-out: 'screw_*' matches no part" in line
