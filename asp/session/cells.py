"""Cell co-processes: start ``executor serve`` nodes, follow their output, stop them.

A session (or a test) starts its cells with :func:`start_cell`, each with its settings as
one document (:class:`bridge.cell_settings.ServeSettings`). Each cell runs with
``lifeline`` set: it holds our pipe on its stdin and exits when we die, so a killed
planner leaves no cell behind. Output lines (``ready``, ``start <id> ...``,
``done <id> ...``) are collected by a reader thread; :meth:`CellProcess.wait_for_line`
waits for one with a deadline.
"""

from __future__ import annotations

import logging
import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Sequence
from pathlib import Path

import msgspec

from asp import PlannerError
from bridge.cell_settings import ServeSettings, encode_settings
from bridge.cli_types import MAX_SEED

ROOT = Path(__file__).resolve().parents[2]
"""The folder holding the packages (the repository, or site-packages when installed): the
cells get it on their PYTHONPATH and run in it."""

LOG = logging.getLogger(__name__)

STOP_S = 60.0
"""How long [s] a stopped process may take to exit (a cell compacts its recording
first) before it is killed."""


def _absolute(settings: ServeSettings) -> ServeSettings:
    """``settings`` with its files' paths absolute: the cell runs in :data:`ROOT`, not our folder."""
    paths = {name: str(Path(value).absolute()) for name in ("rrd", "ilc_state", "zenoh_config")
             if (value := getattr(settings, name)) is not None}
    return msgspec.structs.replace(settings, **paths)


class LineProcess:
    """One running co-process of the planner (a cell, a router), started from the
    repository with ``argv``, and the lines it printed; ``name`` says what it is in errors
    (``cell c1``, ``router``).

    It runs in its own process session, as a process started by hand in another
    terminal would: the kernel then schedules it beside the planner rather than inside
    the planner's share of the cores (with autogroup scheduling, two cells in the
    planner's session shared one core on a loaded machine).
    """

    def __init__(self, name: str, argv: Sequence[str]) -> None:
        self.name = name
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(
            [str(ROOT), *filter(None, [os.environ.get("PYTHONPATH")])]))
        self.popen = subprocess.Popen(argv, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                      stderr=subprocess.STDOUT, env=env, cwd=ROOT, text=True,
                                      start_new_session=True)
        self.lines: list[str] = []
        self._eof = False
        self._new = threading.Condition()
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        assert self.popen.stdout is not None
        for line in self.popen.stdout:
            with self._new:
                self.lines.append(line.rstrip("\n"))
                self._new.notify_all()
        with self._new:
            self._eof = True
            self._new.notify_all()

    def wait_for_line(self, prefix: str, timeout: float, count: int = 1) -> str:
        """Wait up to ``timeout`` [s] for the ``count``-th line starting with ``prefix``."""
        deadline = time.monotonic() + timeout
        with self._new:
            while True:
                found = [line for line in self.lines if line.startswith(prefix)]
                if len(found) >= count:
                    return found[count - 1]
                remaining = deadline - time.monotonic()
                if remaining <= 0 or self._eof:
                    tail = "\n".join(self.lines[-20:])
                    why = (f"exited (code {self.exit_code()}) before printing"
                           if self._eof else "printed no")
                    raise PlannerError(f"{self.name}: {why} line '{prefix}...' "
                                       f"(waited up to {timeout:.0f} s); last output:\n{tail}")
                self._new.wait(remaining)

    def exit_code(self, timeout: float = 2.0) -> int | None:
        """The exit code of the process, waiting up to ``timeout`` [s] for it to end
        (None if it is still running then)."""
        try:
            return self.popen.wait(timeout)
        except subprocess.TimeoutExpired:
            return None

    def last_line(self) -> str | None:
        """The last non-blank line the process printed (None if none)."""
        with self._new:
            return next((line for line in reversed(self.lines) if line.strip()), None)

    def stop(self, timeout: float = STOP_S) -> int:
        """SIGTERM, then SIGKILL after ``timeout`` [s]; returns the exit code. A cell
        compacts its recording before it exits (:mod:`bridge.recording.compaction`), which
        on a loaded machine takes tens of seconds; killed earlier, it leaves the file
        uncompacted."""
        return stop_all([self], timeout)[0]

    def kill(self) -> None:
        """SIGKILL (as a crash would)."""
        if self.popen.poll() is None:
            self.popen.kill()
        self.popen.wait(10.0)


def stop_all(processes: Sequence[LineProcess], timeout: float = STOP_S) -> list[int]:
    """:meth:`LineProcess.stop` for several processes at once: SIGTERM to every one
    still running, then each waited for until ``timeout`` [s] after the signals (SIGKILL
    then); their exit codes. They compact their recordings side by side instead of one
    after the other."""
    running = [p for p in processes if p.popen.poll() is None]
    for process in running:
        process.popen.send_signal(signal.SIGTERM)
    deadline = time.monotonic() + timeout
    codes = []
    for process in processes:
        try:
            codes.append(process.popen.wait(max(0.0, deadline - time.monotonic())))
        except subprocess.TimeoutExpired:
            LOG.warning("%s did not exit within %.0f s of SIGTERM; killed (its recording stays uncompacted)",
                        process.name, timeout)
            process.popen.kill()
            codes.append(process.popen.wait(timeout))
    return codes


class CellProcess(LineProcess):
    """One running ``executor serve`` process, started with ``settings`` as its one
    document (``--settings JSON``, with ``lifeline`` set: it ends with the planner, when
    its stdin closes), run under ``prefix`` if given (e.g. ``ip netns exec NS``)."""

    @staticmethod
    def command(settings: ServeSettings) -> list[str]:
        """The command line of the cell: ``executor serve --settings JSON``, the settings
        with ``lifeline`` set and their files' paths absolute."""
        started = _absolute(msgspec.structs.replace(settings, lifeline=True))
        return [sys.executable, "-m", "assembly_constraints", "executor", "serve", "--settings",
                encode_settings(started)]

    def __init__(self, settings: ServeSettings, prefix: Sequence[str] = ()) -> None:
        super().__init__(f"cell {settings.cell_id}", [*prefix, *self.command(settings)])
        self.cell_id = settings.cell_id


def cell_seed(first: int, number: int) -> int:
    """The cell seed (systematic errors) of the session's cell ``c<number>`` (1, 2, ...):
    the session's first cell seed plus ``number`` − 1 (modulo 2**32), so each cell of a session is
    another cell, and the same cell again when the session is resumed."""
    return (first + number - 1) % (MAX_SEED + 1)


def start_cell(settings: ServeSettings, *, ready_timeout: float = 60.0) -> CellProcess:
    """Start a cell and wait until it prints ``ready``."""
    cell = CellProcess(settings)
    try:
        cell.wait_for_line("ready", ready_timeout)
    except PlannerError:
        cell.kill()
        raise
    return cell
