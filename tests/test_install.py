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
LAYERS = ("asp", "bridge", "executor")


@pytest.fixture(scope="module")
def pip_install(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, str]:
    """The package installed (a wheel built from the repository, not editable) into a fresh
    folder; returns that folder and what pip wrote to stderr."""
    source = tmp_path_factory.mktemp("source") / "repository"  # pip builds in the tree: not in ours
    shutil.copytree(ROOT, source, ignore=shutil.ignore_patterns(".*", "build", "runs", "*.egg-info", "__pycache__"))
    target = tmp_path_factory.mktemp("site")
    done = subprocess.run([sys.executable, "-m", "pip", "install", "--quiet", "--no-deps", "--no-build-isolation",
                           "--target", str(target), str(source)],
                          capture_output=True, text=True, timeout=180)
    assert done.returncode == 0, done.stderr
    return target, done.stderr


@pytest.fixture(scope="module")
def installed(pip_install: tuple[Path, str]) -> tuple[Path, dict[str, str]]:
    """The console command of :func:`pip_install` and the environment that runs it (its
    folder on PYTHONPATH, the repository nowhere on it; the dependencies from this interpreter)."""
    target = pip_install[0]
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
    where = subprocess.run([sys.executable, "-c", "import bridge.assembly as a; "
                            "import asp as asp; print(a.DATA_DIR); print(asp.__file__)"],
                           cwd=tmp_path, env=env, capture_output=True, text=True, timeout=60)
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


@pytest.mark.slow
def test_the_installed_package_adds_the_four_folders_of_the_repository(installed: tuple[Path, dict[str, str]]) -> None:
    """The packages installed are the repository's folders under their own names, as real
    folders (not links back to a checkout), and nothing else stands beside other packages."""
    site = Path(installed[1]["PYTHONPATH"])
    names = {p.name for p in site.iterdir()
             if p.name not in {"bin", "__pycache__"} and not p.name.endswith(".dist-info")}
    assert names == set(LAYERS) | {"assembly_constraints"}
    assert all((site / layer).is_dir() and not (site / layer).is_symlink() and (site / layer / "__init__.py").is_file()
               for layer in names)


@pytest.mark.slow
def test_the_build_warns_of_nothing_and_ships_every_encoding(pip_install: tuple[Path, str]) -> None:
    """Data folders (``asp/encodings``, each assembly's ``assets/``) are package data, not
    packages the build would warn about ("Package would be ignored"); pip re-emits whatever
    the build backend warns as a ``BuildBackendWarning``."""
    target, stderr = pip_install
    assert "BuildBackendWarning" not in stderr and "would be ignored" not in stderr, stderr
    def encodings(asp: Path) -> set[Path]:
        return {f.relative_to(asp) for f in (asp / "encodings").rglob("*.lp")}
    assert encodings(ROOT / "asp") == encodings(target / "asp") != set()
