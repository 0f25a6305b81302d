"""Opening Zenoh sessions: loopback defaults, config files, bad endpoints."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from bridge import BridgeError
from bridge.session import free_loopback_endpoint, make_config, open_session


def test_default_config_is_a_peer_without_multicast_listening_nowhere() -> None:
    config = make_config()
    assert json.loads(config.get_json("mode")) == "peer"
    assert json.loads(config.get_json("scouting/multicast/enabled")) is False
    assert json.loads(config.get_json("listen/endpoints")) == []


def test_endpoints_override_a_config_file(tmp_path: Path) -> None:
    file = tmp_path / "zenoh.json5"
    file.write_text('{ mode: "peer", listen: { endpoints: ["tcp/127.0.0.1:1"] } }')
    endpoint = free_loopback_endpoint()
    overridden = make_config(listen=[endpoint], config_file=file)
    assert json.loads(overridden.get_json("listen/endpoints")) == [endpoint]
    from_file = make_config(config_file=file)
    assert json.loads(from_file.get_json("listen/endpoints")) == ["tcp/127.0.0.1:1"]
    session = open_session(listen=[endpoint], config_file=file)
    session.close()


@pytest.mark.parametrize("kwargs, message", [
    ({"listen": ["127.0.0.1:7447"]}, "PROTO/ADDRESS:PORT"),
    ({"listen": ["tcp/127.0.0.1:99999"]}, "cannot open"),
    ({"config_file": Path("/nonexistent/zenoh.json5")}, "no such Zenoh config"),
])
def test_bad_endpoints_and_files_are_bridge_errors(kwargs: dict, message: str) -> None:
    with pytest.raises(BridgeError, match=message):
        open_session(**kwargs).close()
