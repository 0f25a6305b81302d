"""The session tests' fixture: ``run_session`` in this process (it overrides the top-level
one, a process of its own: the session's process start is tested where a planner is
started, killed or stopped, e.g. ``test_session_cells.py``, ``test_session_folder.py``)."""

from __future__ import annotations

import json
from collections.abc import Callable

import pytest

from tests.conftest import TRUTH_SESSION, Runner


@pytest.fixture
def run_session(run_main: Runner) -> Callable[..., dict]:
    """A truth session (``TRUTH_SESSION`` and the arguments given) in this process, its cells
    processes of their own: its JSON result, the command having exited 0."""
    def run(*args: str, timeout: float = 60) -> dict:
        done = run_main(*TRUTH_SESSION, *args, timeout=timeout)
        assert done.returncode == 0, done.stderr
        return json.loads(done.stdout)
    return run
