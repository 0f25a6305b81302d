"""The shipped products exported in the assembled pose and imported, once per test
session (a worker's): ``imported(product)`` → (what the import derived, the assembly
folder it wrote), shared by the round trips of ``test_import`` and ``test_covers``; and
helpers: ``teach(folder)`` (an imported product's skills taught in this process),
``learned_in_the_cell`` (taught, then a sim session with its assembly) and
``trial_on_edited_mesh`` (one attempt in a copy whose mesh was changed)."""

from __future__ import annotations

import hashlib
import json
import shutil
import tomllib
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import trimesh

from assembly_constraints.cli import main
from executor.cad.cli import run_import
from executor.cad.derive import Derived
from executor.evidence import TrialResult
from executor.skills.teach import teach_all
from executor.trial import Cell
from tests.conftest import Runner


@pytest.fixture(scope="session")
def imported(tmp_path_factory: pytest.TempPathFactory) -> Callable[[str], tuple[Derived, Path]]:
    """A product exported in the assembled pose (``executor export --assembled``) and
    imported (``import --units m --config import.toml``), once per product."""
    done: dict[str, tuple[Derived, Path]] = {}

    def get(product: str) -> tuple[Derived, Path]:
        if product not in done:
            tmp = tmp_path_factory.mktemp(product)
            assert main(["-q", "executor", "export", "--assembled", "--assembly", product, str(tmp / "meshes")]) == 0
            derived = run_import(tmp / "meshes", tmp / "out", "m", tmp / "meshes" / "import.toml").derived
            done[product] = derived, tmp / "out"
        return done[product]

    return get


def teach(folder: Path) -> Path:
    """The skills of every part shape of the product in ``folder`` taught in its simulated
    cell, in this process (as ``executor teach`` does); returns ``folder``."""
    cell = Cell(str(folder))
    try:
        teach_all(cell)
    finally:
        cell.close()
    return folder


def import_on_base(cad: Path, folder: Path, base: str) -> Path:
    """The meshes in ``cad`` imported (``./run.sh import``, in this process) with ``base`` the
    fixture, its settings in ``folder/import.toml``, into ``folder/out``: that folder."""
    (folder / "import.toml").write_text(f'base = "{base}"\n')
    out = folder / "out"
    assert main(["-q", "import", str(cad), "--out", str(out), "--config", str(folder / "import.toml")]) == 0
    return out


def manual_reasons(out: Path) -> dict[str, str]:
    """Part id -> why the import in ``out`` placed it by hand (``[manual.*]`` of its ``geometry.toml``)."""
    return {pid: entry["reason"] for pid, entry in tomllib.loads((out / "geometry.toml").read_text())
            .get("manual", {}).items()}


def learned_in_the_cell(run_main: Runner, folder: Path, run: Path) -> tuple[dict[str, Any], dict[tuple[str, str], str]]:
    """Teach the product in ``folder``, run a sim session with ``--assemble`` into ``run``
    (the commands in this process, the session's cell a process of its own): its result and
    the outcome of each (part, hole) its journal records."""
    taught = run_main("executor", "teach", "--assembly", str(folder))
    assert taught.returncode == 0, taught.stderr
    session = run_main("session", "--assembly", str(folder), "--out", str(run), "--assemble", "--json")
    assert session.returncode == 0, session.stderr
    journal = [json.loads(line) for line in (run / "journal.jsonl").read_text().splitlines()]
    return json.loads(session.stdout), {(e["part"], e["hole"]): e["result"] for e in journal if "result" in e}


def trial_on_edited_mesh(taught: Path, copy: Path, mesh: str, edit: Callable[[trimesh.Trimesh], None],
                         part: str, hole: str) -> TrialResult:
    """One attempt of ``part`` into ``hole`` (seed 0) in a cell of ``taught`` copied to
    ``copy`` with ``meshes/<mesh>.obj`` changed by ``edit`` (its digest in ``geometry.toml``
    with it): the cell collides with the edited mesh."""
    shutil.copytree(taught, copy)
    mesh_file = copy / "meshes" / f"{mesh}.obj"
    loaded = trimesh.load(mesh_file, force="mesh", process=False)
    edit(loaded)
    loaded.export(mesh_file)
    old = hashlib.sha256((taught / "meshes" / f"{mesh}.obj").read_bytes()).hexdigest()
    text = copy / "geometry.toml"
    text.write_text(text.read_text().replace(old, hashlib.sha256(mesh_file.read_bytes()).hexdigest()))
    cell = Cell(str(copy))
    try:
        return cell.run_trial(part, hole, 0, max_attempts=1)
    finally:
        cell.close()
