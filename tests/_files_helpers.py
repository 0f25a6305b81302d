"""Helpers of the output-file tests: a child process whose disk is "full".

``run_with_file_limit(argv, limit)`` runs ``argv`` with ``RLIMIT_FSIZE`` = ``limit``
bytes and ``SIGXFSZ`` ignored, so a write that would grow any file beyond ``limit``
fails with ``EFBIG`` (``File too large``), as a full disk fails with ``ENOSPC``.
"""

from __future__ import annotations

import resource
import signal
import subprocess
from pathlib import Path

from tests.conftest import ROOT, child_env


def _limit_file_size(limit: int) -> None:
    resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)


def run_with_file_limit(argv: list[str], limit: int, cwd: Path | str | None = None,
                        timeout: float = 60.0) -> subprocess.CompletedProcess[str]:
    """``argv`` as a child process that cannot write files beyond ``limit`` bytes."""
    return subprocess.run(argv, cwd=ROOT if cwd is None else cwd, env=child_env(), capture_output=True,
                          text=True, timeout=timeout, preexec_fn=lambda: _limit_file_size(limit))


def leftovers(folder: Path) -> list[str]:
    """Names of temporary files left in ``folder`` (``.<name>.<random>.tmp``)."""
    return sorted(p.name for p in folder.iterdir() if p.name.endswith(".tmp"))
