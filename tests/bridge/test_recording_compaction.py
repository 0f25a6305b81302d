"""Compaction of finished recordings: fewer chunks, same content, original kept on failure."""

from __future__ import annotations

from pathlib import Path

import rerun as rr

from bridge.recording.compaction import compact_recording
from bridge.recording.layout import APPLICATION_ID, Contents, blueprint
from bridge.recording.reader import blueprint_origins, chunk_count, column_values, read_recording


def _many_chunk_recording(path: Path, rows: int = 60) -> None:
    """A recording flushed after every row, as a slow writer makes it."""
    rec = rr.RecordingStream(APPLICATION_ID, recording_id="compaction-test")
    rec.save(str(path))
    rec.send_blueprint(blueprint(Contents(cells=("c1",))))
    for k in range(rows):
        rec.set_time("experiment", sequence=k)
        rec.log("executor/c1/result/max_force_dev", rr.Scalars(float(k)))
        rec.log("executor/c1/outcome", rr.TextLog(f"row {k}"))
        rec.flush()
    rec.disconnect()


def test_compaction_merges_chunks_and_keeps_every_row_and_the_blueprint(tmp_path: Path) -> None:
    rrd = tmp_path / "c1.rrd"
    _many_chunk_recording(rrd)
    before = chunk_count(rrd)
    assert compact_recording(rrd)
    after = chunk_count(rrd)
    assert after < before / 4, (before, after)
    assert column_values(rrd, "executor/c1/outcome", "TextLog:text") == [[f"row {k}"] for k in range(60)]
    assert read_recording(rrd).entities["/executor/c1/result/max_force_dev"].rows == 60
    assert "executor/c1" in blueprint_origins(rrd)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c1.rrd"]


def test_a_file_that_cannot_be_compacted_stays_as_it_was(tmp_path: Path) -> None:
    rrd = tmp_path / "broken.rrd"
    rrd.write_bytes(b"not a recording at all")
    assert not compact_recording(rrd)
    assert rrd.read_bytes() == b"not a recording at all"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["broken.rrd"]
