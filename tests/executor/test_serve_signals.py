"""A cell waiting for work ends on SIGTERM even when another of its threads takes the
signal (as Zenoh's threads may: a process-directed signal goes to any thread)."""

from __future__ import annotations

import subprocess
import sys

import pytest

from tests.conftest import ROOT

SCRIPT = """
import signal, sys, threading, time
from assembly_constraints.executor.serve.node import CellNode, _exit_on_signal
signal.signal(signal.SIGTERM, _exit_on_signal)
node = CellNode("c1", backend=None)  # no work arrives: the backend is never used

def other_thread_takes_the_signal():
    time.sleep(0.3)
    signal.pthread_kill(threading.get_ident(), signal.SIGTERM)

threading.Thread(target=other_thread_takes_the_signal, daemon=True).start()
node.serve()
"""


@pytest.mark.slow
def test_a_sigterm_taken_by_another_thread_ends_the_waiting_cell() -> None:
    done = subprocess.run([sys.executable, "-c", SCRIPT], cwd=ROOT, capture_output=True, text=True, timeout=20,
                          env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"})
    assert done.returncode == 128 + 15, done.stderr
