"""A cell that fails at start-up makes the session fail at once with the cell's error."""

from __future__ import annotations

import shutil
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def test_a_cell_dying_at_start_up_fails_the_session_at_once(tmp_path: Path) -> None:
    assembly = tmp_path / "no_geometry"
    shutil.copytree(ROOT / "data" / "cranfield", assembly)
    (assembly / "geometry.toml").unlink()  # the sim cell cannot build its scene
    start = time.monotonic()
    done = subprocess.run(
        [sys.executable, "-m", "asp.cli", "session", "--assembly", str(assembly),
         "--cells", "1", "--out", str(tmp_path / "run")],
        cwd=ROOT, capture_output=True, text=True, timeout=50,
    )
    assert done.returncode == 2
    assert "exited (code 2) before printing line 'ready" in done.stderr
    assert "geometry.toml" in done.stderr  # the cell's own message is passed on
    assert "Traceback" not in done.stderr
    assert time.monotonic() - start < 30  # not the 60 s wait for a cell
