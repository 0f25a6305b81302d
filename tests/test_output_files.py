"""Output files of the planner's command lines: written whole or not at all.

A bad output path (missing folder, a directory, under a regular file) is one line
``error: <path>: cannot write (<reason>)`` and exit code 2; a full disk (a child process
limited by ``RLIMIT_FSIZE``) leaves the previous file whole and no temporary file behind.
The commands run in this process (``run_main``) but where the limit or stdout of a process
is what is tested.
"""

from __future__ import annotations

import shutil
import stat
import subprocess
import sys
from pathlib import Path

import pytest

from tests._files_helpers import leftovers, run_with_file_limit
from tests.conftest import CLI_MODULE, ROOT, child_env

CRANFIELD = ROOT / "data" / "cranfield"
PLAN = ("plan", str(CRANFIELD / "precedence.lp"), str(CRANFIELD / "sizes.lp"), "--assembly", "cranfield")
COMMANDS = {  # command line writing one file to OUT
    "plan --travel-out": (*PLAN, "--travel-out", "OUT"),
    "precedence learn --out": ("precedence", "learn", "--assembly", "cranfield", "--out", "OUT"),
    "precedence learn --dot": ("precedence", "learn", "--assembly", "cranfield", "--dot", "OUT"),
    "precedence learn --png": ("precedence", "learn", "--assembly", "cranfield", "--png", "OUT"),
    "sizes learn --out": ("sizes", "learn", "--assembly", "cranfield", "--out", "OUT"),
    "precedence evaluate --plot": ("precedence", "evaluate", "--assembly", "cranfield", "--demonstrations", "5",
                                   "--trials", "2", "--plot", "OUT"),
    "sizes evaluate --plot": ("sizes", "evaluate", "--assembly", "cranfield", "--policy", "best",
                              "--relabelings", "2", "--plot", "OUT"),
}
BAD_PATHS = {"missing folder": ("missing/out.png",  # .png: --png asks for it
                                "No such file or directory: no folder {tmp}/missing; create it first"),
             "a directory": ("folder.png", "Is a directory"),
             "under a regular file": ("file/out.png", "Not a directory")}


def _argv(command: str, out: Path) -> list[str]:
    return [str(out) if arg == "OUT" else arg for arg in COMMANDS[command]]


@pytest.mark.parametrize("bad", BAD_PATHS)
@pytest.mark.parametrize("command", COMMANDS)
def test_bad_output_path_is_one_line_exit_2(tmp_path: Path, run_main, command: str, bad: str) -> None:
    (tmp_path / "folder.png").mkdir()
    (tmp_path / "file").write_text("a regular file\n")
    name, reason = BAD_PATHS[bad]
    out = tmp_path / name
    done = run_main(*_argv(command, out))
    assert done.returncode == 2, done.stderr
    assert done.stderr == f"error: {out}: cannot write ({reason.format(tmp=tmp_path)})\n"
    assert (tmp_path / "file").read_text() == "a regular file\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file", "folder.png"]
    assert list((tmp_path / "folder.png").iterdir()) == []


@pytest.mark.parametrize("command", ["plan --travel-out", "precedence learn --out"])
def test_full_disk_leaves_the_old_file_whole(tmp_path: Path, run_main, command: str) -> None:
    out = tmp_path / "facts.lp"
    first = run_main(*_argv(command, out))
    assert first.returncode == 0, first.stderr
    good = out.read_bytes()
    assert len(good) > 600
    done = run_with_file_limit([sys.executable, "-m", CLI_MODULE, *_argv(command, out)], limit=500)
    assert done.returncode == 2, done.stderr
    assert done.stderr.endswith(f"error: {out}: cannot write (File too large)\n")
    assert "Traceback" not in done.stderr
    assert out.read_bytes() == good
    assert leftovers(tmp_path) == [] and [p.name for p in tmp_path.iterdir()] == ["facts.lp"]


@pytest.mark.parametrize("command", ["plan --travel-out", "precedence learn --out"])
def test_a_device_is_written_through_never_replaced(tmp_path: Path, run_main, command: str) -> None:
    """``--out /dev/null`` discards the output (exit 0), ``/dev/full`` is a full disk (exit
    2); both stay devices. Links to them, so that a writer that replaced the path would
    replace the link, never the machine's ``/dev/null``."""
    null, full = tmp_path / "null", tmp_path / "full"
    null.symlink_to("/dev/null")
    full.symlink_to("/dev/full")
    done = run_main(*_argv(command, null))
    assert done.returncode == 0, done.stderr
    done = run_main(*_argv(command, full))
    assert done.returncode == 2, done.stderr
    assert done.stderr.splitlines() == [f"error: {full}: cannot write (No space left on device)"]
    assert null.resolve() == Path("/dev/null") and full.resolve() == Path("/dev/full")
    assert stat.S_ISCHR(null.stat().st_mode) and stat.S_ISCHR(full.stat().st_mode)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["full", "null"]


@pytest.mark.parametrize("argv", [("precedence", "count", "--assembly", "cranfield"),
                                  ("precedence", "enumerate", "--assembly", "cranfield"),
                                  pytest.param(("executor", "trial", "--part", "p1", "--hole", "r1"),
                                               marks=pytest.mark.slow)])
def test_stdout_on_a_full_disk_is_one_line_exit_2(argv: tuple[str, ...]) -> None:
    with open("/dev/full", "w") as full:
        done = subprocess.run([sys.executable, "-m", "assembly_constraints", *argv], cwd=ROOT, env=child_env(),
                              stdout=full, stderr=subprocess.PIPE, text=True, timeout=120)
    lines = [line for line in done.stderr.splitlines() if not line.startswith("pybullet build time")]
    assert done.returncode == 2, done.stderr
    assert lines == ["error: stdout: cannot write (No space left on device)"], done.stderr


def _rerun_lines(stderr: str) -> list[str]:
    """Lines of the Rerun SDK's native logger (``... ERROR re_log_encoding::...: ... (os error 28)``)."""
    return [line for line in stderr.splitlines() if "re_log_encoding" in line or "os error" in line
            or "re_sdk" in line]


@pytest.mark.slow
def test_a_recording_that_outgrows_the_file_size_limit_is_one_line_exit_2(tmp_path: Path) -> None:
    """A session whose planner.rrd outgrows the limit on file sizes (60 kB): the facts are
    written, then ``error: RUN/planner.rrd: cannot write (File too large: ...)`` is the last
    line, without the Rerun SDK's own report of the failed write; exit 2, no traceback."""
    run = tmp_path / "run"
    done = run_with_file_limit([sys.executable, "-m", CLI_MODULE, "session", "--backend", "truth", "--out", str(run)],
                               limit=60_000, timeout=120)
    assert done.returncode == 2, done.stderr
    assert done.stderr.splitlines()[-1].startswith(
        f"error: {run / 'planner.rrd'}: cannot write (File too large: files are limited to 60000 bytes"), done.stderr
    assert "Traceback" not in done.stderr and not _rerun_lines(done.stderr), done.stderr
    assert (run / "learned.lp").is_file()


def _private_tmpfs_works() -> bool:
    """Whether this process may mount a tmpfs in a mount namespace of its own (root, or
    CAP_SYS_ADMIN, and ``unshare`` from util-linux)."""
    if shutil.which("unshare") is None:
        return False
    probe = subprocess.run(["unshare", "--mount", "--propagation", "private", "sh", "-c",
                            "mount -t tmpfs -o size=64k tmpfs /mnt"], capture_output=True, timeout=30, check=False)
    return probe.returncode == 0


@pytest.mark.slow
@pytest.mark.skipif(not _private_tmpfs_works(), reason="cannot mount a tmpfs in a private mount namespace "
                    "(needs root or CAP_SYS_ADMIN and util-linux's unshare)")
def test_a_recording_on_a_full_filesystem_is_one_line_exit_2(tmp_path: Path) -> None:
    """A session on a real filesystem that fills up (a 64 KiB tmpfs, mounted in a mount
    namespace of the child's own, gone with it; smaller than the planner's blueprint alone,
    about 200 kB, so the planner's own first writes fail whichever process writes first):
    its last line is ``error:
    RUN/planner.rrd: cannot write (No space left on device; ...)``, and no line of the
    Rerun SDK's native logger ("os error 28") shows; exit 2, no traceback."""
    disk = tmp_path / "disk"
    disk.mkdir()
    run = disk / "run"
    mount = 'mount -t tmpfs -o size=64k tmpfs "$0" && exec "$@"'
    done = subprocess.run(["unshare", "--mount", "--propagation", "private", "sh", "-c", mount, str(disk),
                           sys.executable, "-m", CLI_MODULE, "session", "--backend", "truth", "--out", str(run)],
                          cwd=ROOT, env=child_env(), capture_output=True, text=True, timeout=120, check=False)
    assert done.returncode == 2, done.stderr
    assert done.stderr.splitlines()[-1].startswith(
        f"error: {run / 'planner.rrd'}: cannot write (No space left on device; "), done.stderr
    assert "Traceback" not in done.stderr and not _rerun_lines(done.stderr), done.stderr
    assert list(disk.iterdir()) == []  # the session wrote into the tmpfs, not into the folder below it
