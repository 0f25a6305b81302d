"""Parts simulated from their own meshes (a ``mesh`` of ``[part_shapes.*]``, ``[covers.*]``,
``[heads.*]`` or ``[base]``, docs/geometry.md): the OBJ files of their convex pieces, the
pieces as the cell loads them, mass and inertia from the mesh, and the URDF link of such
a part (:class:`MeshBody`, :func:`mesh_link_xml`).

A moving part collides as the convex pieces of its ``convex`` file (one OBJ object each,
made at import time). PyBullet's URDF importer makes one convex hull of each object and
inflates every hull by :data:`URDF_HULL_MARGIN` (measured: a 10 mm box rests 1.0 mm above
the floor; ``changeDynamics(collisionMargin=...)`` does not reach a URDF link's hulls).
So the generated asset is each piece eroded by that margin (its faces moved inwards),
which the margin then adds back: the piece as it is, its edges rounded by 1 mm (as the
cell's primitive shapes' edges act). Across a face where the piece is thinner than twice
the margin (a 2 mm plate), its faces are moved in to near its middle instead, so the cell's
piece is the piece with each face at most :data:`THIN_EXCESS` farther out; a piece thinner
than :data:`MIN_THICKNESS` has no eroded form and is refused. The base is a static concave
triangle mesh (no margin).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import trimesh
from scipy.optimize import linprog
from scipy.spatial import ConvexHull, HalfspaceIntersection, QhullError

from bridge.product import Mesh
from executor import ExecutorError
from executor.world import SIZE_RESOLUTION

URDF_HULL_MARGIN = 0.001
"""How much PyBullet's URDF importer inflates each convex hull of a link [m]."""
THIN_EXCESS = SIZE_RESOLUTION
"""How far [m] a face of a convex piece as the cell collides as it may lie outside the
piece's (where the piece is thinner than twice :data:`URDF_HULL_MARGIN` across it): the
size the cell resolves."""
THIN_CORE = 1e-6
"""Half the thickness [m] an eroded piece keeps across a face where the piece is thinner
than twice the margin (a flat core would have no interior for the half-space intersection)."""
MIN_THICKNESS = 2 * (URDF_HULL_MARGIN - THIN_EXCESS + THIN_CORE)
"""The thinnest [m] a convex piece of a moving part may be across any face (1.952 mm)."""


def obj_text(objects: Sequence[tuple[str, np.ndarray, np.ndarray]], header: str) -> str:
    """Wavefront OBJ of named triangle meshes ``(name, vertices (n, 3) [m], faces (m, 3))``,
    one ``o`` object each, after the comment line ``header``; vertices to 0.1 µm."""
    parts = [header + "\n"]
    base = 1
    for name, vertices, faces in objects:
        # one % of a whole object's lines: formatted as by f"{x:.7f}", without a loop in Python
        corners = np.asarray(vertices, dtype=float).ravel().tolist()
        indices = (np.asarray(faces, dtype=np.int64) + base).ravel().tolist()
        parts += [f"o {name}\n", "v %.7f %.7f %.7f\n" * (len(corners) // 3) % tuple(corners),
                  "f %d %d %d\n" * (len(indices) // 3) % tuple(indices)]
        base += len(vertices)
    return "".join(parts)


def read_objects(path: Path) -> list[np.ndarray]:
    """The vertices [m] of each ``o`` object of an OBJ file (vertices before the first
    ``o`` are an object of their own); ExecutorError naming the file and line."""
    objects: list[list[list[float]]] = [[]]
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise ExecutorError(f"{path}: cannot read the convex pieces ({exc})") from None
    for number, line in enumerate(lines, 1):
        words = line.split()
        if words[:1] == ["o"]:
            objects.append([])
        elif words[:1] == ["v"]:
            try:
                objects[-1].append([float(w) for w in words[1:4]])
            except ValueError:
                raise ExecutorError(f"{path}:{number}: expected a vertex 'v x y z' in metres, got {line!r}") from None
    pieces = [np.array(o) for o in objects if o]
    if not pieces:
        raise ExecutorError(f"{path}: no vertices; expected the convex pieces of a part, one OBJ object each")
    return pieces


def eroded(vertices: np.ndarray, margin: float) -> trimesh.Trimesh | None:
    """The convex hull of ``vertices`` [m] with every face moved inwards by ``margin``
    [m]; a face whose hull is thinner than twice the margin across it moved in to
    :data:`THIN_CORE` of its middle instead, when that leaves it at most
    :data:`THIN_EXCESS` short of the margin (a 2 mm plate: its faces across its thickness
    meet near its mid-plane, and the margin added back makes it 2 mm thick again); None
    when nothing is left (the hull thinner than :data:`MIN_THICKNESS` across a face)."""
    try:
        hull = ConvexHull(vertices)
    except QhullError:
        return None  # flat or degenerate: no volume to erode
    normals = hull.equations[:, :3]
    widths = (-(normals @ np.asarray(vertices, dtype=float).T + hull.equations[:, 3:])).max(axis=1)
    moved = np.minimum(margin, widths / 2 - THIN_CORE)  # across a face: the hull's extent from its plane
    if np.any(moved < margin - THIN_EXCESS):
        return None
    return _moved_in(normals, hull.equations[:, 3] + moved)


def narrowed(vertices: np.ndarray, room: float) -> trimesh.Trimesh | None:
    """The convex hull of ``vertices`` [m] less ``room`` [m] all round the z axis: every
    face moved inwards by ``room`` times its normal's part across z (the hull eroded by a
    disc of radius ``room`` across z), so a prism along z has its section ``room`` narrower
    per side and its ends where they were; None when nothing is left."""
    try:
        hull = ConvexHull(vertices)
    except QhullError:
        return None
    normals = hull.equations[:, :3]
    return _moved_in(normals, hull.equations[:, 3] + room * np.hypot(normals[:, 0], normals[:, 1]))


def _moved_in(normals: np.ndarray, offsets: np.ndarray) -> trimesh.Trimesh | None:
    """The convex solid of the half-spaces ``normals @ x + offsets <= 0`` [m], None when it
    is empty or thinner than 0.2 µm."""
    # The centre of the largest ball inside the solid (Chebyshev centre): a strictly
    # interior point for the intersection, and its radius says whether anything is left.
    res = linprog(c=[0, 0, 0, -1], A_ub=np.hstack([normals, np.ones((len(normals), 1))]), b_ub=-offsets,
                  bounds=[(None, None)] * 3 + [(0, None)])
    if not res.success or res.x[3] <= 1e-7:
        return None
    corners = HalfspaceIntersection(np.hstack([normals, offsets[:, None]]), res.x[:3]).intersections
    return trimesh.convex.convex_hull(corners)


def eroded_pieces_text(convex: Path, what: str) -> str:
    """The asset a URDF collides as: every piece of the ``convex`` file eroded by
    :data:`URDF_HULL_MARGIN` (:func:`eroded_text`)."""
    return eroded_text(read_objects(convex), what, str(convex))


def eroded_text(pieces: Sequence[np.ndarray], what: str, source: str) -> str:
    """Wavefront OBJ of the convex hulls of ``pieces`` (vertices (n, 3) [m] each) eroded by
    :data:`URDF_HULL_MARGIN`; ExecutorError naming the ``source`` (a file, or a table of
    ``geometry.toml``), ``what`` (the part) and the piece when one is too thin."""
    objects = []
    for k, vertices in enumerate(pieces):
        piece = eroded(vertices, URDF_HULL_MARGIN)
        if piece is None:
            raise ExecutorError(f"{source}: convex piece {k + 1} of {what} is thinner than "
                                f"{1e3 * MIN_THICKNESS:g} mm (the cell's hull margin twice, less what it resolves); "
                                "expected pieces the simulated cell can collide as")
        objects.append((f"piece{k + 1}", piece.vertices, piece.faces))
    return obj_text(objects, f"# generated from {Path(source).name}: each piece eroded by {URDF_HULL_MARGIN} m, "
                             "the URDF hull margin that PyBullet adds back")


@dataclass(frozen=True)
class MeshInertia:
    """A part's ``com`` [m] in its frame and ``inertia`` [kg m^2] about it (3 x 3, the
    part frame's axes), for ``mass`` [kg] spread uniformly over its mesh."""

    mass: float
    com: np.ndarray
    inertia: np.ndarray


def mesh_inertia(path: Path, mass: float) -> MeshInertia:
    """Centre of mass and inertia of the closed mesh in ``path`` [m] for ``mass`` [kg]."""
    mesh = trimesh.load(path, force="mesh")
    if not isinstance(mesh, trimesh.Trimesh) or not mesh.is_volume:
        raise ExecutorError(f"{path}: not a closed mesh with a volume; expected the part's own closed mesh [m]")
    mesh.density = mass / mesh.volume
    return MeshInertia(mass, np.array(mesh.center_mass), np.array(mesh.moment_inertia))


def pieces_inertia(pieces: Sequence[np.ndarray], mass: float) -> MeshInertia:
    """Centre of mass and inertia of the solid made of the convex hulls of ``pieces``
    (vertices (n, 3) [m] each, interiors apart) for ``mass`` [kg] spread uniformly."""
    solid = trimesh.util.concatenate([trimesh.convex.convex_hull(vertices) for vertices in pieces])
    assert isinstance(solid, trimesh.Trimesh)  # hulls are triangle meshes
    solid.density = mass / solid.volume
    return MeshInertia(mass, np.array(solid.center_mass), np.array(solid.moment_inertia))


@dataclass(frozen=True)
class MeshBody:
    """A moving part simulated from its own ``mesh`` (a peg shape's, a cover's or a
    head's): ``stem`` of its generated assets (``<stem>.urdf``, ``<stem>.convex.obj``), its
    ``mass`` [kg], and ``what`` names it in messages."""

    stem: str
    mesh: Mesh
    mass: float
    what: str

    @property
    def convex_asset(self) -> str:
        """The file name in ``assets/`` of its eroded convex pieces."""
        return f"{self.stem}.convex.obj"


@dataclass(frozen=True)
class MeshFiles:
    """A mesh part in a URDF: its ``visual`` mesh and the ``collision`` asset (its eroded
    convex pieces), as the URDF names them, and its mass properties."""

    visual: str
    collision: str
    inertia: MeshInertia


_FLIP = np.diag([1.0, -1.0, -1.0])  # a half turn about x: the held part's frame, z pointing away from the arm


def mesh_link_xml(files: MeshFiles, rgba: str, flip: bool) -> str:
    """URDF ``<inertial>``, ``<visual>`` and ``<collision>`` of a mesh part (``files``) at
    the link origin: its centre of mass and full inertia tensor, its mesh and its pieces,
    turned half about x when ``flip``."""
    turn = _FLIP if flip else np.eye(3)
    (x, y, z), i = turn @ files.inertia.com, turn @ files.inertia.inertia @ turn.T
    origin = f'<origin xyz="0 0 0" rpy="{np.pi if flip else 0.0:.15g} 0 0"/>'
    return (
        f'    <inertial><origin xyz="{x:.9g} {y:.9g} {z:.9g}" rpy="0 0 0"/><mass value="{files.inertia.mass:.9g}"/>'
        f'<inertia ixx="{i[0, 0]:.9g}" ixy="{i[0, 1]:.9g}" ixz="{i[0, 2]:.9g}" iyy="{i[1, 1]:.9g}" '
        f'iyz="{i[1, 2]:.9g}" izz="{i[2, 2]:.9g}"/></inertial>\n'
        f'    <visual>{origin}<geometry><mesh filename="{files.visual}"/></geometry>'
        f'<material name="part"><color rgba="{rgba}"/></material></visual>\n'
        f'    <collision>{origin}<geometry><mesh filename="{files.collision}"/></geometry></collision>\n'
    )


def mesh_urdf_text(name: str, files: MeshFiles, rgba: str) -> str:
    """A free mesh part (robot ``name``), its frame the part frame of its mesh."""
    return (f'<?xml version="1.0"?>\n<robot name="{name}">\n  <link name="part">\n'
            + mesh_link_xml(files, rgba, flip=False) + "  </link>\n</robot>\n")
