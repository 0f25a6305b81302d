"""A shipped product's parts as closed meshes in the assembled pose, as the simulated
cell builds them (``executor export --assembled OUT``): the input of ``import``'s round
trips.

The assembling world (:class:`executor.assembly.world.AssemblyWorld`) is built, every part
is put at its goal pose (each peg turned to its hole's yaw, in the first hole by id it passes
(:func:`executor.world.geometry.feature_passes`) among those still free, smallest hole first), and
each part's shapes are read back from PyBullet (boxes, grown by :data:`JOIN` in a part
of several shapes; cylinders as 256-gons whose corners lie on the circle; meshes) and
joined by an exact boolean union (manifold3d, in double precision) into one solid; the base is its plate's
block minus the hole cavities. Written as ``OUT/<part>.obj`` in metres (10 digits: STL's single precision would
merge the union's nearby vertices), with ``OUT/import.toml`` naming
the base, every part's tray and the heads fixed to their parts.
"""

from __future__ import annotations

from functools import reduce

import manifold3d
import numpy as np
import pybullet as pb
import trimesh

from bridge.files import make_folder, write_atomic
from executor import ExecutorError
from executor.assembly.product import load_product
from executor.assembly.world import AssemblyWorld
from executor.cell_description import load_cell_description
from executor.world.geometry import feature_passes, tile_of
from executor.world.scene import link_frame

CYLINDER_SECTIONS = 256
JOIN = 1e-6
"""Boxes of a part of several shapes are grown by this [m] a side along x and y (never in
height: a peg stands on them), so that boxes meeting along an edge overlap and their union
is a manifold solid; a cover's outline and openings come out this much larger and smaller."""
SNAP = 9
"""Decimals [m] the vertices of a part of several shapes are rounded to before their union (1 nm)."""


def _peg_holes(world: AssemblyWorld) -> dict[str, str]:
    """Peg → hole: the smallest free hole it passes, pegs by id."""
    geometry = world.product.geometry
    free = sorted(geometry.holes, key=lambda h: (max(geometry.holes[h].sides), h))
    chosen: dict[str, str] = {}
    for pid in sorted(world.product.pegs):
        hole = next((h for h in free if feature_passes(world.product.pegs[pid], geometry.holes[h])), None)
        if hole is not None:
            chosen[pid] = hole
            free.remove(hole)
    return chosen


def _shape(geom_type: int, dims: tuple[float, ...], mesh_file: str, grow: float) -> trimesh.Trimesh:
    if geom_type == pb.GEOM_BOX:
        return trimesh.creation.box(np.asarray(dims) + [2 * grow, 2 * grow, 0.0])
    if geom_type == pb.GEOM_CYLINDER:
        return trimesh.creation.cylinder(radius=dims[1], height=dims[0], sections=CYLINDER_SECTIONS)
    mesh = trimesh.load(mesh_file, force="mesh")
    assert isinstance(mesh, trimesh.Trimesh), mesh_file
    mesh.apply_scale(dims)
    return mesh


def _matrix(pos: tuple[float, ...], quat_xyzw: tuple[float, ...]) -> np.ndarray:
    """The 4 × 4 transform of a pose (position [m], quaternion xyzw)."""
    matrix = np.eye(4)
    matrix[:3, :3] = np.array(pb.getMatrixFromQuaternion(quat_xyzw)).reshape(3, 3)
    matrix[:3, 3] = pos
    return matrix


def _union(pieces: list[trimesh.Trimesh]) -> trimesh.Trimesh:
    """The exact union of closed meshes in double precision (trimesh's booleans hand manifold3d
    single precision vertices, with which boxes grown by :data:`JOIN` joined into a solid with
    edges of four faces), their vertices first rounded to :data:`SNAP` (faces meant to be
    one plane may be an ulp apart, slivers the union would keep)."""
    solids = [manifold3d.Manifold(manifold3d.Mesh64(vert_properties=np.round(np.asarray(p.vertices), SNAP),
                                                    tri_verts=np.asarray(p.faces, dtype=np.uint64)))
              for p in pieces]
    joined = reduce(lambda a, b: a + b, solids).to_mesh64()
    return trimesh.Trimesh(np.asarray(joined.vert_properties)[:, :3], np.asarray(joined.tri_verts), process=False)


def _base_solid(world: AssemblyWorld) -> trimesh.Trimesh:
    """The base as one solid: the plate's box from the floor to its top minus the cavities
    (the deck's axis-aligned square around each hole minus the boss mesh), the same solid
    as the cell's boss mesh, deck and box under them, without their shared faces. A turned
    boss leaves the corners of its square open, as in the cell. A base with its own mesh
    is that mesh; ExecutorError for a plate with holes at their own levels (not made)."""
    geometry = world.product.geometry
    if geometry.base_mesh is not None:
        own = trimesh.load(geometry.base_mesh, force="mesh")
        assert isinstance(own, trimesh.Trimesh)  # the loader checked the file
        return own
    plate = geometry.plate
    top, depth = plate.top_z, plate.tile_thickness
    levelled = sorted(h.id for h in geometry.holes.values() if (h.top_z, h.depth) != (top, depth))
    if levelled:
        raise ExecutorError(f"{geometry.folder / 'geometry.toml'}: holes {', '.join(levelled)} have their own top_z or "
                            "depth; the base's solid is exported only for holes at the plate's level")
    (sx, sy), (cx, cy) = plate.base_size, plate.base_center
    block = trimesh.creation.box((sx, sy, top))
    block.apply_translation((cx, cy, top / 2))
    tiles = []
    for hole in geometry.holes.values():
        tile = tile_of(plate, hole)
        square = trimesh.creation.box((tile, tile, depth))
        square.apply_translation((*hole.position, top - depth / 2))
        tiles.append(square)
    bosses = trimesh.load(geometry.assets / "plate.obj", force="mesh")
    cavities = trimesh.boolean.difference([trimesh.boolean.union(tiles, engine="manifold"), bosses],
                                          engine="manifold")
    return trimesh.boolean.difference([block, cavities], engine="manifold")


def part_meshes(assembly: str) -> tuple[dict[str, trimesh.Trimesh], str, dict[str, tuple[float, float]],
                                        dict[str, str]]:
    """Every part's closed mesh in the assembled pose [m], the base's id, the trays [m]
    (the base's: its plate's centre) and the heads' parts."""
    product = load_product(assembly)
    world = AssemblyWorld(product, gains=load_cell_description(None).gains)
    try:
        turns: dict[str, tuple[float, ...]] = {}
        for pid, hole in _peg_holes(world).items():
            world.set_peg_goal(pid, hole)
            turns[pid] = pb.getQuaternionFromEuler((0.0, 0.0, product.geometry.holes[hole].yaw))
        meshes: dict[str, trimesh.Trimesh] = {}
        meshes[product.base.id] = _base_solid(world)
        for pid, frames in sorted(world.frames.items()):
            world.set_pose(pid, world.goals[pid], turns.get(pid, (0.0, 0.0, 0.0, 1.0)))
            if pid == product.base.id:
                continue
            visuals = pb.getVisualShapeData(frames.body, physicsClientId=world.client)
            links = {visual[1] for visual in visuals}
            assert len(links) == 1, f"part {pid} has shapes on links {links}; expected one body"
            grow = JOIN if len(visuals) > 1 else 0.0
            pieces = []  # in the link's frame, exact as given (poses read back are single precision)
            for visual in visuals:
                geom_type, dims, mesh_file = visual[2], visual[3], visual[4].decode()
                pieces.append(_shape(geom_type, dims, mesh_file, grow).apply_transform(_matrix(visual[5], visual[6])))
            solid = pieces[0] if len(pieces) == 1 else _union(pieces)
            meshes[pid] = solid.apply_transform(_matrix(*link_frame(world.client, frames.body, links.pop())))
        trays = {pid: (float(world.tray_position(pid)[0]), float(world.tray_position(pid)[1]))
                 for pid in world.frames}
        trays[product.base.id] = product.base.tray
        return meshes, product.base.id, trays, {h: head.into for h, head in product.heads.items()}
    finally:
        world.close()


def write_assembled(assembly: str, out: str) -> list:
    """``out/<part>.obj`` and ``out/import.toml`` for ``assembly``; returns the files."""
    folder = make_folder(out)
    meshes, base, trays, heads = part_meshes(assembly)
    written = [write_atomic(folder / f"{pid}.obj", trimesh.exchange.obj.export_obj(mesh, digits=10))
               for pid, mesh in meshes.items()]
    lines = [f"# {assembly} in the assembled pose (executor export --assembled); import with --units m",
             f'base = "{base}"', ""]
    for pid in sorted(meshes):
        lines += [f"[parts.{pid}]", f"tray = [{trays[pid][0]:.6f}, {trays[pid][1]:.6f}]"]
        if pid in heads:
            lines.append(f'fixed_to = "{heads[pid]}"')
        lines.append("")
    written.append(write_atomic(folder / "import.toml", "\n".join(lines)))
    return written
