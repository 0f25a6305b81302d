"""Opening Zenoh sessions: peer mode on loopback by default.

Without options a node is a Zenoh peer with multicast scouting off that listens only on
the endpoints it is given (default :data:`DEFAULT_ENDPOINT`, loopback) and connects to
the ones it is given. ``--zenoh-config FILE`` loads a full Zenoh config (JSON5) for a
router, other hosts, TLS, authentication and access control (docs/session.md);
``--listen``/``--connect`` still override its endpoints, and ``--connect`` without
``--listen`` listens nowhere, whatever the file says. Nothing
listens on a non-loopback address unless an option or the config file says so.
"""

from __future__ import annotations

import argparse
import json
import re
import socket
from collections.abc import Sequence
from pathlib import Path

import zenoh

from bridge import BridgeError
from bridge.messages import MAX_MESSAGE_BYTES

DEFAULT_ENDPOINT = "tcp/127.0.0.1:7447"
"""Where a cell listens and a planner connects when given no endpoint."""

MAX_TRANSPORT_BYTES = 8 * MAX_MESSAGE_BYTES
"""Zenoh refuses bigger messages before they reach Python (the application's own cap,
:data:`bridge.messages.MAX_MESSAGE_BYTES`, then refuses what gets through and is too big)."""

LOOPBACK_ANY_PORT = "tcp/127.0.0.1:0"
"""A loopback listener on a port the system picks."""

_ENDPOINT = re.compile(r"^(tcp|udp|tls|quic|ws|unixsock-stream)/\S+$")
_LOOPBACK = re.compile(r"^[a-z-]+/(127\.\d+\.\d+\.\d+|localhost|\[::1\]):\d+$")


def add_endpoint_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``--listen EP``, ``--connect EP`` (repeatable) and ``--zenoh-config FILE``."""
    group = parser.add_argument_group("zenoh")
    group.add_argument("--listen", action="append", default=[], metavar="EP",
                       help="endpoint to listen on, e.g. tcp/127.0.0.1:7447 (repeatable)")
    group.add_argument("--connect", action="append", default=[], metavar="EP",
                       help="endpoint to connect to, e.g. tcp/127.0.0.1:7447 (repeatable)")
    group.add_argument("--zenoh-config", type=Path, metavar="FILE",
                       help="a Zenoh JSON5 config file (router, other hosts)")


def check_endpoint(endpoint: str) -> str:
    """Return ``endpoint`` if it looks like a Zenoh locator, else raise BridgeError."""
    if not _ENDPOINT.match(endpoint):
        raise BridgeError(f"endpoint {endpoint!r}: expected PROTO/ADDRESS:PORT, "
                          "e.g. tcp/127.0.0.1:7447")
    return endpoint


def cell_listen(listen: Sequence[str], connect: Sequence[str], config_file: Path | None) -> list[str]:
    """Where a cell listens: ``listen`` if given; else nowhere new with a config file (the
    file says); else, when it connects only to loopback endpoints, a loopback port the
    system picks (Zenoh's gossip then connects the cells of one planner to each other, so
    a second process on one cell id is seen: :mod:`executor.claim`); else, connecting
    elsewhere, nowhere; else :data:`DEFAULT_ENDPOINT`."""
    if listen or config_file is not None:
        return list(listen)
    if connect:
        return [LOOPBACK_ANY_PORT] if all(_LOOPBACK.match(e) for e in connect) else []
    return [DEFAULT_ENDPOINT]


def make_config(listen: Sequence[str] = (), connect: Sequence[str] = (),
                config_file: Path | None = None, mode: str | None = None) -> zenoh.Config:
    """A Zenoh config: the file if given, else a loopback peer; endpoints and ``mode``
    (``peer``, ``client``, ``router``) override it."""
    if config_file is not None:
        if not config_file.is_file():
            raise BridgeError(f"{config_file}: no such Zenoh config file")
        try:
            config = zenoh.Config.from_file(str(config_file))
        except zenoh.ZError as exc:
            raise BridgeError(f"{config_file}: not a valid Zenoh config: {exc}") from None
    else:
        config = zenoh.Config()
        config.insert_json5("mode", '"peer"')
        config.insert_json5("scouting/multicast/enabled", "false")
        config.insert_json5("listen/endpoints", "[]")
    config.insert_json5("transport/link/rx/max_message_size", str(MAX_TRANSPORT_BYTES))
    if mode is not None:
        config.insert_json5("mode", json.dumps(mode))
    if listen or connect or config_file is None:  # --connect alone: listen nowhere
        config.insert_json5("listen/endpoints", json.dumps([check_endpoint(e) for e in listen]))
    if connect:
        config.insert_json5("connect/endpoints", json.dumps([check_endpoint(e) for e in connect]))
    return config


def open_session(listen: Sequence[str] = (), connect: Sequence[str] = (),
                 config_file: Path | None = None, mode: str | None = None) -> zenoh.Session:
    """Open a Zenoh session (~0.5 s; see :func:`make_config`); BridgeError if an endpoint
    cannot be used.

    Close it (``with`` or ``.close()``): an open session keeps the process alive.
    """
    config = make_config(listen, connect, config_file, mode)
    try:
        return zenoh.open(config)
    except zenoh.ZError as exc:
        where = ", ".join([*listen, *connect]) or str(config_file)
        raise BridgeError(f"cannot open a Zenoh session on {where}: {exc}") from None


def free_loopback_endpoint() -> str:
    """A ``tcp/127.0.0.1:PORT`` endpoint on a port that was free a moment ago."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        sock.bind(("127.0.0.1", 0))
        port = sock.getsockname()[1]
    return f"tcp/127.0.0.1:{port}"
