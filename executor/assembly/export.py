"""``executor export --assembly A OUT/``: the assembling cell as URDF and meshes.

The cell is built as the assembling world builds it (:class:`AssemblyWorld`: every part
on the tray, the back plate with its holes, the arm with flange and gripper) and then read
back from PyBullet, so the export shows what the simulation uses:

- ``OUT/cell.urdf``: one robot with a fixed ``world`` link; the arm's links and joints
  (the kuka iiwa, flange, tool) fixed to it at the arm's base, and every part as one link
  fixed at its tray pose (the back plate at its place on the table), each with its visual
  and collision shapes (boxes, cylinders, meshes);
- ``OUT/meshes/``: every mesh the URDF names (the arm's links, the plate's bosses), so the
  folder can be moved and opened in other tools (RViz, MeshLab, Isaac, a URDF viewer).

Units: metres, kilograms, radians (URDF's).
"""

from __future__ import annotations

import re
from pathlib import Path
from xml.sax.saxutils import quoteattr

import pybullet as pb

from bridge.files import make_folder, write_atomic
from bridge.inputs import read_bytes
from executor import ExecutorError
from executor.assembly.product import load_product
from executor.assembly.world import AssemblyWorld
from executor.cell_description import CellDescription
from executor.world.scene import link_frame

_BASE = -1


def export_cell(assembly: str, out: Path, description: CellDescription | None = None) -> list[Path]:
    """Write ``out/cell.urdf`` and ``out/meshes/*`` for ``assembly`` with the gripper of
    the cell ``description`` (default :class:`CellDescription`) unless the product has its
    own; returns the files."""
    description = CellDescription() if description is None else description
    product = load_product(assembly, description)
    meshes = make_folder(Path(out) / "meshes")
    world = AssemblyWorld(product, gains=description.gains)
    try:
        written: list[Path] = []
        arm = _arm_links(world, meshes, written)
        parts = [_part_link(world, pid, meshes, written) for pid in sorted(world.frames)]
        urdf = (f'<?xml version="1.0"?>\n<robot name={quoteattr(f"{assembly}_cell")}>\n'
                '  <link name="world"/>\n' + arm + "".join(parts) + "</robot>\n")
        written.insert(0, write_atomic(Path(out) / "cell.urdf", urdf))
        return written
    finally:
        world.close()


def _mesh(source: str, meshes: Path, written: list[Path]) -> str:
    """Copy a mesh (with its ``.mtl`` if any) into ``meshes``, each file atomically (a full
    disk leaves no torn copy); its path relative to the URDF."""
    path = Path(source)
    target = meshes / path.name
    if target not in written:
        material = path.with_suffix(".mtl")
        for original in [path, *([material] if material.is_file() else [])]:
            data = read_bytes(original, "mesh file", error=ExecutorError)
            written.append(write_atomic(meshes / original.name, data))
    return f"meshes/{path.name}"


def _origin(pos: tuple[float, ...], quat: tuple[float, ...]) -> str:
    roll, pitch, yaw = pb.getEulerFromQuaternion(quat)
    xyz = " ".join(f"{v:.6f}" for v in pos)
    return f'<origin xyz="{xyz}" rpy="{roll:.6f} {pitch:.6f} {yaw:.6f}"/>'


def _geometry(geom_type: int, dims: tuple[float, ...], mesh: str | None) -> str:
    if geom_type == pb.GEOM_MESH and mesh is not None:
        return f'<mesh filename="{mesh}" scale="{dims[0]:g} {dims[1]:g} {dims[2]:g}"/>'
    if geom_type == pb.GEOM_CYLINDER:
        return f'<cylinder length="{dims[0]:.6f}" radius="{dims[1]:.6f}"/>'
    return f'<box size="{dims[0]:.6f} {dims[1]:.6f} {dims[2]:.6f}"/>'


def _part_link(world: AssemblyWorld, pid: str, meshes: Path, written: list[Path]) -> str:
    """One part as a link fixed to ``world`` at its base frame; every visual shape of its
    links placed relative to that frame (as visual and collision)."""
    body, client = world.frames[pid].body, world.client
    base_pos, base_quat = link_frame(client, body, _BASE)
    inverse = pb.invertTransform(base_pos, base_quat)
    shapes: list[str] = []
    for visual in pb.getVisualShapeData(body, physicsClientId=client):
        link, geom_type, dims, mesh_file = visual[1], visual[2], visual[3], visual[4].decode()
        frame = link_frame(client, body, link)
        world_pose = pb.multiplyTransforms(*frame, visual[5], visual[6])
        local = pb.multiplyTransforms(*inverse, *world_pose)
        mesh = _mesh(mesh_file, meshes, written) if geom_type == pb.GEOM_MESH else None
        shape = f"{_origin(*local)}<geometry>{_geometry(geom_type, dims, mesh)}</geometry>"
        rgba = " ".join(f"{c:.3f}" for c in visual[7])
        shapes.append(f'    <visual>{shape}<material name="{pid}_{len(shapes)}"><color rgba="{rgba}"/>'
                      f"</material></visual>\n    <collision>{shape}</collision>\n")
    mass = pb.getDynamicsInfo(body, _BASE, physicsClientId=client)[0]
    return (f'  <link name="{pid}">\n    <inertial><mass value="{mass:.6f}"/>'
            '<inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial>\n'
            + "".join(shapes) + "  </link>\n"
            f'  <joint name="world_{pid}" type="fixed"><parent link="world"/><child link="{pid}"/>'
            f"{_origin(base_pos, base_quat)}</joint>\n")


def _arm_links(world: AssemblyWorld, meshes: Path, written: list[Path]) -> str:
    """The arm's URDF (as the world loaded it) with its meshes copied, fixed to ``world``."""
    text = world.arm_urdf
    for source in sorted(set(re.findall(r'filename="([^"]+)"', text))):
        text = text.replace(f'filename="{source}"', f'filename="{_mesh(source, meshes, written)}"')
    inner = text[text.index(">", text.index("<robot")) + 1:text.rindex("</robot>")]
    root = re.search(r'<link name="([^"]+)"', inner)
    assert root is not None, "the arm's URDF has no link"
    pos, quat = link_frame(world.client, world.robot, _BASE)
    return (inner + f'  <joint name="world_arm" type="fixed"><parent link="world"/>'
            f'<child link="{root.group(1)}"/>{_origin(pos, quat)}</joint>\n')
