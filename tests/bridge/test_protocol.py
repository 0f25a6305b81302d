"""The published protocol (docs/protocol.md): the JSON Schemas in docs/protocol/ are those
of the message types, and a client written only against them talks to a real cell."""

from __future__ import annotations

import ast
import json
import subprocess
import sys
from pathlib import Path

import msgspec
import pytest

from asp.session.cells import CellProcess, start_cell
from bridge.cell_settings import ServeSettings
from bridge.messages import ErrorReply, Evidence, InsertReply, InsertRequest, encode
from bridge.product import ID_PATTERN
from bridge.protocol_schema import MESSAGES, drift, main, schemas
from bridge.session import free_loopback_endpoint
from tests.conftest import ROOT, child_env

PUBLISHED = ROOT / "docs" / "protocol"
CLIENT = ROOT / "docs" / "examples" / "third_party_client.py"


def test_the_published_schemas_are_those_of_the_message_types() -> None:
    assert drift(PUBLISHED) == [], "regenerate: ./run.sh protocol --out docs/protocol"


def test_a_changed_type_shows_as_drift(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["--out", str(tmp_path)]) == 0 and main(["--check", str(tmp_path)]) == 0
    edited = json.loads((tmp_path / "insert_request.schema.json").read_text())
    edited["properties"].pop("timeout_s")  # as if the field were added to the type only
    (tmp_path / "insert_request.schema.json").write_text(json.dumps(edited))
    capsys.readouterr()
    assert main(["--check", str(tmp_path)]) == 1
    assert "insert_request.schema.json: differs from the types" in capsys.readouterr().out


@pytest.mark.parametrize("message", [
    InsertRequest(id="r1", part="p1", hole="r1", seed=3, timeout_s=5.0),
    InsertReply(id="r1", cell="c1", part="p1", hole="r1", result="fit",
                evidence=Evidence(attempts=1, max_force_dev=2.0, max_torque_dev=0.1, end_error=0.001, duration_s=3.0)),
    ErrorReply(cell="c1", code="busy", error="16 requests are waiting", id="r1"),
])
def test_encoded_messages_have_the_published_fields(message: msgspec.Struct) -> None:
    """Every key a message carries is a published property, every required one is there."""
    stem = next(stem for stem, (kind, _) in MESSAGES.items() if isinstance(message, kind))
    published = json.loads(schemas()[f"{stem}.schema.json"])
    sent = json.loads(encode(message))  # type: ignore[arg-type]
    assert set(sent) <= set(published["properties"]) and set(published["required"]) <= set(sent)
    assert [sent["kind"]] == published["properties"]["kind"]["enum"]


def test_the_third_party_client_imports_only_zenoh_and_the_standard_library() -> None:
    tree = ast.parse(CLIENT.read_text())
    imported = {alias.name.split(".")[0] for node in ast.walk(tree) if isinstance(node, ast.Import)
                for alias in node.names}
    imported |= {(node.module or "").split(".")[0] for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)}
    assert imported - {"zenoh"} <= set(sys.stdlib_module_names) | {"__future__"}


@pytest.mark.slow
def test_the_third_party_client_talks_to_a_real_cell(cells: list[CellProcess], tmp_path: Path) -> None:
    endpoint = free_loopback_endpoint()
    cells.append(start_cell(ServeSettings(cell_id="c1", backend="truth", listen=(endpoint,))))

    def client(part: str, hole: str) -> tuple[int, dict]:
        done = subprocess.run([sys.executable, "-I", str(CLIENT), endpoint, part, hole], cwd=tmp_path,
                              env=child_env(), capture_output=True, text=True, timeout=60)
        return done.returncode, json.loads(done.stdout or "{}")

    code, reply = client("p3", "s1")
    assert code == 0, reply
    assert reply["kind"] == "insert_reply" and reply["result"] == "fit" and reply["cell"] == "c1"
    assert (reply["part"], reply["hole"]) == ("p3", "s1")  # replies echo the request
    code, reply = client("p3", "r1")
    assert code == 0 and reply["result"] == "no_fit"
    code, reply = client("p3", "zz")
    assert code == 1 and reply["kind"] == "error" and reply["code"] == "unknown_id"


@pytest.mark.parametrize("stem", ["assembly", "geometry"])
def test_the_published_product_schemas_are_strict(stem: str) -> None:
    """Every table of the product files refuses unknown keys in the schema as the loader
    does, and ids carry the loader's pattern."""
    published = json.loads((PUBLISHED / f"{stem}.schema.json").read_text())
    tables = [published, *published["$defs"].values()]
    assert tables and all(table.get("additionalProperties") is False for table in tables if "properties" in table)
    text = json.dumps(published)
    assert json.dumps(ID_PATTERN) in text
    required = {"assembly": ["parts"], "geometry": ["plate"]}[stem]
    assert published["required"] == required
