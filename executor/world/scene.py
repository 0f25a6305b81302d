"""The PyBullet world of the cell: floor, back plate with real holes, parts on the tray,
and the arm holding one part.

Physics: 1 kHz time step (torque control needs it), gravity, and
``deterministicOverlappingPairs`` so that a seed replays bit for bit.

Every client reads the files it loads as they are (:func:`connect`): PyBullet's own cache of
parsed Wavefront files, one table per process keyed by the file's path and shared by its
clients, is off, so an asset regenerated under the same path (the plate after an edited hole)
is never simulated with its old mesh by a later client of the same process.
"""

from __future__ import annotations

import os
import sys
import tempfile
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pybullet as pb
import pybullet_data

from executor import ExecutorError
from executor.world import TIME_STEP
from executor.world.arm import turn_z
from executor.world.assets import current_assets
from executor.world.frames import yaw_quat
from executor.world.geometry import (
    CellGeometry,
    PartSpec,
    arm_urdf_text,
    outline_polygon,
    peg_files,
    seated_pose,
    tile_of,
)

PART_FRICTION = 0.5  # PyBullet's default lateral friction of a link, kept by the held part
TEACH_FRICTION = 0.25  # part-plate friction coefficient with both at the default (0.5 × 0.5)
# Parked parts (the one in the hand) wait here, out of the way [m].
_PARKED = (0.0, -2.0, 0.05)


def require_display() -> None:
    """ExecutorError unless a GUI can open (PyBullet would exit the process instead)."""
    if sys.platform.startswith("linux") and not os.environ.get("DISPLAY"):
        raise ExecutorError("--gui needs a display, but DISPLAY is not set (expected an X display; "
                            "run without --gui for the DIRECT mode)")


def connect(gui: bool = False) -> int:
    """A new PyBullet client (``gui``: the GUI, else DIRECT) with ``deterministicOverlappingPairs``
    and PyBullet's file cache off (module docstring; a :class:`Scene` of a shipped product
    takes 55 to 63 ms of CPU without it, 35 ms with it); ExecutorError when PyBullet cannot
    make it."""
    client = pb.connect(pb.GUI if gui else pb.DIRECT)
    if client < 0:
        raise ExecutorError("could not connect to PyBullet" + (" (GUI requested without a display?)" if gui else ""))
    pb.setPhysicsEngineParameter(deterministicOverlappingPairs=1, enableFileCaching=0, physicsClientId=client)
    return client


class Scene:
    """A PyBullet client with the static cell and the arm for one part shape;
    ``hold(part)`` puts a part of that shape in the hand.

    One client per part shape: swapping arms inside one client (remove + load) made
    later trials differ from process to process, and parked spare arms cost 25 % speed.
    """

    def __init__(self, geometry: CellGeometry, shape: str, gui: bool = False) -> None:
        self.geometry = geometry
        self.shape = shape
        if gui:
            require_display()
        self.client = connect(gui)
        pb.setTimeStep(TIME_STEP, physicsClientId=self.client)
        pb.setGravity(0, 0, -9.81, physicsClientId=self.client)
        pb.setAdditionalSearchPath(pybullet_data.getDataPath(), physicsClientId=self.client)
        plate_obj = current_assets(geometry) / "plate.obj"
        self.floor = pb.loadURDF("plane.urdf", physicsClientId=self.client)
        self.plate = load_plate(self.client, geometry, plate_obj)
        self.tray_parts = {
            pid: pb.loadURDF(
                str(geometry.assets / f"part_{spec.shape}.urdf"),
                basePosition=(*spec.start, 0.0),
                useFixedBase=True,
                flags=pb.URDF_USE_IMPLICIT_CYLINDER,
                physicsClientId=self.client,
            )
            for pid, spec in sorted(geometry.parts.items())
        }
        part = next(p for _, p in sorted(geometry.parts.items()) if p.shape == shape)
        with tempfile.TemporaryDirectory(prefix="executor-arm-") as tmp:
            urdf = Path(tmp) / f"arm_{shape}.urdf"
            urdf.write_text(arm_urdf_text(part, geometry.gripper, peg_files(geometry, part, absolute=True)))
            self.robot = pb.loadURDF(str(urdf), useFixedBase=True,
                                     flags=pb.URDF_USE_IMPLICIT_CYLINDER | pb.URDF_USE_INERTIA_FROM_FILE,
                                     physicsClientId=self.client)
        if any(hole.pin for hole in geometry.holes.values()):
            wrist_clear_of(self.client, self.robot, self.plate)
        owners = sorted({hole.owner for hole in geometry.holes.values() if hole.owner is not None}
                        | {pid for shape in geometry.tables.part_shapes.values() for pid in shape.pins_of or ()})
        self.owners = {owner: self.tray_parts[owner] if owner in geometry.parts else
                       static_mesh(self.client, geometry.folder / geometry.tables.manual[owner].mesh.file)
                       for owner in owners}
        """The parts whose pins parts go onto (:meth:`feature`): placed by hand (a static
        mesh), or pegs the cell inserts (their tray copy)."""
        for body in self.owners.values():
            wrist_clear_of(self.client, self.robot, body)
        if any(hole.sideways for hole in geometry.holes.values()):
            # A hole entered sideways a few cm above the floor puts the wrist below the
            # floor's level: the cell simulates no table under it (docs/cell.md).
            wrist_clear_of(self.client, self.robot, self.floor)
        self.held: str | None = None

    def feature(self, hole: str) -> None:
        """Make the scene the one of a trial into (or onto) ``hole``: the part whose pin it is
        (and the parts placed by hand whose pins the held part goes onto besides: ``pins_of``)
        at its goal (a peg's in its ``demo_hole``, turned as the cell inserts it:
        :func:`executor.world.geometry.seated_pose`), the other such parts out of the way (a
        part placed by hand parked, a peg on its tray or in the hand: a trial into another
        feature meets none of them, as when they were never placed)."""
        owners = {self.geometry.holes[hole].owner}
        if self.held is not None:  # the owners of its other pins (a plate onto pins of several parts)
            owners |= set(self.geometry.tables.part_shapes[self.geometry.parts[self.held].shape].pins_of or ())
        for k, (pid, body) in enumerate(sorted(self.owners.items())):
            peg = self.geometry.parts.get(pid)
            at: Sequence[float]
            turn: Sequence[float] = (0.0, 0.0, 0.0, 1.0)
            if peg is not None and pid in owners:
                seated, turn = seated_pose(peg, self.geometry.holes[peg.demo_hole])
                at = seated.tolist()
            elif peg is not None:
                at = _PARKED if pid == self.held else (*peg.start, 0.0)
            else:
                at = self.geometry.tables.manual[pid].goal if pid in owners else (0.5 * k, _PARKED[1] - 1.0, 0.0)
            pose = pb.multiplyTransforms(list(at), list(turn), *inertial_frame(self.client, body))  # PyBullet's base
            pb.resetBasePositionAndOrientation(body, *pose, physicsClientId=self.client)

    def set_friction(self, coefficient: float | None) -> None:
        """Make the Coulomb friction coefficient between the held part and the plate
        ``coefficient`` (None: the default, ``TEACH_FRICTION``).  Bullet multiplies the two
        bodies' coefficients; the part keeps ``PART_FRICTION``, the plate gets the rest."""
        mu = TEACH_FRICTION if coefficient is None else coefficient
        pb.changeDynamics(self.plate, -1, lateralFriction=mu / PART_FRICTION, physicsClientId=self.client)

    def hold(self, part: PartSpec) -> int:
        """Put ``part`` in the gripper; its tray copy is parked out of sight.  Returns the
        robot body id."""
        if part.shape != self.shape:
            raise ExecutorError(f"part '{part.id}' has shape '{part.shape}', this arm holds '{self.shape}' parts")
        self.release()
        pb.resetBasePositionAndOrientation(self.tray_parts[part.id], _PARKED, (0, 0, 0, 1),
                                           physicsClientId=self.client)
        self.held = part.id
        return self.robot

    def release(self) -> None:
        """The held part goes back to its start on the tray."""
        if self.held is not None:
            spec = self.geometry.parts[self.held]
            pb.resetBasePositionAndOrientation(self.tray_parts[self.held], (*spec.start, 0.0), (0, 0, 0, 1),
                                               physicsClientId=self.client)
            self.held = None

    def close(self) -> None:
        if pb.isConnected(self.client):
            pb.disconnect(self.client)


def wrist_clear_of(client: int, robot: int, base: int) -> None:
    """Only the held part (the arm's last link) of ``robot`` collides with ``base`` (a body:
    the base, a part placed by hand with a pin): a pin a part with a bore goes onto reaches
    up past the part's top, where a real gripper's fingers hold the part from its sides (the
    cell simulates no fingers, and its wrist is no cylinder around them); the floor, under a
    wrist holding a part sideways into a hole near it."""
    held = pb.getNumJoints(robot, physicsClientId=client) - 1
    for link in range(-1, held):
        pb.setCollisionFilterPair(robot, base, link, -1, 0, physicsClientId=client)


def static_mesh(client: int, mesh: Path, position: Sequence[float] = (0.0, 0.0, 0.0)) -> int:
    """A static body of the concave triangle mesh in file ``mesh`` [m] (a part placed by
    hand), its frame at ``position`` [m]."""
    col = pb.createCollisionShape(pb.GEOM_MESH, fileName=str(mesh), flags=pb.GEOM_FORCE_CONCAVE_TRIMESH,
                                  physicsClientId=client)
    vis = pb.createVisualShape(pb.GEOM_MESH, fileName=str(mesh), rgbaColor=(0.55, 0.75, 0.45, 1),
                               physicsClientId=client)
    return pb.createMultiBody(baseMass=0, baseCollisionShapeIndex=col, baseVisualShapeIndex=vis,
                              basePosition=list(position), physicsClientId=client)


def load_plate(client: int, geometry: CellGeometry, plate_obj: Path,
               deck: Sequence[tuple[float, float, float, float]] = ()) -> int:
    """Static plate: a box under the bosses plus the concave trimesh of the bosses, and
    optionally ``deck`` boxes ([xmin, ymin, xmax, ymax] [m]) filling the space between the
    bosses up to the plate's ``top_z`` (a flat top for parts lying on the plate; a hole
    at its own level has its boss standing out of it or sunk into it); a base with its
    own mesh is that mesh alone, a static concave trimesh in the cell frame (no deck
    needed: its top is its own)."""
    base_mesh = geometry.base_mesh
    if base_mesh is not None:
        col = pb.createCollisionShape(pb.GEOM_MESH, fileName=str(base_mesh), flags=pb.GEOM_FORCE_CONCAVE_TRIMESH,
                                      physicsClientId=client)
        vis = pb.createVisualShape(pb.GEOM_MESH, fileName=str(base_mesh), rgbaColor=(0.7, 0.72, 0.75, 1),
                                   physicsClientId=client)
        return pb.createMultiBody(baseMass=0, baseCollisionShapeIndex=col, baseVisualShapeIndex=vis,
                                  physicsClientId=client)
    plate = geometry.plate
    boss_bottom = geometry.base_top
    (sx, sy), (cx, cy) = plate.base_size, plate.base_center
    boxes = [((sx / 2, sy / 2, boss_bottom / 2), (cx, cy, boss_bottom / 2), (0.55, 0.6, 0.65, 1))]
    deck_half = (plate.tile_thickness + geometry.sunk_by) / 2
    boxes += [(((x1 - x0) / 2, (y1 - y0) / 2, deck_half), ((x0 + x1) / 2, (y0 + y1) / 2, boss_bottom + deck_half),
               (0.62, 0.66, 0.7, 1)) for x0, y0, x1, y1 in deck]
    cols = [pb.createCollisionShape(pb.GEOM_BOX, halfExtents=half, physicsClientId=client) for half, _, _ in boxes]
    vis = [pb.createVisualShape(pb.GEOM_BOX, halfExtents=half, rgbaColor=rgba, physicsClientId=client)
           for half, _, rgba in boxes]
    mesh_col = pb.createCollisionShape(pb.GEOM_MESH, fileName=str(plate_obj),
                                       flags=pb.GEOM_FORCE_CONCAVE_TRIMESH, physicsClientId=client)
    mesh_vis = pb.createVisualShape(pb.GEOM_MESH, fileName=str(plate_obj), rgbaColor=(0.7, 0.72, 0.75, 1),
                                    physicsClientId=client)
    n = len(boxes)
    return pb.createMultiBody(
        baseMass=0, baseCollisionShapeIndex=mesh_col, baseVisualShapeIndex=mesh_vis,
        linkMasses=[0] * n, linkCollisionShapeIndices=cols, linkVisualShapeIndices=vis,
        linkPositions=[centre for _, centre, _ in boxes], linkOrientations=[(0, 0, 0, 1)] * n,
        linkInertialFramePositions=[(0, 0, 0)] * n, linkInertialFrameOrientations=[(0, 0, 0, 1)] * n,
        linkParentIndices=[0] * n, linkJointTypes=[pb.JOINT_FIXED] * n, linkJointAxis=[(0, 0, 1)] * n,
        physicsClientId=client,
    )


def scene_shapes(geometry: CellGeometry) -> list[tuple]:
    """Static bodies for the Rerun log: ``(name, "box"|"cylinder", half_extents [m],
    position [m], quat_xyzw, rgb)``: the plate, each hole (as the cavity), the tray parts."""
    plate = geometry.plate
    boss_bottom = geometry.base_top
    (sx, sy), (cx, cy) = plate.base_size, plate.base_center
    shapes: list[tuple] = [("plate", "box", (sx / 2, sy / 2, boss_bottom / 2), (cx, cy, boss_bottom / 2),
                            (0, 0, 0, 1), (140, 150, 165))]
    for hid, hole in sorted(geometry.holes.items()):
        half_tile = tile_of(plate, hole) / 2
        turned = yaw_quat(hole.yaw)  # the boss turns with its hole
        half_depth = hole.depth / 2
        a, b = hole.sides
        cavity, cavity_quat = np.array([*hole.position, hole.top_z - half_depth]), np.array(turned)
        frame = hole.frame
        if frame is None:
            half_thick = (hole.depth + (hole.bottom_z - boss_bottom)) / 2  # its depth and floor
            shapes.append((f"boss_{hid}", "box", (half_tile, half_tile, half_thick),
                           (*hole.position, hole.top_z - half_thick), turned, (180, 185, 190)))
        else:  # in the base's own mesh (no boss), along its axis
            cavity, cavity_quat = frame.pose_to_cell(cavity, cavity_quat)
        shapes.append((f"hole_{hid}", "cylinder" if hole.kind == "round" else "box", (a / 2, b / 2, half_depth),
                       tuple(cavity.tolist()), tuple(cavity_quat.tolist()), (40, 40, 40)))
    for pid, part in sorted(geometry.parts.items()):
        a, b = part.sides
        shapes.append((f"part_{pid}", "cylinder" if part.kind == "round" else "box", (a / 2, b / 2, part.length / 2),
                       (*part.start, part.length / 2), (0, 0, 0, 1), (205, 155, 50)))
    return shapes


def hole_rims(geometry: CellGeometry, segments: int = 48) -> list[np.ndarray]:
    """Each hole's rim at the plate's top as a closed line ``(K, 3)`` [m]: a circle of the
    hole's diameter, its outline (a polygon) or its rectangle, turned by its yaw; a hole
    entered sideways's at its entry, across its axis."""
    top = geometry.plate.top_z
    rims = []
    for _hid, hole in sorted(geometry.holes.items()):
        a, b = hole.sides
        if hole.kind == "polygon":
            ring = np.asarray(outline_polygon(hole, peg=False).exterior.coords)
            outline = np.column_stack([ring, np.zeros(len(ring))])
        elif hole.kind == "round":
            angle = np.linspace(0.0, 2.0 * np.pi, segments + 1)
            outline = np.column_stack([a / 2 * np.cos(angle), b / 2 * np.sin(angle), np.zeros(segments + 1)])
        else:
            corners = [(1, 1), (-1, 1), (-1, -1), (1, -1), (1, 1)]
            outline = np.array([[sx * a / 2, sy * b / 2, 0.0] for sx, sy in corners])
        frame = hole.frame
        if frame is None:
            rims.append(turn_z(outline, hole.yaw) + np.array([*hole.position, top]))
        else:  # at its own entry, across its axis
            rims.append(frame.points_to_cell(turn_z(outline, hole.yaw) + np.array([*hole.position, hole.top_z])))
    return rims


def link_frame(client: int, body: int, link: int) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """World pose (position [m], quaternion x y z w) of a link's URDF frame, where its
    visual and collision shapes are placed; ``link`` -1 is the base, whose pose PyBullet
    reports at the base's centre of mass instead."""
    if link >= 0:
        state = pb.getLinkState(body, link, computeForwardKinematics=1, physicsClientId=client)
        return tuple(state[4]), tuple(state[5])
    pos, quat = pb.getBasePositionAndOrientation(body, physicsClientId=client)
    inv_pos, inv_quat = pb.invertTransform(*inertial_frame(client, body))
    frame_pos, frame_quat = pb.multiplyTransforms(pos, quat, inv_pos, inv_quat)
    return tuple(frame_pos), tuple(frame_quat)


def inertial_frame(client: int, body: int, link: int = -1) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """A link's inertial frame in its URDF frame (position [m], quaternion x y z w): its
    centre of mass, turned onto its principal axes where its inertia has products of
    inertia (a polygon peg's, a mesh part's). PyBullet poses a base, and places
    constraints on a link, in this frame."""
    local_pos, local_quat = pb.getDynamicsInfo(body, link, physicsClientId=client)[3:5]
    return tuple(local_pos), tuple(local_quat)
