"""``executor serve --backend MODULE:CLASS``: a user's backend loaded by name; the replay
backend (executor.replay) answers from a recorded session's journal. The commands run in
this process (``run_main``); the cells are processes of their own."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from asp.session.cells import CellProcess
from bridge.cell_settings import ServeSettings
from bridge.messages import InsertRequest
from bridge.session import free_loopback_endpoint
from executor import ExecutorError
from executor.backend_plugin import CellContext, UnknownPair
from executor.replay import ReplayBackend
from tests.conftest import TRUTH_SESSION, Runner

REPLAY = "executor.replay:ReplayBackend"


def _journal(path: Path, *records: dict) -> Path:
    path.write_text("".join(json.dumps(r) + "\n" for r in records) + '{"part": "torn')
    return path


def test_replay_answers_each_pair_with_its_recorded_answers_in_order(tmp_path: Path) -> None:
    evidence = {"attempts": 2, "max_force_dev": 9.0, "max_torque_dev": 0.2, "end_error": 0.01, "duration_s": 4.0}
    journal = _journal(tmp_path / "journal.jsonl",
                       {"event": "started", "experiment": 1, "id": "a", "part": "p1", "hole": "r1"},
                       {"id": "a", "part": "p1", "hole": "r1", "result": "no_fit", "cell": "c1", "evidence": evidence},
                       {"id": "b", "part": "p1", "hole": "r1", "result": "fit", "cell": "c1", "evidence": None})
    backend = ReplayBackend(CellContext("c1", "cranfield", options={"journal": str(journal)}))
    ask = InsertRequest(id="x", part="p1", hole="r1")
    first, second, third = backend.run(ask), backend.run(ask), backend.run(ask)
    assert first[0] == "no_fit" and first[1] is not None and first[1].attempts == 2
    assert second == ("fit", None) and third == ("fit", None)  # past the last answer: the last again
    with pytest.raises(UnknownPair, match=r"no experiment for \(p2,r1\)"):
        backend.run(InsertRequest(id="y", part="p2", hole="r1"))


def test_a_bad_journal_line_is_named(tmp_path: Path) -> None:
    journal = tmp_path / "journal.jsonl"
    journal.write_text('{"id": "a", "part": "p1", "hole": "r1", "result": "maybe"}\n')
    with pytest.raises(ExecutorError, match=r"journal.jsonl:1: not a finished experiment .*'maybe'"):
        ReplayBackend(CellContext("c1", "cranfield", options={"journal": str(journal)}))


@pytest.mark.slow  # the cell's imports (about 3 s)
def test_bad_backend_names_exit_2_with_one_line(run_main: Runner, tmp_path: Path) -> None:
    for argv, expected in [(["--backend", "no_such_module:Backend"], "cannot import no_such_module"),
                           (["--backend", "executor.replay:Nope"],
                            "expected a class Nope in executor.replay"),
                           (["--backend", REPLAY], "needs --backend-option journal=")]:
        done = run_main("executor", "serve", *argv, cwd=tmp_path, timeout=60)
        assert done.returncode == 2 and expected in done.stderr and len(done.stderr.splitlines()) == 1, done.stderr


@pytest.mark.slow
def test_a_session_against_a_replay_cell_repeats_the_recorded_session(
        run_main: Runner, cells: list[CellProcess], tmp_path: Path) -> None:
    def run_session(*args: str) -> dict:
        done = run_main(*TRUTH_SESSION, *args, timeout=60)
        assert done.returncode == 0, done.stderr
        return json.loads(done.stdout)

    recorded = run_session("--out", str(tmp_path / "recorded"))
    endpoint = free_loopback_endpoint()
    cell = CellProcess(ServeSettings(cell_id="c1", backend=REPLAY, listen=(endpoint,),
                                     backend_options={"journal": str(tmp_path / "recorded" / "journal.jsonl")}))
    cells.append(cell)
    cell.wait_for_line("ready", timeout=60)
    replayed = run_session("--cells", "0", "--connect", endpoint, "--out", str(tmp_path / "replayed"))
    assert replayed["fits"] == recorded["fits"] and replayed["experiments"] == recorded["experiments"]
    assert len([line for line in cell.lines if line.startswith("done ")]) == recorded["experiments"]
