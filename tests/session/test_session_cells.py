"""The session over Zenoh with real processes on loopback (truth backend, a few s each).

- two cells, one SIGKILLed mid-experiment: the session completes with the right
  relation and no experiment twice;
- a planner SIGKILLed mid-session: its cells exit; resumed, it sends no finished
  experiment again;
- learned.lp, session.json, journal and the shared Rerun recording are read back.

The sessions that are not killed run in the test's process (``run_main``), their cells
processes of their own; a killed planner is a process.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import threading
import time
from collections import Counter
from pathlib import Path

import pytest

from asp.session.cells import CellProcess, start_cell
from asp.session.journal import read_journal
from asp.sizes.truth_oracle import TruthOracle
from asp.solve import atoms_by_name, load_atoms
from bridge.cell_settings import ServeSettings
from bridge.session import free_loopback_endpoint
from tests.conftest import ROOT, TRUTH_SESSION
from tests.session.test_session_batches import BEST_TWO_CELLS

pytestmark = [pytest.mark.timeout(90), pytest.mark.slow]  # real processes over Zenoh, 3-11 s each
TRUTH = TruthOracle.from_assembly("cranfield")


def assert_learned_truth(result: dict, run: Path, truth: TruthOracle = TRUTH) -> None:
    """The session's result and its run folder hold ``truth``'s relation (default
    Cranfield's), each pair run once and every experiment answered as the truth says."""
    assert result["matches_truth"] is True
    assert {tuple(pair) for pair in result["fits"]} == truth.fits
    journal = read_journal(run / "journal.jsonl")
    assert len(journal) == result["experiments"]
    assert len({e.id for e in journal}) == len(journal)
    assert all(not e.retest for e in journal)
    assert max(Counter((e.part, e.hole) for e in journal).values()) == 1
    for entry in journal:
        assert entry.result == truth.ask(entry.part, entry.hole)
    learned = load_atoms([run / "learned.lp"])
    assert set(atoms_by_name(learned, "fits", 2)) == truth.fits
    assert len(atoms_by_name(learned, "tried", 4)) == len(journal)


def test_two_cells_one_killed_mid_experiment(tmp_path: Path, cells: list[CellProcess], run_session) -> None:
    """The session in the test's process; c1, a process of its own, SIGKILLed by a thread."""
    endpoints = [free_loopback_endpoint(), free_loopback_endpoint()]
    # c1 slow enough to be killed in an experiment (its third, when about 9 of Cranfield's
    # 19 are done); c2, which runs the rest, quicker
    for cell_id, endpoint, delay in zip(("c1", "c2"), endpoints, (0.5, 0.15)):
        cells.append(start_cell(ServeSettings(cell_id=cell_id, backend="truth", listen=(endpoint,), delay_s=delay)))
    run = tmp_path / "run"
    connect = [arg for ep in endpoints for arg in ("--connect", ep)]

    def kill_c1_in_its_third_experiment() -> None:
        cells[0].wait_for_line("start", timeout=30, count=3)
        cells[0].kill()

    killer = threading.Thread(target=kill_c1_in_its_third_experiment)
    killer.start()
    try:
        result = run_session("--cells", "0", *connect, "--out", str(run), "--policy", "best")
    finally:
        killer.join(30)
    assert_learned_truth(result, run)
    journal = read_journal(run / "journal.jsonl")
    by_id = {e.id: e for e in journal}
    started_on_c1 = {line.split()[1] for line in cells[0].lines if line.startswith("start")}
    lost = {rid for rid in started_on_c1 if by_id[rid].cell != "c1"}
    assert lost, "c1 died during an experiment..."
    assert all(by_id[rid].cell == "c2" for rid in lost)  # ...which c2 then ran, once
    assert {e.cell for e in journal} == {"c1", "c2"}


def test_killed_planner_resumes_without_repeating_and_its_cells_exit(
        tmp_path: Path, cells: list[CellProcess], root: Path, cli_argv, cli_env: dict[str, str], run_session) -> None:
    """The planner (two cells of its own, experiments of 0.15 s) is SIGKILLed once 5
    experiments are journaled: its cells exit (their lifeline, stdin, closed). The session
    resumed at a fresh cell (no reply cache: a re-sent experiment would run again) sends no
    journaled experiment again."""
    run = tmp_path / "run"
    planner = subprocess.Popen(cli_argv(*TRUTH_SESSION, "--cells", "2", "--delay", "0.15", "--out", str(run)),
                               cwd=root, env=cli_env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    children: list[int] = []
    try:
        wait_until(lambda: (run / "journal.jsonl").is_file() and len(read_journal(run / "journal.jsonl")) >= 5,
                   30, "five finished experiments")
        children = [int(pid) for pid in subprocess.run(
            ["ps", "-o", "pid=", "--ppid", str(planner.pid)], capture_output=True, text=True,
            check=True).stdout.split()]
        assert len(children) == 2
        planner.send_signal(signal.SIGKILL)
        planner.wait(10)
        wait_until(lambda: not any(map(is_cell, children)), 15, "the cells to exit")
    finally:
        planner.kill()
        for pid in filter(is_cell, children):
            os.kill(pid, signal.SIGKILL)
    before = read_journal(run / "journal.jsonl")
    assert 5 <= len(before) < 25
    endpoint = free_loopback_endpoint()
    cells.append(start_cell(ServeSettings(cell_id="c1", backend="truth", listen=(endpoint,), delay_s=0.0)))
    result = run_session("--cells", "0", "--connect", endpoint, "--resume", str(run))
    assert result["run"] == str(run)
    assert_learned_truth(result, run)
    after = read_journal(run / "journal.jsonl")
    assert after[:len(before)] == before
    rerun_ids = {line.split()[1] for line in cells[0].lines if line.startswith("start")}
    assert rerun_ids == {e.id for e in after[len(before):]}
    assert not rerun_ids & {e.id for e in before}


def test_a_two_cell_session_needs_few_experiments_and_writes_one_recording(tmp_path: Path, run_session) -> None:
    from bridge.recording.reader import column_values, read_recording

    run = tmp_path / "run"
    result = run_session("--cells", "2", "--out", str(run), "--policy", "best")
    assert_learned_truth(result, run)
    assert result["experiments"] <= BEST_TWO_CELLS  # batches of independent pairs waste none
    assert all(len(plan) == 10 for plan in result["plans"])
    settings = json.loads((run / "session.json").read_text())
    assert settings["status"] == "done" and set(settings["cells"]) == {"c1", "c2"}
    summary = read_recording(sorted(run.glob("*.rrd")))
    assert set(summary.recording_ids) == {settings["recording_id"]}
    entities = set(summary.entities)
    for entity in ("/planner/knowledge", "/planner/precedence", "/planner/smaller",
                   "/planner/assignment", "/executor/c1/outcome", "/executor/c2/outcome"):
        assert entity in entities
    assert summary.entities["/planner/knowledge"].rows == result["experiments"] + 1  # and the start, experiment 0
    files = sorted(run.glob("*.rrd"))
    numbers = set(range(1, result["experiments"] + 1))
    assert set(column_values(files, "/planner/knowledge", "experiment")) == numbers | {0}
    by_cells = [n for c in ("c1", "c2") for n in column_values(files, f"/executor/{c}/outcome", "experiment")]
    assert sorted(by_cells) == sorted(numbers)  # each experiment logged once, by its cell


def wait_until(condition, timeout: float, what: str) -> None:
    """Poll ``condition`` every 50 ms until true; fail after ``timeout`` [s]."""
    deadline = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < deadline, f"timed out waiting for {what}"
        time.sleep(0.05)


def is_cell(pid: int) -> bool:
    """Whether process ``pid`` exists and its command line reads ``executor serve``."""
    try:
        return "executor serve" in Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode()
    except (FileNotFoundError, ProcessLookupError):
        return False


def test_confirmed_session_retests_each_essential_experiment_once(tmp_path: Path, run_session) -> None:
    """--confirm 1 with truthful cells: one agreeing re-test per essential experiment, on top
    of the experiments the same policy needs without (learned in process)."""
    from asp.sizes.learner import learn_sizes

    plain = learn_sizes(TRUTH.parts, TRUTH.holes, TRUTH, "systematic").count
    run = tmp_path / "confirmed"
    result = run_session("--cells", "1", "--out", str(run), "--policy", "systematic", "--confirm", "1")
    assert result["matches_truth"] is True
    journal = read_journal(run / "journal.jsonl")
    retests = [e for e in journal if e.retest]
    assert len(journal) == result["experiments"] == plain + len(retests)
    assert len(retests) == 15  # Cranfield's essential observations, for every policy
    asked = Counter((e.part, e.hole) for e in journal)
    assert all(asked[(e.part, e.hole)] == 2 for e in retests)
    assert all(e.result == TRUTH.ask(e.part, e.hole) for e in journal)


def test_a_session_starts_from_its_demonstrations_and_never_uses_a_rogue_cell(tmp_path: Path, run_session) -> None:
    """``--demos``: the session starts from the fits its demonstrations show. Once its first
    experiment is journaled, a local process joins it, declares ``cell/evil/alive`` and
    answers every request with "fit"; the session, which started its own cell, uses only
    that cell, learns the truth, and chooses the experiments it would choose without the
    rogue (a token counted mid-session would make its batches bigger, hence its choices other)."""
    from asp.sizes.learner import LearningOptions, learn_sizes
    from bridge.keys import alive_key
    from bridge.messages import InsertReply, decode_request, encode
    from bridge.session import open_session

    demos = ROOT / "data" / "cranfield" / "demos_annotated.txt"
    run = tmp_path / "run"
    journal = run / "journal.jsonl"
    endpoint = free_loopback_endpoint()
    asked: list[str] = []
    joined: list[int] = []  # how many experiments were journaled when the rogue was linked
    stop = threading.Event()

    def always_fit(query) -> None:
        request = decode_request(query.payload.to_bytes())
        asked.append(request.id)
        query.reply(query.key_expr, encode(InsertReply(id=request.id, cell="evil", part=request.part,
                                                       hole=request.hole, result="fit")))

    def rogue() -> None:
        while not (journal.is_file() and read_journal(journal)):
            if stop.wait(0.02):
                return
        session = open_session(connect=(endpoint,))  # the session listens by now: linked at once
        try:
            handles = (session.declare_queryable("cell/evil/insert", always_fit),
                       session.liveliness().declare_token(alive_key("evil")))
            while not list(session.info.peers_zid()):
                if stop.wait(0.02):
                    return
            joined.append(len(read_journal(journal)))
            stop.wait()
            del handles
        finally:
            session.close()

    thread = threading.Thread(target=rogue, daemon=True)
    thread.start()
    try:  # experiments of 0.3 s: the rogue joins while several are left to choose
        result = run_session("--listen", endpoint, "--out", str(run), "--demos", str(demos), "--delay", "0.3")
    finally:
        stop.set()
        thread.join(30)
    assert_learned_truth(result, run)
    assert "assembly" not in result  # no --assemble
    assert joined and joined[0] < result["experiments"] and asked == [], joined
    assert {e.cell for e in read_journal(run / "journal.jsonl")} == {"c1"}
    shown = {tuple(pair) for pair in result["demonstrated"]}
    assert len(shown) == 9 and shown <= TRUTH.fits
    in_order = [tuple(pair) for pair in result["demonstrated"]]  # the learner's choices follow their order
    alone = learn_sizes(TRUTH.parts, TRUTH.holes, TRUTH, "best", options=LearningOptions(demonstrated=in_order))
    assert result["experiments"] == alone.count < 19  # 19: best from nothing
    assert not {(e.part, e.hole) for e in read_journal(run / "journal.jsonl")} & shown
    learned = load_atoms([run / "learned.lp"])
    assert set(atoms_by_name(learned, "demonstrated", 2)) == shown
    assert len([a for a in learned if a.match("demo", 4)]) == 4 * 5  # 4 demonstrations, 5 pegs each
    assert json.loads((run / "session.json").read_text())["demos"] == str(demos)
