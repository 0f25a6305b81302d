"""A recording with a torn tail (its writer died mid-message: a full disk, a kill) is read
up to its last whole message, with a warning naming the file, by ``view RUN --print`` and
by :mod:`bridge.recording.reader`."""

from __future__ import annotations

import struct
from pathlib import Path

import pytest

from bridge import BridgeError
from bridge.recording.reader import column_values, read_recording


@pytest.fixture(scope="module")
def recording(tmp_path_factory: pytest.TempPathFactory, run_executor) -> bytes:
    """The bytes of a real recording: one trial of the simulated cell."""
    rrd = tmp_path_factory.mktemp("trial") / "c1.rrd"
    done = run_executor("trial", "--part", "p1", "--hole", "r1", "--rrd", str(rrd), timeout=120)
    assert done.returncode == 0, done.stderr
    return rrd.read_bytes()


def _last_message(data: bytes) -> tuple[int, int]:
    """Offset and payload length of the last message before the end marker (kind 0),
    read from the framing: a 12-byte stream header, then (kind u64, length u64, payload)."""
    offset, last = 12, (0, 0)
    while offset + 16 <= len(data):
        kind, length = struct.unpack_from("<QQ", data, offset)
        if kind == 0:
            return last
        last = (offset, length)
        offset += 16 + length
    return last


@pytest.fixture
def torn(tmp_path: Path, recording: bytes) -> Path:
    """The real recording cut in the middle of its last message's payload."""
    offset, length = _last_message(recording)
    assert length > 16
    rrd = tmp_path / "c1.rrd"
    rrd.write_bytes(recording[: offset + 16 + length // 2])
    return rrd


@pytest.mark.slow
def test_the_reader_reads_a_torn_recording_up_to_its_last_whole_message(torn: Path, caplog) -> None:
    with caplog.at_level("WARNING"):
        summary = read_recording(torn)
    assert len(summary.recording_ids) == 1
    assert {"/executor/c1/outcome", "/executor/c1/wrench/force/measured"} <= set(summary.entities)
    assert len(column_values(torn, "executor/c1/wrench/force/measured", "sim_time")) > 100
    warnings = [r.getMessage() for r in caplog.records if r.levelname == "WARNING"]
    assert warnings and all(f"{torn}: torn tail" in w for w in warnings), warnings
    assert sorted(p.name for p in torn.parent.iterdir()) == ["c1.rrd"]  # no copy left behind


@pytest.mark.slow
def test_view_prints_a_torn_run_with_a_warning(torn: Path, run_main) -> None:
    done = run_main("view", str(torn.parent), "--print")
    assert done.returncode == 0, done.stderr
    assert "/executor/c1/wrench/force/measured" in done.stdout
    lines = [line for line in done.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith(f"warning: {torn}: torn tail"), done.stderr


@pytest.mark.slow
def test_a_file_torn_inside_its_stream_header_is_still_refused(tmp_path: Path, recording: bytes) -> None:
    rrd = tmp_path / "c1.rrd"
    rrd.write_bytes(recording[:6])
    with pytest.raises(BridgeError, match="c1.rrd: not a"):
        read_recording(rrd)


@pytest.mark.slow
def test_a_file_torn_inside_its_end_message_keeps_every_entity(tmp_path: Path, recording: bytes, caplog) -> None:
    offset, length = _last_message(recording)
    end = offset + 16 + length  # the end message (its footer data) starts here
    rrd = tmp_path / "c1.rrd"
    rrd.write_bytes(recording[: end + 100])
    whole = tmp_path / "whole.rrd"
    whole.write_bytes(recording)
    with caplog.at_level("WARNING"):
        assert set(read_recording(rrd).entities) == set(read_recording(whole).entities)
    assert any(f"{rrd}: torn tail" in r.getMessage() for r in caplog.records)
