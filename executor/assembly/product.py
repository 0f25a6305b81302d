"""The whole product as the assembling cell sees it: the cell geometry of
:mod:`assembly_constraints.executor.world.geometry` (plate, holes, pegs) plus the ``[base]``, ``[covers.*]``
and ``[heads.*]`` tables of ``geometry.toml`` (documented in ``docs/geometry.md``).

Every part gets a tray pose (where it waits), a goal pose (where the product has it),
a grip point and the tool-centre point (TCP) the insertion skill drives: a peg's bottom
centre, a cover's bottom at the centre of its first opening, a head's bottom centre.
Poses are ``(position [m], quat_xyzw)`` of the part's body frame; all parts stand
upright, so quaternions are the identity.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from assembly_constraints.bridge.inputs import shorten
from assembly_constraints.executor import ExecutorError
from assembly_constraints.executor.world.geometry import CellGeometry, PartSpec, load_geometry

Vec3 = tuple[float, float, float]


@dataclass(frozen=True)
class Box:
    """An axis-aligned box: centre and half extents [m], in its body's frame."""

    centre: Vec3
    half: Vec3


@dataclass(frozen=True)
class CoverSpec:
    """A part with openings going down over the pins in ``over`` (holes of the plate):
    ``boxes`` (its solid, in its body frame: origin = the centre of those holes, bottom
    face at z = 0), ``bottom`` above the plate top when placed [m], ``grip`` on its top
    [m], ``tray`` origin [m], ``skill`` name, optional ``socket`` (x, y, side, depth [m])."""

    id: str
    over: tuple[str, ...]
    boxes: tuple[Box, ...]
    thickness: float
    bottom: float
    mass: float
    grip: tuple[float, float]
    tray: tuple[float, float]
    skill: str
    socket: tuple[float, float, float, float] | None


@dataclass(frozen=True)
class HeadSpec:
    """A part going into the socket of cover ``into`` (round or square cross-section)."""

    id: str
    into: str
    kind: str
    size: float
    length: float
    mass: float
    start: tuple[float, float]
    skill: str


@dataclass(frozen=True)
class BaseSpec:
    """The base part: the plate of the cell geometry, waiting with its ``base_center`` at
    ``tray`` [m], gripped at ``grip`` from ``base_center`` [m]."""

    id: str
    tray: tuple[float, float]
    grip: tuple[float, float]
    mass: float


@dataclass(frozen=True)
class Product:
    """Everything the assembling cell builds: the cell geometry, the base, the pegs (the
    parts of ``assembly.toml`` with a part shape), covers and heads."""

    geometry: CellGeometry
    base: BaseSpec
    pegs: dict[str, PartSpec]
    covers: dict[str, CoverSpec]
    heads: dict[str, HeadSpec]

    @property
    def folder(self) -> Path:
        return self.geometry.folder

    @property
    def top_z(self) -> float:
        return float(self.geometry.plate["top_z"])

    @property
    def parts(self) -> list[str]:
        return sorted([self.base.id, *self.pegs, *self.covers, *self.heads])

    def over_centre(self, cover: CoverSpec) -> np.ndarray:
        """The centre [m] of the holes a cover goes over (its body origin, x y)."""
        return np.mean([self.geometry.holes[h].position for h in cover.over], axis=0)


def rect_minus_squares(outline: tuple[float, float, float, float],
                       squares: list[tuple[float, float, float]]) -> list[tuple[float, float, float, float]]:
    """Rectangles [xmin, ymin, xmax, ymax] covering ``outline`` minus the axis-aligned
    squares (centre x, y, side) [m]: the cells of the grid their edges make, merged
    along x row by row."""
    xs = sorted({outline[0], outline[2], *(c - s / 2 for c, _, s in squares), *(c + s / 2 for c, _, s in squares)})
    ys = sorted({outline[1], outline[3], *(c - s / 2 for _, c, s in squares), *(c + s / 2 for _, c, s in squares)})
    xs = [x for x in xs if outline[0] <= x <= outline[2]]
    ys = [y for y in ys if outline[1] <= y <= outline[3]]

    def free(x: float, y: float) -> bool:
        return not any(abs(x - cx) < s / 2 and abs(y - cy) < s / 2 for cx, cy, s in squares)

    rects = []
    for y0, y1 in zip(ys, ys[1:]):
        run: float | None = None
        for x0, x1 in zip(xs, xs[1:]):
            solid = free((x0 + x1) / 2, (y0 + y1) / 2)
            if solid and run is None:
                run = x0
            if not solid and run is not None:
                rects.append((run, y0, x0, y1))
                run = None
        if run is not None:
            rects.append((run, y0, xs[-1], y1))
    return rects


def _pair(table: dict, key: str, where: str) -> tuple[float, float]:
    value = table.get(key)
    if not (isinstance(value, list) and len(value) == 2 and all(isinstance(v, (int, float)) for v in value)):
        raise ExecutorError(f"{where}: {key}: expected [x, y] in m, got {shorten(repr(value))}")
    return float(value[0]), float(value[1])


def _number(table: dict, key: str, where: str, default: float | None = None) -> float:
    value = table.get(key, default)
    if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value) or value < 0:
        raise ExecutorError(f"{where}: {key}: expected a number >= 0, got {shorten(repr(value))}")
    return float(value)


def _cover(cid: str, table: dict, geometry: CellGeometry, where: str) -> CoverSpec:
    over = table.get("over")
    if not (isinstance(over, list) and over and all(h in geometry.holes for h in over)):
        raise ExecutorError(f"{where}: over: expected a list of holes of the plate "
                            f"({', '.join(sorted(geometry.holes))}), got {shorten(repr(over))}")
    outline = table.get("outline")
    if not (isinstance(outline, list) and len(outline) == 4 and outline[0] < outline[2] and outline[1] < outline[3]):
        raise ExecutorError(f"{where}: outline: expected [xmin, ymin, xmax, ymax] in m, got {shorten(repr(outline))}")
    thickness = _number(table, "thickness", where)
    clearance = _number(table, "clearance", where, 0.003)
    centre = np.mean([geometry.holes[h].position for h in over], axis=0)
    openings = [(*(np.array(geometry.holes[h].position) - centre), geometry.holes[h].size + clearance)
                for h in over]
    socket = table.get("socket")
    if socket is not None and not (isinstance(socket, list) and len(socket) == 4):
        raise ExecutorError(f"{where}: socket: expected [x, y, side, depth] in m, got {shorten(repr(socket))}")
    if socket is not None:
        openings.append((float(socket[0]), float(socket[1]), float(socket[2])))
    half_t = thickness / 2
    xmin, ymin, xmax, ymax = map(float, outline)
    boxes = [Box(((x0 + x1) / 2, (y0 + y1) / 2, half_t), ((x1 - x0) / 2, (y1 - y0) / 2, half_t))
             for x0, y0, x1, y1 in rect_minus_squares((xmin, ymin, xmax, ymax), openings)]
    if socket is not None:  # the socket's floor
        floor = (thickness - float(socket[3])) / 2
        boxes.append(Box((float(socket[0]), float(socket[1]), floor), (socket[2] / 2, socket[2] / 2, floor)))
    return CoverSpec(cid, tuple(over), tuple(boxes), thickness, _number(table, "bottom", where, 0.0),
                     _number(table, "mass", where), _pair(table, "grip", where), _pair(table, "tray", where),
                     str(table.get("skill", "")),
                     None if socket is None else (float(socket[0]), float(socket[1]), float(socket[2]),
                                                  float(socket[3])))


def load_product(assembly: str = "cranfield") -> Product:
    """The product of an assembly folder; ExecutorError naming the table and key when the
    ``[base]``, ``[covers.*]`` or ``[heads.*]`` tables are missing or malformed, or a part of
    ``assembly.toml`` has no geometry."""
    from assembly_constraints.executor.world.geometry import _read_toml  # one reader of the file

    geometry = load_geometry(assembly)
    path = geometry.folder / "geometry.toml"
    geo = _read_toml(path)
    base = geo.get("base")
    if not isinstance(base, dict) or not isinstance(base.get("part"), str):
        raise ExecutorError(f"{path}: no [base] table with part = \"<id>\" (see docs/geometry.md)")
    where = f"{path}: [base]"
    base_spec = BaseSpec(base["part"], _pair(base, "tray", where), _pair(base, "grip", where),
                         _number(base, "mass", where))
    covers = {cid: _cover(cid, t, geometry, f"{path}: [covers.{cid}]") for cid, t in geo.get("covers", {}).items()}
    from assembly_constraints.bridge.assembly import load_assembly

    layout = load_assembly(assembly)
    starts = {p.id: p.start for p in layout.parts}
    heads: dict[str, HeadSpec] = {}
    for hid, t in geo.get("heads", {}).items():
        where = f"{path}: [heads.{hid}]"
        if t.get("into") not in covers or covers[t["into"]].socket is None:
            raise ExecutorError(f"{where}: into: expected a cover with a socket, got {shorten(repr(t.get('into')))}")
        start = starts.get(hid)
        if start is None:
            raise ExecutorError(f"{where}: part '{hid}' has no start in assembly.toml")
        heads[hid] = HeadSpec(hid, t["into"], str(t.get("kind", "round")), _number(t, "size", where),
                              _number(t, "length", where), _number(t, "mass", where), start, str(t.get("skill", "")))
    pegs = {pid: spec for pid, spec in geometry.parts.items() if pid in starts}
    product = Product(geometry, base_spec, pegs, covers, heads)
    missing = sorted(set(starts) - set(product.parts))
    if missing:
        raise ExecutorError(f"{path}: part(s) {', '.join(missing)} of assembly.toml have no geometry "
                            "(expected a [part_shapes.*], [covers.*], [heads.*] or [base] entry)")
    return product
