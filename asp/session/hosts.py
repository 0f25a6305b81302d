"""Cells on other hosts, on one machine: network namespaces joined through a router namespace.

:class:`Hosts` makes a *router namespace* and ``count`` *cell namespaces*; cell namespace
k (1-based) has one link, a veth pair to the router namespace on 198.18.k.0/24 (the range
RFC 2544 sets aside for benchmarking network devices: no real host has these addresses,
and the namespaces have no other link, so their traffic stays inside them): the router
side is ``198.18.k.1``, the cell side ``198.18.k.2``. Processes are started inside a
namespace with :meth:`Hosts.argv`; :meth:`Hosts.cut` takes a cell's link down (as a
pulled cable would: no reset reaches either side). It needs root (``CAP_NET_ADMIN``) and
the ``ip`` command (iproute2); :func:`unavailable` says why not. :meth:`Hosts.close`
removes every namespace it made (with their links), also after a failure.
"""

from __future__ import annotations

import itertools
import os
import shutil
import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path

from asp import PlannerError
from asp.session.cells import CellProcess, LineProcess
from bridge.cell_settings import ServeSettings

ROUTER_PORT = 7447
"""The port the router listens on in the router namespace."""

CLIENT_CONFIG = '{ mode: "client", scouting: { multicast: { enabled: false } } }\n'
"""The Zenoh config of a planner or cell that reaches the others only through the router:
a client of it (two peers that listen nowhere never meet through a router)."""

_SERIAL = itertools.count(1)


def _ip(*args: str) -> None:
    """Run ``ip ARGS``; PlannerError with its message if it fails."""
    done = subprocess.run(["ip", *args], capture_output=True, text=True, timeout=30)
    if done.returncode != 0:
        raise PlannerError(f"ip {' '.join(args)}: {done.stderr.strip() or f'exit code {done.returncode}'}")


def unavailable() -> str | None:
    """Why network namespaces cannot be made here (None when they can): not root, no
    ``ip`` command, or the kernel refusing a namespace."""
    if os.geteuid() != 0:
        return "network namespaces need root (CAP_NET_ADMIN)"
    if shutil.which("ip") is None:
        return "the ip command (iproute2) is not installed"
    probe = f"ac{os.getpid()}-probe"
    try:
        _ip("netns", "add", probe)
    except PlannerError as exc:
        return f"cannot make a network namespace: {exc}"
    _ip("netns", "del", probe)
    return None


class Hosts:
    """A router namespace and ``count`` cell namespaces, each linked to the router's
    (module doc); a context manager that removes them on exit."""

    def __init__(self, count: int) -> None:
        if not 1 <= count <= 250:
            raise PlannerError(f"hosts {count}: expected 1 to 250 cell namespaces")
        base = f"ac{os.getpid()}-{next(_SERIAL)}"
        self.router = f"{base}-router"
        self.cells = [f"{base}-cell{k}" for k in range(1, count + 1)]
        self._made: list[str] = []
        try:
            self._make()
        except BaseException:
            self.close()
            raise

    def _make(self) -> None:
        for name in [self.router, *self.cells]:
            _ip("netns", "add", name)
            self._made.append(name)
            _ip("-n", name, "link", "set", "lo", "up")
        for k, cell in enumerate(self.cells, start=1):
            _ip("link", "add", f"to-cell{k}", "netns", self.router, "type", "veth",
                "peer", "name", "uplink", "netns", cell)
            _ip("-n", self.router, "addr", "add", f"{self.router_address(k)}/24", "dev", f"to-cell{k}")
            _ip("-n", cell, "addr", "add", f"{self.cell_address(k)}/24", "dev", "uplink")
            _ip("-n", self.router, "link", "set", f"to-cell{k}", "up")
            _ip("-n", cell, "link", "set", "uplink", "up")

    @staticmethod
    def router_address(k: int) -> str:
        """The router namespace's address on the link to cell namespace ``k``."""
        return f"198.18.{k}.1"

    @staticmethod
    def cell_address(k: int) -> str:
        """Cell namespace ``k``'s address."""
        return f"198.18.{k}.2"

    def router_endpoints(self) -> list[str]:
        """Where the router listens: one endpoint per cell link, and loopback for the
        processes of the router namespace (the planner)."""
        return [f"tcp/127.0.0.1:{ROUTER_PORT}",
                *(f"tcp/{self.router_address(k)}:{ROUTER_PORT}" for k in range(1, len(self.cells) + 1))]

    def cell_endpoint(self, k: int) -> str:
        """The router's endpoint as cell namespace ``k`` reaches it."""
        return f"tcp/{self.router_address(k)}:{ROUTER_PORT}"

    def argv(self, namespace: str, argv: Sequence[str]) -> list[str]:
        """``argv`` run inside ``namespace``."""
        return ["ip", "netns", "exec", namespace, *argv]

    def start_fleet(self, client_config: Path, *, backend: str = "truth", delay_s: float = 0.0,
                    assembly: str = "cranfield", ready_timeout: float = 60.0) -> list[LineProcess]:
        """Start ``./run.sh router`` in the router namespace and cell ``c<k>`` in cell
        namespace k, a Zenoh client (``client_config``, e.g. :data:`CLIENT_CONFIG`) of the
        router only; returns the router's and the cells' processes once each printed
        ``ready`` (stop them; on a failure here they are killed)."""
        router = [sys.executable, "-m", "assembly_constraints", "router",
                  *(f"--listen={endpoint}" for endpoint in self.router_endpoints())]
        started: list[LineProcess] = [LineProcess("router", self.argv(self.router, router))]
        try:
            started[0].wait_for_line("ready", timeout=ready_timeout)
            for k, namespace in enumerate(self.cells, start=1):
                cell = ServeSettings(cell_id=f"c{k}", backend=backend, assembly=assembly,
                                     connect=(self.cell_endpoint(k),), delay_s=delay_s, zenoh_config=str(client_config))
                started.append(CellProcess(cell, prefix=self.argv(namespace, [])))
            for process in started[1:]:
                process.wait_for_line("ready", timeout=ready_timeout)
        except BaseException:
            for process in started:
                process.kill()
            raise
        return started

    def cut(self, k: int) -> None:
        """Take cell namespace ``k``'s only link down."""
        _ip("-n", self.cells[k - 1], "link", "set", "uplink", "down")

    def close(self) -> None:
        """Remove every namespace made (their links go with them); idempotent."""
        while self._made:
            name = self._made.pop()
            try:
                _ip("netns", "del", name)
            except PlannerError:
                pass  # already gone

    def __enter__(self) -> Hosts:
        return self

    def __exit__(self, *_: object) -> None:
        self.close()
