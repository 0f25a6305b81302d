"""A cell the session started and that crashes during learning (a real SIGKILL) is named as
crashed, with its exit status, never reported as a cell that did not reply in time:

- two cells, one killed: the session finishes with the other, the relation exact, no
  experiment lost or run twice;
- the only cell killed: the session fails at once (not after ``--wait-for-cell``) with one
  line naming the crash, exit code 2, no traceback.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import time
from collections import Counter
from collections.abc import Iterator
from pathlib import Path

import pytest

from asp.session.journal import read_journal
from asp.sizes.truth_oracle import TruthOracle
from tests.conftest import TRUTH_SESSION

pytestmark = [pytest.mark.timeout(120), pytest.mark.slow]  # real processes over Zenoh, 5-15 s each
TRUTH = TruthOracle.from_assembly("cranfield")


def cell_pids(planner: int) -> dict[str, int]:
    """The planner's cell processes: cell id -> pid (the ``cell_id`` of the settings
    document in their command lines, ``serve --settings JSON``)."""
    found: dict[str, int] = {}
    listed = subprocess.run(["ps", "-o", "pid=", "--ppid", str(planner)], capture_output=True, text=True)
    for pid in map(int, listed.stdout.split()):
        try:
            argv = Path(f"/proc/{pid}/cmdline").read_bytes().split(b"\0")
        except FileNotFoundError:
            continue
        if b"serve" in argv and b"--settings" in argv:
            found[json.loads(argv[argv.index(b"--settings") + 1])["cell_id"]] = pid
    return found


def wait_for_journal(run: Path, lines: int, planner: subprocess.Popen, timeout: float = 60.0) -> None:
    """Poll until the run's journal holds ``lines`` finished experiments."""
    deadline = time.monotonic() + timeout
    journal = run / "journal.jsonl"
    while not (journal.is_file() and len(read_journal(journal)) >= lines):
        assert planner.poll() is None, "the session ended before the cell was killed"
        assert time.monotonic() < deadline, f"no {lines} experiments within {timeout} s"
        time.sleep(0.05)


@pytest.fixture
def planner_of(tmp_path: Path, root: Path, cli_argv, cli_env: dict[str, str]) -> Iterator:
    """Start a truth session (``--out tmp/run``, experiments of 0.15 s: the test kills a
    cell while many are left) with more arguments; killed at the end, with any cell it left."""
    started: list[subprocess.Popen] = []

    def start(*args: str) -> subprocess.Popen:
        argv = cli_argv(*TRUTH_SESSION, "--delay", "0.15", "--out", str(tmp_path / "run"), *args)
        started.append(subprocess.Popen(argv, cwd=root, env=cli_env, stdout=subprocess.PIPE,
                                        stderr=subprocess.PIPE, text=True))
        return started[-1]

    yield start
    for planner in started:
        leftover = cell_pids(planner.pid)
        planner.kill()
        planner.communicate(timeout=30)
        for pid in leftover.values():
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass


def test_a_crashed_cell_is_named_and_the_session_finishes_with_the_other(tmp_path: Path, planner_of) -> None:
    run = tmp_path / "run"
    planner = planner_of("--cells", "2", "--policy", "best")
    wait_for_journal(run, 4, planner)
    os.kill(cell_pids(planner.pid)["c2"], signal.SIGKILL)
    out, err = planner.communicate(timeout=90)
    assert planner.returncode == 0, err
    assert "cell c2 crashed (killed by signal SIGKILL)" in err
    assert "cell c2: no reply" not in err and "missed replies" not in err
    journal = read_journal(run / "journal.jsonl")
    learned = {(e.part, e.hole): e.result for e in journal}
    assert len(learned) == len(journal)  # no pair twice
    assert len({e.id for e in journal}) == len(journal)
    assert all(result == TRUTH.ask(*pair) for pair, result in learned.items())
    assert Counter(e.cell for e in journal)["c1"] > 0
    assert '"matches_truth": true' in out


def test_the_only_cell_crashing_fails_the_session_at_once_naming_it(tmp_path: Path, planner_of) -> None:
    planner = planner_of("--cells", "1", "--wait-for-cell", "60")
    wait_for_journal(tmp_path / "run", 2, planner)
    killed = time.monotonic()
    os.kill(cell_pids(planner.pid)["c1"], signal.SIGKILL)
    out, err = planner.communicate(timeout=90)
    assert time.monotonic() - killed < 30  # not the 60 s wait for a cell
    assert planner.returncode == 2 and out == ""
    errors = [line for line in err.splitlines() if line.startswith("error:")]
    assert len(errors) == 1 and "Traceback" not in err
    assert "cell c1 crashed (killed by signal SIGKILL); no other cell left" in errors[0]
    assert "no reply" not in errors[0]
