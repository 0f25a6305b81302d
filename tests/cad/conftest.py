"""The shipped products exported in the assembled pose and imported, once per test
session (a worker's): ``imported(product)`` → (what the import derived, the assembly
folder it wrote), shared by the round trips of ``test_import`` and ``test_covers``; and
``teach(folder)``, a helper: an imported product's skills taught in this process."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from assembly_constraints.cli import main
from executor.cad.cli import run_import
from executor.cad.derive import Derived
from executor.skills.teach import teach_all
from executor.trial import Cell


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
