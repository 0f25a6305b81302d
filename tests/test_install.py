"""The package as a user installs it: ``pip install`` (not editable), then the console
command from a folder outside the repository, with the shipped assemblies."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import DISPLAY_VARIABLES, ROOT

PROGRAM = "assembly-constraints"


@pytest.fixture(scope="module")
def installed(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, str]]:
    """The package installed (a wheel built from the repository, not editable) into a fresh
    folder; returns the console command and the environment that runs it (that folder on
    PYTHONPATH, the repository nowhere on it; the dependencies from this interpreter)."""
    source = tmp_path_factory.mktemp("source") / "repository"  # pip builds in the tree: not in ours
    shutil.copytree(ROOT, source, ignore=shutil.ignore_patterns(".*", "build", "runs", "*.egg-info", "__pycache__"))
    target = tmp_path_factory.mktemp("site")
    done = subprocess.run([sys.executable, "-m", "pip", "install", "--quiet", "--no-deps", "--no-build-isolation",
                           "--target", str(target), str(source)],
                          capture_output=True, text=True, timeout=180)
    assert done.returncode == 0, done.stderr
    env = {name: value for name, value in os.environ.items() if name not in DISPLAY_VARIABLES}
    env["PYTHONPATH"] = str(target)
    return target / "bin" / PROGRAM, env


@pytest.mark.slow
def test_the_installed_command_runs_a_session_from_a_folder_outside_the_repository(
        installed: tuple[Path, dict[str, str]], tmp_path: Path) -> None:
    command, env = installed
    version = subprocess.run([str(command), "--version"], cwd=tmp_path, env=env, capture_output=True, text=True,
                             timeout=60)
    assert version.returncode == 0 and version.stdout.startswith(f"{PROGRAM} "), version.stderr
    where = subprocess.run([sys.executable, "-c", "import assembly_constraints.bridge.assembly as a, asp; print(a.DATA_DIR); "
                            "print(assembly_constraints.asp.__file__)"], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=60)
    data_dir, asp_file = where.stdout.split()
    site = Path(env["PYTHONPATH"])
    assert Path(data_dir).is_relative_to(site) and Path(asp_file).is_relative_to(site)  # not the repository
    def files(folder: Path) -> set[Path]:
        return {f.relative_to(folder) for f in folder.rglob("*") if f.is_file()}
    assert files(ROOT / "data") <= files(Path(data_dir))  # every shipped assembly, its assets and skills
    done = subprocess.run([str(command), "session", "--assembly", "cranfield", "--backend", "truth", "--json",
                           "--out", "my-run"], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["matches_truth"] is True
    run = tmp_path / "my-run"  # relative to the caller's folder
    assert {"learned.lp", "journal.jsonl", "session.json", "planner.rrd", "c1.rrd"} <= {p.name for p in run.iterdir()}
