"""Imports shared once per test session (a worker's): the shipped products exported in the
assembled pose and imported, ``imported(product)`` → (what the import derived, the assembly
folder it wrote), shared by the round trips of ``test_import`` and ``test_covers``; each
corpus product imported, ``corpus_import(name)`` (``test_corpus``, ``test_suction``; a test
that writes into the folder works on a copy, :func:`corpus_copy`). And helpers:
``teach(folder)`` (an imported product's skills taught in this process, of every part shape
or of some parts' only), ``learned_in_the_cell`` (a sim session of a taught product with its
assembly), ``trial_on_edited_mesh`` (one attempt in a copy whose mesh was changed) and
``exact_setup`` (the cell without pose errors both of these can run on)."""

from __future__ import annotations

import dataclasses
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
from assembly_constraints.corpus_truth import CorpusImport, import_product
from bridge.cell_settings import Magnitudes
from executor.cad.cli import run_import
from executor.cad.derive import Derived
from executor.cell_description import load_cell_description
from executor.evidence import TrialResult
from executor.skills.dmp import save_skill
from executor.skills.teach import teach_all, teach_shape
from executor.trial import Cell, CellSetup
from executor.world.assets import regenerate_assets
from tests.conftest import Runner
from tests.session import exact_cell

CORPUS = Path(__file__).parent / "corpus"
"""The corpus of products of real CAD (``tests/cad/corpus/README.md``)."""


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


@pytest.fixture(scope="session")
def corpus_import(tmp_path_factory: pytest.TempPathFactory) -> Callable[[str], CorpusImport]:
    """A corpus product (``tests/cad/corpus/<name>/``) imported (``import meshes/ --config
    import.toml``) with its truth, once per product."""
    done: dict[str, CorpusImport] = {}

    def get(name: str) -> CorpusImport:
        if name not in done:
            done[name] = import_product(CORPUS / name, tmp_path_factory.mktemp(name) / "out")
        return done[name]

    return get


def corpus_copy(done: CorpusImport, folder: Path) -> CorpusImport:
    """The imported corpus product ``done`` with its assembly folder copied to ``folder``."""
    return dataclasses.replace(done, out=Path(shutil.copytree(done.out, folder)))


def teach(folder: Path, parts: set[str] | None = None) -> Path:
    """The skills of the part shapes of the product in ``folder`` taught in its simulated
    cell, in this process (as ``executor teach`` does; ``parts``: only their shapes, default
    every one); returns ``folder``."""
    cell = Cell(str(folder))
    try:
        if parts is None:
            teach_all(cell)
        else:
            regenerate_assets(cell.geometry)
            for shape in sorted({cell.geometry.parts[pid].shape for pid in parts}):
                save_skill(folder, teach_shape(cell, shape))
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


def learned_in_the_cell(run_main: Runner, folder: Path, run: Path, exact: bool = False,
                        assemble: bool = True) -> tuple[dict[str, Any], dict[tuple[str, str], str]]:
    """A sim session of the taught product in ``folder`` (:func:`teach`), with ``--assemble``
    if ``assemble``, into ``run`` (the command in this process, the session's cell a process
    of its own): its result and the outcome of each (part, hole) its journal records. With ``exact``, its cell
    without pose errors and its search 1 mm wide (:func:`tests.session.exact_cell`, written
    beside ``run``): the experiments decide on the geometry alone, a ``no_fit`` without the
    default search's spirals (the cell's default uncertainty through a session:
    ``tests/session/test_session_sim.py``)."""
    cell = exact_cell(run.parent) if exact else ()
    session = run_main("session", "--assembly", str(folder), "--out", str(run), "--json",
                       *(("--assemble",) if assemble else ()), *cell)
    assert session.returncode == 0, session.stderr
    journal = [json.loads(line) for line in (run / "journal.jsonl").read_text().splitlines()]
    return json.loads(session.stdout), {(e["part"], e["hole"]): e["result"] for e in journal if "result" in e}


def exact_setup(folder: Path) -> CellSetup:
    """A simulated cell without pose errors, its search 1 mm wide: :func:`tests.session.exact_cell`
    (its cell description written in ``folder``) as a :class:`CellSetup`."""
    argv = exact_cell(folder)  # --option value pairs
    options = dict(zip(argv[::2], argv[1::2]))
    description = load_cell_description(Path(options.pop("--cell-description")))
    return CellSetup(magnitudes=Magnitudes(**{name[2:].replace("-", "_"): float(value)
                                               for name, value in options.items()}), description=description)


def trial_on_edited_mesh(taught: Path, copy: Path, mesh: str, edit: Callable[[trimesh.Trimesh], None],
                         part: str, hole: str) -> TrialResult:
    """One attempt of ``part`` into ``hole`` (seed 0) in a cell of ``taught`` copied to
    ``copy`` with ``meshes/<mesh>.obj`` changed by ``edit`` (its digest in ``geometry.toml``
    with it): the cell collides with the edited mesh. The cell is :func:`exact_setup`'s: the
    attempt decides on the edited geometry alone, without the default search's spirals."""
    shutil.copytree(taught, copy)
    mesh_file = copy / "meshes" / f"{mesh}.obj"
    loaded = trimesh.load(mesh_file, force="mesh", process=False)
    edit(loaded)
    loaded.export(mesh_file)
    old = hashlib.sha256((taught / "meshes" / f"{mesh}.obj").read_bytes()).hexdigest()
    text = copy / "geometry.toml"
    text.write_text(text.read_text().replace(old, hashlib.sha256(mesh_file.read_bytes()).hexdigest()))
    cell = Cell(str(copy), setup=exact_setup(copy.parent))
    try:
        return cell.run_trial(part, hole, 0, max_attempts=1)
    finally:
        cell.close()
