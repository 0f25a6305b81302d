"""``./run.sh router``: the Zenoh router that joins a planner and cells on other hosts.

eclipse-zenoh's router daemon ``zenohd`` is not in the eclipse-zenoh Python wheel, and no
package of the registries this project installs from provides it, so the router is a
Zenoh session in *router mode* opened through the eclipse-zenoh Python API: the same
routing code as ``zenohd`` (it routes liveliness tokens, queries and replies between the
sessions connected to it), without ``zenohd``'s plugins (REST, storages) or its command
line. It prints ``ready router <zid> listen <endpoints>`` once it listens and runs until
SIGTERM or SIGINT (exit 0).

By default it listens on :data:`bridge.session.DEFAULT_ENDPOINT` (loopback); cells and
planners on other hosts need an endpoint on an address they can reach
(``--listen tcp/192.0.2.10:7447``), and a ``--zenoh-config`` file for TLS,
authentication and access control (``docs/session.md``; its ``mode`` is set to router).
Planner and cells then connect to it (``--connect tcp/192.0.2.10:7447``).
"""

from __future__ import annotations

import signal
import time
from collections.abc import Sequence
from pathlib import Path

from bridge.cli_types import ArgumentParser
from bridge.session import DEFAULT_ENDPOINT, open_session


def _exit_on_signal(signum: int, _frame: object) -> None:
    raise SystemExit(128 + signum)


def main(argv: Sequence[str]) -> int:
    parser = ArgumentParser(prog="router", description=__doc__.split("\n\n")[0])
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
        where = " ".join(listen) or f"as in {args.zenoh_config}"
        print(f"ready router {session.zid()} listen {where}", flush=True)
        while True:
            time.sleep(3600.0)
    except SystemExit:
        pass  # SIGTERM/SIGINT: close below
    finally:
        session.close()
    return 0
