"""Progress bars appear only on a terminal with INFO logging, never change the items."""

from __future__ import annotations

import fcntl
import io
import json
import logging
import os
import pty
import struct
import subprocess
import termios
from pathlib import Path

import pytest

from bridge.progress import progress


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


@pytest.mark.parametrize(("tty", "level", "drawn"), [
    (True, logging.INFO, True), (True, logging.WARNING, False), (False, logging.INFO, False),
])
def test_a_bar_only_on_a_terminal_that_wants_info(tty: bool, level: int, drawn: bool,
                                                  monkeypatch: pytest.MonkeyPatch,
                                                  caplog: pytest.LogCaptureFixture) -> None:
    stream = Terminal() if tty else io.StringIO()
    monkeypatch.setattr("sys.stderr", stream)
    caplog.set_level(level)
    assert list(progress(iter(range(5)), desc="trials", total=5)) == [0, 1, 2, 3, 4]
    assert ("trials: 100%" in stream.getvalue()) is drawn
    assert drawn or stream.getvalue() == ""


def run_with_terminal_stderr(argv: list[str], cwd: Path, env: dict[str, str]) -> tuple[str, str]:
    """Run ``argv`` with stdout a pipe and stderr a pseudo-terminal; (stdout, stderr) as text."""
    leader, follower = pty.openpty()
    # a terminal 120 columns wide (a new pseudo-terminal has none: a bar of no width)
    fcntl.ioctl(follower, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 120, 0, 0))
    with subprocess.Popen(argv, cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=follower, text=True) as process:
        os.close(follower)
        chunks = []
        while True:
            try:
                chunk = os.read(leader, 4096)
            except OSError:  # the terminal closed with the process
                break
            if not chunk:
                break
            chunks.append(chunk)
        out = process.stdout.read() if process.stdout else ""
        process.wait(120)
    os.close(leader)
    return out, b"".join(chunks).decode(errors="replace")


@pytest.mark.slow  # a truth-cell assembly of two plans
@pytest.mark.timeout(180)
def test_bench_assemble_draws_a_bar_on_a_terminal_stderr_only_and_never_in_its_json(
        root: Path, cli_argv, cli_env: dict[str, str]) -> None:
    """The command as a process, its stderr a terminal; with stderr not a terminal it draws
    none (the same command in ``tests/test_jobs.py``, in the test's process)."""
    out, err = run_with_terminal_stderr(cli_argv("bench", "assemble", "--backend", "truth", "--plans", "2",
                                                 "--jobs", "2", "--json"), root, cli_env)
    assert out, err
    report = json.loads(out)
    assert len(report["plans"]) == 2
    assert "plans: 100%" in err
    assert "100%" not in out
