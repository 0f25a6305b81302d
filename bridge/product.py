"""The product description: ``assembly.toml`` and ``geometry.toml`` of an assembly folder,
decoded into typed structs and checked as a whole, in one place.

Both the planner (parts, holes, the declared size model) and the cell (dimensions, the
base, covers and heads) read a product; they meet only through ``bridge``, so the one
loader is here. :func:`load_product_description` reads the files with :mod:`tomllib`,
converts them with msgspec into :class:`AssemblyFile` and :class:`GeometryFile` (types,
ranges, required and unknown keys; the ranges and their units are in the types'
descriptions, so the JSON Schema :func:`product_schema` publishes says the same), then
checks what one struct cannot: references between tables (a hole's position, a part's
start, a ``demo_hole``, a cover's holes, a head's cover), a rect's size ``[a, b]`` with
``a >= b``, a chamfer inside its boss, bosses that do not overlap, a grasp shorter than
the part, the shapes of ``assembly.toml`` against the kinds of ``geometry.toml``.

Every failure is one line ``<file>: [<table>] <key>: expected ..., got ...`` (a
:class:`bridge.BridgeError`, exit 2). Units: lengths and positions [m], masses [kg],
inertia [kg m^2], yaw [degrees].

Pairs and quadruples are lists of fixed length, not tuples: msgspec 0.22 corrupts memory
when a union holds a constrained float and a tuple of them (docs/decisions.md).
"""

from __future__ import annotations

import math
import re
import tomllib
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Annotated, Any, Literal, TypeVar

import msgspec
from msgspec import Meta

from bridge import BridgeError
from bridge.inputs import read_text, shorten

ID_PATTERN = r"^(?!not$)[a-z][a-zA-Z0-9_]{0,63}$(?!\n)"
"""A part or hole id: an ASP constant of at most 64 ASCII characters, a lower-case letter
first, not the keyword ``not`` (clingo's only lower-case keyword). ``(?!\n)`` keeps a
trailing newline out (Python's ``$`` would match before it); the pattern means the same
in Python and in JSON Schema (ECMA 262)."""
_ID = re.compile(ID_PATTERN)
_T = TypeVar("_T")


def is_id(value: object) -> bool:
    """Whether ``value`` is a part or hole id (:data:`ID_PATTERN`)."""
    return isinstance(value, str) and _ID.match(value) is not None


MAX_COORDINATE = 100.0
"""Positions ([x, y] of parts and holes, a tool home) are finite with |x|, |y| <= this [m]."""
SHAPES = ("round", "square", "rect")
"""The cross-section kinds of a part's or hole's ``shape`` (``kind`` in ``geometry.toml``)."""
SIZE_MODELS = ("line", "sections", "pairs")
"""The size models a product may declare (``[sizes] model``; docs/sizes.md)."""
TOUCH_TOLERANCE = 1e-6
"""Bosses of neighbouring holes may touch (Cranfield's do), not overlap: up to rounding [m]."""
DEFAULT_COVER_CLEARANCE = 0.003
"""A cover's openings are its holes' sizes plus this when the file gives no ``clearance`` [m]."""

Id = Annotated[str, Meta(pattern=ID_PATTERN, description="an id (a lower-case ASP constant of at most 64 "
                         "characters, not 'not')")]
Ids = Annotated[list[Id], Meta(min_length=1, max_length=1000, description="a non-empty list of distinct ids")]
Text = Annotated[str, Meta(min_length=1, max_length=200, description="a non-empty text of at most 200 characters")]
Kind = Literal["round", "square", "rect"]
Coordinate = Annotated[float, Meta(ge=-MAX_COORDINATE, le=MAX_COORDINATE,
                                   description="a number in [-100, 100] m")]
XY = Annotated[list[Coordinate], Meta(min_length=2, max_length=2,
                                      description="[x, y] in metres, finite and within ±100")]
Offset = Annotated[float, Meta(ge=-1.0, le=1.0, description="a number in [-1, 1] m")]
OffsetXY = Annotated[list[Offset], Meta(min_length=2, max_length=2, description="[x, y], each in [-1, 1] m")]
Side = Annotated[float, Meta(gt=0.0, le=0.1, description="a number in (0, 0.1] m")]
SectionSize = Side | Annotated[list[Side], Meta(min_length=2, max_length=2, description="for a rect [a, b] with "
                                                "a >= b, each such a number")]
Length = Annotated[float, Meta(gt=0.0, le=0.3, description="a number in (0, 0.3] m")]
Mass = Annotated[float, Meta(gt=0.0, le=10.0, description="a number in (0, 10] kg")]
Yaw = Annotated[float, Meta(gt=-360.0, le=360.0, description="a number in (-360, 360] degrees")]


class Table(msgspec.Struct, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """A table of a product file: unknown keys are refused."""


# ---- assembly.toml ----

class PartEntry(Table, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """``[parts.<id>]``: a readable ``name``, a ``role``, where the part waits (``start``
    [m]), its cross-section kind (``shape``) and, for a rect part, its ``section`` label
    (parts of one section are scaled copies of one cross-section)."""

    name: Text | None = None
    role: Text = "part"
    start: XY | None = None
    shape: Kind | None = None
    section: Id | None = None


class HoleEntry(Table, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """``[holes.<id>]``: a readable ``name``, its cross-section kind, its ``position`` [m]
    on the base plate."""

    name: Text | None = None
    shape: Kind = "round"
    position: XY | None = None


class SizesTable(Table, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """``[sizes]``: the size model the product declares (docs/sizes.md)."""

    model: Literal["line", "sections", "pairs"]


class AssemblyFile(Table, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """``assembly.toml``: the parts (at least one), the holes, the declared size model."""

    parts: Annotated[dict[Id, PartEntry], Meta(min_length=1)]
    name: Text | None = None
    holes: dict[Id, HoleEntry] = {}
    sizes: SizesTable | None = None


# ---- geometry.toml ----

class Plate(Table, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """``[plate]``: the bosses' top face height, side and thickness (= hole depth), the
    entry chamfer [m], the sides of a round hole's polygon, the plate under the bosses."""

    top_z: Annotated[float, Meta(gt=0.0, le=1.0, description="a number in (0, 1] m")]
    tile_size: Annotated[float, Meta(gt=0.0, le=0.5, description="a number in (0, 0.5] m")]
    tile_thickness: Annotated[float, Meta(gt=0.0, le=0.2, description="a number in (0, 0.2] m")]
    chamfer: Annotated[float, Meta(gt=0.0, le=0.01, description="a number in (0, 0.01] m")]
    polygon_sides: Annotated[int, Meta(ge=8, le=256, multiple_of=8,
                                       description="an integer multiple of 8 in 8 .. 256")]
    base_thickness: Annotated[float, Meta(gt=0.0, le=0.2, description="a number in (0, 0.2] m")]
    base_size: Annotated[list[Annotated[float, Meta(gt=0.0, le=2.0)]],
                         Meta(min_length=2, max_length=2, description="[x, y], each a number in (0, 2] m")]
    base_center: XY


class Gripper(Table, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """``[gripper]``: flange + F/T sensor + gripper mass [kg] and inertia [kg m^2], flange
    face to the fingertips [m], part length inside the fingers [m]."""

    flange_mass: Annotated[float, Meta(gt=0.0, le=20.0, description="a number in (0, 20] kg")]
    flange_inertia: Annotated[float, Meta(gt=0.0, le=1.0, description="a number in (0, 1] kg m^2")]
    flange_length: Annotated[float, Meta(gt=0.0, le=0.5, description="a number in (0, 0.5] m")]
    grasp_depth: Annotated[float, Meta(gt=0.0, le=0.2, description="a number in (0, 0.2] m")]


class HoleShape(Table, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """``[hole_shapes.<name>]``: holes of one cross-section; ``size`` a diameter or side
    [m], for a rect ``[a, b]`` (a along the hole's x axis, turned by ``yaw`` [degrees])."""

    holes: Ids
    kind: Kind
    size: SectionSize
    yaw: Yaw = 0.0


class PartShape(Table, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """``[part_shapes.<name>]``: pegs of one cross-section (the name is their skill's);
    ``length`` [m], ``mass`` [kg], the hole its demonstration is taught in."""

    parts: Ids
    kind: Kind
    size: SectionSize
    length: Length
    mass: Mass
    demo_hole: Id


class ExtraPart(Table, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """``[extra_parts.<id>]``: a part of the cell that is not in ``assembly.toml``."""

    start: XY
    name: Text | None = None


class Base(Table, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """``[base]``: the part carrying the plate, where its ``base_center`` waits (``tray``
    [m]), its grip point from ``base_center`` [m], its mass [kg]."""

    part: Id
    tray: XY
    grip: OffsetXY
    mass: Annotated[float, Meta(gt=0.0, le=50.0, description="a number in (0, 50] kg")]


class Cover(Table, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """``[covers.<id>]``: a part whose openings go down over the pins in the holes
    ``over``; ``outline`` [xmin, ymin, xmax, ymax] [m] around their centre, ``socket``
    ``[x, y, side, depth]`` [m] an optional blind opening for a head, ``skill`` the part
    shape whose taught motion places it."""

    over: Ids
    outline: Annotated[list[Offset], Meta(min_length=4, max_length=4,
                                          description="[xmin, ymin, xmax, ymax], each in [-1, 1] m")]
    thickness: Annotated[float, Meta(gt=0.0, le=0.1, description="a number in (0, 0.1] m")]
    mass: Mass
    grip: OffsetXY
    tray: XY
    skill: Id
    bottom: Annotated[float, Meta(ge=0.0, le=0.5, description="a number in [0, 0.5] m")] = 0.0
    clearance: Annotated[float, Meta(ge=0.0, le=0.02, description="a number in [0, 0.02] m")] = \
        DEFAULT_COVER_CLEARANCE
    socket: Annotated[list[Offset], Meta(min_length=4, max_length=4,
                                         description="[x, y, side, depth] in m")] | None = None
    name: Text | None = None


class Head(Table, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """``[heads.<id>]``: a part going into the socket of cover ``into``; round (``size``
    a diameter) or square (a side) [m], ``length`` [m], ``mass`` [kg]."""

    into: Id
    size: Side
    length: Length
    mass: Mass
    skill: Id
    kind: Literal["round", "square"] = "round"
    name: Text | None = None


class GeometryFile(Table, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """``geometry.toml``: the plate, the cross-sections of holes and pegs, the cell's extra
    parts, an optional gripper (else the cell description's), the product's base, covers
    and heads."""

    plate: Plate
    hole_shapes: dict[Id, HoleShape] = {}
    part_shapes: dict[Id, PartShape] = {}
    extra_parts: dict[Id, ExtraPart] = {}
    gripper: Gripper | None = None
    base: Base | None = None
    covers: dict[Id, Cover] = {}
    heads: dict[Id, Head] = {}


class ProductDescription(msgspec.Struct, frozen=True, kw_only=True):
    """A product folder as decoded and checked: ``geometry`` None when it has no
    ``geometry.toml`` (a planner-only product)."""

    folder: Path
    assembly: AssemblyFile
    geometry: GeometryFile | None


# ---- reading and translating errors ----

def _where(table: str, key: str) -> str:
    """``[table] key``, ``[table]`` or ``key``."""
    return " ".join(([f"[{table}]"] if table else []) + ([key] if key else []))


def _fail(path: Path, table: str, key: str, expected: str, value: object) -> BridgeError:
    return BridgeError(f"{path}: {_where(table, key)}: expected {expected}, got {shorten(repr(value))}")


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
        raise BridgeError(f"{path}: nested too deeply; expected the tables of docs/geometry.md") from None


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
        table = ".".join(names)
        return _fail(path, table, "a table name", _expected(msgspec.inspect.type_info(Id)),
                     bad[0] if bad else entries)
    segments = _segments(at, data, root)
    while segments and isinstance(segments[-1], int):  # a bad item: name its list
        segments.pop()
    missing = re.match(r"Object missing required field `(\w+)`", what)
    unknown = re.match(r"Object contains unknown field `(.+)`$", what)
    if unknown:
        parent = _unwrap(_info_at(root, segments))
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
        return BridgeError(f"{path}: {_where(table, key)}: expected {expected}, got nothing (a required key)")
    return _fail(path, table, key, expected, value)


def _info_at(root: msgspec.inspect.Type, segments: list[str | int]) -> msgspec.inspect.Type:
    info = root
    for segment in segments:
        child = _child(info, segment)
        if child is None:
            return info
        info = child
    return info


# ---- the checks between tables ----

def _sides(size: float | list[float]) -> tuple[float, float]:
    """(a, b) [m] of a decoded section size: a rect's ``[a, b]``, else the size twice."""
    return (size[0], size[1]) if isinstance(size, list) else (size, size)


def _check_assembly(path: Path, layout: AssemblyFile) -> None:
    for pid, part in layout.parts.items():
        if part.section is not None and part.shape != "rect":
            raise BridgeError(f"{path}: [parts.{pid}] section: only a part of shape \"rect\" has one "
                              f"(a {part.shape or 'part without a shape'} is its own section)")
    clash = set(layout.parts) & set(layout.holes)
    if clash:
        raise BridgeError(f"{path}: ids used for both a part and a hole: {sorted(clash)}")


def _members(path: Path, group: str, tables: Mapping[str, HoleShape] | Mapping[str, PartShape]) -> dict[str, str]:
    """Member id -> shape name; each id in one shape table once."""
    owner: dict[str, str] = {}
    for name, table in tables.items():
        members = table.holes if isinstance(table, HoleShape) else table.parts
        key = "holes" if isinstance(table, HoleShape) else "parts"
        for member in members:
            if member in owner:
                raise _fail(path, f"{group}.{name}", key, f"ids not already in [{group}.{owner[member]}]", member)
            owner[member] = name
    return owner


def _check_sections(path: Path, group: str, tables: Mapping[str, HoleShape] | Mapping[str, PartShape]) -> None:
    """A rect's size is ``[a, b]`` with a >= b, any other kind's one number."""
    for name, table in tables.items():
        rect, size = table.kind == "rect", table.size
        if rect != isinstance(size, list):
            expected = ("[a, b] in m with a >= b > 0 (the long side a along x) for a rect" if rect
                        else f"one number (the {'diameter' if table.kind == 'round' else 'side'}) for a {table.kind}")
            raise _fail(path, f"{group}.{name}", "size", expected, size)
        if isinstance(size, list) and size[0] < size[1]:
            raise _fail(path, f"{group}.{name}", "size", "[a, b] with a >= b (the long side a along x)", size)


def check_grasp(path: Path, geometry: GeometryFile, gripper: Gripper) -> None:
    """Every peg is longer than the part of it inside ``gripper``'s fingers."""
    for name, table in geometry.part_shapes.items():
        if gripper.grasp_depth >= table.length:
            raise _fail(path, f"part_shapes.{name}", "length",
                        f"longer than [gripper] grasp_depth ({gripper.grasp_depth:g} m)", table.length)


def _check_geometry(path: Path, geo: GeometryFile, layout: AssemblyFile) -> None:
    plate = geo.plate
    holes = _members(path, "hole_shapes", geo.hole_shapes)
    pegs = _members(path, "part_shapes", geo.part_shapes)
    _check_sections(path, "hole_shapes", geo.hole_shapes)
    _check_sections(path, "part_shapes", geo.part_shapes)
    if plate.chamfer >= plate.tile_thickness:
        raise _fail(path, "plate", "chamfer", f"less than tile_thickness ({plate.tile_thickness:g} m)", plate.chamfer)
    for name, hole_shape in geo.hole_shapes.items():
        if _sides(hole_shape.size)[0] + 2 * plate.chamfer >= plate.tile_size:
            raise _fail(path, f"hole_shapes.{name}", "size", f"a hole and its chamfer inside the {plate.tile_size:g} "
                        "m boss (size + 2 chamfer < tile_size)", hole_shape.size)
    for name, part_shape in geo.part_shapes.items():
        if part_shape.demo_hole not in holes:
            raise _fail(path, f"part_shapes.{name}", "demo_hole",
                        f"a hole of [hole_shapes.*] ({', '.join(sorted(holes))})", part_shape.demo_hole)
    if geo.gripper is not None:
        check_grasp(path, geo, geo.gripper)
    for hid, name in holes.items():
        entry = layout.holes.get(hid)
        if entry is None or entry.position is None:
            why = "has no position there" if entry is not None else "is not a hole there"
            raise _fail(path, f"hole_shapes.{name}", "holes", f"holes of assembly.toml with a position ({hid} {why})",
                        hid)
    starts = {pid for pid, part in layout.parts.items() if part.start is not None} | set(geo.extra_parts)
    for pid, name in pegs.items():
        if pid not in starts:
            raise _fail(path, f"part_shapes.{name}", "parts", "parts of assembly.toml with a start, or of "
                        f"[extra_parts] ({pid} is neither)", pid)
    for pid in geo.extra_parts:
        if pid in layout.parts:
            raise _fail(path, f"extra_parts.{pid}", "start", "a part that is not in assembly.toml (this one is)",
                        pid)
    positions = {hid: layout.holes[hid].position for hid in holes}
    turned = {hid for hole_shape in geo.hole_shapes.values() if hole_shape.yaw for hid in hole_shape.holes}
    _check_bosses(path, plate.tile_size, {h: (p[0], p[1]) for h, p in positions.items() if p is not None}, turned)
    _check_kinds(path, geo, layout)
    _check_product(path, geo, layout, holes)


def _check_bosses(path: Path, tile: float, positions: Mapping[str, tuple[float, float]], turned: set[str]) -> None:
    """No two square bosses (side ``tile`` [m], around the holes at ``positions``) overlap.
    A boss of a ``turned`` hole is turned with it: two bosses whose centres are closer than
    ``tile`` overlap whatever their yaws (their inscribed circles do)."""
    ordered = sorted(positions.items())
    for k, (a, (xa, ya)) in enumerate(ordered):
        for b, (xb, yb) in ordered[k + 1:]:
            if a in turned or b in turned:
                overlap = math.hypot(xa - xb, ya - yb) < tile - TOUCH_TOLERANCE
            else:
                overlap = abs(xa - xb) < tile - TOUCH_TOLERANCE and abs(ya - yb) < tile - TOUCH_TOLERANCE
            if overlap:
                raise BridgeError(f"{path}: [plate] tile_size: expected bosses that do not overlap, got holes "
                                  f"{a} at ({xa:g}, {ya:g}) and {b} at ({xb:g}, {yb:g}) m closer than {tile:g} m")


def _describe(kind: str, size: float | list[float]) -> str:
    """``round d 12 mm``, ``square 4 mm``, ``rect 16 x 10 mm``."""
    a, b = (1000 * side for side in _sides(size))
    return {"round": f"round d {a:g} mm", "square": f"square {a:g} mm"}.get(kind, f"rect {a:g} x {b:g} mm")


def _check_kinds(path: Path, geo: GeometryFile, layout: AssemblyFile) -> None:
    """The ``shape`` of each part and hole in ``assembly.toml`` (where given) is the
    ``kind`` of its cross-section in ``geometry.toml``, and the parts of one ``section``
    are scaled copies of one cross-section (one aspect ratio b/a, all round or none)."""
    source = path.parent / "assembly.toml"
    part_shape = {pid: shape for shape in geo.part_shapes.values() for pid in shape.parts}
    hole_shape = {hid: shape for shape in geo.hole_shapes.values() for hid in shape.holes}
    declared: list[tuple[str, str, str | None, HoleShape | PartShape | None]]
    declared = [(pid, "part", part.shape, part_shape.get(pid)) for pid, part in layout.parts.items()]
    declared += [(hid, "hole", hole.shape, hole_shape.get(hid)) for hid, hole in layout.holes.items()]
    for item, what, shape, spec in declared:
        if shape is not None and spec is not None and spec.kind != shape:
            raise BridgeError(f"{source}: {what} '{item}' has shape \"{shape}\" but geometry.toml gives it kind "
                              f"\"{spec.kind}\"")
    first: dict[str, tuple[str, PartShape]] = {}
    for pid, part in layout.parts.items():
        spec = part_shape.get(pid)
        if part.shape is None or spec is None:
            continue
        section = part.section or (pid if part.shape == "rect" else part.shape)
        other_id, other = first.setdefault(section, (pid, spec))
        (a, b), (oa, ob) = _sides(spec.size), _sides(other.size)
        if (other.kind == "round") != (spec.kind == "round") or not math.isclose(b / a, ob / oa, rel_tol=1e-9):
            raise BridgeError(f"{source}: parts '{other_id}' and '{pid}' share section \"{section}\" but are no "
                              f"scaled copies of one cross-section ({_describe(other.kind, other.size)} and "
                              f"{_describe(spec.kind, spec.size)} in geometry.toml)")


def _check_product(path: Path, geo: GeometryFile, layout: AssemblyFile, holes: Mapping[str, str]) -> None:
    """The base, covers and heads name parts of ``assembly.toml``, holes of the plate, part
    shapes (their skills) and covers with a socket; with a ``[base]``, every part of
    ``assembly.toml`` has exactly one geometry."""
    skills = sorted(geo.part_shapes)
    pegs = {pid for shape in geo.part_shapes.values() for pid in shape.parts}
    for cid, cover in geo.covers.items():
        table = f"covers.{cid}"
        for hid in cover.over:
            if hid not in holes:
                raise _fail(path, table, "over", f"holes of [hole_shapes.*] ({', '.join(sorted(holes))})", hid)
        if len(set(cover.over)) != len(cover.over):
            raise _fail(path, table, "over", "distinct holes", cover.over)
        xmin, ymin, xmax, ymax = cover.outline
        if not (xmin < xmax and ymin < ymax):
            raise _fail(path, table, "outline", "[xmin, ymin, xmax, ymax] with xmin < xmax and ymin < ymax",
                        cover.outline)
        if cover.socket is not None and not (0 < cover.socket[2] and 0 < cover.socket[3] < cover.thickness):
            raise _fail(path, table, "socket", f"[x, y, side, depth] with side > 0 and 0 < depth < thickness "
                        f"({cover.thickness:g} m)", cover.socket)
        if cover.skill not in geo.part_shapes:
            raise _fail(path, table, "skill", f"a part shape of [part_shapes.*] ({', '.join(skills)})", cover.skill)
    for hid, head in geo.heads.items():
        table = f"heads.{hid}"
        cover_of = geo.covers.get(head.into)
        if cover_of is None or cover_of.socket is None:
            with_socket = sorted(c for c, t in geo.covers.items() if t.socket is not None)
            raise _fail(path, table, "into", f"a cover with a socket ({', '.join(with_socket) or 'none'})",
                        head.into)
        if head.skill not in geo.part_shapes:
            raise _fail(path, table, "skill", f"a part shape of [part_shapes.*] ({', '.join(skills)})", head.skill)
        part = layout.parts.get(hid)
        if part is None or part.start is None:
            raise _fail(path, table, "", "a part of assembly.toml with a start", hid)
    for cid in geo.covers:
        if cid not in layout.parts:
            raise _fail(path, f"covers.{cid}", "", "a part of assembly.toml", cid)
    if geo.base is None:
        return
    if geo.base.part not in layout.parts:
        raise _fail(path, "base", "part", f"a part of assembly.toml ({', '.join(layout.parts)})", geo.base.part)
    owners: dict[str, list[str]] = {pid: [] for pid in layout.parts}
    for pid in pegs:
        owners.get(pid, []).append("[part_shapes.*]")
    for pid in geo.covers:
        owners[pid].append("[covers.*]")
    for pid in geo.heads:
        owners[pid].append("[heads.*]")
    owners[geo.base.part].append("[base]")
    missing = sorted(pid for pid, tables in owners.items() if not tables)
    if missing:
        raise BridgeError(f"{path}: part(s) {', '.join(missing)} of assembly.toml have no geometry "
                          "(expected a [part_shapes.*], [covers.*], [heads.*] or [base] entry)")
    twice = sorted(pid for pid, tables in owners.items() if len(tables) > 1)
    if twice:
        raise BridgeError(f"{path}: part {twice[0]} of assembly.toml has more than one geometry "
                          f"({' and '.join(owners[twice[0]])}); expected one")


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
    _check_assembly(source, layout)
    if geometry is None:
        return ProductDescription(folder=folder, assembly=layout, geometry=None)
    path = folder / "geometry.toml"
    tables = _decode(path, geometry, GeometryFile)
    _check_geometry(path, tables, layout)
    return ProductDescription(folder=folder, assembly=layout, geometry=tables)


def product_schema() -> dict[str, Any]:
    """The JSON Schema (2020-12) of ``assembly.toml`` and ``geometry.toml`` as decoded
    TOML: one document with both files' definitions."""
    (assembly, geometry), definitions = msgspec.json.schema_components([AssemblyFile, GeometryFile])
    return {"$schema": "https://json-schema.org/draft/2020-12/schema",
            "title": "product description (assembly.toml, geometry.toml)",
            "description": "An assembly folder's assembly.toml and geometry.toml as decoded TOML "
                           "(docs/geometry.md); generated from bridge/product.py.",
            "properties": {"assembly.toml": assembly, "geometry.toml": geometry},
            "$defs": definitions}
