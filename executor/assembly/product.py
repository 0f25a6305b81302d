"""The whole product as the assembling cell sees it: the cell geometry of
:mod:`executor.world.geometry` (plate, holes, pegs) plus the ``[base]``, ``[covers.*]``
and ``[heads.*]`` tables of ``geometry.toml`` (documented in ``docs/geometry.md``).

Every part gets a tray pose (where it waits), a goal pose (where the product has it),
a grip point and the tool-centre point (TCP) the insertion skill drives: a peg's bottom
centre, a cover's bottom at the centre of the holes it goes over, a head's bottom centre.
Poses are ``(position [m], quat_xyzw)`` of the part's body frame; all parts stand
upright, so quaternions are the identity.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from bridge.product import Cover, Mesh
from executor import ExecutorError
from executor.cell_description import CellDescription
from executor.world.geometry import CellGeometry, HoleSpec, PartSpec, load_geometry

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
    face at z = 0; none when it is its own ``mesh``, in that frame), ``bottom`` above the
    plate top when placed [m], ``grip`` on its top [m], ``tray`` origin [m], ``skill``
    name, optional ``socket`` (x, y, side, depth [m])."""

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
    mesh: Mesh | None = None


@dataclass(frozen=True)
class HeadSpec:
    """A part going into the socket of cover ``into`` (round or square cross-section), a
    cylinder or box unless it is its own ``mesh`` (frame at its bottom centre)."""

    id: str
    into: str
    kind: str
    size: float
    length: float
    mass: float
    start: tuple[float, float]
    skill: str
    mesh: Mesh | None = None


@dataclass(frozen=True)
class ManualSpec:
    """A part the cell has no operation for, placed by hand at its ``goal`` (its frame's
    origin [m]: the centre of its bottom face), waiting at ``tray`` [m]; ``reason`` why;
    simulated as its own ``mesh``, static."""

    id: str
    goal: Vec3
    tray: tuple[float, float]
    reason: str
    mesh: Mesh


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
    parts of ``assembly.toml`` with a part shape), covers, heads and parts placed by hand."""

    geometry: CellGeometry
    base: BaseSpec
    pegs: dict[str, PartSpec]
    covers: dict[str, CoverSpec]
    heads: dict[str, HeadSpec]
    manual: dict[str, ManualSpec]

    @property
    def folder(self) -> Path:
        return self.geometry.folder

    @property
    def top_z(self) -> float:
        return self.geometry.plate.top_z

    @property
    def parts(self) -> list[str]:
        return sorted([self.base.id, *self.pegs, *self.covers, *self.heads, *self.manual])

    def over_centre(self, cover: CoverSpec) -> np.ndarray:
        """The centre [m] of the holes a cover goes over (its body origin, x y)."""
        return np.mean([self.geometry.holes[h].position for h in cover.over], axis=0)


SAME_EDGE = 1e-6
"""Edges of a cover's openings closer than this [m] are one edge (1 µm)."""
MAX_COVER_BOXES = 16
"""The most boxes a cover's solid may have: PyBullet keeps the first 16 shapes of a compound
body made by ``createCollisionShapeArray`` and drops the others (measured: a ball fell through
the 26th box of 30); a cover that needs more is simulated from its own mesh."""


def _edges(values: list[float]) -> list[float]:
    """``values`` sorted, each within :data:`SAME_EDGE` of the last kept one dropped."""
    kept: list[float] = []
    for value in sorted(values):
        if not kept or value - kept[-1] > SAME_EDGE:
            kept.append(value)
    return kept


def rect_minus_squares(outline: tuple[float, float, float, float],
                       squares: list[tuple[float, float, float]]) -> list[tuple[float, float, float, float]]:
    """Rectangles [xmin, ymin, xmax, ymax] covering ``outline`` minus the axis-aligned
    squares (centre x, y, side) [m]: the cells of the grid their edges make (edges within
    :data:`SAME_EDGE` of each other taken as one: no sliver cells), merged along x row by row."""
    xs = _edges([outline[0], outline[2], *(c - s / 2 for c, _, s in squares), *(c + s / 2 for c, _, s in squares)])
    ys = _edges([outline[1], outline[3], *(c - s / 2 for _, c, s in squares), *(c + s / 2 for _, c, s in squares)])
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


def cover_spec(cid: str, table: Cover, holes: Mapping[str, HoleSpec]) -> CoverSpec:
    """A checked ``[covers.<id>]`` table (:mod:`bridge.product`) over
    the plate's ``holes``: its solid is the outline minus square openings (each hole's size
    + clearance, and the socket), or its own mesh."""
    centre = np.mean([holes[h].position for h in table.over], axis=0)
    socket = None if table.socket is None else (table.socket[0], table.socket[1], table.socket[2], table.socket[3])
    boxes: list[Box] = []
    if table.mesh is None:
        openings = [(*(np.array(holes[h].position) - centre), holes[h].size + table.clearance) for h in table.over]
        if socket is not None:
            openings.append(socket[:3])
        half_t = table.thickness / 2
        xmin, ymin, xmax, ymax = table.outline
        boxes = [Box(((x0 + x1) / 2, (y0 + y1) / 2, half_t), ((x1 - x0) / 2, (y1 - y0) / 2, half_t))
                 for x0, y0, x1, y1 in rect_minus_squares((xmin, ymin, xmax, ymax), openings)]
        if socket is not None:  # the socket's floor
            floor = (table.thickness - socket[3]) / 2
            boxes.append(Box((socket[0], socket[1], floor), (socket[2] / 2, socket[2] / 2, floor)))
    return CoverSpec(cid, tuple(table.over), tuple(boxes), table.thickness, table.bottom, table.mass,
                     (table.grip[0], table.grip[1]), (table.tray[0], table.tray[1]), table.skill, socket, table.mesh)


def load_product(assembly: str = "cranfield", description: CellDescription | None = None) -> Product:
    """The product of an assembly folder with the gripper of the cell ``description``
    unless ``geometry.toml`` has its own (:func:`executor.world.geometry.load_geometry`:
    the whole description checked); ExecutorError when it has no ``[base]`` table."""
    geometry = load_geometry(assembly, description)
    tables, path = geometry.tables, geometry.folder / "geometry.toml"
    if tables.base is None:
        raise ExecutorError(f"{path}: no [base] table with part = \"<id>\"; expected the whole product "
                            "(see docs/geometry.md)")
    base = BaseSpec(tables.base.part, (tables.base.tray[0], tables.base.tray[1]),
                    (tables.base.grip[0], tables.base.grip[1]), tables.base.mass)
    covers = {cid: cover_spec(cid, table, geometry.holes) for cid, table in tables.covers.items()}
    for cid, cover in covers.items():
        if len(cover.boxes) > MAX_COVER_BOXES:
            raise ExecutorError(f"{path}: [covers.{cid}] over: expected a cover whose outline less its openings is at "
                                f"most {MAX_COVER_BOXES} boxes (the cell's compound bodies hold no more), got "
                                f"{len(cover.boxes)}; give it a mesh (docs/geometry.md)")
    starts = {p.id: p.start for p in geometry.layout.parts}
    heads: dict[str, HeadSpec] = {}
    for hid, head in tables.heads.items():
        start = starts[hid]
        assert start is not None  # the loader checked that every head has a start
        heads[hid] = HeadSpec(hid, head.into, head.kind, head.size, head.length, head.mass, start, head.skill,
                              head.mesh)
    pegs = {pid: spec for pid, spec in geometry.parts.items() if pid in starts}
    manual = {mid: ManualSpec(mid, (table.goal[0], table.goal[1], table.goal[2]), (table.tray[0], table.tray[1]),
                              table.reason, table.mesh) for mid, table in tables.manual.items()}
    return Product(geometry, base, pegs, covers, heads, manual)
