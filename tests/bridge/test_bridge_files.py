"""Atomic output files (bridge.files): whole or not at all, one-line errors naming the path."""

from __future__ import annotations

import os
import stat
import sys
from pathlib import Path

import pytest

from bridge import BridgeError
from bridge.files import check_writable, make_folder, write_atomic, write_figure
from tests._files_helpers import leftovers, run_with_file_limit


def test_write_atomic_writes_text_and_bytes(tmp_path: Path) -> None:
    target = tmp_path / "out.lp"
    assert write_atomic(target, "a.\nb.\n") == target
    assert target.read_text() == "a.\nb.\n"
    write_atomic(target, b"\x00\x01")
    assert target.read_bytes() == b"\x00\x01"
    assert leftovers(tmp_path) == []


def test_a_new_file_gets_the_usual_mode_an_old_one_keeps_its_own(tmp_path: Path) -> None:
    mask = os.umask(0o022)
    os.umask(mask)
    new = write_atomic(tmp_path / "new.txt", "x")
    assert stat.S_IMODE(new.stat().st_mode) == 0o666 & ~mask
    old = tmp_path / "old.txt"
    old.write_text("old")
    old.chmod(0o600)
    write_atomic(old, "new")
    assert stat.S_IMODE(old.stat().st_mode) == 0o600 and old.read_text() == "new"


@pytest.mark.parametrize("name, reason", [
    ("missing/out.lp", "No such file or directory: no folder {tmp}/missing; create it first"),
    ("folder", "Is a directory"),
    ("file/out.lp", "Not a directory"),
])
def test_bad_output_paths_are_one_line_errors(tmp_path: Path, name: str, reason: str) -> None:
    (tmp_path / "folder").mkdir()
    (tmp_path / "file").write_text("a regular file")
    target = tmp_path / name
    with pytest.raises(BridgeError) as error:
        write_atomic(target, "x.\n")
    assert str(error.value) == f"{target}: cannot write ({reason.format(tmp=tmp_path)})"
    with pytest.raises(BridgeError) as error:
        check_writable(target)
    assert str(error.value) == f"{target}: cannot write ({reason.format(tmp=tmp_path)})"
    assert (tmp_path / "file").read_text() == "a regular file"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file", "folder"]
    assert list((tmp_path / "folder").iterdir()) == []


def test_a_full_disk_leaves_the_old_file_whole(tmp_path: Path) -> None:
    target = tmp_path / "facts.lp"
    target.write_text("old.\n")
    program = ("import sys; from bridge.files import write_atomic\n"
               "from bridge import BridgeError\n"
               "try:\n    write_atomic(sys.argv[1], 'x' * 100_000)\n"
               "except BridgeError as exc:\n    print(exc)\n")
    done = run_with_file_limit([sys.executable, "-c", program, str(target)], limit=10_000)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == f"{target}: cannot write (File too large)"
    assert target.read_text() == "old.\n"
    assert leftovers(tmp_path) == []


def test_write_figure_renders_in_memory_then_writes(tmp_path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, axis = plt.subplots()
    axis.plot([0, 1], [1, 0])
    write_figure(tmp_path / "plot.png", figure)
    missing = r"/missing/plot\.png: cannot write \(No such file or directory: no folder .*/missing; create it first\)$"
    with pytest.raises(BridgeError, match=missing):
        write_figure(tmp_path / "missing" / "plot.png", figure)
    plt.close(figure)
    assert (tmp_path / "plot.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["plot.png"]


def test_make_folder(tmp_path: Path) -> None:
    assert make_folder(tmp_path / "a" / "b").is_dir()
    make_folder(tmp_path / "a" / "b")  # exists: fine
    (tmp_path / "file").write_text("")
    with pytest.raises(BridgeError, match=r"file: cannot create the folder \(a file of that name exists\)$"):
        make_folder(tmp_path / "file")
    with pytest.raises(BridgeError, match=r"file/x: cannot create the folder \(Not a directory\)$"):
        make_folder(tmp_path / "file" / "x")


def _device(folder: Path, name: str, minor: int) -> Path:
    """A character device ``folder/name`` like ``/dev/<name>`` (major 1, ``minor``): made
    with mknod as root, else a symbolic link to it. Never the machine's own path: a broken
    writer would replace ``/dev/null`` itself."""
    path = folder / name
    if os.geteuid() == 0:
        os.mknod(path, stat.S_IFCHR | 0o666, os.makedev(1, minor))
    else:
        path.symlink_to(Path("/dev") / name)
    return path


def test_a_character_device_is_written_through_never_replaced(tmp_path: Path) -> None:
    null, full = _device(tmp_path, "null", 3), _device(tmp_path, "full", 7)
    assert write_atomic(null, "a.\n") == null
    assert stat.S_ISCHR(null.stat().st_mode)
    with pytest.raises(BridgeError) as error:
        write_atomic(full, "a.\n")
    assert str(error.value) == f"{full}: cannot write (No space left on device)"
    assert stat.S_ISCHR(full.stat().st_mode)
    assert leftovers(null.parent) == []


def test_a_fifo_is_written_through_to_its_reader_and_refused_without_one(tmp_path: Path) -> None:
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    with pytest.raises(BridgeError) as error:  # nobody reads: refused at once, never blocks
        write_atomic(fifo, "a.\n")
    assert str(error.value) == f"{fifo}: cannot write (a FIFO with no reader)"
    reader = os.open(fifo, os.O_RDONLY | os.O_NONBLOCK)
    try:
        write_atomic(fifo, "a.\nb.\n")
        assert os.read(reader, 100) == b"a.\nb.\n"
    finally:
        os.close(reader)
    assert stat.S_ISFIFO(fifo.stat().st_mode)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pipe"]


def test_a_socket_is_refused_and_kept(tmp_path: Path) -> None:
    import socket

    path = tmp_path / "sock"
    with socket.socket(socket.AF_UNIX) as server:
        server.bind(str(path))
        with pytest.raises(BridgeError) as error:
            write_atomic(path, "a.\n")
    assert str(error.value) == f"{path}: cannot write (a socket; expected a regular file, a character device or a FIFO)"
    assert stat.S_ISSOCK(path.stat().st_mode)
