"""The viewer-control request ``view --screenshot --at`` hands the web viewer is the one
Rerun's own ``ViewerClient.set_time`` sends: captured from the SDK over a loopback socket
(a minimal HTTP/2 peer that reads the gRPC request and answers nothing)."""

from __future__ import annotations

import socket
import threading
from collections.abc import Callable

import pytest
from rerun.experimental import ViewerClient

from asp.view.screenshot import set_time_request
from bridge.recording.layout import TimePoint

_PREFACE = b"PRI * HTTP/2.0\r\n\r\nSM\r\n\r\n"
_DATA, _END_STREAM = 0, 0x1


def _request_body(connection: socket.socket) -> bytes:
    """The gRPC message of the first request on ``connection``: the DATA frames' payloads
    up to END_STREAM, without the 5-byte gRPC prefix (compression flag, length)."""
    connection.sendall(b"\x00\x00\x00\x04\x00\x00\x00\x00\x00")  # the server's (empty) SETTINGS
    buffer, body = b"", b""
    while True:
        chunk = connection.recv(65536)
        if not chunk:
            raise AssertionError("the SDK closed the connection before its request ended")
        buffer += chunk
        buffer = buffer.removeprefix(_PREFACE)
        while len(buffer) >= 9 and len(buffer) >= 9 + int.from_bytes(buffer[:3], "big"):
            length, kind, flags = int.from_bytes(buffer[:3], "big"), buffer[3], buffer[4]
            payload, buffer = buffer[9:9 + length], buffer[9 + length:]
            if kind == _DATA:
                body += payload
                if flags & _END_STREAM:
                    assert int.from_bytes(body[1:5], "big") == len(body) - 5
                    return body[5:]


def _sent_by_the_sdk(point: TimePoint) -> bytes:
    listener = socket.create_server(("127.0.0.1", 0))
    port = listener.getsockname()[1]
    client = ViewerClient(f"rerun+http://127.0.0.1:{port}/proxy")
    arguments = {{"sequence": "sequence", "duration": "duration", "timestamp": "timestamp"}[point.kind]:
                 int(point.value) if point.kind == "sequence" else point.value}
    caller = threading.Thread(target=_ignore_errors, args=(client.set_time, point.timeline), kwargs=dict(
        play_state="paused", **arguments), daemon=True)
    caller.start()
    listener.settimeout(15)
    connection, _ = listener.accept()
    with connection, listener:
        connection.settimeout(15)
        return _request_body(connection)


def _ignore_errors(call: Callable[..., object], *args: object, **kwargs: object) -> None:
    try:
        call(*args, **kwargs)
    except ConnectionError:
        pass  # the peer never answers


@pytest.mark.parametrize("point", [TimePoint("experiment", 1), TimePoint("experiment", 300),
                                   TimePoint("sim_time", 2.5), TimePoint("log_time", 1764633600.25)])
def test_the_request_is_the_one_the_sdk_sends(point: TimePoint) -> None:
    assert set_time_request(point) == _sent_by_the_sdk(point)
