"""Processes and ports: a command stopped by SIGTERM (or Ctrl-C) leaves no process of its
own behind, and a port is bound by the process that serves on it (port 0, then reported),
never picked free first and bound later. Real processes, real signals; what runs is read
from ``/proc``."""

from __future__ import annotations

import os
import re
import signal
import socket
import subprocess
import time
from collections.abc import Callable
from pathlib import Path

import pytest
import rerun as rr

from tests.conftest import ROOT, child_env
from tests.test_live_viewer import assert_closed

EXIT_TERMINATED = 143  # 128 + SIGTERM


def descendants(pid: int) -> set[int]:
    """Every process below ``pid`` now (children, their children...), from ``/proc``."""
    children: dict[int, list[int]] = {}
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
            except OSError:
                continue
            parent = int(stat[stat.rindex(")") + 2:].split()[1])
            children.setdefault(parent, []).append(int(entry.name))
    found: set[int] = set()
    todo = [pid]
    while todo:
        for child in children.get(todo.pop(), []):
            found.add(child)
            todo.append(child)
    return found


def running(pid: int) -> bool:
    """``pid`` exists and is not a zombie (an orphan's zombie waits for init to reap it)."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat[stat.rindex(")") + 2] != "Z"


def _line(process: subprocess.Popen[str], pattern: str, timeout: float = 120.0) -> re.Match[str]:
    """The first line of ``process``'s stderr matching ``pattern`` (the process's own timeout
    is the test's: a line that never comes ends in pytest-timeout)."""
    assert process.stderr is not None
    seen = []
    for line in process.stderr:
        seen.append(line)
        if match := re.search(pattern, line):
            return match
    raise AssertionError(f"no line matching {pattern!r} in {''.join(seen)[-2000:]}")


def _stop_by_signal(process: subprocess.Popen[str], signum: int = signal.SIGTERM) -> set[int]:
    """SIGTERM (or ``signum``) ``process``; returns those of its descendants (before the
    signal) still running."""
    before = descendants(process.pid)
    assert before, "the command started no process of its own"
    process.send_signal(signum)
    process.communicate(timeout=60)
    deadline = time.monotonic() + 5.0
    while time.monotonic() < deadline and any(running(pid) for pid in before):
        time.sleep(0.1)
    return {pid for pid in before if running(pid)}


def _accepts(address: str) -> bool:
    """Something accepts connections on the port of ``address`` (``http://127.0.0.1:PORT/...``)."""
    port = int(address.split(":")[2].split("/")[0])
    with socket.socket() as probe:
        return probe.connect_ex(("127.0.0.1", port)) == 0


def _recording(path: Path) -> Path:
    stream = rr.RecordingStream("assembly_constraints", recording_id="sigterm")
    stream.save(str(path))
    stream.log("planner/experiments", rr.TextLog("one line"))
    stream.flush()
    stream.disconnect()
    return path


@pytest.mark.slow  # the Rerun web viewer's start (~2 s)
def test_view_web_stopped_by_sigterm_stops_its_web_viewer(tmp_path: Path, cli_argv: Callable[..., list[str]]
                                                          ) -> None:
    rrd = _recording(tmp_path / "c1.rrd")
    view = subprocess.Popen(cli_argv("view", str(rrd), "--web"), cwd=ROOT, env=child_env(),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        address = _line(view, r"http://127\.0\.0\.1:\d+/\S*").group(0)
        left = _stop_by_signal(view)
    finally:
        view.kill()
    assert view.returncode == EXIT_TERMINATED
    assert not left, f"still running after SIGTERM: {left}"
    grpc = re.search(r"url=rerun%2Bhttp%3A%2F%2F127\.0\.0\.1%3A(\d+)%2F", address)
    assert grpc is not None, address
    assert_closed(address)
    assert_closed(f"http://127.0.0.1:{grpc.group(1)}/")


@pytest.mark.slow  # a session with two truth cells
def test_a_session_stopped_by_sigterm_stops_its_cells(tmp_path: Path, cli_argv: Callable[..., list[str]]) -> None:
    session = subprocess.Popen(cli_argv("session", "--backend", "truth", "--cells", "2", "--delay", "1",
                                        "--out", str(tmp_path / "run")),
                               cwd=ROOT, env=child_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        _line(session, r"experiment 1 on c\d")
        left = _stop_by_signal(session)
    finally:
        session.kill()
    assert session.returncode == EXIT_TERMINATED
    assert not left, f"still running after SIGTERM: {left}"


@pytest.mark.parametrize(("argv", "ready"), [
    (("router",), r"ready router \w+ listen tcp/127\.0\.0\.1:(\d+)\n"),
    pytest.param(("executor", "serve", "--backend", "truth", "--cell", "c5"),
                 r"ready cell c5 backend truth listen \['tcp/127\.0\.0\.1:(\d+)'\] connect \[\]\n",
                 marks=pytest.mark.slow)])  # a cell's start: about 2.5 s of CPU (its imports)
def test_a_listener_on_port_0_reports_the_port_it_bound(argv: tuple[str, ...], ready: str,
                                                        cli_argv: Callable[..., list[str]]) -> None:
    listener = subprocess.Popen(cli_argv(*argv, "--listen", "tcp/127.0.0.1:0"), cwd=ROOT, env=child_env(),
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert listener.stdout is not None
        line = listener.stdout.readline()
        match = re.fullmatch(ready, line)
        assert match and int(match.group(1)) != 0, line
        with socket.socket() as probe:  # it listens there
            assert probe.connect_ex(("127.0.0.1", int(match.group(1)))) == 0
        listener.send_signal(signal.SIGTERM)
        listener.communicate(timeout=30)
    finally:
        listener.kill()
    assert listener.returncode == 0


@pytest.mark.slow  # the Rerun web viewer's start (~2 s)
def test_view_web_killed_by_sigkill_leaves_no_web_viewer(tmp_path: Path, cli_argv: Callable[..., list[str]]) -> None:
    """SIGKILL runs no handler and no ``finally``: the Rerun server dies with its parent by
    the death signal the kernel sends it."""
    rrd = _recording(tmp_path / "c2.rrd")
    view = subprocess.Popen(cli_argv("view", str(rrd), "--web"), cwd=ROOT, env=child_env(),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        address = _line(view, r"http://127\.0\.0\.1:\d+/\S*").group(0)
        left = _stop_by_signal(view, signal.SIGKILL)
        for pid in left:  # not left to the next test
            os.kill(pid, signal.SIGKILL)
    finally:
        view.kill()
    assert view.returncode == -signal.SIGKILL
    assert not left, f"still running after SIGKILL: {left}"
    deadline = time.monotonic() + 5.0  # its sockets close as it exits, whoever reaps it
    while time.monotonic() < deadline and _accepts(address):
        time.sleep(0.1)
    assert_closed(address)
