"""A client of an assembly cell written only against the published protocol (docs/protocol.md).

It uses nothing of this project: only ``eclipse-zenoh`` (``pip install eclipse-zenoh``)
and the standard library, as a third party in another code base would.

    python third_party_client.py tcp/127.0.0.1:7447 p1 r1

1. opens a Zenoh peer session connected to the cell's endpoint;
2. finds the cells by their liveliness tokens ``cell/<id>/alive/<instance>``;
3. sends an insert request (JSON) to the first cell's queryable ``cell/<id>/insert``
   and prints the reply (``insert_reply``: the result, echoing ``part`` and ``hole``;
   or ``error``: a code saying why the request was refused);
4. exits 0 on an ``insert_reply``, 1 on an ``error`` reply, 2 on no reply or no cell.
"""

from __future__ import annotations

import json
import sys
import time
import uuid

import zenoh

PROTOCOL_VERSION = 2
ALIVE = "cell/*/alive/*"


def open_session(endpoint: str) -> zenoh.Session:
    """A Zenoh peer that connects to ``endpoint`` and listens nowhere."""
    config = zenoh.Config()
    config.insert_json5("mode", '"peer"')
    config.insert_json5("scouting/multicast/enabled", "false")
    config.insert_json5("listen/endpoints", "[]")
    config.insert_json5("connect/endpoints", json.dumps([endpoint]))
    return zenoh.open(config)


def find_cells(session: zenoh.Session, wait_s: float = 10.0) -> list[str]:
    """The ids of the cells holding a liveliness token, waiting up to ``wait_s`` [s] for one."""
    deadline = time.monotonic() + wait_s
    while True:
        cells = set()
        for reply in session.liveliness().get(ALIVE, timeout=1.0):
            if reply.ok is not None:
                cells.add(str(reply.ok.key_expr).split("/")[1])  # cell/<id>/alive/<instance>
        if cells or time.monotonic() > deadline:
            return sorted(cells)
        time.sleep(0.2)


def insert(session: zenoh.Session, cell: str, part: str, hole: str, timeout_s: float = 60.0) -> dict | None:
    """Ask cell ``cell`` to insert ``part`` into ``hole``; the decoded reply, or None."""
    request = {"kind": "insert", "v": PROTOCOL_VERSION, "id": f"demo-{uuid.uuid4().hex}",
               "part": part, "hole": hole, "timeout_s": timeout_s}
    for reply in session.get(f"cell/{cell}/insert", payload=json.dumps(request).encode(), timeout=timeout_s):
        if reply.ok is not None:
            message = json.loads(reply.ok.payload.to_bytes())
            if message.get("id") in (request["id"], None):  # an error reply to a unparsable request has no id
                return message
    return None


def main(argv: list[str]) -> int:
    endpoint, part, hole = argv
    with open_session(endpoint) as session:
        cells = find_cells(session)
        if not cells:
            print(f"no cell at {endpoint}", file=sys.stderr)
            return 2
        reply = insert(session, cells[0], part, hole)
    if reply is None:
        print(f"cell {cells[0]}: no reply", file=sys.stderr)
        return 2
    print(json.dumps(reply, sort_keys=True))
    return 0 if reply["kind"] == "insert_reply" else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
