"""A pool a command forks is stopped without a traceback: its workers, forked with the
command's SIGTERM handler (which raises ``Terminated``), take back the default one."""

from __future__ import annotations

import subprocess
import sys

import pytest

_POOL = """
import multiprocessing, sys, time
from bridge.cli_types import _terminate_by_exception, worker_signals
_terminate_by_exception()  # the handler a command runs under
pool = multiprocessing.get_context("fork").Pool(8, initializer=worker_signals if sys.argv[1] == "reset" else None)
pool.map_async(time.sleep, [30.0] * 8, chunksize=1)
time.sleep(1.0)  # the workers busy: the pool cannot end them by telling them to stop
pool.terminate()
pool.join()
"""


@pytest.mark.parametrize("initializer", ["reset", "none"])
def test_a_terminated_pool_of_a_command_prints_no_traceback(initializer: str) -> None:
    done = subprocess.run([sys.executable, "-c", _POOL, initializer], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    if initializer == "reset":
        assert "Traceback" not in done.stderr, done.stderr
    else:  # the case the initializer is for: the inherited handler raises in each busy worker
        assert "Terminated" in done.stderr
