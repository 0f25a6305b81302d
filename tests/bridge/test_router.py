"""``./run.sh router``: a Zenoh session in router mode joins clients that reach nothing else.

Real processes on loopback: the router with the authentication and access-control recipe
of docs/session.md, a truth cell and a planner session each a Zenoh client of it only, with
their own credentials: the planner sees the cell's token and gets its answer through the
router; a client without credentials, or with a wrong password, cannot connect.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from asp.session.cells import LineProcess, start_cell
from bridge import BridgeError
from bridge.cell_settings import ServeSettings
from bridge.client import CellDirectory, request_insert
from bridge.messages import InsertRequest
from bridge.session import free_loopback_endpoint, open_session

pytestmark = [pytest.mark.timeout(90), pytest.mark.slow]  # router and cell processes, ~5 s

RULES = {"enabled": True, "default_permission": "deny",
         "rules": [{"id": "cells", "permission": "allow", "flows": ["ingress", "egress"], "key_exprs": ["cell/**"],
                    "messages": ["query", "reply", "declare_queryable", "liveliness_token", "declare_subscriber",
                                 "liveliness_query", "declare_liveliness_subscriber"]}],
         "subjects": [{"id": "users", "usernames": ["cell", "planner"]}],
         "policies": [{"rules": ["cells"], "subjects": ["users"]}]}


def client_config(path: Path, user: str | None = None, password: str | None = None) -> Path:
    """A Zenoh client config (the router's endpoint comes from ``--connect``)."""
    config: dict = {"mode": "client", "scouting": {"multicast": {"enabled": False}}}
    if user is not None:
        config["transport"] = {"auth": {"usrpwd": {"user": user, "password": password}}}
    path.write_text(json.dumps(config), encoding="utf-8")
    return path


@pytest.fixture
def router(tmp_path: Path) -> Iterator[str]:
    """A router with user/password authentication and the access-control rules; its endpoint."""
    endpoint = free_loopback_endpoint()
    users = tmp_path / "users.txt"
    users.write_text("cell:cell-secret\nplanner:planner-secret\n", encoding="utf-8")
    config = tmp_path / "router.json5"
    config.write_text(json.dumps({
        "mode": "router", "scouting": {"multicast": {"enabled": False}}, "listen": {"endpoints": [endpoint]},
        "transport": {"auth": {"usrpwd": {"user": "router", "password": "router-secret",
                                          "dictionary_file": str(users)}}},
        "access_control": RULES}), encoding="utf-8")
    process = LineProcess("router", [sys.executable, "-m", "assembly_constraints", "router",
                                     "--zenoh-config", str(config)])
    try:
        process.wait_for_line("ready router", timeout=60)
        yield endpoint
    finally:
        assert process.stop() == 0  # SIGTERM: it closes its session and exits 0


def test_a_cell_and_a_planner_with_credentials_meet_through_the_router(tmp_path: Path, router: str) -> None:
    cell = start_cell(ServeSettings(cell_id="c1", backend="truth", connect=(router,),
                                    zenoh_config=str(client_config(tmp_path / "cell.json5", "cell", "cell-secret"))))
    session = open_session(connect=[router],
                           config_file=client_config(tmp_path / "planner.json5", "planner", "planner-secret"))
    try:
        assert CellDirectory(session).wait_for(1, timeout=30) == {"c1"}
        reply = request_insert(session, "c1", InsertRequest(id="r1", part="p1", hole="r1"), timeout=10)
        assert (reply.cell, reply.result) == ("c1", "fit")
    finally:
        session.close()
        cell.kill()


@pytest.mark.parametrize("credentials", [(None, None), ("cell", "wrong")])
def test_a_client_without_the_right_credentials_cannot_connect(
        tmp_path: Path, router: str, credentials: tuple[str | None, str | None]) -> None:
    with pytest.raises(BridgeError, match="cannot open a Zenoh session"):
        open_session(connect=[router], config_file=client_config(tmp_path / "rogue.json5", *credentials))
