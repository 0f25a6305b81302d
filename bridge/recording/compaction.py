"""Compacting a finished Rerun recording (``.rrd``) in place.

The SDK streams a recording to its file in many small chunks (one per ``log`` call or
batcher flush: a cell's recording holds ~180 where ~70 would do). When a writer closes
its file, :func:`compact_recording` rewrites it through Rerun's own optimiser
(``rerun rrd optimize``, shipped with ``rerun-sdk`` as the ``rerun_cli`` module), which
merges chunks of one entity and keeps every store (recording and blueprint).

The rewrite goes to a temporary file in the same folder that replaces the original only
once complete, so a failure (full disk, killed process) leaves the original whole.
"""

from __future__ import annotations

import logging
import os
import stat
import subprocess
import sys
import tempfile
from pathlib import Path

_LOG = logging.getLogger(__name__)
OPTIMIZE_TIMEOUT_S = 120.0
"""Longest a compaction may take [s] before the original file is kept."""


def compact_recording(rrd_path: Path) -> bool:
    """Rewrite ``rrd_path`` with merged chunks; True when it was replaced.

    On any failure (optimiser missing or failing, no space) the original file stays as it
    was and a warning is logged: a recording that is not compacted is still complete.
    """
    folder = rrd_path.parent
    fd, tmp_name = tempfile.mkstemp(prefix=f".{rrd_path.name}.", suffix=".tmp", dir=folder)
    os.close(fd)
    tmp = Path(tmp_name)
    try:
        done = subprocess.run(
            [sys.executable, "-m", "rerun_cli", "rrd", "optimize", str(rrd_path), "-o", str(tmp)],
            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
            timeout=OPTIMIZE_TIMEOUT_S, check=False,
        )
        if done.returncode != 0 or tmp.stat().st_size == 0:
            reason = done.stderr.decode(errors="replace").strip().splitlines()[-1:] or ["no output"]
            _LOG.warning("%s: not compacted (%s)", rrd_path, reason[0])
            return False
        with tmp.open("rb") as handle:
            os.fsync(handle.fileno())
        tmp.chmod(stat.S_IMODE(rrd_path.stat().st_mode))
        os.replace(tmp, rrd_path)
        return True
    except (OSError, subprocess.TimeoutExpired) as exc:
        _LOG.warning("%s: not compacted (%s)", rrd_path, exc)
        return False
    finally:
        tmp.unlink(missing_ok=True)
