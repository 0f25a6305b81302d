"""A cell waiting for work ends on SIGTERM even when another of its threads takes the
signal (as Zenoh's threads may: a process-directed signal goes to any thread)."""

from __future__ import annotations

import subprocess
import sys

import pytest

from tests.conftest import ROOT

SCRIPT = """
import signal, sys, threading, time
from executor.serve.node import CellNode, _exit_on_signal
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


LINES_FROM_THREADS = """
import threading
from executor.serve.node import say
def lines(k):
    for i in range(2000):
        say(f"start q{k}-{i} p1 r1 {i}")
threads = [threading.Thread(target=lines, args=(k,)) for k in range(6)]
[t.start() for t in threads]
[t.join() for t in threads]
"""


def test_lines_the_cell_prints_from_several_threads_stay_whole() -> None:
    # The refusals (zenoh's callback threads) and the start/done lines (the worker) go to one
    # pipe the planner reads line by line; print() writes text and newline apart, so with
    # it two threads glue lines (thousands of these 12,000).
    done = subprocess.run([sys.executable, "-c", LINES_FROM_THREADS], cwd=ROOT, capture_output=True, text=True,
                          timeout=60, check=True)
    lines = done.stdout.splitlines()
    assert len(lines) == 12_000
    assert sorted(lines) == sorted(f"start q{k}-{i} p1 r1 {i}" for k in range(6) for i in range(2000))
