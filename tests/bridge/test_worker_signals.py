"""A pool a command forks is stopped without a traceback: its workers, forked with the
command's SIGTERM handler (which raises ``Terminated``), take back the default one; and
their garbage collections leave alone the objects they inherit (frozen)."""

from __future__ import annotations

import gc
import multiprocessing
import subprocess
import sys

import pytest

from bridge.cli_types import forked_worker

_POOL = """
import multiprocessing, sys, time
from bridge.cli_types import _terminate_by_exception, forked_worker
_terminate_by_exception()  # the handler a command runs under
pool = multiprocessing.get_context("fork").Pool(8, initializer=forked_worker if sys.argv[1] == "reset" else None)
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


def test_a_forked_worker_freezes_what_it_inherits() -> None:
    """The worker's collections do not walk (and so do not copy) the parent's objects."""
    inherited = [[k] for k in range(10_000)]  # tracked objects of the parent's
    pool = multiprocessing.get_context("fork").Pool(1, initializer=forked_worker)
    try:
        frozen = pool.apply(gc.get_freeze_count)
    finally:
        pool.terminate()
        pool.join()
    assert frozen >= len(inherited)
