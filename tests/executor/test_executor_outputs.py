"""The cell's output files: a bad ``--rrd`` or ``--plot`` path is one line and exit 2
before any work; generated assets and demonstrations are written atomically."""

from __future__ import annotations

import dataclasses
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


@pytest.mark.parametrize("bad", BAD_RRD)
@pytest.mark.parametrize("command", [
    ("trial", "--part", "p1", "--hole", "r1"),
    ("serve", "--backend", "truth", "--listen", "tcp/127.0.0.1:0"),
])
@pytest.mark.slow
def test_unwritable_rrd_is_one_line_exit_2(places: Path, run_executor, command: tuple[str, ...],
                                           bad: str) -> None:
    name, reason = BAD_RRD[bad]
    rrd = places / name
    done = run_executor(*command, "--rrd", str(rrd), timeout=30)
    assert done.returncode == 2, done.stderr
    expected = f"error: {rrd}: cannot write ({reason.format(places=places)})"
    assert done.stderr.splitlines()[-1] == expected  # after PyBullet's banner
    assert "Traceback" not in done.stderr
    assert "ready" not in done.stdout
    assert sorted(p.name for p in places.iterdir()) == ["file", "folder"]


@pytest.mark.slow
@pytest.mark.parametrize("name, reason", [("file", "a file of that name exists"),
                                          ("file/plots", "Not a directory")])
def test_campaign_plot_folder_is_checked_before_the_campaign(places: Path, run_executor, name: str,
                                                            reason: str) -> None:
    folder = places / name
    done = run_executor("campaign", "--trials", "1", "--pairs", "p1:r1", "--jobs", "1", "--plot", str(folder),
                        timeout=30)
    assert done.returncode == 2, done.stderr
    assert done.stderr.splitlines()[-1] == f"error: {folder}: cannot create the folder ({reason})"
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
