"""Fuzzing the whole product description (``assembly.toml`` and ``geometry.toml``) with
hypothesis: valid files mutated (wrong types, missing tables and keys, zero, negative,
huge and non-finite values, unknown keys, bad ids, dangling references). Whatever comes
out, the loader either returns a description the cell can build (the plate mesh, the
part and arm URDFs, the sizes.lp, the product's covers and heads) or refuses it with one
line naming the file; and the command line (``executor trial``, ``plan --assembly``)
then exits 2 with one line ``error: ...``, never a traceback."""

from __future__ import annotations

import copy
import json
import math
import shutil
import tempfile
import tomllib
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from assembly_constraints.cli import main
from bridge import BridgeError
from bridge.errors import EXIT_BAD_INPUT, ToolError
from bridge.product import load_product_description
from executor.assembly.product import load_product
from executor.world.geometry import (
    arm_urdf_text,
    load_geometry,
    part_urdf_text,
    plate_obj_text,
    sizes_lp_text,
)
from tests.conftest import ROOT

CRANFIELD = ROOT / "data" / "cranfield"
FILES = ("assembly.toml", "geometry.toml")
ORIGINALS = {name: tomllib.loads((CRANFIELD / name).read_text()) for name in FILES}
IDS = ["p1", "r1", "br", "zz", "sh", "pd", "round_peg", "shaft", "Bad", "not", "1x", "", "p1). bomb(1"]
VALUES = st.one_of(
    st.integers(-10**20, 10**20), st.sampled_from([0, 0.0, -1.0, 1e300, -1e-9, math.nan, math.inf, -math.inf]),
    st.floats(-1.0, 1.0), st.booleans(), st.sampled_from(IDS),
    st.text(st.characters(min_codepoint=32, max_codepoint=126), max_size=8),
    st.lists(st.floats(-0.2, 0.2), max_size=5), st.lists(st.sampled_from(IDS), max_size=3),
    st.just({}), st.just({"x": 1}), st.just([[0.1, 0.1]]),
)


def _paths(data: object, prefix: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    """Every key and list index of ``data``, as paths from its root."""
    found: list[tuple[Any, ...]] = [prefix] if prefix else []
    if isinstance(data, dict):
        for key, value in data.items():
            found += _paths(value, (*prefix, key))
    elif isinstance(data, list):
        for index, value in enumerate(data):
            found += _paths(value, (*prefix, index))
    return found


def _parent(data: Any, path: tuple[Any, ...]) -> Any:
    for step in path[:-1]:
        data = data[step]
    return data


@st.composite
def mutated(draw: st.DrawFn) -> dict[str, dict[str, Any]]:
    """The Cranfield files with one to three mutations: a value replaced, a key or table
    removed, an unknown key added, a table renamed (a bad id, or a valid id the other
    tables do not reference: dangling references)."""
    files = json.loads(json.dumps(ORIGINALS, allow_nan=True))
    for _ in range(draw(st.integers(1, 3))):
        name = draw(st.sampled_from(FILES))
        paths = _paths(files[name])
        path = draw(st.sampled_from(paths))
        parent = _parent(files[name], path)
        action = draw(st.sampled_from(["replace", "replace", "remove", "add", "rename"]))
        if action == "replace":
            parent[path[-1]] = copy.deepcopy(draw(VALUES))  # a fresh value: st.just shares its object
        elif action == "remove":
            del parent[path[-1]]
        elif action == "add" and isinstance(parent, dict):
            parent[draw(st.sampled_from(["extra", "Size", "mass", "x y"]))] = copy.deepcopy(draw(VALUES))
        elif action == "rename" and isinstance(parent, dict):
            parent[draw(st.sampled_from(IDS))] = parent.pop(path[-1])
    return files


def _toml_value(value: object) -> str:
    """``value`` as a TOML value (inline tables and arrays; nan and inf as TOML writes them)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float) and not math.isfinite(value):
        return "nan" if math.isnan(value) else "inf" if value > 0 else "-inf"
    if isinstance(value, int | float):
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, list):
        return "[" + ", ".join(map(_toml_value, value)) + "]"
    assert isinstance(value, dict)
    return "{" + ", ".join(f"{json.dumps(k)} = {_toml_value(v)}" for k, v in value.items()) + "}"


def _write(folder: Path, files: dict[str, dict[str, Any]]) -> None:
    for name, data in files.items():
        text = "".join(f"{json.dumps(key)} = {_toml_value(value)}\n" for key, value in data.items())
        (folder / name).write_text(text)


def _builds(folder: Path) -> None:
    """What a cell builds from a product: assets, URDFs, sizes.lp, the product's solids."""
    geometry = load_geometry(str(folder))
    assert plate_obj_text(geometry).startswith("#")
    for part in geometry.parts.values():
        assert "<robot" in part_urdf_text(part)
    first = next(iter(geometry.parts.values()), None)
    if first is not None:
        assert "ft_sensor" in arm_urdf_text(first, geometry.gripper)
    assert "part(" in sizes_lp_text(str(folder)) or not geometry.parts
    if geometry.tables.base is not None:
        product = load_product(str(folder))
        assert all(cover.boxes for cover in product.covers.values())


def _one_line_exit_2(argv: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    capsys.readouterr()
    code = main(argv)
    err = capsys.readouterr().err.strip()
    assert code == EXIT_BAD_INPUT, (argv, code, err)
    assert err.startswith("error: ") and "\n" not in err and "Traceback" not in err, err


@pytest.mark.slow  # about 0.3 s an example (the refused ones run the command line twice)
@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture,
                                                                  HealthCheck.too_slow])
@given(files=mutated())
def test_a_mutated_product_builds_or_is_refused_in_one_line(files: dict[str, dict[str, Any]],
                                                            capsys: pytest.CaptureFixture[str]) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp) / "asm"
        shutil.copytree(CRANFIELD, folder, ignore=shutil.ignore_patterns("assets", "demonstrations", "*.toml"))
        _write(folder, files)
        written = {name: tomllib.loads((folder / name).read_text()) for name in FILES}
        assert json.dumps(written) == json.dumps(files)  # the files hold the mutation (NaN included)
        try:
            load_product_description(folder)
        except BridgeError as exc:
            message = str(exc)
            assert message.startswith(str(folder)) and "\n" not in message and len(message) < 600, message
            _one_line_exit_2(["executor", "trial", "--assembly", str(folder), "--part", "p1", "--hole", "r1"], capsys)
            _one_line_exit_2(["plan", "--optimal", "--assembly", str(folder), str(folder / "sizes.lp"),
                              str(folder / "precedence.lp")], capsys)
            return
        try:
            _builds(folder)
        except ToolError as exc:  # only what a cell adds: no [base] for the assembling cell
            assert "no [base] table" in str(exc), str(exc)

