"""The product in franky-sim's MuJoCo scene, built from the cell geometry that the PyBullet
cell loads (:func:`executor.world.geometry.load_geometry`: ``geometry.toml`` and
``assembly.toml`` of a product folder).

What is built, in MuJoCo's world frame (= the arm's base frame, :data:`PRODUCT_IN_BASE`):

- the plate under the bosses: one box from the floor up to :attr:`CellGeometry.base_top`;
- each hole's boss as convex pieces (MuJoCo collides a mesh as its convex hull, so a
  concave boss is cut into convex ones): for each of the ``polygon_sides`` sectors of the
  boss ring, the solid between the hole's wall and the boss's square outline, with the
  45° entry chamfer as a plane cut (:func:`boss_pieces`); the same surfaces as the
  PyBullet cell's triangle mesh (:func:`executor.world.geometry.plate_obj_text`), round
  holes the same n-gons, square and rect holes exact; a hole with a floor gets the floor
  as one more piece;
- each peg (``[part_shapes.*]``) as a free body at its tray start, upright on the floor:
  a cylinder or box of its mass, or with a ``mesh`` its convex pieces (the ``convex``
  file as made at import, not eroded: MuJoCo adds no margin) with the mesh's inertia.

Part-plate friction is the PyBullet cell's teaching friction (MuJoCo takes the larger of
two geoms' coefficients, so the pegs and the plate both carry it; the fingers keep
MuJoCo's 1.0 and grip with that). Not built: covers, heads, parts placed by hand, a
base given as its own mesh (a concave mesh has no convex-hull form) and polygon holes;
each is refused or left out as stated in :func:`add_product`.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass

import numpy as np

from bridge.product import Plate
from executor import ExecutorError
from executor.world.geometry import FLOOR_MIN, CellGeometry, HoleSpec, PartSpec, _ring, _turned
from executor.world.meshes import mesh_inertia, read_objects
from executor.world.scene import TEACH_FRICTION

PRODUCT_IN_BASE = np.zeros(3)
"""Where the product frame's origin lies in the arm's base frame [m], axes parallel: the
cell frame of ``geometry.toml`` and ``assembly.toml`` is the arm base's, as in the PyBullet
cell, whose arm also stands at the origin. Every pose between the two goes through
:func:`to_base` and :func:`from_base`."""

PART_PREFIX = "part_"
"""MuJoCo body name of a part: this prefix and the part's id."""

_FRICTION = f"{TEACH_FRICTION} 0.005 0.0001"  # sliding, torsional [m], rolling [m] (MuJoCo's defaults for the last two)
_PART_CONDIM = "4"  # sliding and torsional friction: a held part does not spin about the fingers' closing axis
_PLATE_RGBA = "0.7 0.72 0.75 1"
_PART_RGBA = "0.8 0.6 0.2 1"


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
    """The boss around ``hole`` as convex solids, vertices (n, 3) [m]: sector k of the ring
    between the hole's wall (points k, k+1 of its n-gon, square or rect ring) and the
    boss's square outline (points k, k+1 of the square ring; both rings have their corners
    at the same indices, so each sector's inner and outer edges are straight), from the
    plate under the bosses (``base`` [m]) up to the entry, the chamfer cut off it by the
    plane through the mouth's and the wall's edges (a convex prism cut by a plane stays
    convex); plus the hole's floor, the inner prism from ``base`` up to the bottom, when the
    hole does not go through its boss (as :func:`executor.world.geometry._boss_triangles`)."""
    n = plate.polygon_sides
    centre = np.array(hole.position)
    half_a, half_b = hole.sides[0] / 2, hole.sides[1] / 2
    outer = _turned(_ring("square", plate.tile_size / 2, n), hole.yaw) + centre
    mouth = _turned(_ring(hole.kind, half_a + plate.chamfer, n, half_b + plate.chamfer), hole.yaw) + centre
    inner = _turned(_ring(hole.kind, half_a, n, half_b), hole.yaw) + centre
    top, below_chamfer = hole.top_z, hole.top_z - plate.chamfer
    floor = hole.bottom_z if hole.bottom_z - base >= FLOOR_MIN else base

    def at(ring: np.ndarray, k: int, z: float) -> list[float]:
        return [*ring[k % n], z]

    pieces = []
    for k in range(n):
        points = []
        for j in (k, k + 1):
            points += [at(outer, j, top), at(outer, j, base), at(mouth, j, top),
                       at(inner, j, below_chamfer), at(inner, j, floor)]
        pieces.append(np.array(points))
    if floor > base:
        pieces.append(np.array([at(inner, k, z) for k in range(n) for z in (base, floor)]))
    return pieces


def plate_solids(geometry: CellGeometry) -> tuple[list[StaticBox], list[ConvexPiece]]:
    """The plate as MuJoCo builds it: the box under the bosses and every boss's convex
    pieces (:func:`boss_pieces`), in the product frame; ExecutorError naming
    ``geometry.toml`` for a base given as its own mesh or a polygon hole."""
    path = geometry.folder / "geometry.toml"
    if geometry.base_mesh is not None:
        raise ExecutorError(f"{path}: [base] mesh: the MuJoCo scene collides a mesh as its convex hull and has no "
                            "form of a concave base; expected a plate of [plate] and [hole_shapes.*]")
    polygons = sorted(hid for hid, hole in geometry.holes.items() if hole.kind == "polygon")
    if polygons:
        raise ExecutorError(f"{path}: hole {polygons[0]} is a polygon; the MuJoCo scene builds round, square and "
                            "rect holes")
    plate = geometry.plate
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
    common = {"friction": _FRICTION, "condim": _PART_CONDIM, "rgba": _PART_RGBA}
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


def add_product(scene: ET.Element, worldbody: ET.Element, geometry: CellGeometry) -> dict[str, str]:
    """Add the plate (static) and the pegs (free, at their tray starts) of ``geometry`` to a
    MuJoCo scene (``scene``: the ``<mujoco>`` root, whose ``<asset>`` gets the pieces'
    meshes; ``worldbody`` its ``<worldbody>``), before the model is compiled. Returns the
    MuJoCo body name of each peg by part id. Covers, heads and parts placed by hand are
    not added."""
    asset = scene.find("asset")
    if asset is None:
        asset = ET.SubElement(scene, "asset")
    boxes, pieces = plate_solids(geometry)
    plate = ET.SubElement(worldbody, "body", name="plate", pos=_vec(PRODUCT_IN_BASE))
    for box in boxes:
        ET.SubElement(plate, "geom", name=box.name, type="box", size=_vec(box.half), pos=_vec(box.centre),
                      friction=_FRICTION, rgba=_PLATE_RGBA)
    for piece in pieces:
        ET.SubElement(asset, "mesh", name=piece.name, vertex=_vec(piece.vertices))
        ET.SubElement(plate, "geom", name=piece.name, type="mesh", mesh=piece.name, friction=_FRICTION,
                      rgba=_PLATE_RGBA)
    return {pid: _part_body(worldbody, asset, geometry, part) for pid, part in sorted(geometry.parts.items())}


def hole_entry(geometry: CellGeometry, hole: str) -> np.ndarray:
    """The centre of a hole's entry [m] in the arm's base frame."""
    spec = geometry.holes[hole]
    return to_base(np.array([*spec.position, spec.top_z]))


def yaw_of(quat_wxyz: np.ndarray) -> float:
    """The rotation [rad] about z of a MuJoCo quaternion (w x y z) of an upright body."""
    w, x, y, z = (float(v) for v in quat_wxyz)
    return math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
