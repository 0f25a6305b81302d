"""The grasp: a fixed constraint between the gripper tool and the part, made at pick and
released once the part is placed (it then rests on its own contacts). A part on the
suction cup is held the same way while the arm's sensor watches the pull on the cup
(:class:`executor.world.arm.Dropped` once it exceeds the cup's holding force).

The constraint holds the part at its nominal grip pose composed with a random grasp
error (≤ 1 mm lateral offset, ≤ 1° tilt, as in the single trials): the robot believes the
nominal pose, so the skills meet a real, unknown error. The tool may hold the part turned
about the grip point's vertical (:attr:`Grasp.yaw`): the part keeps that pose in the tool,
so the tool is turned by it wherever the part is placed. The back plate is a static
(fixed-base) body: while held it is moved kinematically with the tool instead.
"""

from __future__ import annotations

import numpy as np
import pybullet as pb

from executor.assembly.world import AssemblyWorld
from executor.skills.insertion import rotvec_quat_xyzw
from executor.world.arm import tool_quat
from executor.world.scene import inertial_frame

GRASP_FORCE = 500.0  # [N] the constraint's maximum force


class Grasp:
    """A part in the gripper; :meth:`follow` moves a kinematic (base) part with the tool."""

    def __init__(self, world: AssemblyWorld, part: str, offset: np.ndarray, tilt: np.ndarray,
                 yaw: float = 0.0) -> None:
        self.world, self.part = world, part
        self.yaw = yaw
        """[rad] the tool's turn about the part's z axis: the tool in the part's frame is
        :func:`executor.world.arm.tool_quat` of it, at the grip point"""
        frames = world.frames[part]
        c = world.client
        # Part body in the tool frame: tool at the grip point, pointing down, turned by the yaw; the grasp error on top.
        tool_in_part = (list(frames.grip), list(tool_quat(yaw)))
        body_pos, body_quat = pb.invertTransform(*tool_in_part)
        self.body_in_tool = pb.multiplyTransforms(list(offset), list(rotvec_quat_xyzw(tilt)), body_pos, body_quat)
        self.kinematic = part == world.product.base.id
        self.constraint: int | None = None
        if not self.kinematic:
            # Constraint frames are relative to the links' inertial frames.
            parent = pb.multiplyTransforms(*pb.invertTransform(*inertial_frame(c, world.robot, world.tool_link)),
                                           *self.body_in_tool)
            child = pb.invertTransform(*inertial_frame(c, frames.body))
            self.constraint = pb.createConstraint(
                world.robot, world.tool_link, frames.body, -1, pb.JOINT_FIXED, (0, 0, 0),
                parentFramePosition=parent[0], childFramePosition=child[0],
                parentFrameOrientation=parent[1], childFrameOrientation=child[1], physicsClientId=c)
            pb.changeConstraint(self.constraint, maxForce=GRASP_FORCE, physicsClientId=c)
        # On the suction cup the arm's sensor watches the pull on it (executor.world.arm.Dropped).
        spec = world.product.geometry.parts.get(part)
        world.arm.hold_limit = world.product.geometry.gripper.cup_force if spec and spec.tool == "suction" else None
        # The believed TCP in the tool frame (nominal grasp): what the controller drives.
        tcp_in_tool = pb.multiplyTransforms(body_pos, body_quat, list(frames.tcp), [0, 0, 0, 1])[0]
        world.arm.set_grasp_error(-np.array(tcp_in_tool), np.array([0.0, 0.0, 0.0, 1.0]))

    def follow(self) -> None:
        """A kinematic part takes its place in the tool (call after each physics step)."""
        if self.kinematic:
            ls = pb.getLinkState(self.world.robot, self.world.tool_link, computeForwardKinematics=1,
                                 physicsClientId=self.world.client)
            pos, quat = pb.multiplyTransforms(ls[4], ls[5], *self.body_in_tool)
            self.world.set_pose(self.part, np.array(pos), quat)

    def release(self) -> None:
        """Open the gripper: the part rests on its contacts; the TCP becomes the tool frame."""
        if self.constraint is not None:
            pb.removeConstraint(self.constraint, physicsClientId=self.world.client)
            self.constraint = None
        self.world.arm.set_grasp_error(np.zeros(3), np.array([0.0, 0.0, 0.0, 1.0]))
        self.world.arm.hold_limit = None
