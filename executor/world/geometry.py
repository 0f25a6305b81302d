"""Geometry of the simulated cell: dimensions from ``geometry.toml``, positions from
``assembly.toml``, and the generated assets (plate mesh, part URDFs, arm+tool URDF).

The back plate is a static concave triangle mesh (PyBullet's trimesh has effectively no
collision margin, so 0.1 mm clearances are real): one square boss per hole, from the
plate under the bosses (:attr:`CellGeometry.base_top`) up to the hole's entry (the
plate's ``top_z`` or the hole's own), with a 45° entry chamfer and the hole down to its
bottom (the plate's ``tile_thickness`` or its own ``depth`` below the entry): through the
boss when the bottom is the plate's top, else onto a floor of the boss; round
holes are n-gons (``polygon_sides``) whose inradius is the hole radius, square and
rectangular holes exact; a hole with a yaw has its whole boss turned by it about the
hole's centre; a polygon hole's boss is made from its outline the same way
(:mod:`executor.world.outlines`).  Parts are exact primitive shapes (cylinder with
``URDF_USE_IMPLICIT_CYLINDER``, box, a polygon peg the prism of its outline over its
length as exact convex pieces), or, with a ``mesh``, their own mesh colliding as its
convex pieces (:mod:`executor.world.meshes`); a base with a ``mesh``
is that mesh as a static concave triangle mesh instead of the plate.

Cross-sections (``kind``): ``round`` (``size`` = diameter), ``square`` (``size`` = side)
and ``rect`` (``size = [a, b]``, a ≥ b: the long side a along the part's or hole's x
axis), with an optional ``corner`` radius, or ``polygon`` (an ``outline``), all in m; a
hole's ``yaw`` [°] turns its x axis about z (counter-clockwise from the cell's x axis).
:func:`passes` compares aligned cross-sections: the skills turn the part to the hole's
(measured) yaw, so the yaw never changes whether a part fits; with a polygon the polygon
relation (:mod:`executor.world.polygon_fit`) finds the yaw and
shift, and the skills add them (:func:`fit_pose`).
``write_assets`` regenerates ``data/<assembly>/assets/`` deterministically (the URDFs byte
for byte on any CPU; the mesh's cos/sin may move its last printed digit, 1 µm).
"""

from __future__ import annotations

import dataclasses
import functools
import math
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TypeVar

import clingo
import numpy as np
import pybullet_data
import shapely
import trimesh

from bridge.assembly import Assembly, assembly_of, resolve_assembly_folder
from bridge.files import make_folder, write_atomic
from bridge.product import (
    GeometryFile,
    Gripper,
    HoleShape,
    Mesh,
    PartShape,
    Plate,
    check_grasp,
    hole_level,
    load_product_description,
)
from bridge.product.nominal import NOMINAL_FIT_ROOM, models_nominal_fits
from executor import ExecutorError
from executor.cell_description import CellDescription
from executor.world.frames import HoleFrame, aligned_yaw, hole_frame, yaw_quat
from executor.world.meshes import (
    MIN_THICKNESS,
    URDF_HULL_MARGIN,
    MeshBody,
    MeshFiles,
    eroded,
    eroded_pieces_text,
    eroded_text,
    mesh_inertia,
    mesh_link_xml,
    mesh_urdf_text,
    obj_text,
    pieces_inertia,
)
from executor.world.outlines import boss_triangles, corners, prism_pieces
from executor.world.polygon_fit import (
    OutlineError,
    PolygonFit,
    circle,
    polygon,
    polygon_fit,
    round_fit,
)

FLOOR_MIN = 1e-6
"""A hole whose bottom is less than this above the plate under the bosses goes through its
boss onto the plate [m] (the mesh is printed to 1 µm): no floor thinner than that."""


@dataclass(frozen=True)
class Section:
    """A part's or a hole's cross-section: ``kind`` "round" (``size`` = diameter [m]),
    "square" (``size`` = side [m]), "rect" (``size`` = long side a along x [m],
    ``width`` = short side b along y [m]; 0 means ``size``: round and square) or
    "polygon" (``outline`` its points (x, y) [m] in its own frame, ``size`` and ``width``
    its extents along x and y, ``inner`` the rings cut out of it: a hole's islands, a
    part's bores, in that frame); a square's or rect's ``corner`` radius [m] (0: sharp)."""

    id: str
    kind: str
    size: float
    width: float = field(default=0.0, kw_only=True)
    outline: tuple[tuple[float, float], ...] = field(default=(), kw_only=True)
    corner: float = field(default=0.0, kw_only=True)
    inner: tuple[tuple[tuple[float, float], ...], ...] = field(default=(), kw_only=True)

    @property
    def sides(self) -> tuple[float, float]:
        """(a, b) [m]: the extents along x and y (a round section: its diameter twice)."""
        return self.size, self.width if self.width > 0 else self.size

    @property
    def circumradius(self) -> float:
        """How far [m] the section reaches from its centre: a round one's radius, a
        polygon's farthest outline point, a square's or rect's half diagonal (its corners
        taken sharp)."""
        if self.kind == "round":
            return self.size / 2
        if self.outline:
            return float(np.max(np.linalg.norm(np.asarray(self.outline), axis=1)))
        return math.hypot(*self.sides) / 2


@dataclass(frozen=True)
class HoleSpec(Section):
    """A hole of the plate at ``position`` [m], its x axis turned by ``yaw`` [rad] about z,
    its entry at height ``top_z`` [m] and its bottom ``depth`` [m] below the entry; a
    ``pin`` of the base a part with a bore goes onto (its section the pin's, ``top_z`` its
    top, the bottom where a part going onto it rests), standing up on its ``owner`` where
    that is a part placed by hand or a peg the cell inserts down into its ``demo_hole``
    (None: the base's; its position and top with the owner at its goal there:
    :func:`seated_pose`); the parts stated to fit it at room 0
    (``zero_clearance``, a nominal zero-clearance fit: :func:`feature_passes`); the parts
    with a bore whose room on it is under what the cell resolves, whose bore it builds wider
    (``widened``: :func:`_with_widened_fits`; a hole's: the pegs it builds narrower); the pegs
    that miss it by less than the cell resolves, or, on a pin, the parts that would stop on
    its end as near their goal as one on it (``near_miss``: :mod:`executor.world.near_miss`,
    :func:`executor.cad.write.near_misses.pin_near_misses`; no experiment); ``tile``
    the side of its square boss [m] where it differs from the plate's ``tile_size``
    (:func:`tile_of`)."""

    position: tuple[float, float]
    yaw: float = 0.0
    top_z: float = field(kw_only=True)
    depth: float = field(kw_only=True)
    pin: bool = field(default=False, kw_only=True)
    axis: str = field(default="-z", kw_only=True)
    zero_clearance: tuple[str, ...] = field(default=(), kw_only=True)
    widened: tuple[str, ...] = field(default=(), kw_only=True)
    near_miss: tuple[str, ...] = field(default=(), kw_only=True)
    tile: float | None = field(default=None, kw_only=True)
    owner: str | None = field(default=None, kw_only=True)

    @property
    def bottom_z(self) -> float:
        """Height of the hole's bottom [m] (of a hole entered down)."""
        return self.top_z - self.depth

    @property
    def sideways(self) -> bool:
        """Whether a part goes in along another ``axis`` than down (the hole is in the base's
        own mesh, its ``position`` and ``top_z`` its entry's centre)."""
        return self.axis != "-z"

    @functools.cached_property
    def frame(self) -> HoleFrame | None:
        """The frame the skills insert down into this hole in (:mod:`executor.world.frames`):
        its ``position``, ``top_z``, section and ``yaw`` are this frame's; None for a hole
        entered down (the cell frame)."""
        return hole_frame(self.axis, (*self.position, self.top_z))


@dataclass(frozen=True)
class PartSpec(Section):
    """A graspable part of shape ``shape`` (its skill's name): ``length`` [m], ``mass`` [kg],
    ``start`` on the tray [m], ``demo_hole`` where its shape's skill is taught (a rect
    part's long side is along the tool's x axis when held), ``mesh`` when it is simulated
    from its own mesh (paths inside the assembly folder); a part with a ``bore`` goes
    onto pins (its section the bore's, its tip the centre of the bore at its bottom)."""

    shape: str
    length: float
    mass: float
    start: tuple[float, float]
    demo_hole: str
    mesh: Mesh | None = field(default=None, kw_only=True)
    bore: bool = field(default=False, kw_only=True)
    tool: str = field(default="fingers", kw_only=True)
    grasp_depth: float | None = field(default=None, kw_only=True)

    def held_depth(self, gripper: Gripper) -> float:
        """How deep [m] the part is in the gripper's fingers: the gripper's ``grasp_depth``,
        or the part's own where less (a peg standing out of the product by less at its goal),
        a part with a bore at most half its length (a ring is held by its top); 0 on the
        suction cup (its face on the part's top)."""
        if self.tool == "suction":
            return 0.0
        depth = gripper.grasp_depth if self.grasp_depth is None else min(self.grasp_depth, gripper.grasp_depth)
        return min(depth, self.length / 2) if self.bore else depth


@dataclass(frozen=True)
class CellGeometry:
    """Everything the scene needs: the ``[plate]``, the gripper in use (the product's
    ``[gripper]`` or the cell description's), the holes and parts by id, the decoded
    ``geometry.toml`` (``tables``: the product's base, covers and heads) and the parts and
    holes of ``assembly.toml`` (``layout``)."""

    folder: Path
    plate: Plate
    gripper: Gripper
    holes: dict[str, HoleSpec]
    parts: dict[str, PartSpec]
    tables: GeometryFile
    layout: Assembly

    @property
    def assets(self) -> Path:
        return self.folder / "assets"

    @property
    def base_top(self) -> float:
        """Height of the plate under the bosses [m]: the bottom of a hole at the plate's
        level (``top_z - tile_thickness``), or of the deepest hole where that is lower; a
        hole whose bottom is above it has a floor in its boss."""
        default = self.plate.top_z - self.plate.tile_thickness
        return min([default, *(hole.bottom_z for hole in self.holes.values() if not hole.sideways)])

    @property
    def sunk_by(self) -> float:
        """How far [m] the plate under the bosses lies below the bottom of a hole at the
        plate's level (0.0 exactly when no hole is deeper)."""
        return self.plate.top_z - self.plate.tile_thickness - self.base_top

    @property
    def base_mesh(self) -> Path | None:
        """The base's own mesh file (the cell frame [m]) when it is simulated from it, else None."""
        base = self.tables.base
        return None if base is None or base.mesh is None else self.folder / base.mesh.file


def load_geometry(assembly: str = "cranfield", description: CellDescription | None = None) -> CellGeometry:
    """The cell geometry of an assembly folder (a name under ``data/`` or a path): its
    product description (:func:`bridge.product.load_product_description`, checked as a
    whole) with the gripper of ``geometry.toml`` or else of the cell ``description``
    (default :class:`executor.cell_description.CellDescription`); BridgeError naming the
    file, table and key."""
    folder = resolve_assembly_folder(assembly)
    product = load_product_description(folder)
    path = folder / "geometry.toml"
    if product.geometry is None:
        raise ExecutorError(f"{path}: no such file; expected the cell geometry of assembly '{assembly}' "
                            "(docs/geometry.md)")
    geo = product.geometry
    gripper = geo.gripper
    if gripper is None:
        gripper = (CellDescription() if description is None else description).gripper
        check_grasp(path, geo, gripper)
    return _geometry(folder, assembly_of(product), geo, gripper)


def _section(shape: HoleShape | PartShape) -> tuple[str, float, float]:
    """``kind``, size and width [m] of a shape table: a rect's or polygon's ``[a, b]``
    gives a and b, any other kind its one size and width 0."""
    if isinstance(shape.size, list):
        return shape.kind, float(shape.size[0]), float(shape.size[1])
    return shape.kind, float(shape.size), 0.0


def _outline(shape: HoleShape | PartShape) -> tuple[tuple[float, float], ...]:
    """A polygon's outline points [m] (empty for the other kinds)."""
    return () if shape.outline is None else tuple((float(x), float(y)) for x, y in shape.outline)


def _geometry(folder: Path, layout: Assembly, geo: GeometryFile, gripper: Gripper) -> CellGeometry:
    positions = {hole.id: hole.position for hole in layout.holes if hole.position is not None}
    holes: dict[str, HoleSpec] = {}
    for hole_shape in geo.hole_shapes.values():
        kind, size, width = _section(hole_shape)
        top, depth = hole_level(geo.plate, hole_shape)
        for hid in hole_shape.holes:
            holes[hid] = HoleSpec(hid, kind, size, positions[hid], yaw=math.radians(hole_shape.yaw), width=width,
                                  top_z=top, depth=depth, outline=_outline(hole_shape), corner=hole_shape.corner,
                                  pin=hole_shape.pin, axis=hole_shape.axis,
                                  zero_clearance=tuple(sorted(hole_shape.zero_clearance or ())),
                                  widened=tuple(sorted(hole_shape.widened or ())),
                                  near_miss=tuple(sorted(hole_shape.near_miss or ())),
                                  tile=hole_shape.tile, owner=hole_shape.owner)
    starts = {part.id: part.start for part in layout.parts if part.start is not None}
    starts |= {pid: (extra.start[0], extra.start[1]) for pid, extra in geo.extra_parts.items()}
    parts: dict[str, PartSpec] = {}
    for name, part_shape in geo.part_shapes.items():
        kind, size, width = _section(part_shape)
        for pid in part_shape.parts:
            x, y = starts[pid]
            parts[pid] = PartSpec(
                pid, kind, size, shape=name, length=float(part_shape.length), mass=float(part_shape.mass),
                start=(float(x), float(y)), demo_hole=part_shape.demo_hole, width=width, mesh=part_shape.mesh,
                outline=_outline(part_shape), corner=part_shape.corner, bore=part_shape.bore, tool=part_shape.tool,
                grasp_depth=part_shape.grasp_depth,
            )
    if models_nominal_fits(geo):
        holes = {hid: _with_nominal_room(hole, parts) for hid, hole in holes.items()}
    parts = {pid: _with_widened_fits(part, holes) for pid, part in parts.items()}
    return CellGeometry(folder, geo.plate, gripper, holes, parts, geo, layout)


_Widened = TypeVar("_Widened", bound=Section)


def widened(hole: _Widened, room: float) -> _Widened:
    """``hole`` (a hole's section, a part's bore) with ``room`` [m] more all round: a round,
    square or rect section ``2 room`` wider on each side's extent (a corner radius grown by
    ``room``, a sharp corner kept sharp), a polygon's outline offset outwards by ``room``
    (mitred corners)."""
    if hole.kind == "polygon":
        grown = shapely.Polygon(hole.outline).buffer(room, join_style="mitre")
        outline = tuple((float(x), float(y)) for x, y in np.asarray(grown.exterior.coords)[:-1])
        xmin, ymin, xmax, ymax = grown.bounds
        return dataclasses.replace(hole, outline=outline, size=xmax - xmin, width=ymax - ymin)
    return dataclasses.replace(hole, size=hole.size + 2 * room, width=hole.width + 2 * room if hole.width else 0.0,
                               corner=hole.corner + room if hole.corner else 0.0)


def _with_nominal_room(hole: HoleSpec, parts: dict[str, PartSpec]) -> HoleSpec:
    """The hole as the simulated cell builds it: one that states nominal zero-clearance
    fits (``zero_clearance``) :func:`widened` by
    :data:`bridge.product.nominal.NOMINAL_FIT_ROOM` per side, so that the physics resolves
    them (docs/cell.md#nominal-zero-clearance-fits); ExecutorError naming the first part
    whose answer in the hole that room would change (:func:`feature_passes`)."""
    if not hole.zero_clearance or hole.pin:
        return hole
    built = widened(hole, NOMINAL_FIT_ROOM)
    for pid, part in sorted(parts.items()):
        if not part.bore and feature_passes(part, hole) != feature_passes(part, built):
            raise ExecutorError(
                f"hole '{hole.id}': the simulated cell builds its nominal zero-clearance fits "
                f"({', '.join(hole.zero_clearance)}) with {NOMINAL_FIT_ROOM * 1e3:g} mm of room per side, and "
                f"part '{pid}' ({margin(part, hole) * 500:+.4f} mm per side) would then "
                f"{'fit' if feature_passes(part, built) else 'not fit'}: expected every other pair's answer "
                "unchanged (docs/cell.md#nominal-zero-clearance-fits)")
    return built


def _with_widened_fits(part: PartSpec, holes: dict[str, HoleSpec]) -> PartSpec:
    """The part as the simulated cell builds it: a part that a feature names in ``widened``
    (its room there, room 0 or positive, is under what the cell resolves) has
    :data:`bridge.product.nominal.NOMINAL_FIT_ROOM` more room per side, its bore
    :func:`widened` by that on a pin, its section narrowed by that in a hole of a base
    with its own mesh (its pieces are made so: :func:`executor.world.rings.round_bores`,
    :func:`executor.world.meshes.narrowed`); ExecutorError naming the first feature of its
    kind (pins for a bore, holes for a peg) in which that room would change its answer
    (:func:`feature_passes`)."""
    if not any(part.id in hole.widened for hole in holes.values() if hole.pin == part.bore):
        return part
    built = widened(part, NOMINAL_FIT_ROOM if part.bore else -NOMINAL_FIT_ROOM)
    for hid, hole in sorted(holes.items()):
        if hole.pin == part.bore and feature_passes(part, hole) != feature_passes(built, hole):
            room, what = (margin(hole, part), "bore {:g} mm wider") if part.bore else (
                margin(part, hole), "section {:g} mm narrower")
            raise ExecutorError(
                f"part '{part.id}': the simulated cell builds its fits whose room it does not resolve (widened) with "
                f"its {what.format(NOMINAL_FIT_ROOM * 1e3)} per side, and "
                f"{'on pin' if hole.pin else 'in hole'} '{hid}' ({room * 500:+.4f} mm per side) it would then "
                f"{'fit' if feature_passes(built, hole) else 'not fit'}: expected every other pair's answer unchanged"
                " (docs/cell.md#nominal-zero-clearance-fits)")
    return built


def margin(part: Section, hole: Section) -> float:
    """How much room the part's cross-section has in the hole's, aligned [m] (negative: it
    does not pass; the skill turns the part to the hole's yaw): round in round D - d; a
    square or rect a × b in round D - √(a² + b²); round in a square or rect B - d (its short
    side); a square or rect in a square or rect, long side along long side, min(A - a, B - b)
    (a square is a rect with a = b). Corner radii: a part's rounded corners bring its
    farthest point in (D - 2 (|c| + ρ), c the centre of its corner's arc); in a square or
    rect hole the room is twice the largest offset of the part whose corner arcs (or sharp
    corners) stay inside the hole's (its corner arcs' centres less than ρ_hole - the
    offset part's radius from the hole's inner rectangle; a bisection to 0.1 nm). With a polygon on either
    side: twice the room of :func:`section_fit` (the largest uniform offset of the part
    that passes, at the yaw and shift the polygon relation finds), which agrees with these
    rules on their kinds (a rect held along the hole's long side)."""
    if "polygon" in (part.kind, hole.kind):
        return section_fit(part, hole).margin
    if hole.kind == "round":
        if part.kind == "round":
            return hole.size - part.size
        a, b = part.sides
        return hole.size - 2 * (math.hypot(a / 2 - part.corner, b / 2 - part.corner) + part.corner)
    long_side, short_side = hole.sides
    if part.kind == "round":
        return short_side - part.size
    a, b = part.sides
    room = min(long_side - a, short_side - b) / 2
    if not (part.corner or hole.corner):
        return 2 * room

    def corners_pass(offset: float) -> bool:
        """Whether the part offset by ``offset`` [m] has its corner arcs (radius ρ + offset,
        or sharp corners once that is negative) inside the hole's."""
        arc = max(part.corner + offset, 0.0)
        inward = min(part.corner + offset, 0.0)  # a sharp corner's centre moves in with it
        beyond = math.hypot(max(0.0, a / 2 - part.corner + inward - (long_side / 2 - hole.corner)),
                            max(0.0, b / 2 - part.corner + inward - (short_side / 2 - hole.corner)))
        return beyond == 0.0 or beyond + arc <= hole.corner

    if corners_pass(room):
        return 2 * room
    low = -b / 2  # the part shrunk to a line passes any corner
    while room - low > 1e-10:
        mid = (low + room) / 2
        low, room = (mid, room) if corners_pass(mid) else (low, mid)
    return 2 * low


def passes(part: Section, hole: Section) -> bool:
    """Whether the part's cross-section passes the hole's, aligned: a positive
    :func:`margin` (no clearance needed beyond a positive one)."""
    return margin(part, hole) > 0


def feature_passes(part: PartSpec, hole: HoleSpec) -> bool:
    """Whether the cell's ``part`` goes into or onto the feature ``hole``: a peg into a
    hole when its section :func:`passes` the hole's, a part with a bore onto a pin when the
    pin's section passes the bore's, and at room 0 too (a :func:`margin` of 0, never less)
    when the part is one the hole states a nominal zero-clearance fit with
    (``zero_clearance``); a peg onto a pin or a part with a bore into a hole never (the
    cell does not try them, and an import's closed world has no such fit)."""
    if part.bore != hole.pin:
        return False
    room = margin(hole, part) if hole.pin else margin(part, hole)
    return room > 0 or (room >= 0 and part.id in hole.zero_clearance)


def outline_polygon(section: Section, *, peg: bool) -> shapely.Polygon:
    """The section as a polygon in its own frame [m]: a polygon's outline less its
    ``inner`` rings, a square's or
    rect's exact rectangle (its corner arcs 256-gons as a circle's), a round one's 256-gon
    around the circle for a ``peg`` (it holds the part), inside it for a hole.
    OutlineError naming the section when its outline is no simple polygon."""
    if section.kind == "polygon":
        return polygon(np.array(section.outline), f"the section of {section.id}",
                       [np.array(ring) for ring in section.inner])
    if section.kind == "round":
        return circle(section.size / 2, outside=peg)
    a, b = section.sides
    if section.corner <= 0:
        return shapely.box(-a / 2, -b / 2, a / 2, b / 2)
    arc = circle(section.corner, outside=peg)
    core = shapely.box(section.corner - a / 2, section.corner - b / 2, a / 2 - section.corner, b / 2 - section.corner)
    return shapely.convex_hull(shapely.union_all([shapely.affinity.translate(arc, x, y)
                                                  for x, y in np.asarray(core.exterior.coords)[:4]]))


def section_fit(part: Section, hole: Section) -> PolygonFit:
    """How the part's section sits in the hole's (:mod:`executor.world.polygon_fit`):
    the room [m], the part's yaw [°] and offset [m] in the hole's frame; a round side's
    closed forms, the search otherwise; the exact rules of :func:`margin` (room half the
    margin, yaw 0, centred) when neither side is a polygon."""
    try:
        return _section_fit(_key(part), _key(hole))
    except OutlineError:  # the cached answer knows no ids: name the section that is no simple polygon
        for section in (part, hole):
            outline_polygon(section, peg=True)
        raise


def fit_pose(part: Section, hole: HoleSpec) -> tuple[float, np.ndarray]:
    """The part's yaw [rad] in the hole's frame and its origin's offset (x, y) [m] from the
    hole's position in the cell's axes where the polygon relation passes it (:func:`section_fit`);
    (0, 0) for pairs of round, square and rect sections (the skill aligns those itself,
    :func:`executor.world.frames.aligned_yaw`). A part with a bore onto a pin: the relation
    places the pin in the bore, so the part's pose is that placement's inverse."""
    if "polygon" not in (part.kind, hole.kind):
        return 0.0, np.zeros(2)
    if hole.pin:  # the pin at (yaw φ, offset o) in the bore: the bore at (-φ, -R(-φ) o) about the pin
        found = section_fit(hole, part)
        yaw = -math.radians(found.yaw)
        x, y = found.offset
        x, y = -(math.cos(yaw) * x - math.sin(yaw) * y), -(math.sin(yaw) * x + math.cos(yaw) * y)
    else:
        found = section_fit(part, hole)
        yaw, (x, y) = math.radians(found.yaw), found.offset
    c, s = math.cos(hole.yaw), math.sin(hole.yaw)
    return yaw, np.array([c * x - s * y, s * x + c * y])


def seat(peg: Section, hole: HoleSpec, stacked: float = 0.0) -> np.ndarray:
    """Where a peg's body origin is at its goal in ``hole`` [m, cell frame]: standing on its
    bottom, shifted as the polygon relation passes it (:func:`fit_pose`); in a hole entered
    sideways, at its tip's depth on the hole's axis; a part with a bore onto a pin
    ``stacked`` [m] farther out along its axis, on the parts already on the pin."""
    x, y = np.array(hole.position) + fit_pose(peg, hole)[1]
    goal = np.array([x, y, hole.bottom_z + stacked])
    return goal if hole.frame is None else hole.frame.points_to_cell(goal)


def seated_pose(peg: Section, hole: HoleSpec) -> tuple[np.ndarray, tuple[float, float, float, float]]:
    """The body pose (position [m], quaternion xyzw) of a peg at its goal in ``hole``, a hole
    entered down (:func:`seat`), turned as the cell inserts it without errors
    (:func:`executor.world.frames.aligned_yaw` of the hole's yaw and the relation's turn)."""
    return seat(peg, hole), yaw_quat(aligned_yaw(peg.kind, hole.kind, hole.yaw + fit_pose(peg, hole)[0]))


def _key(section: Section) -> Section:
    """The section without its id (pairs of equal sections share one answer)."""
    return Section("", section.kind, section.size, width=section.width, outline=section.outline,
                   corner=section.corner, inner=section.inner)


@functools.lru_cache(maxsize=4096)
def _section_fit(part: Section, hole: Section) -> PolygonFit:
    if "polygon" not in (part.kind, hole.kind):
        return PolygonFit(margin(part, hole) / 2, 0.0, (0.0, 0.0))
    if hole.kind == "round":
        return round_fit(outline_polygon(part, peg=True), None, hole_diameter=hole.size)
    if part.kind == "round":
        return round_fit(None, outline_polygon(hole, peg=False), peg_diameter=part.size)
    return polygon_fit(outline_polygon(part, peg=True), outline_polygon(hole, peg=False))


def sizes_lp_text(assembly: str) -> str:
    """The ``sizes.lp`` of an assembly folder as its geometry makes it: ``part/1`` for each
    part of ``assembly.toml`` with a cross-section (``[part_shapes.*]``), ``hole/1`` for
    each hole, ``fits/2`` for every pair that :func:`feature_passes` (closed world), as clingo
    symbols in the order of ``assembly.toml``, one line per part."""
    geometry = load_geometry(assembly)
    layout = geometry.layout
    pegs = [part.id for part in layout.parts if part.id in geometry.parts]
    holes = [hole.id for hole in layout.holes if hole.id in geometry.holes]

    def facts(symbols: list[clingo.Symbol]) -> str:
        return " ".join(f"{symbol}." for symbol in symbols)

    lines = [f"% {geometry.folder.name}: which part fits which hole (closed world), generated from geometry.toml",
             "% by executor.world.geometry.passes; do not edit, regenerate with",
             f"% ./run.sh executor sizes --assembly {geometry.folder.name} --out "
             f"data/{geometry.folder.name}/sizes.lp",
             facts([clingo.Function("part", [clingo.Function(pid)]) for pid in pegs]),
             facts([clingo.Function("hole", [clingo.Function(hid)]) for hid in holes])]
    for pid in pegs:
        fits = [clingo.Function("fits", [clingo.Function(pid), clingo.Function(hid)]) for hid in holes
                if feature_passes(geometry.parts[pid], geometry.holes[hid])]
        if fits:
            lines.append(facts(fits))
    return "\n".join(lines) + "\n"


def _ring(kind: str, half: float, n: int, half_y: float = 0.0) -> np.ndarray:
    """(n, 2) boundary points [m]: an n-gon of inradius ``half`` at angles 2πk/n, a square
    of half side ``half`` at those angles (its corners are among the points since n is a
    multiple of 8), or (rect) that square ring scaled to half sides ``half`` × ``half_y``,
    so its corners have the same indices and its points the same order as the boss's."""
    angles = 2.0 * np.pi * np.arange(n) / n
    c, s = np.cos(angles), np.sin(angles)
    if kind == "round":
        radius = np.full(n, half / math.cos(math.pi / n))
    elif kind == "rect":
        unit = 1.0 / np.maximum(np.abs(c), np.abs(s))
        return np.stack([half * unit * c, half_y * unit * s], axis=1)
    else:
        radius = half / np.maximum(np.abs(c), np.abs(s))
    return np.stack([radius * c, radius * s], axis=1)


def _turned(ring: np.ndarray, yaw: float) -> np.ndarray:
    """``ring`` (n, 2) [m] turned by ``yaw`` [rad] about the origin (unchanged at yaw 0)."""
    if yaw == 0.0:
        return ring
    c, s = math.cos(yaw), math.sin(yaw)
    return ring @ np.array([[c, s], [-s, c]])


def _boss_triangles(hole: HoleSpec, plate: Plate, base: float) -> list[np.ndarray]:
    """Triangles (3×3 vertex arrays [m], outward normals) of one boss standing on the
    plate under the bosses (its top at ``base`` [m]) up to the hole's entry, with a 45°
    entry chamfer and the hole down to its bottom: through the boss (the plate is the
    bottom) when the bottom is at ``base``, else onto a floor of the boss; a polygon
    hole's from its outline (:func:`executor.world.outlines.boss_triangles`)."""
    n = plate.polygon_sides
    cx, cy = hole.position
    top = hole.top_z
    floor = hole.bottom_z if hole.bottom_z - base >= FLOOR_MIN else None
    if hole.kind == "polygon":
        return _oriented(_polygon_boss(hole, plate, base if floor is None else floor, base))
    chamfer = plate.chamfer
    half_a, half_b = hole.sides[0] / 2, hole.sides[1] / 2
    outer = _turned(_ring("square", tile_of(plate, hole) / 2, n), hole.yaw) + (cx, cy)
    mouth = _turned(_ring(hole.kind, half_a + chamfer, n, half_b + chamfer), hole.yaw) + (cx, cy)
    inner = _turned(_ring(hole.kind, half_a, n, half_b), hole.yaw) + (cx, cy)

    def v(ring: np.ndarray, k: int, z: float) -> np.ndarray:
        x, y = ring[k % n]
        return np.array([x, y, z])

    tris: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = []  # (a, b, c, wanted normal)
    centre_top = np.array([cx, cy, top])
    up, down = np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, -1.0])
    for k in range(n):
        o0, o1, m0, m1 = v(outer, k, top), v(outer, k + 1, top), v(mouth, k, top), v(mouth, k + 1, top)
        tris += [(o0, o1, m1, up), (o0, m1, m0, up)]
        i0, i1 = v(inner, k, top - chamfer), v(inner, k + 1, top - chamfer)
        slope = centre_top - (m0 + m1) / 2 + np.array([0.0, 0.0, np.linalg.norm(centre_top - (m0 + m1) / 2)])
        tris += [(m0, m1, i1, slope), (m0, i1, i0, slope)]
        f0, f1 = v(inner, k, base if floor is None else floor), v(inner, k + 1, base if floor is None else floor)
        wall_in = centre_top - (i0 + i1) / 2
        wall_in[2] = 0.0
        tris += [(i0, i1, f1, wall_in), (i0, f1, f0, wall_in)]
        b0, b1 = v(outer, k, base), v(outer, k + 1, base)
        wall_out = (o0 + o1) / 2 - centre_top
        tris += [(o0, o1, b1, wall_out), (o0, b1, b0, wall_out)]
        if floor is None:  # an open ring on the plate, which is the hole's bottom
            tris += [(b0, b1, f1, down), (b0, f1, f0, down)]
        else:  # the boss's floor inside the hole, its solid bottom on the plate
            tris += [(np.array([cx, cy, floor]), f0, f1, up), (np.array([cx, cy, base]), b0, b1, down)]
    return _oriented([(np.array([a, b, c]), wanted) for a, b, c, wanted in tris])


def _oriented(tris: list[tuple[np.ndarray, np.ndarray]]) -> list[np.ndarray]:
    """Each triangle (3×3 [m]) with its corners in the order whose normal points along its wanted normal."""
    out = []
    for tri, wanted in tris:
        a, b, c = tri
        if np.dot(np.cross(b - a, c - a), wanted) < 0:
            b, c = c, b
        out.append(np.array([a, b, c]))
    return out


_Made = TypeVar("_Made")


def _polygon_boss(hole: HoleSpec, plate: Plate, bottom: float, base: float) -> list[tuple[np.ndarray, np.ndarray]]:
    """The boss of a polygon hole in the cell frame (:func:`executor.world.outlines.boss_triangles`);
    ExecutorError naming the hole when its chamfered mouth leaves the boss."""
    return polygon_boss(hole, plate, bottom, base, boss_triangles)


def polygon_boss(hole: HoleSpec, plate: Plate, bottom: float, base: float,
                 make: Callable[[np.ndarray, np.ndarray, float, float, float, float], list[_Made] | str]
                 ) -> list[_Made]:
    """The boss of a polygon hole as ``make`` builds it
    (:func:`executor.world.outlines.boss_triangles` or ``boss_solids``) from the hole's
    outline and its square tile in the cell frame (turned by its yaw, at its position),
    the plate's chamfer, the hole's entry, ``bottom`` and ``base`` [m]; ExecutorError naming
    the hole when its chamfered mouth leaves the boss."""
    ring = corners(outline_polygon(hole, peg=False))
    half = tile_of(plate, hole) / 2
    tile = np.array([[-half, -half], [half, -half], [half, half], [-half, half]])
    found = make(_turned(ring, hole.yaw) + hole.position, _turned(tile, hole.yaw) + hole.position,
                 plate.chamfer, hole.top_z, bottom, base)
    if isinstance(found, str):
        raise ExecutorError(f"hole '{hole.id}': {found} (boss side {tile_of(plate, hole):g} m, chamfer "
                            f"{plate.chamfer:g} m)")
    return found


def tile_of(plate: Plate, hole: HoleSpec) -> float:
    """The side of ``hole``'s square boss [m]: its own ``tile``, else the plate's ``tile_size``."""
    return plate.tile_size if hole.tile is None else hole.tile


def plate_obj_text(geometry: CellGeometry) -> str:
    """Wavefront OBJ of all hole bosses, in the cell frame [m] (vertices rounded to 1 µm);
    none for a base simulated from its own mesh (:attr:`CellGeometry.base_mesh`: its holes
    and pins are in it, and the cell loads it in place of the plate)."""
    lines = ["# generated by executor/world/geometry.py from geometry.toml and assembly.toml"]
    if geometry.base_mesh is not None:
        return "\n".join([*lines, "# no bosses: the base is its own mesh"]) + "\n"
    count = 0
    for hid in sorted(geometry.holes):  # a hole entered sideways or a pin needs the base's own mesh (the loader)
        lines.append(f"o boss_{hid}")
        for tri in _boss_triangles(geometry.holes[hid], geometry.plate, geometry.base_top):
            lines += [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in tri]
            lines.append(f"f {count + 1} {count + 2} {count + 3}")
            count += 3
    return "\n".join(lines) + "\n"


PART_RGBA = "0.8 0.6 0.2 1"
"""The colour of the pegs, covers and heads in the generated URDFs."""


def peg_body(part: PartSpec) -> MeshBody | None:
    """A peg's shape simulated from its own mesh (None for a cylinder or box)."""
    return None if part.mesh is None else MeshBody(f"part_{part.shape}", part.mesh, part.mass, f"part '{part.id}'")


def product_bodies(geometry: CellGeometry) -> dict[str, MeshBody]:
    """The covers and heads simulated from their own meshes, by part id."""
    tables = geometry.tables
    bodies = {cid: MeshBody(f"cover_{cid}", cover.mesh, cover.mass, f"cover '{cid}'")
              for cid, cover in sorted(tables.covers.items()) if cover.mesh is not None}
    return bodies | {hid: MeshBody(f"head_{hid}", head.mesh, head.mass, f"head '{hid}'")
                     for hid, head in sorted(tables.heads.items()) if head.mesh is not None}


def is_prism(part: PartSpec) -> bool:
    """Whether the cell builds the peg as the prism of its outline: a polygon without a mesh."""
    return part.kind == "polygon" and part.mesh is None


def prism(part: PartSpec) -> list[np.ndarray] | None:
    """The convex pieces (vertices (n, 3) [m] in its upright part frame) of a peg the cell
    builds as its outline's prism over its length (:func:`is_prism`,
    :func:`executor.world.outlines.prism_pieces`); None for any other peg."""
    return prism_pieces(outline_polygon(part, peg=True), part.length) if is_prism(part) else None


def thin_prism(part: Section, length: float) -> str | None:
    """Why the cell cannot collide as the prism of a polygon section over ``length`` [m]
    (a convex piece of its outline thinner than :data:`executor.world.meshes.MIN_THICKNESS`,
    which the margin would widen), None when it can."""
    for k, vertices in enumerate(prism_pieces(outline_polygon(part, peg=True), length)):
        if eroded(vertices, URDF_HULL_MARGIN) is None:
            inradius = shapely.length(shapely.maximum_inscribed_circle(shapely.MultiPoint(vertices[:, :2]).convex_hull,
                                                                       1e-7))
            return (f"convex piece {k + 1} of its outline is {2e3 * inradius:.3f} mm thick, less than the cell's hull "
                    f"margin twice less what it resolves ({1e3 * MIN_THICKNESS:g} mm)")
    return None


def prism_names(shape: str) -> tuple[str, str]:
    """The files in ``assets/`` of a polygon peg shape's prism: its exact pieces (the
    visual) and those pieces eroded by the hull margin (the collision)."""
    return f"part_{shape}.prism.obj", f"part_{shape}.convex.obj"


def peg_files(geometry: CellGeometry, part: PartSpec, *, absolute: bool) -> MeshFiles | None:
    """The files of a peg simulated from its own mesh (:func:`mesh_files`) or as the prism
    of its polygon outline (:func:`prism`); None for a cylinder or box."""
    pieces = prism(part)
    if pieces is None:
        return mesh_files(geometry, peg_body(part), absolute=absolute)
    visual, collision = (str(geometry.assets / name) if absolute else name for name in prism_names(part.shape))
    return MeshFiles(visual, collision, pieces_inertia(pieces, part.mass))


def mesh_files(geometry: CellGeometry, body: MeshBody | None, *, absolute: bool) -> MeshFiles | None:
    """The files of a mesh part (None for a primitive one): relative to ``assets/`` (a URDF
    written there) or ``absolute`` (one written elsewhere)."""
    if body is None:
        return None
    visual = geometry.folder / body.mesh.file
    collision = geometry.assets / body.convex_asset
    names = (str(visual), str(collision)) if absolute else (f"../{body.mesh.file}", collision.name)
    return MeshFiles(*names, mesh_inertia(visual, body.mass))


def part_geometry_xml(part: PartSpec, z_centre: float, rgba: str) -> str:
    """URDF ``<visual>`` + ``<collision>`` of a cylinder or box part whose axis is z,
    centred at ``z_centre`` [m]."""
    if part.kind == "round":
        shape = f'<cylinder radius="{part.size / 2:.6f}" length="{part.length:.6f}"/>'
    else:
        a, b = part.sides
        shape = f'<box size="{a:.6f} {b:.6f} {part.length:.6f}"/>'
    origin = f'<origin xyz="0 0 {z_centre:.6f}" rpy="0 0 0"/>'
    return (
        f"    <visual>{origin}<geometry>{shape}</geometry>"
        f'<material name="part"><color rgba="{rgba}"/></material></visual>\n'
        f"    <collision>{origin}<geometry>{shape}</geometry></collision>\n"
    )


def _inertial_xml(mass: float, inertia: float, z: float) -> str:
    return (
        f'    <inertial><origin xyz="0 0 {z:.6f}" rpy="0 0 0"/><mass value="{mass:.6f}"/>'
        f'<inertia ixx="{inertia:.6f}" ixy="0" ixz="0" iyy="{inertia:.6f}" iyz="0" izz="{inertia:.6f}"/></inertial>\n'
    )


def _part_link_xml(part: PartSpec, files: MeshFiles | None, held: bool) -> str:
    """Inertial, visual and collision of a part upright on the tray (link frame at its
    bottom face centre) or ``held`` (frame at its tip, z pointing away from the arm)."""
    if files is not None:
        return mesh_link_xml(files, PART_RGBA, held)
    inertia = part.mass * (part.size**2 + part.length**2) / 12
    centre = -part.length / 2 if held else part.length / 2
    return _inertial_xml(part.mass, inertia, centre) + part_geometry_xml(part, centre, PART_RGBA)


def part_urdf_text(part: PartSpec, files: MeshFiles | None = None) -> str:
    """A free part lying on the tray (upright, frame at its bottom face centre); a mesh
    part needs its ``files`` (:func:`mesh_files`)."""
    return (
        f'<?xml version="1.0"?>\n<robot name="{part.shape}">\n  <link name="part">\n'
        + _part_link_xml(part, files, held=False)
        + "  </link>\n</robot>\n"
    )


# The flange link is attached 45 mm beyond joint 7 (the iiwa's flange face).
_FLANGE_OFFSET = 0.045
JOINT_RATE_LIMITS = (85.0, 85.0, 100.0, 75.0, 130.0, 135.0, 135.0)
"""[°/s] the axis speeds A1–A7 of the KUKA LBR iiwa 14 R820 (KUKA, "LBR iiwa 7 R800, LBR iiwa
14 R820 Specification", axis data), the arm whose geometry pybullet_data's ``kuka_iiwa`` has
(0.36 m from its base to A2, 0.42 m on to A4, 0.40 m to A6, 0.126 m to the flange face);
that URDF's ``velocity`` is 10 rad/s on every joint, no arm's: :func:`arm_urdf_text` writes
these (in rad/s) in its place. PyBullet does not enforce them (the arm is torque driven):
the cell's moves keep within them (:mod:`executor.assembly.transfer`)."""
_JOINT_LIMIT = re.compile(r'(<joint name="lbr_iiwa_joint_(\d)".*?<limit [^>]*?velocity=")[^"]*(")', re.S)


def _rate_limits(text: str, source: Path) -> str:
    """The iiwa URDF ``text`` with each joint's ``velocity`` set to :data:`JOINT_RATE_LIMITS`."""
    def limit(match: re.Match[str]) -> str:
        return f"{match[1]}{math.radians(JOINT_RATE_LIMITS[int(match[2]) - 1]):.6f}{match[3]}"

    text, count = _JOINT_LIMIT.subn(limit, text)
    if count != len(JOINT_RATE_LIMITS):
        raise ExecutorError(f"{source}: {count} joints lbr_iiwa_joint_N with a velocity limit, expected "
                            f"{len(JOINT_RATE_LIMITS)} (the arm's URDF of pybullet_data)")
    return text


def arm_urdf_text(part: PartSpec, gripper: Gripper, files: MeshFiles | None = None) -> str:
    """The pybullet_data ``kuka_iiwa``, its joints' speed limits the real arm's
    (:data:`JOINT_RATE_LIMITS`), with a flange (realistic inertia) and the held part.

    Links appended after ``lbr_iiwa_link_7``: ``flange`` (fixed) and ``part`` (fixed joint
    ``ft_sensor``: the wrist force/torque sensor).  The ``part`` link frame is at the
    part's tip (the tool centre point), z along the part axis, pointing away from the arm.
    Mesh paths point into the installed pybullet_data, so the text is written at run time;
    a mesh part needs its ``files`` with absolute paths (:func:`mesh_files`).
    """
    source = Path(pybullet_data.getDataPath()) / "kuka_iiwa" / "model.urdf"
    text = _rate_limits(source.read_text(), source).replace('filename="meshes/', f'filename="{source.parent}/meshes/')
    flange_len = gripper.flange_length
    tip = flange_len + part.length - part.held_depth(gripper)
    tool = (
        '  <joint name="flange_joint" type="fixed"><parent link="lbr_iiwa_link_7"/><child link="flange"/>'
        f'<origin xyz="0 0 {_FLANGE_OFFSET}" rpy="0 0 0"/></joint>\n'
        '  <link name="flange">\n'
        + _inertial_xml(gripper.flange_mass, gripper.flange_inertia, flange_len / 2)
        + f'    <visual><origin xyz="0 0 {flange_len / 2:.6f}" rpy="0 0 0"/><geometry>'
        f'<cylinder radius="0.03" length="{flange_len:.6f}"/></geometry>'
        '<material name="gripper"><color rgba="0.3 0.3 0.35 1"/></material></visual>\n'
        "  </link>\n"
        '  <joint name="ft_sensor" type="fixed"><parent link="flange"/><child link="part"/>'
        f'<origin xyz="0 0 {tip:.6f}" rpy="0 0 0"/></joint>\n'
        '  <link name="part">\n'
        + _part_link_xml(part, files, held=True)
        + "  </link>\n"
    )
    return text.replace("</robot>", tool + "</robot>")


def _hull(vertices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (n, 3) [m] and faces (m, 3) of the convex hull of ``vertices``."""
    hull = trimesh.convex.convex_hull(vertices)
    return np.asarray(hull.vertices), np.asarray(hull.faces)


def write_assets(geometry: CellGeometry) -> list[Path]:
    """(Re)generate ``assets/plate.obj``, ``assets/part_<shape>.urdf``, for a part shape,
    cover or head simulated from its own mesh its eroded convex pieces, for a polygon peg
    shape without one its prism's pieces, exact and eroded (:func:`prism_names`), for such a
    cover or head its URDF (``cover_<id>.urdf``, ``head_<id>.urdf``), each written
    atomically (a cell starting meanwhile never loads half a file); returns the paths."""
    make_folder(geometry.assets)
    written = [write_atomic(geometry.assets / "plate.obj", plate_obj_text(geometry))]
    pegs: dict[str, PartSpec] = {}
    for part in geometry.parts.values():
        pegs.setdefault(part.shape, part)
    others = product_bodies(geometry)
    for body in [peg_body(part) for _, part in sorted(pegs.items())] + list(others.values()):
        if body is not None and body.mesh.convex is not None:
            written.append(write_atomic(geometry.assets / body.convex_asset,
                                        eroded_pieces_text(geometry.folder / body.mesh.convex, body.what)))
    for shape, part in sorted(pegs.items()):
        pieces = prism(part)
        if pieces is not None:
            exact, collision = prism_names(shape)
            what = f"the prism of part '{part.id}'"
            written += [write_atomic(geometry.assets / exact, obj_text(
                            [(f"piece{k + 1}", *_hull(piece)) for k, piece in enumerate(pieces)],
                            f"# generated from [part_shapes.{shape}] outline and length: its convex pieces")),
                        write_atomic(geometry.assets / collision,
                                     eroded_text(pieces, what, f"[part_shapes.{shape}] outline"))]
    for shape, part in sorted(pegs.items()):
        files = peg_files(geometry, part, absolute=False)
        written.append(write_atomic(geometry.assets / f"part_{shape}.urdf", part_urdf_text(part, files)))
    for body in others.values():
        files = mesh_files(geometry, body, absolute=False)
        assert files is not None  # a body of its own mesh
        written.append(write_atomic(geometry.assets / f"{body.stem}.urdf", mesh_urdf_text(body.stem, files, PART_RGBA)))
    return written
