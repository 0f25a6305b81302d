"""An assembly folder: parts, holes, ground truths and demonstrations.

An assembly is a folder (a name under ``data/`` or a path) holding:

- ``assembly.toml``: ``[parts.<id>]`` with ``name``, ``role``, optional ``start``
  ``[x, y]`` [m] (where the part waits in the cell), optional ``shape`` (its cross-section
  kind, :data:`SHAPES`) and, for a rect part, optional ``section`` (a label: parts of one
  section are scaled copies of one cross-section; default the shape for round and
  square, the part's own id for rect); ``[holes.<id>]`` with ``name``, ``shape`` (default
  round) and ``position`` ``[x, y]`` [m] on the base plate; an optional ``[sizes]``
  table with ``model`` (the size model the product declares: ``line``, ``sections`` or
  ``pairs``, docs/sizes.md);
- ``precedence.lp`` (optional): the true precedence constraints (``part/1``,
  ``precedence_edge/2`` or ``must_precede/2``);
- ``sizes.lp`` (optional): which part fits which hole (``part/1``, ``hole/1``,
  ``fits/2``; closed world);
- ``demos.txt`` (optional): demonstrated feasible sequences;
- ``geometry.toml`` (optional): dimensions for the simulated cell.
"""

from __future__ import annotations

import math
import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from assembly_constraints.bridge import BridgeError
from assembly_constraints.bridge.inputs import read_text, shorten

_INSTALLED_ASSEMBLIES = Path(__file__).resolve().parent / "assemblies"
DATA_DIR = (_INSTALLED_ASSEMBLIES if _INSTALLED_ASSEMBLIES.is_dir()
            else Path(__file__).resolve().parent.parent / "data")
"""The shipped assemblies: the repository's ``data/``, or in an installed copy its package
data ``bridge/assemblies`` (``setup.py``), so ``--assembly cranfield`` works from any folder."""
ID_PATTERN = r"^(?!not$)[a-z][a-zA-Z0-9_]{0,63}$(?!\n)"
"""A part or hole id: an ASP constant of at most 64 ASCII characters, a lower-case letter
first, not the keyword ``not`` (clingo's only lower-case keyword). ``(?!\n)`` keeps a
trailing newline out (Python's ``$`` would match before it); the pattern means the same
in Python and in JSON Schema (ECMA 262)."""
_ID = re.compile(ID_PATTERN)


def is_id(value: object) -> bool:
    """Whether ``value`` is a part or hole id (:data:`ID_PATTERN`)."""
    return isinstance(value, str) and _ID.match(value) is not None


MAX_COORDINATE = 100.0
"""Positions ([x, y] of parts and holes, a tool home) are finite with |x|, |y| <= this [m]."""


@dataclass(frozen=True)
class Item:
    """A part or a hole: its id (an ASP constant) and a readable name."""

    id: str
    name: str


SHAPES = ("round", "square", "rect")
"""The cross-section kinds of a part's or hole's ``shape`` (``kind`` in ``geometry.toml``)."""

SIZE_MODELS = ("line", "sections", "pairs")
"""The size models a product may declare (``[sizes] model``; docs/sizes.md)."""


@dataclass(frozen=True)
class Part(Item):
    """One part of an assembly; ``start`` is its waiting position [m] or None; ``shape``
    its cross-section kind (one of :data:`SHAPES`, None when the file gives none) and
    ``section`` the label of its cross-section (None without a shape)."""

    role: str = "part"
    start: tuple[float, float] | None = None
    shape: str | None = None
    section: str | None = None


@dataclass(frozen=True)
class Hole(Item):
    """One hole of the base plate; ``position`` [m] or None."""

    shape: str = "round"
    position: tuple[float, float] | None = None


@dataclass(frozen=True)
class Assembly:
    """An assembly folder loaded from disk."""

    folder: Path
    name: str
    parts: tuple[Part, ...]
    holes: tuple[Hole, ...] = field(default_factory=tuple)
    size_model: str | None = None
    """The size model the product declares (``[sizes] model``), None when it declares none."""

    def sections(self) -> dict[str, str]:
        """Part id -> section, for the parts whose cross-section is stated."""
        return {p.id: p.section for p in self.parts if p.section is not None}

    @property
    def part_ids(self) -> list[str]:
        return [p.id for p in self.parts]

    @property
    def hole_ids(self) -> list[str]:
        return [h.id for h in self.holes]

    def file(self, name: str) -> Path:
        """Path of a file of the folder; BridgeError if it does not exist."""
        path = self.folder / name
        if not path.is_file():
            raise BridgeError(f"{path}: no such file (assembly '{self.name}' has no {name})")
        return path

    def has_file(self, name: str) -> bool:
        return (self.folder / name).is_file()


def resolve_assembly_folder(name_or_path: str) -> Path:
    """A folder holding ``assembly.toml`` (relative to the working folder) or the name of a
    shipped assembly (a folder of :data:`DATA_DIR`), in this order."""
    candidates = [Path(name_or_path), DATA_DIR / name_or_path]
    for folder in candidates:
        if (folder / "assembly.toml").is_file():
            return folder.resolve()
    known = sorted(p.parent.name for p in DATA_DIR.glob("*/assembly.toml"))
    raise BridgeError(
        f"assembly '{name_or_path}': expected a shipped assembly ({', '.join(known)}) "
        "or a folder holding assembly.toml"
    )


def _position(source: Path, table: str, key: str, value: object) -> tuple[float, float] | None:
    if value is None:
        return None
    if (
        not isinstance(value, list)
        or len(value) != 2
        or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)
        or not all(math.isfinite(v) and abs(v) <= MAX_COORDINATE for v in value)
    ):
        raise BridgeError(f"{source}: [{table}.{key}]: expected [x, y] in metres, finite and within "
                          f"±{MAX_COORDINATE:g}, got {shorten(repr(value))}")
    return (float(value[0]), float(value[1]))


def _shape(source: Path, table: str, key: str, value: object) -> str:
    if value not in SHAPES:
        raise BridgeError(f"{source}: [{table}.{key}] shape: expected one of {', '.join(SHAPES)}, "
                          f"got {shorten(repr(value))}")
    return str(value)


def _part(source: Path, key: str, value: dict) -> Part:
    """One ``[parts.<id>]`` table; ``section`` only for a rect part (an id-like label)."""
    shape = None if value.get("shape") is None else _shape(source, "parts", key, value["shape"])
    section = value.get("section")
    if section is not None and shape != "rect":
        raise BridgeError(f"{source}: [parts.{key}] section: only a part of shape \"rect\" has one "
                          f"(a {shape or 'part without a shape'} is its own section)")
    if section is not None and not (isinstance(section, str) and _ID.match(section)):
        raise BridgeError(f"{source}: [parts.{key}] section: expected a lower-case ASP constant, "
                          f"got {shorten(repr(section))}")
    if shape is not None and section is None:
        section = key if shape == "rect" else shape
    return Part(key, str(value.get("name", key)), str(value.get("role", "part")),
                _position(source, "parts", key, value.get("start")), shape, section)


def _table(source: Path, data: dict, table: str) -> dict[str, dict]:
    entries = data.get(table, {})
    if not isinstance(entries, dict):
        raise BridgeError(f"{source}: [{table}] must be a table of ids")
    for key, value in entries.items():
        if not is_id(key):
            raise BridgeError(
                f"{source}: [{table}.{key}]: an id must be a lower-case ASP constant of at most 64 characters"
            )
        if not isinstance(value, dict):
            raise BridgeError(f"{source}: [{table}.{key}] must be a table")
    return entries


def load_assembly(name_or_path: str) -> Assembly:
    """Load an assembly folder; BridgeError naming the file and field on bad input."""
    folder = resolve_assembly_folder(name_or_path)
    source = folder / "assembly.toml"
    try:
        data = tomllib.loads(read_text(source, "assembly file (TOML)"))
    except tomllib.TOMLDecodeError as exc:
        raise BridgeError(f"{source}: not valid TOML: {exc}") from None
    parts = tuple(_part(source, key, value) for key, value in _table(source, data, "parts").items())
    if not parts:
        raise BridgeError(f"{source}: expected at least one [parts.<id>] table")
    holes = tuple(
        Hole(key, str(value.get("name", key)), _shape(source, "holes", key, value.get("shape", "round")),
             _position(source, "holes", key, value.get("position")))
        for key, value in _table(source, data, "holes").items()
    )
    clash = {p.id for p in parts} & {h.id for h in holes}
    if clash:
        raise BridgeError(f"{source}: ids used for both a part and a hole: {sorted(clash)}")
    return Assembly(folder=folder, name=str(data.get("name", folder.name)), parts=parts, holes=holes,
                    size_model=_size_model(source, data))


def _choice(source: Path, table: str, key: str, value: object, choices: tuple[str, ...]) -> str:
    if not isinstance(value, str) or value not in choices:
        raise BridgeError(f"{source}: [{table}] {key}: expected one of {', '.join(choices)}, "
                          f"got {shorten(repr(value))}")
    return value


def _size_model(source: Path, data: dict) -> str | None:
    table = data.get("sizes")
    if table is None:
        return None
    if not isinstance(table, dict) or set(table) - {"model"}:
        raise BridgeError(f"{source}: [sizes]: expected a table with the key model")
    return _choice(source, "sizes", "model", table.get("model"), SIZE_MODELS)
