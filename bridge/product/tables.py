"""The structs of the product description (:mod:`bridge.product`): ``assembly.toml``
(:class:`AssemblyFile`) and ``geometry.toml`` (:class:`GeometryFile`) as decoded TOML,
their ranges and units in the types' descriptions (the error messages and the published
JSON Schema say the same). Units: lengths and positions [m], masses [kg], inertia
[kg m^2], yaw [degrees].

Pairs and quadruples are lists of fixed length, not tuples: msgspec 0.22 corrupts memory
when a union holds a constrained float and a tuple of them (docs/decisions.md).
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Annotated, Literal

import msgspec
from msgspec import Meta

MAX_ID_CHARS = 64
"""The longest part or hole id [characters]."""
ID_PATTERN = rf"^(?!not$)[a-z][a-zA-Z0-9_]{{0,{MAX_ID_CHARS - 1}}}$(?!\n)"
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
SHAPES = ("round", "square", "rect", "polygon")
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
Kind = Literal["round", "square", "rect", "polygon"]
InsertionAxis = Literal["-z", "+x", "-x", "+y", "-y"]
"""The direction [cell frame] a part goes into a hole along: down, or sideways along an axis."""
Coordinate = Annotated[float, Meta(ge=-MAX_COORDINATE, le=MAX_COORDINATE,
                                   description="a number in [-100, 100] m")]
XY = Annotated[list[Coordinate], Meta(min_length=2, max_length=2,
                                      description="[x, y] in metres, finite and within ±100")]
Offset = Annotated[float, Meta(ge=-1.0, le=1.0, description="a number in [-1, 1] m")]
OffsetXY = Annotated[list[Offset], Meta(min_length=2, max_length=2, description="[x, y], each in [-1, 1] m")]
Side = Annotated[float, Meta(gt=0.0, le=0.1, description="a number in (0, 0.1] m")]
SectionSize = Side | Annotated[list[Side], Meta(min_length=2, max_length=2, description="for a rect [a, b] with "
                                                "a >= b, each such a number")]
MAX_OUTLINE_POINTS = 4096
"""The most points a polygon section's ``outline`` has."""
OutlinePoint = Annotated[list[Annotated[float, Meta(ge=-0.1, le=0.1)]], Meta(
    min_length=2, max_length=2, description="[x, y], each a number in [-0.1, 0.1] m")]
Outline = Annotated[list[OutlinePoint], Meta(min_length=3, max_length=MAX_OUTLINE_POINTS, description=(
    "the points [[x, y], ...] in m of a simple polygon (3 to 4096 points, no crossing edges), in the part's or "
    "hole's frame"))]
Corner = Annotated[float, Meta(ge=0.0, le=0.05, description="a number in [0, 0.05] m")]
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
    """``[holes.<id>]``: a readable ``name``, its cross-section kind (default: the kind of
    its ``[hole_shapes.*]`` in ``geometry.toml``, else round), its ``position`` [m] on the
    base plate, its ``capacity``: how many parts the product stacks in it or onto it (a
    pin several parts go onto, one above the other); for a hole of part ``owner`` on the
    line of another hole (``on_line``: a bracket's flange hole over the plate's hole a bolt
    goes through it into), both: a part goes through it into that hole, never into it
    alone (the planner's ``on_line/3``, docs/plans.md)."""

    name: Text | None = None
    shape: Kind | None = None
    position: XY | None = None
    capacity: Annotated[int, Meta(ge=1, le=64, description="an integer in 1 .. 64")] = 1
    on_line: Id | None = None
    owner: Id | None = None


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

EntryHeight = Annotated[float, Meta(gt=0.0, le=1.0, description="a number in (0, 1] m")]
HoleDepth = Annotated[float, Meta(gt=0.0, le=0.2, description="a number in (0, 0.2] m")]


TileSize = Annotated[float, Meta(gt=0.0, le=0.5, description="a number in (0, 0.5] m")]


class Plate(Table, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """``[plate]``: the bosses' top face height (the hole entries), side and thickness (=
    the hole depth), each hole's unless its shape gives its own, the entry chamfer [m],
    the sides of a round hole's polygon, the plate under the bosses."""

    top_z: EntryHeight
    tile_size: TileSize
    tile_thickness: HoleDepth
    chamfer: Annotated[float, Meta(gt=0.0, le=0.01, description="a number in (0, 0.01] m")]
    polygon_sides: Annotated[int, Meta(ge=8, le=256, multiple_of=8,
                                       description="an integer multiple of 8 in 8 .. 256")]
    base_thickness: Annotated[float, Meta(gt=0.0, le=0.2, description="a number in (0, 0.2] m")]
    base_size: Annotated[list[Annotated[float, Meta(gt=0.0, le=2.0)]],
                         Meta(min_length=2, max_length=2, description="[x, y], each a number in (0, 2] m")]
    base_center: XY


class Gripper(Table, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """``[gripper]``: flange + F/T sensor + gripper mass [kg] and inertia [kg m^2], flange
    face to the fingertips [m], part length inside the fingers [m]; the suction tool the
    same flange carries for a part whose ``[part_shapes.*]`` says ``tool = "suction"``: its
    cup's diameter [m] (its face where the fingertips are) and holding force [N], the most
    force pulling the part off the cup it takes (docs/cell.md#the-suction-tool)."""

    flange_mass: Annotated[float, Meta(gt=0.0, le=20.0, description="a number in (0, 20] kg")]
    flange_inertia: Annotated[float, Meta(gt=0.0, le=1.0, description="a number in (0, 1] kg m^2")]
    flange_length: Annotated[float, Meta(gt=0.0, le=0.5, description="a number in (0, 0.5] m")]
    grasp_depth: Annotated[float, Meta(gt=0.0, le=0.2, description="a number in (0, 0.2] m")]
    cup_diameter: Annotated[float, Meta(gt=0.0, le=0.2, description="a number in (0, 0.2] m")] = 0.03
    cup_force: Annotated[float, Meta(gt=0.0, le=1000.0, description="a number in (0, 1000] N")] = 20.0


class HoleShape(Table, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """``[hole_shapes.<name>]``: holes of one cross-section; ``size`` a diameter or side
    [m], for a rect ``[a, b]`` (a along the hole's x axis, turned by ``yaw`` [degrees]),
    for a polygon the extents ``[a, b]`` of its ``outline`` along x and y (about the
    hole's position, in the hole's frame); a square's or rect's ``corner`` radius [m];
    ``top_z`` the height of their entry and ``depth`` from the entry to their bottom [m],
    where they differ from the plate's ``top_z`` and ``tile_thickness``. With ``pin`` they
    are pins of the base (in its own mesh) that parts with a bore go onto: the section is
    the pin's, ``top_z`` its top and ``depth`` from its top down to where a part going
    onto it rests (both required); a pin with an ``owner`` stands up (``axis`` ``-z``) on
    that part placed by hand (``[manual.<id>]``, in the base's place of a pin: its part is
    put onto it with that part at its ``goal``) or on that peg of ``[part_shapes.*]`` the
    cell inserts down into its ``demo_hole`` (its position and top with the peg at its
    goal there; its part is put onto it where the peg ended). ``axis`` is the direction a part goes in along: ``-z``
    (down) or sideways (``+x``, ``-x``, ``+y``, ``-y``); a sideways hole is in the
    ``[base]``'s own mesh, its section, ``outline`` and ``yaw`` in its hole frame (z out of
    the hole, x and y the import's slice axes: :func:`executor.world.frames.hole_rotation`),
    its position (``assembly.toml``) and ``top_z`` the x, y and z of its entry's centre
    (``top_z`` required), ``depth`` from the entry along the axis to where a part's tip
    ends (the taught goal: nothing stops a part in a through hole); a sideways pin's entry
    is its free end, its ``depth`` along the axis to its part's nearest end. ``zero_clearance`` names
    the parts stated to fit at room 0, a nominal zero-clearance fit (pegs of ``part_shapes``,
    or parts with a ``bore`` for a pin): the section is the nominal one, and a listed part
    whose section is not wider passes (any other part needs room above 0). A pin's
    ``widened`` names the parts whose round bore's room on it (room 0 or positive) is under
    what the simulated cell resolves: that cell builds their bores wider
    (``bridge.product.nominal.NOMINAL_FIT_ROOM`` per side), and the pair is observed with
    that room, not the CAD's; a round hole's of a base with its own mesh names such round
    pegs, which that cell builds that much narrower. ``near_miss``
    names the pegs that miss the hole by less than the simulated cell resolves with their
    corners rounded by its hull margin (``executor.world.near_miss``), or every peg of a
    hole no deeper than the cell's goal tolerance (one blocked on its rim ends as near its
    goal), and on a pin the parts with a bore that do not pass it and would stop on its end
    within that tolerance of their goal on it: no experiment, their outcome is taken from
    ``sizes.lp``. ``tile`` is the
    side of their square bosses [m] where it differs from the plate's ``tile_size``."""

    holes: Ids
    kind: Kind
    size: SectionSize
    outline: Outline | None = None
    corner: Corner = 0.0
    yaw: Yaw = 0.0
    top_z: EntryHeight | None = None
    depth: HoleDepth | None = None
    pin: bool = False
    axis: InsertionAxis = "-z"
    zero_clearance: Ids | None = None
    widened: Ids | None = None
    near_miss: Ids | None = None
    tile: TileSize | None = None
    owner: Id | None = None


class PartShape(Table, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """``[part_shapes.<name>]``: pegs of one cross-section (the name is their skill's);
    ``length`` [m], ``mass`` [kg], the hole its demonstration is taught in, and ``mesh``
    when they are simulated from their own mesh rather than as a cylinder or box; a
    polygon's ``outline`` about the centre of its section in the part frame, ``size`` its
    extents ``[a, b]`` along x and y (a polygon peg is simulated from its mesh); a
    square's or rect's ``corner`` radius [m]. With ``bore`` they are parts with a bore
    that go onto pins (``[hole_shapes.*]`` with ``pin``): the section is the bore's, the
    part frame's origin the centre of the bore at the part's bottom, ``demo_hole`` a pin;
    ``pins_of`` the parts placed by hand (``[manual.<id>]``) whose pins they go onto
    besides their ``demo_hole``, each through a bore of its own (they stand at their goals
    in the trials of these parts). ``grasp_depth`` [m]: how deep the fingers hold them where
    less than the ``[gripper]``'s (a part that stands out of the product at its goal by
    less; a part with a bore is held at most half its length deep besides,
    docs/cell.md#the-fingers-grip)."""

    parts: Ids
    kind: Kind
    size: SectionSize
    outline: Outline | None = None
    corner: Corner = 0.0
    length: Length
    mass: Mass
    demo_hole: Id
    mesh: Mesh | None = None
    bore: bool = False
    pins_of: Ids | None = None
    tool: Literal["fingers", "suction"] = "fingers"
    grasp_depth: Annotated[float, Meta(gt=0.0, le=0.2, description="a number in (0, 0.2] m")] | None = None


MESH_FILE_PATTERN = r"^[A-Za-z0-9_-][A-Za-z0-9_.-]*(/[A-Za-z0-9_-][A-Za-z0-9_.-]*)*\.obj$(?!\n)"
"""A mesh file of a product: a relative path inside its assembly folder (no component
starting with ``.``, so no ``..``), ending in ``.obj``."""
MeshFile = Annotated[str, Meta(pattern=MESH_FILE_PATTERN, max_length=200, description="a path of an .obj file inside "
                               "the assembly folder (relative, '/' between names, none starting with '.')")]
Sha256 = Annotated[str, Meta(pattern=r"^[0-9a-f]{64}$(?!\n)", description="a SHA-256 digest (64 lower-case hex "
                             "digits)")]
CONVEX_HEADER = "# convex pieces of {file} sha256 {sha256}"
"""The first line of a ``convex`` file: the mesh (its path and digest) it was made from."""


class Mesh(Table, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """``mesh`` of a ``[part_shapes.<name>]``, ``[covers.<id>]``, ``[heads.<id>]`` or of the
    ``[base]``: the part simulated from its own closed triangle mesh ``file`` (Wavefront
    OBJ, metres, in the part frame: a peg's origin at the centre of its section at its
    bottom, z its axis upwards, x its section's long side; a cover's at the centre of the
    holes it goes over at its bottom face, a head's at the centre of its section at its
    bottom, a part placed by hand's at the centre of its bottom face, all with the cell's
    axes; the base's is the cell frame), the ``sha256`` of that
    file, and for a moving part ``convex``: the convex pieces it collides as (one OBJ object
    each, first line :data:`CONVEX_HEADER` naming the mesh they were made from)."""

    file: MeshFile
    sha256: Sha256
    convex: MeshFile | None = None


class ExtraPart(Table, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """``[extra_parts.<id>]``: a part of the cell that is not in ``assembly.toml``."""

    start: XY
    name: Text | None = None


class Base(Table, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """``[base]``: the part carrying the plate, where its ``base_center`` waits (``tray``
    [m]), its grip point from ``base_center`` [m], its mass [kg], and ``mesh`` when it is
    simulated from its own mesh (a static concave one) rather than as the ``[plate]``."""

    part: Id
    tray: XY
    grip: OffsetXY
    mass: Annotated[float, Meta(gt=0.0, le=50.0, description="a number in (0, 50] kg")]
    mesh: Mesh | None = None


class Cover(Table, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """``[covers.<id>]``: a part whose openings go down over the pins in the holes
    ``over``; ``outline`` [xmin, ymin, xmax, ymax] [m] around their centre, ``socket``
    ``[x, y, side, depth]`` [m] an optional blind opening for a head, ``skill`` the part
    shape whose taught motion places it, ``mesh`` when it is simulated from its own mesh
    rather than as the outline less square openings (``outline`` and ``clearance`` then
    describe it, the mesh is its solid)."""

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
    mesh: Mesh | None = None


class Head(Table, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """``[heads.<id>]``: a part going into the socket of cover ``into``; round (``size``
    a diameter) or square (a side) [m], ``length`` [m], ``mass`` [kg], ``mesh`` when it is
    simulated from its own mesh rather than as a cylinder or box."""

    into: Id
    size: Side
    length: Length
    mass: Mass
    skill: Id
    kind: Literal["round", "square"] = "round"
    name: Text | None = None
    mesh: Mesh | None = None


class Manual(Table, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """``[manual.<id>]``: a part the cell has no operation for (it goes in along no axis
    into a hole the cell knows), placed by hand: ``reason`` says why, ``goal`` [x, y, z] [m]
    is its frame's origin when assembled, ``tray`` where that origin waits [m]; simulated
    as its own ``mesh`` (its frame at the centre of its bounding box's bottom face, the
    cell's axes), a static concave mesh, fixed where it is placed (no convex pieces).
    ``on``: the holes and pins of ``assembly.toml`` it is in or on where the CAD has it
    (its goal), the plan gives it one of them; ``held_by``: the parts the cell places
    that carry one of those (a nut on a bolt's end), each with the holes it is in where
    the CAD has it, the plan puts it into one of them (else the part would not be on it).
    ``pressed``: it is pressed into what it is ``on`` (a press fit: no fit as the cell
    slides parts), so a plan gives it no hole; the hand presses it to its goal."""

    reason: Text
    goal: Annotated[list[Coordinate], Meta(min_length=3, max_length=3,
                                           description="[x, y, z] in metres, finite and within ±100")]
    tray: XY
    mass: Mass
    mesh: Mesh
    name: Text | None = None
    on: Ids | None = None
    held_by: dict[Id, Ids] = {}
    pressed: bool = False


class GeometryFile(Table, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """``geometry.toml``: the plate, the cross-sections of holes and pegs, the cell's extra
    parts, an optional gripper (else the cell description's), the product's base, covers,
    heads and the parts placed by hand."""

    plate: Plate
    hole_shapes: dict[Id, HoleShape] = {}
    part_shapes: dict[Id, PartShape] = {}
    extra_parts: dict[Id, ExtraPart] = {}
    gripper: Gripper | None = None
    base: Base | None = None
    covers: dict[Id, Cover] = {}
    heads: dict[Id, Head] = {}
    manual: dict[Id, Manual] = {}


class ProductDescription(msgspec.Struct, frozen=True, kw_only=True):
    """A product folder as decoded and checked: ``geometry`` None when it has no
    ``geometry.toml`` (a planner-only product)."""

    folder: Path
    assembly: AssemblyFile
    geometry: GeometryFile | None
