"""A cell that fails at start-up makes the session fail at once with the cell's error."""

from __future__ import annotations

import shutil
import time
from pathlib import Path

import pytest


@pytest.mark.slow
def test_a_cell_dying_at_start_up_fails_the_session_at_once(tmp_path: Path, root: Path, run_cli) -> None:
    assembly = tmp_path / "no_geometry"
    shutil.copytree(root / "data" / "cranfield", assembly)
    (assembly / "geometry.toml").unlink()  # the sim cell cannot build its scene
    start = time.monotonic()
    done = run_cli("session", "--assembly", str(assembly), "--cells", "1", "--out", str(tmp_path / "run"), timeout=50)
    assert done.returncode == 2
    assert "exited (code 2) before printing line 'ready" in done.stderr
    assert "geometry.toml" in done.stderr  # the cell's own message is passed on
    assert "Traceback" not in done.stderr
    assert time.monotonic() - start < 30  # not the 60 s wait for a cell
