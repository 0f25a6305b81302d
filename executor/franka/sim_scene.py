"""The product in franky-sim's MuJoCo scene, built from the cell geometry that the PyBullet
cell loads (:func:`executor.world.geometry.load_geometry`: ``geometry.toml`` and
``assembly.toml`` of a product folder).

What is built, in MuJoCo's world frame (= the arm's base frame, :data:`PRODUCT_IN_BASE`):

- the plate under the bosses: one box from the floor up to :attr:`CellGeometry.base_top`;
- each hole's boss as overlapping convex pieces (MuJoCo collides a mesh as its convex
  hull, so a concave boss is made of convex ones): per face of the hole's wall, the boss
  beyond that face and its 45° entry chamfer (:func:`boss_pieces`); their union has the
  surfaces of the PyBullet cell's triangle mesh
  (:func:`executor.world.geometry.plate_obj_text`): round holes the same n-gons, square
  and rect holes exact; a hole with a floor gets the floor as one more piece; a polygon
  hole's boss is cut into convex pieces that do not overlap
  (:func:`executor.world.outlines.boss_solids`), exact to its outline and chamfer;
- a base given as its own mesh (a concave mesh has no convex-hull form): only its holes
  and round pins along a horizontal axis, each hole's boss turned into the hole's frame
  (:func:`sideways_boss`), each pin with the tile its parts rest against
  (:func:`sideways_pin`): the rest of the mesh is not there to collide with;
- each peg (``[part_shapes.*]``) as a free body at its tray start, upright on the floor:
  a cylinder or box of its mass, or with a ``mesh`` its convex pieces (the ``convex``
  file as made at import, not eroded: MuJoCo adds no margin) with the mesh's inertia.

Part-plate friction is the PyBullet cell's teaching friction (MuJoCo takes the larger of
two geoms' coefficients, so the pegs and the plate both carry it; the fingers keep
MuJoCo's 1.0 and grip with that). Not built: covers, heads, parts placed by hand, the pins
and holes entered down and the pins not round of a base given as its own mesh; each is
refused or left out as stated in :func:`add_product`.
"""

from __future__ import annotations

import dataclasses
import math
import xml.etree.ElementTree as ET
from collections.abc import Collection
from dataclasses import dataclass

import mujoco
import numpy as np
from scipy.spatial import HalfspaceIntersection

from bridge.product import Plate
from executor import ExecutorError
from executor.world.geometry import FLOOR_MIN, CellGeometry, HoleSpec, PartSpec, _ring, _turned, polygon_boss, tile_of
from executor.world.meshes import mesh_inertia, read_objects
from executor.world.outlines import boss_solids
from executor.world.scene import TEACH_FRICTION

PRODUCT_IN_BASE = np.zeros(3)
"""Where the product frame's origin lies in the arm's base frame [m], axes parallel: the
cell frame of ``geometry.toml`` and ``assembly.toml`` is the arm base's, as in the PyBullet
cell, whose arm also stands at the origin. Every pose between the two goes through
:func:`to_base` and :func:`from_base`."""

PART_PREFIX = "part_"
"""MuJoCo body name of a part: this prefix and the part's id."""

_FRICTION = f"{TEACH_FRICTION} 0.005 0.0001"  # sliding, torsional [m], rolling [m] (MuJoCo's defaults for the last two)
_SOLREF = "0.002 1"
"""Contact time constant [s] and damping ratio of the plate and the parts: the stiffest
MuJoCo allows at a 1 ms step. Its default (0.02 s) lets a 50 g part squeeze through an
interference of up to ~1 mm under 10 N (an 8 mm peg went into a 7.3 mm slot)."""
_PART_CONDIM = "4"  # sliding and torsional friction: a held part does not spin about the fingers' closing axis
_PLATE_RGBA = "0.7 0.72 0.75 1"
_PART_RGBA = "0.8 0.6 0.2 1"


CONTACT_OPTIONS = {"cone": "elliptic", "impratio": "10", "noslip_iterations": "5"}
"""MuJoCo's contact options (its documentation's advice against slip in a grasp: elliptic
friction cones, friction 10x stiffer than normal forces, a no-slip pass)."""

TIME_STEP = 0.001
"""MuJoCo's step [s]: franky-sim's, one per control packet (the PyBullet cell's too)."""


def set_contact_options(scene: ET.Element) -> None:
    """Put :data:`CONTACT_OPTIONS` into the ``<option>`` of a MuJoCo scene (made if missing)."""
    option = scene.find("option")
    if option is None:
        option = ET.SubElement(scene, "option")
    for key, value in CONTACT_OPTIONS.items():
        option.set(key, value)



WELD_SOLREF = "0.002 1"
"""Time constant [s] and damping ratio of a grasp weld: the stiffest MuJoCo allows at a
1 ms step (as :data:`_SOLREF`)."""

WELD_SOLIMP = "0.99 0.999 0.001"
"""Impedance of a grasp weld (MuJoCo's d0, dwidth, width [m]): near 1, so the weld gives
little. With :data:`WELD_SOLREF`, a 50 g part under 20 N and 0.2 N m moved 0.002 mm and
0.1° against its hand (MuJoCo's default solref/solimp: 7.8 mm and 24°). The weld's force is
not bounded (the PyBullet cell's grasp constraint stops at 500 N)."""


def weld_name(part: str) -> str:
    """MuJoCo name of the weld that holds ``part`` in the hand."""
    return f"grasp_{part}"


def add_grasp_welds(scene: ET.Element, hand: str, parts: dict[str, str]) -> None:
    """One weld per part (``parts``: MuJoCo body name by part id) between the body
    ``hand`` and the part, inactive, added to the ``<equality>`` of a MuJoCo scene (made if
    missing) before it is compiled; the grasp sets its pose and turns it on."""
    equality = scene.find("equality")
    if equality is None:
        equality = ET.SubElement(scene, "equality")
    for pid, body in sorted(parts.items()):
        ET.SubElement(equality, "weld", name=weld_name(pid), body1=hand, body2=body, active="false",
                      solref=WELD_SOLREF, solimp=WELD_SOLIMP, relpose="0 0 0 1 0 0 0")


def to_base(point: np.ndarray) -> np.ndarray:
    """A point [m] of the product frame in the arm's base frame."""
    return np.asarray(point, dtype=float) + PRODUCT_IN_BASE


def from_base(point: np.ndarray) -> np.ndarray:
    """A point [m] of the arm's base frame in the product frame."""
    return np.asarray(point, dtype=float) - PRODUCT_IN_BASE


@dataclass(frozen=True)
class StaticBox:
    """A box of the plate: centre and half extents [m], product frame, axis-aligned."""

    name: str
    centre: tuple[float, float, float]
    half: tuple[float, float, float]


@dataclass(frozen=True)
class ConvexPiece:
    """A convex solid of the plate: its vertices (n, 3) [m], product frame."""

    name: str
    vertices: np.ndarray


def boss_pieces(hole: HoleSpec, plate: Plate, base: float) -> list[np.ndarray]:
    """The boss around ``hole`` as convex solids, vertices (n, 3) [m], whose union is the
    PyBullet cell's boss (:func:`executor.world.geometry._boss_triangles`): the hole is the
    intersection of the half-planes inside its wall's faces (the n-gon's sides, a square's
    or rect's four), so the boss is the union, over the faces, of the solid beyond one face:
    from the plate under the bosses (``base`` [m]) to the entry, inside the boss's square
    outline, behind the face's plane and behind its chamfer's 45° plane (each an
    intersection of half-spaces: convex). The pieces overlap: a part pressing on a wall
    meets one wide piece and is pushed back through the wall's face (thin sectors of a ring
    let a penetrating corner out sideways, through the seams between them). Plus the hole's
    floor, the inner prism from ``base`` to the bottom, when the hole does not go through
    its boss. A polygon hole's boss is its outline's
    (:func:`executor.world.outlines.boss_solids`)."""
    floor = hole.bottom_z if hole.bottom_z - base >= FLOOR_MIN else base
    if hole.kind == "polygon":
        return polygon_boss(hole, plate, floor, base, boss_solids)
    n = plate.polygon_sides
    centre = np.array(hole.position)
    half_a, half_b = hole.sides[0] / 2, hole.sides[1] / 2
    inner = _turned(_ring(hole.kind, half_a, n, half_b), hole.yaw)  # about the centre
    top, chamfer, half_tile = hole.top_z, plate.chamfer, tile_of(plate, hole) / 2
    yaw = np.array([math.cos(hole.yaw), math.sin(hole.yaw)])
    outline = [np.array(v) for v in (yaw, -yaw, (-yaw[1], yaw[0]), (yaw[1], -yaw[0]))]
    # Half-spaces a·x + b <= 0, x = (x, y, z) in the product frame.
    fixed = [[*m, 0.0, -(m @ centre) - half_tile] for m in outline] + [[0, 0, -1, base], [0, 0, 1, -top]]
    faces: dict[tuple[float, float, float], np.ndarray] = {}
    for k in range(n):
        edge = inner[(k + 1) % n] - inner[k]
        normal = np.array([edge[1], -edge[0]]) / np.linalg.norm(edge)  # outward: the ring runs counter-clockwise
        distance = float(normal @ inner[k])
        faces.setdefault((round(normal[0], 9), round(normal[1], 9), round(distance, 12)), normal)
    pieces = []
    for (_nx, _ny, distance), normal in faces.items():
        if distance + chamfer >= half_tile:
            raise ExecutorError(f"hole {hole.id}: its wall is {distance * 1000:.2f} mm from its centre, the boss's "
                                f"outline {half_tile * 1000:.2f} mm; expected a hole inside its boss (tile_size)")
        offset = normal @ centre + distance
        rows = np.array([*fixed, [*-normal, 0.0, offset], [*-normal, 1.0, offset - top + chamfer]])
        inside = np.array([*(centre + normal * (distance + chamfer + half_tile) / 2), (base + top - chamfer) / 2])
        pieces.append(HalfspaceIntersection(rows, inside).intersections)
    if floor > base:
        pieces.append(np.array([[*(centre + point), z] for point in inner for z in (base, floor)]))
    return pieces


def sideways_boss(hole: HoleSpec, plate: Plate) -> list[np.ndarray]:
    """The boss around a hole entered sideways as convex solids, vertices (n, 3) [m],
    product frame: :func:`boss_pieces` of the same section entered down at its entry, from
    the entry to its ``depth`` (open there: nothing stops a part in it), turned into the
    hole's frame (:attr:`executor.world.geometry.HoleSpec.frame`)."""
    frame = hole.frame
    assert frame is not None  # a hole entered sideways
    down = dataclasses.replace(hole, axis="-z")
    return [frame.points_to_cell(piece) for piece in boss_pieces(down, plate, down.bottom_z)]


def sideways_pin(hole: HoleSpec, plate: Plate) -> list[np.ndarray]:
    """A pin standing out along a horizontal axis as convex solids, vertices (n, 3) [m],
    product frame: in the pin's frame (:attr:`executor.world.geometry.HoleSpec.frame`, z
    out along the pin from its foot), the pin a prism of the plate's ``polygon_sides``
    whose corners lie on its radius (never wider than its size), from its foot (``depth``
    below its free end) to its free end, that end chamfered at 45° by the plate's
    ``chamfer``; and its foot, where a part going onto it rests: the square tile of the
    pin's boss (:func:`executor.world.geometry.tile_of`) the plate's ``tile_thickness``
    deep behind it, turned into the cell frame."""
    frame = hole.frame
    assert frame is not None and hole.pin and hole.kind == "round"  # a round pin along a horizontal axis
    centre, top = np.array([*hole.position, hole.top_z]), hole.top_z
    foot = top - hole.depth
    radius, chamfer = hole.size / 2, plate.chamfer
    angles = 2 * math.pi * np.arange(plate.polygon_sides) / plate.polygon_sides
    ring = np.stack([np.cos(angles), np.sin(angles)], axis=1)
    pin = [np.array([*(centre[:2] + r * point), z]) for point in ring
           for r, z in ((radius - chamfer, top), (radius, top - chamfer), (radius, foot))]
    half = tile_of(plate, hole) / 2
    tile = [np.array([centre[0] + a * half, centre[1] + b * half, z])
            for a in (-1, 1) for b in (-1, 1) for z in (foot, foot - plate.tile_thickness)]
    return [frame.points_to_cell(np.array(pin)), frame.points_to_cell(np.array(tile))]


def plate_solids(geometry: CellGeometry) -> tuple[list[StaticBox], list[ConvexPiece]]:
    """The plate as MuJoCo builds it: the box under the bosses and every boss's convex
    pieces (:func:`boss_pieces`), in the product frame. A base given as its own mesh is
    built as its holes and round pins along a horizontal axis only (:func:`sideways_boss`,
    :func:`sideways_pin`; no box: MuJoCo collides a mesh as its convex hull, which would
    close its holes); ExecutorError naming ``geometry.toml`` for such a base with a hole or
    pin entered down or a pin that is not round."""
    path = geometry.folder / "geometry.toml"
    plate = geometry.plate
    if geometry.base_mesh is not None:
        others = sorted(hid for hid, hole in geometry.holes.items()
                        if not hole.sideways or (hole.pin and hole.kind != "round"))
        if others:
            raise ExecutorError(f"{path}: [base] mesh with holes or pins entered down or pins that are not round "
                                f"({', '.join(others)}): the MuJoCo scene builds a base mesh's holes and round pins "
                                "along a horizontal axis only; expected a plate of [plate] and [hole_shapes.*], or a "
                                "base whose holes and pins are all along a horizontal axis")
        return [], [ConvexPiece(f"{'pin' if hole.pin else 'boss'}_{hid}_{k}", vertices)
                    for hid, hole in sorted(geometry.holes.items())
                    for k, vertices in enumerate((sideways_pin if hole.pin else sideways_boss)(hole, plate))]
    (sx, sy), (cx, cy) = plate.base_size, plate.base_center
    top = geometry.base_top
    boxes = [StaticBox("plate_base", (cx, cy, top / 2), (sx / 2, sy / 2, top / 2))]
    pieces = [ConvexPiece(f"boss_{hid}_{k}", vertices)
              for hid, hole in sorted(geometry.holes.items())
              for k, vertices in enumerate(boss_pieces(hole, plate, top))]
    return boxes, pieces


def _vec(values: np.ndarray | tuple[float, ...]) -> str:
    """MuJoCo's text of a vector, to 0.1 µm for lengths."""
    return " ".join(f"{float(v):.9g}" for v in np.ravel(values))


def _part_body(worldbody: ET.Element, asset: ET.Element, geometry: CellGeometry, part: PartSpec) -> str:
    """A free body for ``part`` upright at its tray start (body frame at its bottom face
    centre); returns its name."""
    name = PART_PREFIX + part.id
    body = ET.SubElement(worldbody, "body", name=name, pos=_vec(to_base(np.array([*part.start, 0.0]))))
    ET.SubElement(body, "freejoint", name=f"{name}_free")
    half = part.length / 2
    common = {"friction": _FRICTION, "condim": _PART_CONDIM, "solref": _SOLREF, "rgba": _PART_RGBA}
    if part.mesh is None:
        a, b = part.sides
        kind, size = ("cylinder", (part.size / 2, half)) if part.kind == "round" else ("box", (a / 2, b / 2, half))
        ET.SubElement(body, "geom", common, type=kind, size=_vec(size), pos=_vec((0, 0, half)), mass=f"{part.mass:.9g}")
        return name
    if part.mesh.convex is None:
        raise ExecutorError(f"{geometry.folder / 'geometry.toml'}: [part_shapes.{part.shape}] mesh has no convex "
                            "pieces; expected mesh.convex (made by ./run.sh import)")
    inertia = mesh_inertia(geometry.folder / part.mesh.file, part.mass)
    i = inertia.inertia
    ET.SubElement(body, "inertial", pos=_vec(inertia.com), mass=f"{part.mass:.9g}",
                  fullinertia=_vec((i[0, 0], i[1, 1], i[2, 2], i[0, 1], i[0, 2], i[1, 2])))
    for k, vertices in enumerate(read_objects(geometry.folder / part.mesh.convex)):
        ET.SubElement(asset, "mesh", name=f"{name}_{k}", vertex=_vec(vertices))
        ET.SubElement(body, "geom", common, type="mesh", mesh=f"{name}_{k}")
    return name


def add_product(scene: ET.Element, worldbody: ET.Element, geometry: CellGeometry,
                parts: Collection[str] | None = None) -> dict[str, str]:
    """Add the plate (static) and the pegs (free, at their tray starts) of ``geometry`` to a
    MuJoCo scene (``scene``: the ``<mujoco>`` root, whose ``<asset>`` gets the pieces'
    meshes; ``worldbody`` its ``<worldbody>``), before the model is compiled. Returns the
    MuJoCo body name of each peg by part id. ``parts``: only these pegs (default all).
    Covers, heads and parts placed by hand are not added."""
    asset = scene.find("asset")
    if asset is None:
        asset = ET.SubElement(scene, "asset")
    boxes, pieces = plate_solids(geometry)
    plate = ET.SubElement(worldbody, "body", name="plate", pos=_vec(PRODUCT_IN_BASE))
    for box in boxes:
        ET.SubElement(plate, "geom", name=box.name, type="box", size=_vec(box.half), pos=_vec(box.centre),
                      friction=_FRICTION, solref=_SOLREF, rgba=_PLATE_RGBA)
    for piece in pieces:
        ET.SubElement(asset, "mesh", name=piece.name, vertex=_vec(piece.vertices))
        ET.SubElement(plate, "geom", name=piece.name, type="mesh", mesh=piece.name, friction=_FRICTION,
                      solref=_SOLREF, rgba=_PLATE_RGBA)
    return {pid: _part_body(worldbody, asset, geometry, part) for pid, part in sorted(geometry.parts.items())
            if parts is None or pid in parts}


def product_model(geometry: CellGeometry, drive: str | None = None
                  ) -> tuple[mujoco.MjModel, mujoco.MjData, dict[str, int]]:
    """A MuJoCo model of the product alone (floor, plate, pegs at their tray starts; no
    arm), gravity, :data:`TIME_STEP` and :data:`CONTACT_OPTIONS`, as franky-sim's scene has
    them; its data after a forward pass, and the body id of each peg and of the plate
    (``"plate"``). ``drive``: the one part built, welded to a mocap body (``"drive"``) that moves it."""
    root = ET.Element("mujoco", model="product")
    ET.SubElement(root, "option", timestep=str(TIME_STEP), gravity="0 0 -9.81", integrator="implicitfast")
    set_contact_options(root)
    ET.SubElement(root, "asset")
    world = ET.SubElement(root, "worldbody")
    ET.SubElement(world, "geom", name="floor", type="plane", size="10 10 0.1")
    names = add_product(root, world, geometry, None if drive is None else [drive]) | {"plate": "plate"}
    if drive is not None:
        ET.SubElement(world, "body", name="drive", mocap="true")
        ET.SubElement(ET.SubElement(root, "equality"), "weld", body1="drive", body2=names[drive], solref="0.005 1",
                      relpose="0 0 0 1 0 0 0")  # the part at the drive body, axes aligned
        names["drive"] = "drive"
    model = mujoco.MjModel.from_xml_string(ET.tostring(root, encoding="unicode"))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    return model, data, {key: mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name) for key, name in names.items()}


def contact_force(model: mujoco.MjModel, data: mujoco.MjData, body: int, other: int) -> np.ndarray:
    """The total contact force [N] (world axes) that body ``other`` exerts on body ``body``."""
    total, wrench = np.zeros(3), np.zeros(6)
    for i in range(data.ncon):
        contact = data.contact[i]
        first, second = (int(model.geom_bodyid[g]) for g in contact.geom)
        if {first, second} != {body, other}:
            continue
        mujoco.mj_contactForce(model, data, i, wrench)
        on_second = contact.frame.reshape(3, 3).T @ wrench[:3]  # the contact frame's rows are its axes
        total += on_second if second == body else -on_second
    return total
