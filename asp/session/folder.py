"""The run folder of a session: one session at a time, held with an OS file lock.

:func:`lock_run_folder` takes an exclusive ``fcntl.flock`` on ``RUN/.lock`` without
waiting; a second session (``--out`` or ``--resume``) on the same folder is refused at
once with a one-line PlannerError naming the process that holds it. The kernel releases
the lock when its process ends in any way (also SIGKILL), so a dead session never
blocks the next one; the ``.lock`` file itself stays (removing it could let two
sessions lock two different files).
"""

from __future__ import annotations

import contextlib
import fcntl
import os
import time
from pathlib import Path

from asp import PlannerError
from bridge.files import os_reason

LOCK_NAME = ".lock"
HOLDER_WAIT = 1.0
"""[s] how long a refused session waits for the holder's pid to show in the lock file (the
holder writes it just after it takes the lock)."""


class RunLock:
    """The held lock of a run folder; :meth:`release` it when the session ends."""

    def __init__(self, run: Path, fd: int) -> None:
        self.run = run
        self._fd = fd

    def release(self) -> None:
        """Release the lock (closing the file releases the ``flock``); idempotent."""
        if self._fd >= 0:
            os.close(self._fd)
            self._fd = -1


def lock_run_folder(run: Path) -> RunLock:
    """Lock the existing folder ``run`` for this process, or raise PlannerError at once:
    ``<run>: in use by another session (pid N); ...`` when another process holds it,
    ``<run>: cannot lock the run folder (<reason>)`` when the lock file cannot be opened."""
    path = run / LOCK_NAME
    try:
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o666)
    except OSError as exc:
        raise PlannerError(f"{run}: cannot lock the run folder ({os_reason(exc)})") from None
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError as exc:
        holder = _holder(fd)
        os.close(fd)
        if isinstance(exc, BlockingIOError):
            raise PlannerError(f"{run}: in use by another session{holder}; "
                               "wait for it to end or use another folder") from None
        raise PlannerError(f"{run}: cannot lock the run folder ({os_reason(exc)})") from None
    with contextlib.suppress(OSError):  # who holds it, for the message above
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
    return RunLock(run, fd)


def _holder(fd: int) -> str:
    """`` (pid N)`` of the session holding the lock file ``fd``: its whole line, read again
    for up to :data:`HOLDER_WAIT` while the holder has taken the lock but not yet written
    it; "" when it never shows."""
    deadline = time.monotonic() + HOLDER_WAIT
    while True:
        with contextlib.suppress(OSError, ValueError):
            if (line := os.pread(fd, 32, 0).decode()).endswith("\n"):
                return f" (pid {int(line)})"
        if time.monotonic() >= deadline:
            return ""
        time.sleep(0.005)
