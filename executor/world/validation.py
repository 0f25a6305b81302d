"""The one check of a cell's ``geometry.toml`` before anything is built from it.

Table-driven: :data:`PLATE`, :data:`GRIPPER`, :data:`HOLE_SHAPE` and :data:`PART_SHAPE`
give every key the cell reads with its type and accepted range; then the references
(each hole and part in one shape table, ``demo_hole`` a hole of the file) and what the
mesh needs (a chamfer inside its boss, bosses that do not overlap, a grasp shorter than
the part). Every failure is one line ``<file>: [<table>] <key>: expected ..., got ...``
(an ExecutorError, exit 2). Cross-section kinds are :data:`KINDS`, one set to extend.
The product tables (``[base]``, ``[covers.*]``, ``[heads.*]``) are checked by the
assembling cell's reader.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from assembly_constraints.bridge.assembly import MAX_COORDINATE, Assembly
from assembly_constraints.bridge.inputs import shorten
from assembly_constraints.executor import ExecutorError

KINDS = frozenset({"round", "square", "rect"})
"""Cross-sections: "round" size = diameter, "square" size = side, "rect" size = [a, b] (a >= b)."""
# Bosses of neighbouring holes may touch (Cranfield's do), not overlap: up to rounding [m].
TOUCH_TOLERANCE = 1e-6


@dataclass(frozen=True)
class Real:
    """A finite number ``low`` < value ≤ ``high`` in ``unit``."""

    low: float
    high: float
    unit: str = "m"

    def accepts(self, value: object) -> bool:
        return (isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
                and self.low < value <= self.high)

    def expected(self) -> str:
        return f"a number in ({self.low:g}, {self.high:g}] {self.unit}"


@dataclass(frozen=True)
class Count:
    """An integer ``low`` ≤ value ≤ ``high``, a multiple of ``step``."""

    low: int
    high: int
    step: int = 1

    def accepts(self, value: object) -> bool:
        return (isinstance(value, int) and not isinstance(value, bool) and self.low <= value <= self.high
                and value % self.step == 0)

    def expected(self) -> str:
        return f"an integer multiple of {self.step} in {self.low} .. {self.high}"


@dataclass(frozen=True)
class Pair:
    """``[x, y]``, each accepted by ``item``."""

    item: Real

    def accepts(self, value: object) -> bool:
        return isinstance(value, list) and len(value) == 2 and all(map(self.item.accepts, value))

    def expected(self) -> str:
        return f"[x, y], each {self.item.expected()}"


@dataclass(frozen=True)
class SectionSize:
    """A cross-section's size: one number (a diameter or side) or, for a rect, ``[a, b]``
    with a ≥ b (the long side a along x), each accepted by ``item``."""

    item: Real

    def accepts(self, value: object) -> bool:
        if isinstance(value, list):
            return len(value) == 2 and all(map(self.item.accepts, value)) and value[0] >= value[1]
        return self.item.accepts(value)

    def expected(self) -> str:
        return f"{self.item.expected()}, or for a rect [a, b] with a >= b, each such a number"


@dataclass(frozen=True)
class OneOf:
    """One of ``choices`` (strings)."""

    choices: frozenset[str]

    def accepts(self, value: object) -> bool:
        return isinstance(value, str) and value in self.choices

    def expected(self) -> str:
        return f"one of {', '.join(sorted(self.choices))}"


@dataclass(frozen=True)
class Ids:
    """A non-empty list of distinct id strings."""

    def accepts(self, value: object) -> bool:
        return (isinstance(value, list) and bool(value) and all(isinstance(v, str) and v for v in value)
                and len(set(value)) == len(value))

    def expected(self) -> str:
        return "a non-empty list of distinct ids"


@dataclass(frozen=True)
class Text:
    """A non-empty string."""

    def accepts(self, value: object) -> bool:
        return isinstance(value, str) and bool(value)

    def expected(self) -> str:
        return "an id"


Rule = Real | Count | Pair | SectionSize | OneOf | Ids | Text
COORDINATE = Real(-MAX_COORDINATE, MAX_COORDINATE)
SECTION_SIZE = SectionSize(Real(0.0, 0.1))  # sides or a diameter the gripper's fingers can hold [m]
YAW = Real(-360.0, 360.0, "degrees")  # a hole's optional yaw

PLATE: dict[str, Rule] = {
    "top_z": Real(0.0, 1.0), "tile_size": Real(0.0, 0.5), "tile_thickness": Real(0.0, 0.2),
    "chamfer": Real(0.0, 0.01), "polygon_sides": Count(8, 256, 8), "base_thickness": Real(0.0, 0.2),
    "base_size": Pair(Real(0.0, 2.0)), "base_center": Pair(COORDINATE),
}
GRIPPER: dict[str, Rule] = {
    "flange_mass": Real(0.0, 20.0, "kg"), "flange_inertia": Real(0.0, 1.0, "kg m^2"),
    "flange_length": Real(0.0, 0.5), "grasp_depth": Real(0.0, 0.2),
}
HOLE_SHAPE: dict[str, Rule] = {"holes": Ids(), "kind": OneOf(KINDS), "size": SECTION_SIZE}
PART_SHAPE: dict[str, Rule] = {"parts": Ids(), "kind": OneOf(KINDS), "size": SECTION_SIZE,
                               "length": Real(0.0, 0.3), "mass": Real(0.0, 10.0, "kg"), "demo_hole": Text()}
EXTRA_PART: dict[str, Rule] = {"start": Pair(COORDINATE)}


def _fail(path: Path, table: str, key: str, expected: str, value: object) -> ExecutorError:
    return ExecutorError(f"{path}: [{table}] {key}: expected {expected}, got {shorten(repr(value))}")


def _table(path: Path, geo: Mapping[str, object], name: str) -> dict:
    table = geo.get(name)
    if not isinstance(table, dict):
        raise ExecutorError(f"{path}: no [{name}] table; expected the tables of data/cranfield/geometry.toml")
    return table


def _check_keys(path: Path, name: str, table: dict, rules: Mapping[str, Rule]) -> None:
    for key, rule in rules.items():
        value = table.get(key)
        if not rule.accepts(value):
            raise _fail(path, name, key, rule.expected(), value)


def _shape_tables(path: Path, geo: Mapping[str, object], group: str, rules: Mapping[str, Rule],
                  members: str) -> dict[str, dict]:
    """The ``[<group>.*]`` tables, each checked by ``rules``; every id of ``members`` in one only."""
    tables = geo.get(group, {})
    if not isinstance(tables, dict) or not all(isinstance(t, dict) for t in tables.values()):
        raise ExecutorError(f"{path}: [{group}]: expected tables [{group}.<name>], got {shorten(repr(tables))}")
    owner: dict[str, str] = {}
    for name, table in tables.items():
        _check_keys(path, f"{group}.{name}", table, rules)
        for member in table[members]:
            if member in owner:
                raise _fail(path, f"{group}.{name}", members, f"ids not already in [{group}.{owner[member]}]",
                            member)
            owner[member] = name
    return tables


def check_geometry(path: Path, geo: Mapping[str, object], layout: Assembly) -> None:
    """Check the decoded ``geometry.toml`` at ``path`` (with the hole positions of
    ``layout``) as a whole; ExecutorError of one line naming the table and key."""
    plate = _table(path, geo, "plate")
    _check_keys(path, "plate", plate, PLATE)
    gripper = _table(path, geo, "gripper")
    _check_keys(path, "gripper", gripper, GRIPPER)
    holes = _shape_tables(path, geo, "hole_shapes", HOLE_SHAPE, "holes")
    parts = _shape_tables(path, geo, "part_shapes", PART_SHAPE, "parts")
    extras = geo.get("extra_parts", {})
    if not isinstance(extras, dict) or not all(isinstance(t, dict) for t in extras.values()):
        raise ExecutorError(f"{path}: [extra_parts]: expected tables [extra_parts.<id>], got {shorten(repr(extras))}")
    for pid, table in extras.items():
        _check_keys(path, f"extra_parts.{pid}", table, EXTRA_PART)
    for group, tables in (("hole_shapes", holes), ("part_shapes", parts)):
        for name, table in tables.items():
            _check_section(path, f"{group}.{name}", table)
    chamfer, tile = plate["chamfer"], plate["tile_size"]
    if chamfer >= plate["tile_thickness"]:
        raise _fail(path, "plate", "chamfer", f"less than tile_thickness ({plate['tile_thickness']:g} m)", chamfer)
    hole_ids = {hid for table in holes.values() for hid in table["holes"]}
    for name, table in holes.items():
        if _long_side(table["size"]) + 2 * chamfer >= tile:
            raise _fail(path, f"hole_shapes.{name}", "size", f"a hole and its chamfer inside the {tile:g} m boss "
                        f"(size + 2 chamfer < tile_size)", table["size"])
    for name, table in parts.items():
        if table["demo_hole"] not in hole_ids:
            raise _fail(path, f"part_shapes.{name}", "demo_hole", f"a hole of [hole_shapes.*] "
                        f"({', '.join(sorted(hole_ids))})", table["demo_hole"])
        if gripper["grasp_depth"] >= table["length"]:
            raise _fail(path, f"part_shapes.{name}", "length",
                        f"longer than [gripper] grasp_depth ({gripper['grasp_depth']:g} m)", table["length"])
    _check_references(path, layout, holes, parts, extras)
    positions = {h.id: h.position for h in layout.holes if h.id in hole_ids and h.position is not None}
    turned = {hid for table in holes.values() if table.get("yaw", 0.0) for hid in table["holes"]}
    _check_bosses(path, tile, positions, turned)


def _check_references(path: Path, layout: Assembly, holes: dict[str, dict], parts: dict[str, dict],
                      extras: dict) -> None:
    """Every hole a hole of ``assembly.toml`` with a position; every part one of its parts
    or of ``[extra_parts]`` (with a start)."""
    positions = {hole.id: hole.position for hole in layout.holes}
    for name, table in holes.items():
        for hid in table["holes"]:
            if positions.get(hid) is None:
                why = "has no position there" if hid in positions else "is not a hole there"
                raise _fail(path, f"hole_shapes.{name}", "holes", f"holes of assembly.toml with a position "
                            f"({hid} {why})", hid)
    starts = {part.id for part in layout.parts if part.start is not None} | set(extras)
    for name, table in parts.items():
        for pid in table["parts"]:
            if pid not in starts:
                raise _fail(path, f"part_shapes.{name}", "parts", "parts of assembly.toml with a start, or of "
                            f"[extra_parts] ({pid} is neither)", pid)


def _check_section(path: Path, table_name: str, table: dict) -> None:
    """A rect's size is ``[a, b]``, any other kind's one number; a hole's ``yaw`` [°] is finite."""
    rect, size = table["kind"] == "rect", table["size"]
    if rect != isinstance(size, list):
        expected = ("[a, b] in m with a >= b > 0 (the long side a along x) for a rect" if rect
                    else f"one number (the {'diameter' if table['kind'] == 'round' else 'side'}) for a {table['kind']}")
        raise _fail(path, table_name, "size", expected, size)
    if "yaw" in table and not YAW.accepts(table["yaw"]):
        raise _fail(path, table_name, "yaw", YAW.expected(), table["yaw"])


def _long_side(size: float | list[float]) -> float:
    """A checked size's largest extent along a side of its boss [m] (a rect's a)."""
    return float(size[0]) if isinstance(size, list) else float(size)


def _check_bosses(path: Path, tile: float, positions: Mapping[str, tuple[float, float]],
                  turned: set[str]) -> None:
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
                raise ExecutorError(f"{path}: [plate] tile_size: expected bosses that do not overlap, got holes "
                                    f"{a} at ({xa:g}, {ya:g}) and {b} at ({xb:g}, {yb:g}) m closer than {tile:g} m")
