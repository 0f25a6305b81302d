"""Every integer, string and array of every message is bounded by the published schema,
and the bounds are what the cell and the planner enforce (the real cell process's answers at
and past the bounds: ``tests/bridge/test_bridge_cells.py``)."""

from __future__ import annotations

import re
from collections.abc import Iterator

import pytest

from bridge.messages import (
    MAX_COUNT,
    MAX_REQUEST_ID,
    InsertRequest,
    MessageError,
    decode_reply,
    decode_request,
    encode,
)
from bridge.protocol_schema import MESSAGES, schema

BOUNDED_PATTERN = re.compile(r"^\^[^*+]*\{\d+,\d+\}[^*+]*\$")
"""A pattern that bounds the length of what it matches: one counted repetition, no * or +."""


def unbounded(node: object, path: str = "$") -> Iterator[str]:
    """The paths of the integers, strings and arrays of a JSON Schema without an upper bound."""
    if isinstance(node, list):
        for index, item in enumerate(node):
            yield from unbounded(item, f"{path}[{index}]")
        return
    if not isinstance(node, dict):
        return
    kind = node.get("type")
    if kind in ("integer", "number") and "maximum" not in node and "exclusiveMaximum" not in node:
        yield path
    if (kind == "string" and "maxLength" not in node and "enum" not in node and "const" not in node
            and not BOUNDED_PATTERN.match(node.get("pattern", ""))):
        yield path
    if kind == "array" and "maxItems" not in node:
        yield path
    for key, value in node.items():
        yield from unbounded(value, f"{path}.{key}")


@pytest.mark.parametrize("name", sorted(MESSAGES))
def test_every_number_string_and_array_of_a_message_is_bounded(name: str) -> None:
    message, direction = MESSAGES[name]
    assert list(unbounded(schema(message, direction))) == []


def test_the_request_id_holds_the_longest_documented_ids() -> None:
    run, part, hole = "r" * 64, "p" + "a" * 63, "h" + "b" * 63
    longest = f"{run}.{part}.{hole}.{MAX_COUNT}"
    assert len(longest) == MAX_REQUEST_ID
    request = InsertRequest(id=longest, part=part, hole=hole, experiment=MAX_COUNT)
    assert decode_request(encode(request)) == request


def test_the_planner_refuses_a_reply_past_the_bounds() -> None:
    reply = b'{"kind":"insert_reply","id":"a","cell":"c1","part":"p1","hole":"r1","result":"fit",' \
            b'"evidence":{"attempts":%d,"max_force_dev":0,"max_torque_dev":0,"end_error":0,"duration_s":0}}'
    assert decode_reply(reply % MAX_COUNT).evidence.attempts == MAX_COUNT  # type: ignore[union-attr]
    with pytest.raises(MessageError, match=r"Expected `int` <= 2147483647 - at `\$.evidence.attempts`"):
        decode_reply(reply % 2**63)
