"""Opening Zenoh sessions: peer mode on loopback by default.

Without options a node is a Zenoh peer with multicast scouting off that listens only on
the endpoints it is given (default :data:`DEFAULT_ENDPOINT`, loopback) and connects to
the ones it is given. ``--zenoh-config FILE`` loads a full Zenoh config (JSON5) for a
router, other hosts, TLS, authentication and access control (docs/session.md);
``--listen``/``--connect`` still override its endpoints, and ``--connect`` without
``--listen`` listens nowhere, whatever the file says. Nothing
listens on a non-loopback address unless an option or the config file says so.
:func:`router_main` is ``./run.sh router``, a session in router mode.
"""

from __future__ import annotations

import argparse
import json
import re
import signal
import socket
import time
from collections.abc import Sequence
from pathlib import Path

import zenoh

from bridge import BridgeError
from bridge.cli_types import ArgumentParser
from bridge.messages import MAX_MESSAGE_BYTES

DEFAULT_ENDPOINT = "tcp/127.0.0.1:7447"
"""Where a cell listens and a planner connects when given no endpoint."""

SIGNAL_POLL_S = 0.2
"""The longest a Zenoh process's main thread waits (for work, or idle) before it looks at
signals [s]: a signal sent to the process may be taken by one of Zenoh's threads, and
Python runs its handler only when the main thread next runs."""

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
    if any(endpoint.endswith(":0") for endpoint in listen):  # bound_endpoints reads the ports bound
        config.insert_json5("adminspace", '{"enabled": true, "permissions": {"read": true, "write": false}}')
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


ADMIN_TIMEOUT_S = 5.0
"""Longest a session may take to answer its own admin-space query [s]."""


def bound_endpoints(session: zenoh.Session, asked: Sequence[str]) -> list[str]:
    """The endpoints ``session`` listens on: ``asked`` as given, or, when one of them asks
    for any port (``...:0``), the endpoints with the ports the session bound (read from its
    admin space, which :func:`make_config` opens for reading in that case only), so a
    process that must connect to it is told a port nobody else can have taken meanwhile.
    BridgeError when the session does not say."""
    if not any(endpoint.endswith(":0") for endpoint in asked):
        return list(asked)
    for reply in session.get(f"@/{session.zid()}/*", timeout=ADMIN_TIMEOUT_S):
        if reply.ok is None:
            continue
        try:
            status = json.loads(reply.ok.payload.to_bytes())
        except ValueError:
            continue
        if isinstance(status, dict) and isinstance(status.get("locators"), list) and status["locators"]:
            return [str(locator) for locator in status["locators"]]
    raise BridgeError(f"the Zenoh session listening on {', '.join(asked)} did not report its ports")


def free_loopback_endpoint() -> str:
    """A ``tcp/127.0.0.1:PORT`` endpoint on a port that was free a moment ago: for tests that
    start a listener and its peers at once on a port they name. The tool itself never
    picks a port to bind later: it listens on port 0 and reads the bound port
    (:func:`bound_endpoints`)."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        sock.bind(("127.0.0.1", 0))
        port = sock.getsockname()[1]
    return f"tcp/127.0.0.1:{port}"


def _exit_on_signal(signum: int, _frame: object) -> None:
    raise SystemExit(128 + signum)


def router_main(argv: Sequence[str]) -> int:
    """``./run.sh router``: the Zenoh router that joins a planner and cells on other hosts.

    eclipse-zenoh's router daemon ``zenohd`` is not in the eclipse-zenoh Python wheel, and no
    package of the registries this project installs from provides it, so the router is a
    Zenoh session in *router mode* opened through the eclipse-zenoh Python API: the same
    routing code as ``zenohd`` (it routes liveliness tokens, queries and replies between the
    sessions connected to it), without ``zenohd``'s plugins (REST, storages) or its command
    line. It prints ``ready router <zid> listen <endpoints>`` once it listens (an endpoint of
    port 0 with the port it bound) and runs until SIGTERM or SIGINT (exit 0).

    By default it listens on :data:`bridge.session.DEFAULT_ENDPOINT` (loopback); cells and
    planners on other hosts need an endpoint on an address they can reach
    (``--listen tcp/192.0.2.10:7447``), and a ``--zenoh-config`` file for TLS,
    authentication and access control (``docs/session.md``; its ``mode`` is set to router).
    Planner and cells then connect to it (``--connect tcp/192.0.2.10:7447``).
    """
    parser = ArgumentParser(prog="router", description="The Zenoh router (router mode of eclipse-zenoh) that "
                                                       "joins a planner and cells on other hosts.")
    parser.add_argument("--listen", action="append", default=[], metavar="EP",
                        help=f"endpoint to listen on (repeatable; default {DEFAULT_ENDPOINT}, "
                             "or those of --zenoh-config)")
    parser.add_argument("--zenoh-config", type=Path, metavar="FILE",
                        help="a Zenoh JSON5 config file (TLS, authentication, access control)")
    args = parser.parse_args(list(argv))
    listen = args.listen or ([] if args.zenoh_config else [DEFAULT_ENDPOINT])
    signal.signal(signal.SIGTERM, _exit_on_signal)
    signal.signal(signal.SIGINT, _exit_on_signal)
    session = open_session(listen, (), args.zenoh_config, mode="router")
    try:
        where = " ".join(bound_endpoints(session, listen)) or f"as in {args.zenoh_config}"
        print(f"ready router {session.zid()} listen {where}", flush=True)
        while True:
            time.sleep(SIGNAL_POLL_S)
    except SystemExit:
        pass  # SIGTERM/SIGINT: close below
    finally:
        session.close()
    return 0
