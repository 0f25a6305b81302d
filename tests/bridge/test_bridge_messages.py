"""Messages of the bridge: round trip, validation, size cap, version (no network)."""

from __future__ import annotations

import msgspec
import pytest

from bridge import BridgeError
from bridge.keys import alive_key, cell_of_alive_key, insert_key
from bridge.messages import (
    MAX_MESSAGE_BYTES,
    ErrorReply,
    Evidence,
    InsertReply,
    InsertRequest,
    MessageError,
    decode_reply,
    decode_request,
    encode,
)


def test_request_and_replies_round_trip() -> None:
    request = InsertRequest(id="run-1:p1:r1:1", part="p1", hole="r1", seed=7)
    assert decode_request(encode(request)) == request
    reply = InsertReply(id=request.id, cell="c1", part="p1", hole="r1", result="no_fit", wall_s=0.5,
                        evidence=Evidence(attempts=2, max_force_dev=31.0, max_torque_dev=1.2,
                                          end_error=0.004, duration_s=3.1))
    assert decode_reply(encode(reply)) == reply
    error = ErrorReply(cell="c1", code="malformed", error="bad")
    assert decode_reply(encode(error)) == error


@pytest.mark.parametrize("payload, code", [
    (b"", "malformed"),
    (b"{not json", "malformed"),
    (b'{"kind":"insert","id":"a","part":"p1"}', "malformed"),
    (b'{"kind":"insert","id":"a","part":"p1;import os","hole":"r1"}', "malformed"),
    (b'{"kind":"insert","id":"a b","part":"p1","hole":"r1"}', "malformed"),
    (b'{"kind":"insert","id":"a","part":"p1","hole":"r1","seed":-1}', "malformed"),
    (b'{"kind":"insert","id":"a","part":"p1","hole":"r1","exec":"x"}', "malformed"),
    (b'{"kind":"insert_reply","id":"a","cell":"c1","result":"fit"}', "malformed"),
    (b'{"kind":"insert","id":"a","part":"p1","hole":"r1","v":1}', "version"),
    (b'{"kind":"insert","id":"a","part":"p1","hole":"r\xff1"}', "malformed"),
    (b'{"kind":"insert","id":"a","part":"p1","hole":"r1","pad":"' + b"x" * MAX_MESSAGE_BYTES + b'"}',
     "oversized"),
])
def test_bad_requests_are_refused_with_a_code(payload: bytes, code: str) -> None:
    with pytest.raises(MessageError) as caught:
        decode_request(payload)
    assert caught.value.code == code


def test_reply_result_is_checked() -> None:
    bad = msgspec.json.encode({"kind": "insert_reply", "id": "a", "cell": "c1", "result": "maybe"})
    with pytest.raises(MessageError):
        decode_reply(bad)


def test_encode_refuses_oversized_messages() -> None:
    with pytest.raises(MessageError, match="cap"):
        encode(ErrorReply(cell="c1", code="failed", error="x" * MAX_MESSAGE_BYTES))


def test_keys() -> None:
    assert insert_key("c1") == "cell/c1/insert"
    assert cell_of_alive_key(alive_key("cell-2", "a1")) == ("cell-2", "a1")
    assert cell_of_alive_key("cell/c1/alive") is None
    assert cell_of_alive_key("cell/c1/insert") is None
    with pytest.raises(BridgeError, match="cell id"):
        insert_key("C/1")


def test_step_messages_round_trip_and_need_version_3() -> None:
    from bridge.messages import StepEvidence, StepReply, StepRequest, decode_step_request

    request = StepRequest(id="run-7-2", assembly="run-7", step=2, part="sp", hole=None, seed=3)
    assert decode_step_request(encode(request)) == request
    reply = StepReply(id=request.id, cell="c1", part="sp", hole=None, result="fit",
                      evidence=StepEvidence(skill="insert_over", attempts=1, max_force_dev=4.0, max_torque_dev=0.1,
                                            duration_s=2.0, sim_time_s=5.0, pose_error_mm=1.2),
                      pose_errors_mm=(("bp", 0.0), ("sp", 1.2)))
    assert decode_reply(encode(reply)) == reply
    hash(reply)  # a reply is compared and de-duplicated by the client
    with pytest.raises(MessageError) as old:
        decode_step_request(b'{"kind":"step","id":"a","assembly":"r","step":1,"part":"p1","v":2}')
    assert old.value.code == "version"
    # Insert messages did not change in version 3: a version-2 insert request is still served.
    assert decode_request(b'{"kind":"insert","id":"a","part":"p1","hole":"r1","v":2}').v == 2


@pytest.mark.parametrize("bad", ["not", "p1\n", "p\u00e91", "p\\ud800", "P1", "1p", "_p", "p" * 65])
def test_ids_that_break_clingo_are_malformed(bad: str) -> None:
    """An id is an ASCII ASP constant: not the keyword ``not``, no trailing newline, no
    non-ASCII letter (clingo panics on one), no lone surrogate."""
    from bridge.messages import decode_step_request

    step = msgspec.json.encode({"kind": "step", "id": "a", "assembly": "r", "step": 1, "part": "p1", "hole": "r1"})
    for field in ("part", "hole"):
        payload = step.replace(f'"{field}":"{"p1" if field == "part" else "r1"}"'.encode(),
                               f'"{field}":"'.encode() + bad.encode("utf-8", "surrogatepass")
                               .replace(b"\n", b"\\n") + b'"')
        assert payload != step
        with pytest.raises(MessageError) as refused:
            decode_step_request(payload)
        assert refused.value.code == "malformed"
    assert decode_step_request(step).part == "p1" and decode_step_request(step.replace(b'"p1"', b'"nots"'))


def test_a_key_given_twice_is_malformed() -> None:
    """msgspec keeps the last of two equal keys: a message with one is refused instead, so
    that a reader of the first one never sees another request than the cell runs."""
    from bridge.messages import decode_step_request

    step = b'{"kind":"step","id":"a","assembly":"r","step":1,"part":"p1","hole":"r1","hole":"br"}'
    with pytest.raises(MessageError, match="the key 'hole' appears twice") as refused:
        decode_step_request(step)
    assert refused.value.code == "malformed"
    with pytest.raises(MessageError, match="'part' appears twice"):
        decode_request(b'{"kind":"insert","id":"a","part":"p1","hole":"r1","part":"p2"}')
    assert decode_request(b'{"kind":"insert","id":"a","part":"p1","hole":"r1"}').part == "p1"
