"""The run folder: one session at a time (an OS lock), ``--out`` refuses a folder with a
journal, a failed start blocks nothing, and a resumed session never reuses an experiment
number (real sessions with truth cells on loopback, real SIGKILL)."""

from __future__ import annotations

import fcntl
import json
import os
import shutil
import signal
import subprocess
import threading
import time
from pathlib import Path

import pytest

from asp import PlannerError
from asp.session.cells import CellProcess, start_cell
from asp.session.folder import lock_run_folder
from asp.session.journal import JournalEntry, JournalEvent, read_journal, read_records
from bridge.cell_settings import ServeSettings
from bridge.session import free_loopback_endpoint
from tests.conftest import TRUTH_SESSION
from tests.session.test_session_cells import assert_learned_truth
from tests.session.test_session_startup import short_peg

pytestmark = pytest.mark.timeout(90)




def lock_is_free(run: Path) -> bool:
    """Whether no process holds the run folder's lock (we can take it and give it back)."""
    fd = os.open(run / ".lock", os.O_RDWR)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        return True
    except BlockingIOError:
        return False
    finally:
        os.close(fd)


def wait_until(condition, timeout: float, what: str) -> None:
    deadline = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < deadline, f"timed out waiting for {what}"
        time.sleep(0.02)


def started_numbers(cell: CellProcess) -> list[int]:
    """The experiment numbers of the requests the cell started (``start ID PART HOLE N``)."""
    return [int(line.split()[4]) for line in cell.lines if line.startswith("start ")]


@pytest.mark.slow
@pytest.mark.timeout(180)  # two tests' sessions in one
def test_after_a_cell_died_at_start_two_sessions_started_at_once_on_one_folder(
        tmp_path: Path, root: Path, cli_argv, cli_env: dict[str, str], run_main) -> None:
    """A start whose cell dies leaves no folder and blocks nothing; of two sessions then
    started at once on the folder, one learns, the other is refused naming the first."""
    broken = tmp_path / "short_peg"
    shutil.copytree(root / "data" / "cranfield", broken)
    short_peg(broken)
    run = tmp_path / "run"
    failed = run_main(*TRUTH_SESSION, "--assembly", str(broken), "--cells", "1", "--out", str(run), timeout=50)
    assert failed.returncode == 2 and "before printing line 'ready" in failed.stderr
    assert not run.exists()
    argv = cli_argv(*TRUTH_SESSION, "--cells", "1", "--delay", "0.05", "--out", str(run))
    both = [subprocess.Popen(argv, cwd=root, env=cli_env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            for _ in range(2)]
    try:
        outputs = [process.communicate(timeout=60) for process in both]
    finally:
        for process in both:
            process.kill()
    codes = sorted(process.returncode for process in both)
    assert codes == [0, 2], outputs
    winner, loser = (0, 1) if both[0].returncode == 0 else (1, 0)
    assert outputs[loser][1] == (f"error: {run}: in use by another session (pid {both[winner].pid}); "
                                 "wait for it to end or use another folder\n")
    result = json.loads(outputs[winner][0])
    assert_learned_truth(result, run)
    records = read_records(run / "journal.jsonl")
    assert {r.cell for r in records} == {"c1"}
    numbers = [e.experiment for e in records if isinstance(e, JournalEntry)]
    assert sorted(numbers) == list(range(1, result["experiments"] + 1))
    assert lock_is_free(run)


@pytest.mark.slow
def test_out_on_a_folder_with_a_journal_is_refused(tmp_path: Path, run_main) -> None:
    run = tmp_path / "run"
    run.mkdir()
    line = '{"id":"x.p1.r1.1","part":"p1","hole":"r1","result":"fit","cell":"c1","experiment":1}\n'
    (run / "journal.jsonl").write_text(line)
    done = run_main(*TRUTH_SESSION, "--cells", "0", "--connect", free_loopback_endpoint(), "--wait-for-cell", "1",
                   "--out", str(run), timeout=30)
    assert done.returncode == 2
    assert done.stderr == (f"error: --out {run}: already holds a session (its journal); "
                           f"use --resume {run} or another folder\n")
    assert (run / "journal.jsonl").read_text() == line
    assert lock_is_free(run)


@pytest.mark.parametrize("parent", ["file", "folder"])
def test_out_under_a_regular_file_is_one_line(tmp_path: Path, run_main, parent: str) -> None:
    (tmp_path / "file").write_text("")
    (tmp_path / "folder").mkdir()
    run = tmp_path / parent / "run" if parent == "file" else tmp_path / "file"
    done = run_main(*TRUTH_SESSION, "--cells", "0", "--out", str(run), timeout=30)
    assert done.returncode == 2
    reason = "Not a directory" if parent == "file" else "a file of that name exists"
    assert done.stderr == f"error: {run}: cannot create the folder ({reason})\n"


@pytest.mark.slow
def test_a_failed_start_leaves_no_run_folder_and_blocks_nothing(tmp_path: Path, run_main) -> None:
    run = tmp_path / "run"
    argv = (*TRUTH_SESSION, "--cells", "1", "--listen", "tcp/127.0.0.1:99999", "--out", str(run))
    failed = run_main(*argv, timeout=30)
    assert failed.returncode == 2 and failed.stderr.startswith("error: cannot open a Zenoh session")
    assert failed.stderr.count("\n") == 1
    assert not run.exists()  # the folder this start made is gone
    run.mkdir()  # a folder the user made stays, and a failed start there blocks nothing
    again = run_main(*argv, timeout=30)
    assert again.returncode == 2 and again.stderr == failed.stderr
    assert run.is_dir() and lock_is_free(run)


@pytest.mark.slow
@pytest.mark.timeout(180)  # two tests' sessions in one
def test_a_running_session_refuses_a_resume_and_once_killed_resumes_with_new_numbers(
        tmp_path: Path, cells: list[CellProcess], root: Path, cli_argv, cli_env: dict[str, str], run_session,
        run_main) -> None:
    endpoints = [free_loopback_endpoint(), free_loopback_endpoint()]
    for cell_id, endpoint in zip(("c1", "c2"), endpoints):
        cells.append(start_cell(ServeSettings(cell_id=cell_id, backend="truth", listen=(endpoint,), delay_s=0.3)))
    connect = [arg for ep in endpoints for arg in ("--connect", ep)]
    run = tmp_path / "run"
    planner = subprocess.Popen(cli_argv(*TRUTH_SESSION, "--cells", "0", *connect, "--out", str(run)),
                               cwd=root, env=cli_env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        cells[0].wait_for_line("start", timeout=30, count=3)  # two cells busy: experiments in flight
        second = run_main("session", "--backend", "truth", "--cells", "1", "--resume", str(run), timeout=30)
        assert second.returncode == 2
        assert second.stderr == (f"error: {run}: in use by another session (pid {planner.pid}); "
                                 "wait for it to end or use another folder\n")
        assert sorted(p.name for p in run.glob("c*.rrd")) == []  # it started no cell
        planner.send_signal(signal.SIGKILL)
        planner.wait(10)
    finally:
        planner.kill()
    before = read_records(run / "journal.jsonl")
    finished_before = {e.experiment: e for e in before if isinstance(e, JournalEntry)}
    in_flight = {e.experiment: e for e in before if isinstance(e, JournalEvent) and e.experiment not in finished_before}
    assert in_flight, "the planner died with experiments in flight"
    highest = max([*finished_before, *in_flight])
    sent_before = {c.cell_id: len(started_numbers(c)) for c in cells}

    result = run_session("--cells", "0", *connect, "--resume", str(run))  # the same cells: they keep their caches
    assert_learned_truth(result, run)
    after = read_records(run / "journal.jsonl")
    assert after[:len(before)] == before
    abandoned = [e for e in after[len(before):] if isinstance(e, JournalEvent) and e.event == "abandoned"]
    assert sorted(e.experiment for e in abandoned) == sorted(in_flight)
    finished = [e for e in after if isinstance(e, JournalEntry)]
    numbers = [e.experiment for e in finished]
    assert len(set(numbers)) == len(numbers) and not set(numbers) & set(in_flight)
    assert len({e.id for e in finished}) == len(finished)
    resumed = [e for e in finished if e.experiment not in finished_before]
    assert all(e.experiment > highest for e in resumed)
    again = {(e.part, e.hole): e for e in resumed}
    for start in in_flight.values():  # run again under a new number and a new request id
        assert again[(start.part, start.hole)].experiment > highest
        assert again[(start.part, start.hole)].id != start.id
    sent = [n for c in cells for n in started_numbers(c)]
    assert len(sent) == len(set(sent)), "an experiment number went to the cells twice"
    assert all(n > highest for c in cells for n in started_numbers(c)[sent_before[c.cell_id]:])
    settings = json.loads((run / "session.json").read_text())
    assert settings["starts"] == 2 and sorted(settings["abandoned"]) == sorted(in_flight)  # not the refused one
    assert len(read_journal(run / "journal.jsonl")) == result["experiments"]


def test_a_refused_session_names_a_holder_that_writes_its_pid_late(tmp_path: Path) -> None:
    # The holder takes the lock, then writes its pid: a session refused in between waits
    # for the line instead of naming no one.
    holder = os.open(tmp_path / ".lock", os.O_RDWR | os.O_CREAT, 0o666)
    fcntl.flock(holder, fcntl.LOCK_EX | fcntl.LOCK_NB)
    late = threading.Timer(0.2, lambda: os.pwrite(holder, b"4242\n", 0))
    late.start()
    try:
        with pytest.raises(PlannerError, match=r"in use by another session \(pid 4242\); wait"):
            lock_run_folder(tmp_path)
    finally:
        late.join()
        os.close(holder)
