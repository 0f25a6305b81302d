"""A session reports each finished experiment (INFO log lines) with the unknown pairs left, then
its files and the next commands."""

from __future__ import annotations

import logging
import re
import subprocess
from pathlib import Path

import pytest

from asp.session.cli import main as session_main
from tests.conftest import ROOT

LINE = re.compile(r"experiment (\d+) on (c\d): (\w+) -> (\w+) (fit|no_fit) \(.*s\); (\d+) pairs unknown")


@pytest.mark.slow
@pytest.mark.timeout(90)
def test_one_progress_line_per_experiment_down_to_no_unknown_pair_and_a_summary_whose_commands_work(
        tmp_path: Path, caplog: pytest.LogCaptureFixture, capsys: pytest.CaptureFixture[str]) -> None:
    """A session of two cells: its INFO lines, one per experiment, and its printed summary:
    the files it wrote and the next commands, which work."""
    run = tmp_path / "run"
    caplog.set_level(logging.INFO, logger="asp.session.run")
    assert session_main(["--backend", "truth", "--cells", "2", "--out", str(run)]) == 0
    lines = [LINE.fullmatch(r.getMessage()) for r in caplog.records if r.getMessage().startswith("experiment")]
    assert lines and all(lines)
    numbers = sorted(int(m.group(1)) for m in lines if m)
    assert numbers == list(range(1, len(numbers) + 1))
    unknown = [int(m.group(6)) for m in lines if m]
    assert unknown[-1] == 0 and unknown == sorted(unknown, reverse=True)
    assert {m.group(2) for m in lines if m} <= {"c1", "c2"}
    out = capsys.readouterr().out
    assert f"{len(numbers)} experiments" in out
    files = next(line for line in out.splitlines() if line.startswith("files written in"))
    assert files.split(": ")[1].split() == sorted(p.name for p in run.iterdir() if not p.name.startswith("."))
    commands = {line.split(":", 1)[0].strip(): line.split(":", 1)[1].strip()
                for line in out.split("next:\n")[1].splitlines()}
    assert commands["view the recording"] == f"{ROOT / 'run.sh'} view {run}"
    holes = subprocess.run(commands["holes p1 fits into"], shell=True, capture_output=True, text=True, timeout=60)
    assert "br r1 r2 s1 s2" in holes.stdout
    plans = subprocess.run(commands["five complete plans"], shell=True, capture_output=True, text=True, timeout=60)
    assert "Models       : 5" in plans.stdout
    header = [line for line in (run / "learned.lp").read_text().splitlines() if line.startswith("%")]
    assert "%   p1: round peg 1" in header and any(line.startswith("%   br: ") for line in header)
