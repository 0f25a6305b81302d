"""One real simulated insertion served over Zenoh by ``executor serve --backend sim``."""

from __future__ import annotations

from pathlib import Path

import pytest

from asp.session.cells import start_cell
from bridge.cell_settings import ServeSettings
from bridge.client import CellDirectory, request_insert
from bridge.messages import InsertRequest
from bridge.session import free_loopback_endpoint, open_session


@pytest.mark.timeout(90)
@pytest.mark.slow
def test_sim_cell_inserts_a_fitting_peg_and_logs_it(tmp_path: Path) -> None:
    from bridge.recording.reader import column_values, read_recording

    endpoint = free_loopback_endpoint()
    rrd = tmp_path / "c1.rrd"
    cell = start_cell(ServeSettings(cell_id="c1", backend="sim", listen=(endpoint,), rrd=str(rrd),
                                    recording_id="sim-test"))
    session = open_session(connect=(endpoint,))
    try:
        CellDirectory(session).wait_for(1, timeout=30)
        request = InsertRequest(id="s1", part="p1", hole="br", seed=3, experiment=7)
        reply = request_insert(session, "c1", request, timeout=60)
        assert reply.result == "fit"
        assert reply.evidence is not None and reply.evidence.attempts >= 1
        assert reply.evidence.end_error < 0.01 and reply.evidence.duration_s > 0
    finally:
        session.close()
        assert cell.stop(timeout=30) == 0  # it flushes its recording; slow on a loaded machine
    summary = read_recording([rrd])
    assert set(summary.recording_ids) == {"sim-test"}
    assert any(path.startswith("/executor/c1/wrench") for path in summary.entities)
    assert set(column_values([rrd], "/executor/c1/outcome", "experiment")) == {7}
