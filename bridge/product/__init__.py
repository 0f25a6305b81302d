"""The product description: ``assembly.toml`` and ``geometry.toml`` of an assembly folder,
decoded into typed structs and checked as a whole, in one place.

Both the planner (parts, holes, the declared size model) and the cell (dimensions, the
base, covers and heads) read a product; they meet only through ``bridge``, so the one
loader is here. :func:`load_product_description` reads the files with :mod:`tomllib`,
converts them with msgspec into :class:`AssemblyFile` and :class:`GeometryFile` (types,
ranges, required and unknown keys; the ranges and their units are in the types'
descriptions, so the JSON Schema ``protocol --out`` publishes, docs/protocol/, says the
same), then checks (:mod:`bridge.product.checks`) what one struct cannot: references
between tables (a hole's position, a part's start, a ``demo_hole``, a cover's holes, a
head's cover), a rect's size ``[a, b]`` with ``a >= b``, a chamfer inside its boss,
every hole deeper than its chamfer (a hole at its own level with its bottom above the
floor), bosses that do not overlap, a grasp shorter than the part, the shapes of
``assembly.toml`` against the kinds of ``geometry.toml``, a part's mesh against the
digest of its file and its convex pieces against that mesh. Each part's and hole's
cross-section kind comes from every statement the product makes
(:mod:`bridge.product.kinds`).

Every failure is one line ``<file>: [<table>] <key>: expected ..., got ...`` (a
:class:`bridge.BridgeError`, exit 2). Units: lengths and positions [m], masses [kg],
inertia [kg m^2], yaw [degrees].
"""

from __future__ import annotations

import re
import tomllib
from collections.abc import Iterable
from pathlib import Path
from typing import Any, TypeVar

import msgspec

from bridge import BridgeError
from bridge.inputs import read_text, shorten
from bridge.product.checks import (
    check_assembly,
    check_geometry,
    check_grasp,
    fail,
    hole_level,
    where,
)
from bridge.product.kinds import hole_kinds, part_kinds, section_label
from bridge.product.tables import (
    CONVEX_HEADER,
    DEFAULT_COVER_CLEARANCE,
    ID_PATTERN,
    MAX_COORDINATE,
    SHAPES,
    SIZE_MODELS,
    AssemblyFile,
    Base,
    Cover,
    ExtraPart,
    GeometryFile,
    Gripper,
    Head,
    HoleEntry,
    HoleShape,
    Id,
    Manual,
    Mesh,
    PartEntry,
    PartShape,
    Plate,
    ProductDescription,
    SizesTable,
    is_id,
)

__all__ = ["CONVEX_HEADER", "DEFAULT_COVER_CLEARANCE", "ID_PATTERN", "MAX_COORDINATE", "SHAPES", "SIZE_MODELS",
           "AssemblyFile", "Base", "Cover", "ExtraPart", "GeometryFile", "Gripper", "Head", "HoleEntry", "HoleShape",
           "Manual", "Mesh", "PartEntry", "PartShape", "Plate", "ProductDescription", "SizesTable", "check_grasp",
           "decode_toml_file", "hole_kinds", "hole_level", "is_id", "load_product_description", "part_kinds",
           "product_from_tables", "section_label"]

_T = TypeVar("_T")
# ---- reading and translating errors ----

def decode_toml_file(path: Path, what: str, kind: type[_T]) -> _T:
    """The TOML file ``path`` (``what`` names it in messages) decoded as a ``kind``;
    one-line BridgeError naming the file, table and key on bad input."""
    return _decode(path, _read(path, what), kind)


def _read(path: Path, what: str) -> dict[str, Any]:
    try:
        return tomllib.loads(read_text(path, what))
    except tomllib.TOMLDecodeError as exc:
        raise BridgeError(f"{path}: not valid TOML ({exc})") from None
    except RecursionError:
        raise BridgeError(f"{path}: nested too deeply; expected a {what}") from None


_MISSING = object()
_SEGMENT = re.compile(r"\.([A-Za-z0-9_]+)|\[(\d+)\]|(\[\.\.\.\])")
_ERROR = re.compile(r"^(?P<what>.*?)(?: - at `(?P<at>[^`]*)`(?: in `(?P<outer>[^`]*)`)?)?$", re.S)


def _segments(at: str, data: object, root: msgspec.inspect.Type) -> list[str | int]:
    """The keys and indexes of a msgspec error path (``$.covers[...].mass``); msgspec
    writes ``[...]`` for a key of a table of tables: the first entry that does not
    convert is the one it means (entries are converted in order)."""
    segments: list[str | int] = []
    info: msgspec.inspect.Type | None = root
    for name, index, _unnamed in _SEGMENT.findall(at):
        segment: str | int = name if name else int(index) if index else _first_bad_entry(_value_at(data, segments),
                                                                                             info)
        segments.append(segment)
        info = None if info is None else _child(info, segment)
    return segments


def _first_bad_entry(entries: object, info: msgspec.inspect.Type | None) -> str:
    value = None if info is None else _unwrap(info)
    if isinstance(entries, dict) and isinstance(value, msgspec.inspect.DictType):
        kind = _unwrap(value.value_type)
        for key, entry in entries.items():
            if not isinstance(kind, msgspec.inspect.StructType):
                break
            try:
                msgspec.convert(entry, kind.cls, strict=True)
            except msgspec.ValidationError:
                return str(key)
    return "..."


def _unwrap(info: msgspec.inspect.Type) -> msgspec.inspect.Type:
    return info.type if isinstance(info, msgspec.inspect.Metadata) else info


def _child(info: msgspec.inspect.Type, segment: str | int) -> msgspec.inspect.Type | None:
    """The type of ``segment`` (a key or an index) inside ``info``, None if it has none."""
    info = _unwrap(info)
    if isinstance(info, msgspec.inspect.UnionType):
        found = (_child(member, segment) for member in info.types)
        return next((child for child in found if child is not None), None)
    if isinstance(info, msgspec.inspect.StructType):
        return next((f.type for f in info.fields if f.encode_name == segment), None)
    if isinstance(info, msgspec.inspect.DictType) and isinstance(segment, str):
        return info.value_type
    if isinstance(info, msgspec.inspect.ListType) and isinstance(segment, int):
        return info.item_type
    return None


def _expected(info: msgspec.inspect.Type) -> str:
    """What a value of ``info`` must be, in words (its description where it has one)."""
    if isinstance(info, msgspec.inspect.Metadata):
        description = (info.extra_json_schema or {}).get("description")
        return str(description) if description else _expected(info.type)
    if isinstance(info, msgspec.inspect.UnionType):
        return ", or ".join(_expected(t) for t in info.types if not isinstance(t, msgspec.inspect.NoneType))
    if isinstance(info, msgspec.inspect.LiteralType):
        return "one of " + ", ".join(sorted(map(str, info.values)))
    if isinstance(info, msgspec.inspect.StructType):
        return "a table with the keys " + ", ".join(f.encode_name for f in info.fields)
    if isinstance(info, msgspec.inspect.DictType):
        return "a table of tables, each named by an id"
    names = {msgspec.inspect.StrType: "a text", msgspec.inspect.FloatType: "a number",
             msgspec.inspect.IntType: "an integer", msgspec.inspect.BoolType: "true or false"}
    return names.get(type(info), "a list")


def _is_table(info: msgspec.inspect.Type) -> bool:
    info = _unwrap(info)
    if isinstance(info, msgspec.inspect.UnionType):
        return any(_is_table(t) for t in info.types if not isinstance(t, msgspec.inspect.NoneType))
    return isinstance(info, msgspec.inspect.StructType | msgspec.inspect.DictType)


def _value_at(data: object, segments: Iterable[str | int]) -> object:
    for segment in segments:
        if isinstance(data, dict) and isinstance(segment, str) and segment in data:
            data = data[segment]
        elif isinstance(data, list) and isinstance(segment, int) and segment < len(data):
            data = data[segment]
        else:
            return _MISSING
    return data


def _location(segments: list[str | int], table: bool) -> tuple[str, str]:
    """(table, key) naming ``segments``: ``plate``, ``top_z``; (``covers.c1``, "") for a table."""
    names = [str(s) for s in segments]
    if table:
        return ".".join(names), ""
    return ".".join(names[:-1]), names[-1] if names else ""


def _decode(path: Path, data: dict[str, Any], kind: type[_T]) -> _T:
    """``data`` (a decoded TOML file) as a ``kind``; one-line BridgeError naming the table,
    the key, what it must be and what it is."""
    try:
        return msgspec.convert(data, kind, strict=True)
    except msgspec.ValidationError as exc:
        raise _translated(path, data, kind, str(exc)) from None


def _translated(path: Path, data: dict[str, Any], kind: type, message: str) -> BridgeError:
    match = _ERROR.match(message)
    assert match is not None  # the pattern matches any text
    what, at, outer = match["what"], match["at"] or "$", match["outer"]
    root: msgspec.inspect.Type = msgspec.inspect.type_info(kind)
    if outer is not None:  # a table name that is no id: find it
        names = [s for s in _segments(outer, data, root) if not isinstance(s, int)]
        entries = _value_at(data, names)
        bad = [key for key in entries if not is_id(key)] if isinstance(entries, dict) else []
        table, key = ".".join(names), bad[0] if bad else "..."
        return BridgeError(f"{path}: [{table}.{shorten(key)}]: expected a table name that is "
                           f"{_expected(msgspec.inspect.type_info(Id))}, got {shorten(repr(key))}")
    segments = _segments(at, data, root)
    while segments and isinstance(segments[-1], int):  # a bad item: name its list
        segments.pop()
    missing = re.match(r"Object missing required field `(\w+)`", what)
    unknown = re.match(r"Object contains unknown field `(.+)`$", what)
    if unknown:
        parent = _unwrap(_info_at(root, segments))
        if isinstance(parent, msgspec.inspect.UnionType):  # an optional table (``mesh``): its table's keys
            parent = next((t for t in parent.types if isinstance(t, msgspec.inspect.StructType)), parent)
        keys = [f.encode_name for f in parent.fields] if isinstance(parent, msgspec.inspect.StructType) else []
        table, key = ".".join(map(str, segments)), unknown[1]
        return BridgeError(f"{path}: [{table}] {key}: unknown key; expected one of {', '.join(keys)}"
                           if table else f"{path}: {key}: unknown table or key; expected one of {', '.join(keys)}")
    if missing:
        segments.append(missing[1])
    info = _info_at(root, segments)
    table, key = _location(segments, _is_table(info))
    value = _value_at(data, segments)
    expected = _expected(info)
    if value is _MISSING:
        return BridgeError(f"{path}: {where(table, key)}: expected {expected}, got nothing (a required key)")
    return fail(path, table, key, expected, value)


def _info_at(root: msgspec.inspect.Type, segments: list[str | int]) -> msgspec.inspect.Type:
    info = root
    for segment in segments:
        child = _child(info, segment)
        if child is None:
            return info
        info = child
    return info


def load_product_description(folder: Path) -> ProductDescription:
    """The product of an assembly folder (holding ``assembly.toml``, optionally
    ``geometry.toml``), decoded and checked as a whole (:func:`product_from_tables`)."""
    path = folder / "geometry.toml"
    geometry = _read(path, "cell geometry file (geometry.toml, TOML)") if path.exists() else None
    return product_from_tables(folder, _read(folder / "assembly.toml", "assembly file (TOML)"), geometry)


def product_from_tables(folder: Path, assembly: dict[str, Any], geometry: dict[str, Any] | None) -> ProductDescription:
    """The product of the decoded TOML of ``folder``'s ``assembly.toml`` and (None: there
    is none) ``geometry.toml``, checked as a whole; one-line BridgeError naming the file,
    the table and key, what was expected and what it holds."""
    source = folder / "assembly.toml"
    layout = _decode(source, assembly, AssemblyFile)
    path = folder / "geometry.toml"
    tables = None if geometry is None else _decode(path, geometry, GeometryFile)
    check_assembly(source, layout, part_kinds(layout, tables))
    if tables is not None:
        check_geometry(path, tables, layout)
    return ProductDescription(folder=folder, assembly=layout, geometry=tables)

