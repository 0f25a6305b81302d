"""The shipped products exported in the assembled pose and imported, once per test
session (a worker's): ``imported(product)`` → (what the import derived, the assembly
folder it wrote), shared by the round trips of ``test_import`` and ``test_covers``."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from assembly_constraints.cli import main
from executor.cad.cli import run_import
from executor.cad.derive import Derived


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
