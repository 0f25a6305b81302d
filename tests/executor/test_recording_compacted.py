"""The cell's Rerun logger compacts the file it wrote when it closes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from bridge.recording.reader import chunk_count, column_values
from executor.evidence import AttemptEvidence
from executor.rerun_log import AttemptLogger


def _log_attempts(rrd: Path) -> None:
    """Thirty short attempts, each flushed (as a cell serving a session does)."""
    logger = AttemptLogger.to_file(rrd, "c1")
    for attempt in range(1, 31):
        logger.begin_attempt("p1", "r1", 7, attempt)
        for k in range(5):
            z = np.array([0.0, 0.0, 0.1 - 0.001 * k])
            logger.log_step(0.01 * k, 0.2 * k, z, z, z, z, z)
        logger.end_attempt(AttemptEvidence(
            outcome="fit", max_force_dev=1.0, max_torque_dev=0.1, end_error=0.0, duration_s=0.1,
            sim_time_s=0.05, jammed=False, wiggles=0, phase_reached=1.0,
        ))
        logger.rec.flush()
    logger.close()


@pytest.mark.slow
def test_the_cell_logger_compacts_its_file_when_it_closes(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    compacted = tmp_path / "compacted.rrd"
    _log_attempts(compacted)
    monkeypatch.setattr("executor.rerun_log.compact_recording", lambda path: False)
    raw = tmp_path / "raw.rrd"
    _log_attempts(raw)
    assert len(column_values(compacted, "executor/c1/outcome", "TextLog:text")) == 30
    assert chunk_count(compacted) < 0.6 * chunk_count(raw), (chunk_count(compacted), chunk_count(raw))
