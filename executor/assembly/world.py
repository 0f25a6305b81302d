"""One PyBullet client holding the whole product: floor, the back plate (static, moved
kinematically while carried), every other part as a free rigid body on the tray, and the
arm with a gripper tool (the wrist force/torque sensor between flange and tool).

The tool link has no collisions: the gripper is a grasp constraint
(:mod:`executor.assembly.grasp`), not simulated fingers.  The world
persists between plan steps: placed parts stay placed.
"""

from __future__ import annotations

import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pybullet as pb
import pybullet_data

from executor.assembly.product import HeadSpec, Product, rect_minus_squares
from executor.control.controller import ImpedanceController
from executor.control.gains import ImpedanceGains
from executor.control.motion import Motion, StepLogger
from executor.world import TIME_STEP
from executor.world.arm import TOOL_DOWN_QUAT_XYZW, Arm, tool_quat
from executor.world.assets import current_assets
from executor.world.geometry import PartSpec, arm_urdf_text, product_bodies, seat, seated_pose, tile_of
from executor.world.scene import connect, inertial_frame, link_frame, load_plate, static_mesh, wrist_clear_of

HOME = np.array([0.40, 0.0, 0.30])  # tool pose the arm starts at [m]
_IDENTITY = (0.0, 0.0, 0.0, 1.0)


@dataclass(frozen=True)
class PartFrames:
    """Where a part is, in its body frame: ``grip`` (the tool frame when held) and ``tcp``
    (the point the skills drive) as offsets from the body origin [m] (upright part)."""

    body: int
    grip: np.ndarray
    tcp: np.ndarray


def _compound(client: int, boxes: list[tuple[tuple, tuple]], mass: float, rgba: tuple) -> int:
    """A free rigid body of boxes ``(centre, half)`` [m] in its frame, at the origin."""
    centres = [list(c) for c, _ in boxes]
    halves = [list(h) for _, h in boxes]
    col = pb.createCollisionShapeArray([pb.GEOM_BOX] * len(boxes), halfExtents=halves,
                                       collisionFramePositions=centres, physicsClientId=client)
    vis = pb.createVisualShapeArray([pb.GEOM_BOX] * len(boxes), halfExtents=halves, visualFramePositions=centres,
                                    rgbaColors=[list(rgba)] * len(boxes), physicsClientId=client)
    com = np.mean(centres, axis=0)
    return pb.createMultiBody(baseMass=mass, baseCollisionShapeIndex=col, baseVisualShapeIndex=vis,
                              baseInertialFramePosition=list(com), physicsClientId=client)


def _head_body(client: int, head: HeadSpec) -> int:
    """A free cylinder or box (the head's section over its length), its frame at its bottom centre."""
    half = head.length / 2
    if head.kind == "round":
        col = pb.createCollisionShape(pb.GEOM_CYLINDER, radius=head.size / 2, height=head.length,
                                      collisionFramePosition=[0, 0, half], physicsClientId=client)
        vis = pb.createVisualShape(pb.GEOM_CYLINDER, radius=head.size / 2, length=head.length,
                                   visualFramePosition=[0, 0, half], rgbaColor=(0.8, 0.3, 0.3, 1),
                                   physicsClientId=client)
    else:
        ext = [head.size / 2, head.size / 2, half]
        col = pb.createCollisionShape(pb.GEOM_BOX, halfExtents=ext, collisionFramePosition=[0, 0, half],
                                      physicsClientId=client)
        vis = pb.createVisualShape(pb.GEOM_BOX, halfExtents=ext, visualFramePosition=[0, 0, half],
                                   rgbaColor=(0.8, 0.3, 0.3, 1), physicsClientId=client)
    return pb.createMultiBody(baseMass=head.mass, baseCollisionShapeIndex=col, baseVisualShapeIndex=vis,
                              baseInertialFramePosition=[0, 0, half], physicsClientId=client)


class AssemblyWorld:
    """The cell of :class:`Product` ``product``: bodies, frames, goal and current poses."""

    def __init__(self, product: Product, logger: StepLogger | None = None, *, gains: ImpedanceGains) -> None:
        """``gains``: the controller's (the cell description's compliant impedance)."""
        self.product = product
        geometry = product.geometry
        self.client = c = connect()
        pb.setTimeStep(TIME_STEP, physicsClientId=c)
        pb.setGravity(0, 0, -9.81, physicsClientId=c)
        pb.setAdditionalSearchPath(pybullet_data.getDataPath(), physicsClientId=c)
        current_assets(geometry)
        self.floor = pb.loadURDF("plane.urdf", physicsClientId=c)
        self.frames: dict[str, PartFrames] = {}
        self.goals: dict[str, np.ndarray] = {}  # body position [m] of each part in the product
        self.goal_quats: dict[str, tuple[float, ...]] = {}  # a peg's body orientation (xyzw) there
        self._tray: dict[str, np.ndarray] = {}
        self._build_base()
        self._build_pegs()
        self._build_covers()
        self.socket_offset: dict[str, np.ndarray] = {}
        self._build_heads()
        self._build_manual()
        self.reset_tray()
        self.rest()
        self._build_arm()
        self.motion = Motion(ImpedanceController(self.arm, c, gains), logger)
        self.arm.inverse_kinematics(HOME, TOOL_DOWN_QUAT_XYZW)
        self.motion.controller.reset()
        self.settle(0.2)

    # --- building -------------------------------------------------------------------
    def _build_base(self) -> None:
        p, plate = self.product, self.product.geometry.plate
        tiles = [(*h.position, tile_of(plate, h)) for h in p.geometry.holes.values()]
        (sx, sy), (cx, cy) = plate.base_size, plate.base_center
        deck = rect_minus_squares((cx - sx / 2, cy - sy / 2, cx + sx / 2, cy + sy / 2), tiles)
        body = load_plate(self.client, p.geometry, p.geometry.assets / "plate.obj", deck)
        grip_xy = np.array([cx, cy]) + p.base.grip
        self.frames[p.base.id] = PartFrames(body, np.array([*grip_xy, p.top_z]), np.array([*grip_xy, p.top_z]))
        self.goals[p.base.id] = np.zeros(3)
        self._tray[p.base.id] = np.array([p.base.tray[0] - cx, p.base.tray[1] - cy, 0.0])

    def _build_pegs(self) -> None:
        gripper = self.product.geometry.gripper
        for pid, spec in sorted(self.product.pegs.items()):
            # A mesh or polygon peg's inertia is its solid's (in the URDF); PyBullet's own would be its pieces' box.
            solid = spec.mesh is not None or spec.kind == "polygon"
            flags = pb.URDF_USE_IMPLICIT_CYLINDER | (pb.URDF_USE_INERTIA_FROM_FILE if solid else 0)
            body = pb.loadURDF(str(self.product.geometry.assets / f"part_{spec.shape}.urdf"),
                               basePosition=(*spec.start, 0.0), flags=flags, physicsClientId=self.client)
            self.frames[pid] = PartFrames(body, np.array([0.0, 0.0, spec.length - spec.held_depth(gripper)]),
                                          np.zeros(3))
            self._tray[pid] = np.array([*spec.start, 0.0])

    def _mesh_body(self, pid: str) -> int:
        """A cover or head simulated from its own mesh: its generated URDF (the mesh's
        inertia, its convex pieces), at the origin."""
        stem = product_bodies(self.product.geometry)[pid].stem
        return pb.loadURDF(str(self.product.geometry.assets / f"{stem}.urdf"), flags=pb.URDF_USE_INERTIA_FROM_FILE,
                           physicsClientId=self.client)

    def _build_covers(self) -> None:
        for cid, cover in sorted(self.product.covers.items()):
            body = (self._mesh_body(cid) if cover.mesh is not None else
                    _compound(self.client, [(b.centre, b.half) for b in cover.boxes], cover.mass, (0.3, 0.5, 0.8, 1)))
            self.frames[cid] = PartFrames(body, np.array([*cover.grip, cover.thickness]), np.zeros(3))
            self.goals[cid] = np.array([*self.product.over_centre(cover), self.product.top_z + cover.bottom])
            self._tray[cid] = np.array([*cover.tray, 0.0])

    def _build_heads(self) -> None:
        c = self.client
        for hid, head in sorted(self.product.heads.items()):
            body = self._mesh_body(hid) if head.mesh is not None else _head_body(c, head)
            grip = min(self.product.geometry.gripper.grasp_depth, head.length / 2)
            self.frames[hid] = PartFrames(body, np.array([0.0, 0.0, head.length - grip]), np.zeros(3))
            self._tray[hid] = np.array([*head.start, 0.0])
            sx, sy, _, depth = self.product.covers[head.into].socket or (0.0, 0.0, 0.0, 0.0)
            cover = self.product.covers[head.into]
            self.socket_offset[hid] = np.array([sx, sy, cover.thickness - depth])
            self.goals[hid] = self.goals[head.into] + self.socket_offset[hid]

    def _build_manual(self) -> None:
        """The parts placed by hand: static concave meshes, moved where they are placed."""
        c = self.client
        for mid, manual in sorted(self.product.manual.items()):
            body = static_mesh(c, self.product.folder / manual.mesh.file)
            self.frames[mid] = PartFrames(body, np.zeros(3), np.zeros(3))
            self.goals[mid] = np.array(manual.goal)
            self._tray[mid] = np.array([*manual.tray, 0.0])

    def _build_arm(self) -> None:
        gripper = self.product.geometry.gripper
        grasp_depth = gripper.grasp_depth
        tool = PartSpec("tool", "round", 0.02, shape="gripper", length=grasp_depth, mass=0.05, start=(0.0, 0.0),
                        demo_hole="")
        self.arm_urdf = arm_urdf_text(tool, gripper)
        """The arm's URDF text (absolute mesh paths), as loaded:
        :mod:`executor.assembly.export`."""
        with tempfile.TemporaryDirectory(prefix="executor-assembly-arm-") as tmp:
            urdf = Path(tmp) / "arm_gripper.urdf"
            urdf.write_text(self.arm_urdf)
            self.robot = pb.loadURDF(str(urdf), basePosition=(0, 0, 0), useFixedBase=True,
                                     flags=pb.URDF_USE_IMPLICIT_CYLINDER | pb.URDF_USE_INERTIA_FROM_FILE,
                                     physicsClientId=self.client)
        self.arm = Arm(self.client, self.robot)
        self.tool_link = self.arm.sensor
        pb.setCollisionFilterGroupMask(self.robot, self.tool_link, 0, 0, physicsClientId=self.client)
        if any(hole.pin for hole in self.product.geometry.holes.values()):
            wrist_clear_of(self.client, self.robot, self.frames[self.product.base.id].body)
        tables = self.product.geometry.tables  # the owners of pins, those of the further pins of parts too
        for owner in ({hole.owner for hole in self.product.geometry.holes.values() if hole.owner is not None}
                      | {pid for shape in tables.part_shapes.values() for pid in shape.pins_of or ()}):
            wrist_clear_of(self.client, self.robot, self.frames[owner].body)  # its pin, as the base's
        if any(hole.sideways for hole in self.product.geometry.holes.values()):  # as in the trial's scene
            wrist_clear_of(self.client, self.robot, self.floor)

    def reset_tray(self) -> None:
        """Every part to its tray pose (at rest); the head-in-socket state is not kept."""
        for pid in self.frames:
            self.set_pose(pid, self.tray_position(pid))

    def set_peg_goal(self, part: str, hole: str, stacked: float = 0.0) -> None:
        """A peg's goal: standing on the bottom of ``hole``, shifted as the polygon relation
        passes it (:func:`executor.world.geometry.seat`; no shift for other sections);
        in a hole entered sideways, at its tip's depth and along the hole's axis
        (``goal_quats``); a part with a bore onto a pin ``stacked`` [m] farther out along
        its axis, on the parts already on the pin; onto a pin of a peg (its ``owner``), that
        goal carried to where the owner is (:meth:`on_owner`)."""
        spec = self.product.geometry.holes[hole]
        frame = spec.frame  # a hole entered sideways: the peg lies along its axis
        self.goals[part] = goal = seat(self.product.pegs[part], spec, stacked)
        self.goal_quats[part] = _IDENTITY if frame is None else frame.quat
        if spec.owner in self.product.pegs:
            self.goals[part], self.goal_quats[part] = self.on_owner(spec.owner, goal)

    def on_owner(self, owner: str, point: np.ndarray) -> tuple[np.ndarray, tuple[float, ...]]:
        """Where ``point`` [m] of peg ``owner``, given with the owner at its goal in its
        ``demo_hole`` (:func:`executor.world.geometry.seated_pose`: a pin's as
        ``geometry.toml`` has it), is with the owner where its body is now, and the owner's
        turn (xyzw): the owner's observed pose times the point's pose in the owner's frame
        (a real cell would measure the owner; the simulation reads it)."""
        spec = self.product.pegs[owner]
        seated, turn = seated_pose(spec, self.product.geometry.holes[spec.demo_hole])
        local = pb.multiplyTransforms(*pb.invertTransform(list(seated), list(turn)), list(point), _IDENTITY)
        pos, quat = self.pose(owner)
        moved, moved_quat = pb.multiplyTransforms(list(pos), list(quat), *local)
        return np.array(moved), tuple(moved_quat)

    def lock(self, part: str) -> None:
        """Lock a placed peg in its hole: fixed where it rests, its contacts with the plate
        switched off (the hole holds it; contacts of a peg with the plate's triangle mesh
        were the most expensive part of every later step)."""
        c, body = self.client, self.frames[part].body
        plate = self.frames[self.product.base.id].body
        for link in range(-1, pb.getNumJoints(plate, physicsClientId=c)):
            pb.setCollisionFilterPair(body, plate, -1, link, 0, physicsClientId=c)
        pos, quat = pb.getBasePositionAndOrientation(body, physicsClientId=c)
        pb.createConstraint(body, -1, -1, -1, pb.JOINT_FIXED, (0, 0, 0), (0, 0, 0), pos,
                            childFrameOrientation=quat, physicsClientId=c)

    def rest(self) -> None:
        """Put every part to sleep: a part at rest costs no contact computation until
        something touches it (it then wakes).  Call with the gripper open."""
        for frames in self.frames.values():
            for state in (pb.ACTIVATION_STATE_ENABLE_SLEEPING, pb.ACTIVATION_STATE_SLEEP):
                pb.changeDynamics(frames.body, -1, activationState=state, physicsClientId=self.client)

    def tray_position(self, part: str) -> np.ndarray:
        """Body position [m] of a part waiting on the tray; a head waits in no socket."""
        return self._tray[part]

    # --- state ----------------------------------------------------------------------
    def settle(self, duration: float) -> None:
        """Hold the arm where it is for ``duration`` [s] (parts come to rest)."""
        s = self.arm.read()
        self.motion.hold(s.tip_pos, tool_quat(self.motion.tool_yaw), duration)

    def position(self, part: str) -> np.ndarray:
        """The part's body origin [m]."""
        return self.pose(part)[0]

    def pose(self, part: str) -> tuple[np.ndarray, np.ndarray]:
        """Body origin [m] and quaternion xyzw (its URDF frame's, :func:`link_frame`)."""
        pos, quat = link_frame(self.client, self.frames[part].body, -1)
        return np.array(pos), np.array(quat)

    def set_pose(self, part: str, pos: np.ndarray, quat: tuple = _IDENTITY) -> None:
        """Put the body origin at ``pos`` [m] turned by ``quat``, at rest."""
        body = self.frames[part].body
        com, com_quat = pb.multiplyTransforms(list(pos), list(quat), *inertial_frame(self.client, body))
        pb.resetBasePositionAndOrientation(body, com, com_quat, physicsClientId=self.client)
        pb.resetBaseVelocity(body, (0, 0, 0), (0, 0, 0), physicsClientId=self.client)

    def goal_error(self, part: str) -> float:
        """Distance [m] of the part's body origin from its goal; a head's goal is the socket of
        its part where that part is (a pendulum swings on its shaft, and its head with it)."""
        head = self.product.heads.get(part)
        if head is None:
            return float(np.linalg.norm(self.position(part) - self.goals[part]))
        pos, quat = self.pose(head.into)
        socket = pb.multiplyTransforms(list(pos), list(quat), list(self.socket_offset[part]), _IDENTITY)[0]
        return float(np.linalg.norm(self.position(part) - np.array(socket)))

    def close(self) -> None:
        if pb.isConnected(self.client):
            pb.disconnect(self.client)
