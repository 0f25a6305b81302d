"""A cell that fails at start-up makes the session fail at once with the cell's error."""

from __future__ import annotations

import shutil
import time
from pathlib import Path

import pytest


def short_peg(product: Path) -> None:
    """Make the round peg of a Cranfield copy shorter (15 mm) than the default gripper grasps
    (20 mm): the planner, which knows no gripper, accepts the product; a cell, which holds
    the gripper of its cell description, exits at start naming the peg."""
    geometry = product / "geometry.toml"
    text = geometry.read_text()
    peg = text.index("[part_shapes.round_peg]")
    length = text.index("length = 0.05 ", peg)
    geometry.write_text(text[:length] + "length = 0.015" + text[length + len("length = 0.05 "):])


@pytest.mark.slow
def test_a_cell_dying_at_start_up_fails_the_session_at_once(tmp_path: Path, root: Path, run_main) -> None:
    assembly = tmp_path / "short_peg"
    shutil.copytree(root / "data" / "cranfield", assembly)
    short_peg(assembly)
    start = time.monotonic()
    done = run_main("session", "--assembly", str(assembly), "--cells", "1", "--out", str(tmp_path / "run"), timeout=50)
    assert done.returncode == 2
    assert "exited (code 2) before printing line 'ready" in done.stderr
    # the cell's own message is passed on
    assert "[part_shapes.round_peg] length: expected longer than [gripper] grasp_depth" in done.stderr
    assert "Traceback" not in done.stderr
    assert time.monotonic() - start < 30  # not the 60 s wait for a cell
