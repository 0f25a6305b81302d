"""Sessions with simulated (PyBullet) cells: a killed session resumes with what its cell
had learned (ILC), and the default session learns the spare plate's exact relation with the
cell's default uncertainty (second attempts included); the cell's options reach the
cells in ``tests/session/test_session_explore.py``.  Real processes: the killed planner,
``executor serve``, Zenoh on loopback; the resumed session in the test's process. The
Cranfield session in the same cells (25 pairs where the spare plate has 12) is
``./run.sh session`` and ``./run.sh bench session`` (docs/results/session.md)."""

from __future__ import annotations

import json
import signal
import subprocess
import time
from pathlib import Path

import pytest

from asp.session.journal import read_journal
from asp.sizes.truth_oracle import TruthOracle
from tests.session.test_session_cells import assert_learned_truth

SIM_SESSION = ("session", "--json", "--assembly", "spare")  # the default backend: sim


def _ilc_iterations(path: Path) -> dict[str, int]:
    """Executions learned from, per ILC key, in a cell's saved ILC state."""
    return {key: entry["iterations"] for key, entry in json.loads(path.read_text())["keys"].items()}


def _processes_naming(text: str) -> list[int]:
    """Ids of the running processes whose command line contains ``text``."""
    found = []
    for cmdline in Path("/proc").glob("[0-9]*/cmdline"):
        try:
            if text in cmdline.read_bytes().decode(errors="replace"):
                found.append(int(cmdline.parent.name))
        except OSError:
            continue  # gone meanwhile
    return found


def _wait_for(condition, timeout: float, what: str) -> None:
    deadline = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < deadline, f"waited {timeout:.0f} s for {what}"
        time.sleep(0.1)


@pytest.mark.slow
def test_a_killed_sim_session_resumes_with_its_cells_ilc_and_learns_the_spare_plate_exactly(
        tmp_path: Path, root: Path, cli_argv, cli_env: dict[str, str], run_main) -> None:
    """Default options (the full layer with ILC, the default uncertainty, two attempts per
    experiment).  The planner is SIGKILLed after two finished experiments; its cell
    follows (lifeline).  The resumed session's cell reloads ``<run>/c1-ilc.json``: every
    key keeps counting from where it was (a cell starting from nothing would save
    counts of its own executions only)."""
    run = tmp_path / "run"
    state = run / "c1-ilc.json"
    planner = subprocess.Popen(cli_argv(*SIM_SESSION, "--out", str(run)), cwd=root, env=cli_env,
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        _wait_for(lambda: (run / "journal.jsonl").is_file() and len(read_journal(run / "journal.jsonl")) >= 2
                  and state.is_file(), 60, "two finished experiments and an ILC state")
        planner.send_signal(signal.SIGKILL)
        planner.wait(10)
    finally:
        planner.kill()
    _wait_for(lambda: not _processes_naming(str(state)), 20, "the cell to follow its planner")
    before = _ilc_iterations(state)
    finished_before = len(read_journal(run / "journal.jsonl"))
    assert sum(before.values()) >= 1

    done = run_main(*SIM_SESSION, "--resume", str(run), timeout=120)
    assert done.returncode == 0, done.stderr
    result = json.loads(done.stdout)
    assert_learned_truth(result, run, TruthOracle.from_assembly("spare"))  # every experiment right
    journal = read_journal(run / "journal.jsonl")
    no_fits = [e for e in journal if e.result == "no_fit"]
    assert no_fits and all(e.evidence is not None and e.evidence.attempts == 2 for e in no_fits)
    after = _ilc_iterations(state)
    fits_after_resume = sum(e.result == "fit" for e in journal[finished_before:])
    assert fits_after_resume >= 1
    assert all(after[key] >= count for key, count in before.items())
    assert sum(after.values()) >= sum(before.values()) + fits_after_resume
