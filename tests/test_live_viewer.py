"""Live viewing: a trial or a session streams its recording to a running Rerun viewer (a
headless ``rerun --save`` server stands in for one), or serves it to a web browser."""

from __future__ import annotations

import re
import signal
import socket
import subprocess
import sys
import time
import urllib.request
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

from bridge.recording.reader import column_values, read_blueprint, read_recording
from bridge.recording.sinks import rerun_server
from tests.conftest import ROOT, child_env


def _wait_for(path: Path, timeout: float = 30.0) -> None:
    deadline = time.monotonic() + timeout
    while not path.exists() and time.monotonic() < deadline:
        time.sleep(0.1)


def assert_closed(address: str) -> None:
    """Nobody serves ``address`` any more: the web viewer went with its command."""
    port = int(re.search(r":(\d+)/", address).group(1))  # type: ignore[union-attr]
    with socket.socket() as probe:
        assert probe.connect_ex(("127.0.0.1", port)) != 0


@contextmanager
def headless_viewer(live: Path) -> Iterator[str]:
    """A Rerun server saving what streams into it to ``live``; yields its URL."""
    with rerun_server(["--save", str(live)]) as viewer:
        try:
            _wait_for(live)
            yield viewer.url
            time.sleep(1.0)
        finally:
            viewer.process.send_signal(signal.SIGINT)  # it finishes its file
            viewer.process.wait(20)


@pytest.mark.slow
def test_a_trial_streams_live_to_a_running_viewer(tmp_path: Path, run_executor) -> None:
    live = tmp_path / "live.rrd"
    with headless_viewer(live) as url:
        done = run_executor("trial", "--part", "p1", "--hole", "r1", "--save", str(tmp_path / "c1.rrd"),
                            "--rerun-connect", url)
        assert done.returncode == 0, done.stderr
    outcomes = column_values(live, "executor/c1/outcome", "TextLog:text")
    assert len(outcomes) == 1 and "p1→r1" in outcomes[0][0]
    assert "/executor/c1/arm/lbr_iiwa_link_4" in read_recording(live).entities
    assert column_values(tmp_path / "c1.rrd", "executor/c1/outcome", "TextLog:text") == outcomes


@pytest.mark.slow
def test_a_trial_serves_its_recording_to_a_web_browser_until_ctrl_c(tmp_path: Path) -> None:
    rrd = tmp_path / "c1.rrd"
    trial = subprocess.Popen(
        [sys.executable, "-m", "assembly_constraints", "executor", "trial", "--part", "p1", "--hole", "r1",
         "--save", str(rrd), "--rerun-serve"],
        cwd=ROOT, env=child_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert trial.stderr is not None
        lines = []
        for line in trial.stderr:
            lines.append(line)
            if "Ctrl-C to stop" in line:
                break
        address = next(m.group(0) for line in lines if (m := re.search(r"http://127\.0\.0\.1:\d+/\S*", line)))
        with urllib.request.urlopen(address, timeout=10) as page:
            assert page.status == 200 and b"<html" in page.read().lower()
        trial.send_signal(signal.SIGINT)
        out, _ = trial.communicate(timeout=30)
    finally:
        trial.kill()
    assert trial.returncode == 0
    assert "summary: 1/1 fit" in out
    assert_closed(address)
    assert len(column_values(rrd, "executor/c1/outcome", "TextLog:text")) == 1


@pytest.fixture(scope="module")
def live_session(tmp_path_factory: pytest.TempPathFactory, run_session) -> tuple[Path, Path, dict]:
    """A two-cell truth session streamed live to a headless viewer: the viewer's file, the
    session's run folder and its result (the run folder is also the one ``view --web`` serves)."""
    tmp = tmp_path_factory.mktemp("live")
    live, run = tmp / "live.rrd", tmp / "run"
    with headless_viewer(live) as url:
        result = run_session("--cells", "2", "--out", str(run), "--rerun-connect", url)
    return live, run, result


@pytest.mark.slow
def test_a_session_streams_planner_and_cells_live(live_session: tuple[Path, Path, dict]) -> None:
    live, run, result = live_session
    entities = read_recording(live).entities
    assert "/planner/experiments" in entities
    assert {"/executor/c1/outcome", "/executor/c2/outcome"} <= set(entities)
    streamed = len(column_values(live, "planner/experiments", "TextLog:text"))
    assert streamed == result["experiments"] + 1  # and the start, experiment 0
    layout = read_blueprint(live)  # the live viewer's blueprint, following the newest data
    assert layout.tabs == ["planner", "c1", "c2"] and layout.time_panel["play_state"] == 3
    assert read_recording(run / "planner.rrd").blueprints == 0  # the folder's is view.rbl


@pytest.mark.slow
def test_view_web_serves_a_run_folder_until_ctrl_c(live_session: tuple[Path, Path, dict]) -> None:
    _, run, _ = live_session
    view = subprocess.Popen([sys.executable, "-m", "assembly_constraints", "view", str(run), "--web"],
                            cwd=ROOT, env=child_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert view.stderr is not None
        address = None
        for line in view.stderr:
            if m := re.search(r"http://127\.0\.0\.1:\d+/\S*", line):
                address = m.group(0)
                break
        assert address is not None
        with urllib.request.urlopen(address, timeout=10) as page:
            assert page.status == 200
        view.send_signal(signal.SIGINT)
        view.communicate(timeout=30)
    finally:
        view.kill()
    assert view.returncode == 0
    assert (run / "view.rbl").is_file()
    assert_closed(address)
