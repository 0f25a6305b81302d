"""``assembly-constraints protocol``: the JSON Schema of every Zenoh message, generated
from the message types of :mod:`bridge.messages`, and of the product description files
(``assembly.toml``, ``geometry.toml`` as decoded TOML), generated from the structs of
:mod:`bridge.product`.

The schemas are published in ``docs/protocol/`` (one file a message or product file,
described in ``docs/protocol.md`` and ``docs/geometry.md``) for clients and editors in
any language; a test fails when the checked-in files and the types drift apart.
``protocol --out docs/protocol`` rewrites them, ``protocol --check docs/protocol`` exits 1
naming the files that differ, and without options the schemas are printed as one JSON
object.
"""

from __future__ import annotations

import argparse
import json
from collections.abc import Sequence
from pathlib import Path

import msgspec

from bridge.cli_types import ArgumentParser
from bridge.files import make_folder, write_atomic
from bridge.keys import ALIVE_PATTERN, CELL_ID_PATTERN
from bridge.messages import (
    MAX_MESSAGE_BYTES,
    PROTOCOL_VERSION,
    ErrorReply,
    InsertReply,
    InsertRequest,
    StepReply,
    StepRequest,
)
from bridge.precedence.experiment import EXPERIMENT_VERSION, PrecedenceExperiment, PrecedenceOutcome
from bridge.product import AssemblyFile, GeometryFile

MESSAGES: dict[str, tuple[type[msgspec.Struct], str]] = {
    "insert_request": (InsertRequest, "planner → cell, a query on cell/<id>/insert"),
    "insert_reply": (InsertReply, "cell → planner, the reply to an insert request"),
    "error_reply": (ErrorReply, "cell → planner, a refused insert, step or precedence request"),
    "step_request": (StepRequest, "planner → cell, a query on cell/<id>/step: one step of a plan"),
    "step_reply": (StepReply, "cell → planner, the reply to a step request"),
    "precedence_experiment": (PrecedenceExperiment, "planner → cell, a query on cell/<id>/precedence: a "
                              "precedence experiment"),
    "precedence_outcome": (PrecedenceOutcome, "cell → planner, the reply to a precedence experiment"),
}
"""File stem → (message type, who sends it where)."""
VERSIONS: dict[type[msgspec.Struct], int] = {PrecedenceExperiment: EXPERIMENT_VERSION,
                                             PrecedenceOutcome: EXPERIMENT_VERSION}
"""The message types versioned on their own (the others: PROTOCOL_VERSION)."""
PRODUCT_FILES: dict[str, tuple[type[msgspec.Struct], str]] = {
    "assembly": (AssemblyFile, "assembly.toml of a product folder: parts, holes, the declared size model"),
    "geometry": (GeometryFile, "geometry.toml of a product folder: the cell geometry, base, covers and heads"),
}
"""File stem → (struct of the decoded TOML, what the file is)."""

DRAFT = "https://json-schema.org/draft/2020-12/schema"


def _plain(value: object) -> object:
    """``value`` with the reStructuredText literals of docstrings (double backquotes) removed."""
    if isinstance(value, dict):
        return {k: v.replace("``", "") if k == "description" and isinstance(v, str) else _plain(v)
                for k, v in value.items()}
    return [_plain(v) for v in value] if isinstance(value, list) else value


def schema(message: type[msgspec.Struct], direction: str) -> dict:
    """The JSON Schema (draft 2020-12) of one message type, self-contained (``$defs``)."""
    version = VERSIONS.get(message, PROTOCOL_VERSION)
    return _schema(message, f"{direction}; protocol version {version}, at most {MAX_MESSAGE_BYTES} "
                   "bytes of UTF-8 JSON")


def _schema(kind: type[msgspec.Struct], context: str) -> dict:
    """The self-contained JSON Schema of ``kind``, its description followed by ``context``."""
    generated: dict = _plain(msgspec.json.schema(kind))  # type: ignore[assignment]
    name = generated["$ref"].rsplit("/", 1)[-1]
    defs = generated["$defs"]
    return {"$schema": DRAFT, "title": name,
            "description": f"{defs[name].get('description', name)} ({context})",
            **{key: value for key, value in defs[name].items() if key not in ("title", "description")},
            "$defs": {key: value for key, value in defs.items() if key != name}}


def schemas() -> dict[str, str]:
    """File name → text of every published schema (sorted keys, two-space indent, newline)."""
    texts = {f"{stem}.schema.json": schema(message, direction) for stem, (message, direction) in MESSAGES.items()}
    texts |= {f"{stem}.schema.json": _schema(kind, f"{what}; TOML, here as the JSON of its decoded tables")
              for stem, (kind, what) in PRODUCT_FILES.items()}
    texts["protocol.json"] = {"protocol_version": PROTOCOL_VERSION, "max_message_bytes": MAX_MESSAGE_BYTES,
                              "cell_id_pattern": CELL_ID_PATTERN, "alive_pattern": ALIVE_PATTERN,
                              "experiment_version": EXPERIMENT_VERSION,
                              "keys": {"insert": "cell/<id>/insert", "step": "cell/<id>/step",
                                       "precedence": "cell/<id>/precedence", "ping": "cell/<id>/ping",
                                       "alive": "cell/<id>/alive/<instance>"},
                              "messages": {f"{stem}.schema.json": direction
                                           for stem, (_, direction) in MESSAGES.items()}}
    return {name: json.dumps(value, indent=2, sort_keys=True, ensure_ascii=False) + "\n"
            for name, value in texts.items()}


def drift(folder: Path) -> list[str]:
    """The files of ``folder`` that differ from the generated schemas (missing ones too)."""
    return [name for name, text in schemas().items()
            if not (folder / name).is_file() or (folder / name).read_text(encoding="utf-8") != text]


def build_parser() -> argparse.ArgumentParser:
    parser = ArgumentParser(prog="protocol", description="Write or check the JSON Schema of every Zenoh message "
                            "and product description file (generated from their types); without options, print "
                            "them as one JSON object.")
    what = parser.add_mutually_exclusive_group()
    what.add_argument("--out", type=Path, metavar="DIR", help="write the schema files into this folder")
    what.add_argument("--check", type=Path, metavar="DIR",
                      help="exit 1 when the schema files in this folder differ from the types")
    return parser


def main(argv: Sequence[str]) -> int:
    args = build_parser().parse_args(list(argv))
    if args.check is not None:
        stale = drift(args.check)
        for name in stale:
            print(f"{args.check / name}: differs from the types (regenerate: protocol --out {args.check})")
        return 1 if stale else 0
    if args.out is not None:
        make_folder(args.out)
        for name, text in schemas().items():
            print(f"wrote {write_atomic(args.out / name, text)}")
        return 0
    print(json.dumps({name: json.loads(text) for name, text in schemas().items()}, indent=2, ensure_ascii=False))
    return 0
