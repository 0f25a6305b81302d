"""Cell co-processes: start ``executor serve`` nodes, follow their output, stop them.

A session (or a test) starts its cells with :func:`start_cell`. Each cell runs with
``--lifeline``: it holds our pipe on its stdin and exits when we die, so a killed
planner leaves no cell behind. Output lines (``ready``, ``start <id> ...``,
``done <id> ...``) are collected by a reader thread; :meth:`CellProcess.wait_for_line`
waits for one with a deadline.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Sequence
from pathlib import Path

from asp import PlannerError
from bridge.cli_types import MAX_SEED

ROOT = Path(__file__).resolve().parents[2]
"""The folder holding the packages (the repository, or site-packages when installed): the
cells get it on their PYTHONPATH and run in it."""


class CellProcess:
    """One running ``executor serve`` process and the lines it printed.

    A cell runs in its own process session, as a cell started by hand in another
    terminal would: the kernel then schedules it beside the planner rather than inside
    the planner's share of the cores (with autogroup scheduling, two cells in the
    planner's session shared one core on a loaded machine). It still ends with the
    planner: ``--lifeline`` makes it exit when its stdin closes.
    """

    def __init__(self, cell_id: str, argv: Sequence[str]) -> None:
        self.cell_id = cell_id
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(
            [str(ROOT), *filter(None, [os.environ.get("PYTHONPATH")])]))
        self.popen = subprocess.Popen(list(argv), stdin=subprocess.PIPE, stdout=subprocess.PIPE,
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
                    raise PlannerError(f"cell {self.cell_id}: {why} line '{prefix}...' "
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

    def stop(self, timeout: float = 60.0) -> int:
        """SIGTERM, then SIGKILL after ``timeout`` [s]; returns the exit code. A cell
        compacts its recording before it exits (:mod:`bridge.recording.compaction`), which
        on a loaded machine takes tens of seconds; killed earlier, it leaves the file
        uncompacted."""
        if self.popen.poll() is None:
            self.popen.send_signal(signal.SIGTERM)
            try:
                return self.popen.wait(timeout)
            except subprocess.TimeoutExpired:
                self.popen.kill()
        return self.popen.wait(timeout)

    def kill(self) -> None:
        """SIGKILL (as a crash would)."""
        if self.popen.poll() is None:
            self.popen.kill()
        self.popen.wait(10.0)


def serve_argv(cell_id: str, *, backend: str, assembly: str = "cranfield",
               listen: Sequence[str] = (), connect: Sequence[str] = (), delay_s: float = 0.0,
               rrd: Path | None = None, recording_id: str | None = None,
               zenoh_config: Path | None = None, viewer_url: str | None = None,
               ilc_state: Path | None = None, block_holes: Sequence[str] = (),
               cell_options: Sequence[str] = (), cell_seed: int | None = None) -> list[str]:
    """The command line of one ``executor serve`` node, with ``--lifeline``; ``viewer_url``:
    a Rerun viewer or server the cell also streams its recording to; ``ilc_state``: the
    file the sim cell keeps its learned ILC corrections in (in the run folder, so a
    resumed session's cell starts from them); ``block_holes``: holes with an obstacle;
    ``cell_options``: the sim cell's execution layer and uncertainty
    (:func:`bridge.cell_options.cell_argv`), ``cell_seed``: the seed of its systematic errors."""
    argv = [sys.executable, "-m", "assembly_constraints", "executor", "serve", "--cell", cell_id,
            "--backend", backend, "--assembly", assembly, "--lifeline"]
    argv += [arg for ep in listen for arg in ("--listen", ep)]
    argv += [arg for ep in connect for arg in ("--connect", ep)]
    if delay_s:
        argv += ["--delay", str(delay_s)]
    if rrd is not None:
        argv += ["--rrd", str(Path(rrd).absolute())]  # the cell runs in the repository, not our cwd
    if recording_id is not None:
        argv += ["--recording-id", recording_id]
    if zenoh_config is not None:
        argv += ["--zenoh-config", str(Path(zenoh_config).absolute())]
    if viewer_url is not None:
        argv += ["--rerun-connect", viewer_url]
    if ilc_state is not None and backend == "sim":
        argv += ["--ilc-state", str(Path(ilc_state).absolute())]
    argv += [arg for hole in block_holes for arg in ("--block-hole", hole)]
    if backend == "sim":
        argv += list(cell_options)
        if cell_seed is not None:
            argv += ["--cell-seed", str(cell_seed)]
    return argv


def cell_seed(session_seed: int, number: int) -> int:
    """The cell seed (systematic errors) of the session's cell ``c<number>`` (1, 2, ...):
    the session seed plus ``number`` − 1 (modulo 2**32), so each cell of a session is
    another cell, and the same cell again when the session is resumed."""
    return (session_seed + number - 1) % (MAX_SEED + 1)


def start_cell(cell_id: str, *, ready_timeout: float = 60.0, **options) -> CellProcess:
    """Start a cell (options of :func:`serve_argv`) and wait until it prints ``ready``."""
    cell = CellProcess(cell_id, serve_argv(cell_id, **options))
    try:
        cell.wait_for_line("ready", ready_timeout)
    except PlannerError:
        cell.kill()
        raise
    return cell
