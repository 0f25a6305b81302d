"""The cell's output files: a bad ``--rrd`` or ``--plot`` path is one line and exit 2
before any work; generated assets and demonstrations are written atomically."""

from __future__ import annotations

import dataclasses
import subprocess
from pathlib import Path

import pytest

from bridge import BridgeError
from executor.world.geometry import load_geometry, write_assets
from tests._files_helpers import leftovers
from tests._tolerances import assert_same_asset

BAD_RRD = {"missing folder": ("missing/x.rrd",
                              "No such file or directory: no folder {places}/missing; create it first"),
           "a directory": ("folder", "Is a directory"),
           "under a regular file": ("file/x.rrd", "Not a directory")}


@pytest.fixture
def places(tmp_path: Path) -> Path:
    (tmp_path / "folder").mkdir()
    (tmp_path / "file").write_text("a regular file\n")
    return tmp_path


RRD_COMMANDS = {"trial": ("trial", "--part", "p1", "--hole", "r1"),
                "serve": ("serve", "--backend", "truth", "--listen", "tcp/127.0.0.1:0")}


def _refused_rrd(places: Path, done: subprocess.CompletedProcess[str], bad: str) -> None:
    """``done`` (a command given ``--rrd places/BAD_RRD[bad]``) exited 2 with one line naming
    the file and why, started nothing and wrote nothing."""
    name, reason = BAD_RRD[bad]
    assert done.returncode == 2, done.stderr
    assert done.stderr.splitlines()[-1] == f"error: {places / name}: cannot write ({reason.format(places=places)})"
    assert "Traceback" not in done.stderr
    assert "ready" not in done.stdout
    assert sorted(p.name for p in places.iterdir()) == ["file", "folder"]


@pytest.mark.parametrize("bad", BAD_RRD)
@pytest.mark.parametrize("command", RRD_COMMANDS)
def test_unwritable_rrd_is_one_line_exit_2(places: Path, run_main, command: str, bad: str) -> None:
    done = run_main("executor", *RRD_COMMANDS[command], "--rrd", str(places / BAD_RRD[bad][0]))
    _refused_rrd(places, done, bad)


@pytest.mark.slow  # a child process: Python and the cell's imports (2-3 s of CPU)
def test_unwritable_rrd_stops_the_serving_process_before_it_is_ready(places: Path, run_executor) -> None:
    """The process boundary of the check above: exit code 2, one line after PyBullet's
    banner, no traceback, the cell never announced."""
    done = run_executor(*RRD_COMMANDS["serve"], "--rrd", str(places / BAD_RRD["under a regular file"][0]), timeout=60)
    _refused_rrd(places, done, "under a regular file")


@pytest.mark.parametrize("name, reason", [("file", "a file of that name exists"),
                                          ("file/plots", "Not a directory")])
def test_campaign_plot_folder_is_checked_before_the_campaign(places: Path, run_main, name: str,
                                                            reason: str) -> None:
    folder = places / name
    done = run_main("executor", "campaign", "--trials", "1", "--pairs", "p1:r1", "--jobs", "1", "--plot", str(folder))
    assert done.returncode == 2, done.stderr
    assert done.stderr.splitlines()[-1] == f"error: {folder}: cannot create the folder ({reason})"
    assert "Traceback" not in done.stderr
    assert sorted(p.name for p in places.iterdir()) == ["file", "folder"]


@pytest.mark.slow  # a child process: Python and the cell's imports (2-3 s of CPU)
def test_a_campaign_process_with_a_bad_plot_folder_exits_2_before_any_trial(places: Path, run_executor) -> None:
    folder = places / "file" / "plots"
    done = run_executor("campaign", "--trials", "1", "--pairs", "p1:r1", "--jobs", "1", "--plot", str(folder),
                        timeout=60)
    assert done.returncode == 2, done.stderr
    assert done.stderr.splitlines()[-1] == f"error: {folder}: cannot create the folder (Not a directory)"
    assert "Traceback" not in done.stderr


def test_assets_are_regenerated_whole_and_the_same(tmp_path: Path) -> None:
    committed = load_geometry("cranfield")
    geometry = dataclasses.replace(committed, folder=tmp_path)
    written = write_assets(geometry)
    for path in written:
        assert_same_asset(path.read_text(), (committed.assets / path.name).read_text())
    assert leftovers(geometry.assets) == []
    (tmp_path / "blocked").write_text("")
    with pytest.raises(BridgeError, match=r"blocked/assets: cannot create the folder \(Not a directory\)$"):
        write_assets(dataclasses.replace(committed, folder=tmp_path / "blocked"))
