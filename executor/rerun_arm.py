"""The arm in the Rerun scene: its links as PyBullet loaded them, moving over ``sim_time``.

An :class:`ArmRecorder` reads the robot's visual shapes once (the kuka_iiwa meshes of
``pybullet_data``, the flange cylinder, the held part) and, at every logged control step,
the world pose of each link frame (one ``getLinkStates`` call, ~15 µs).  Entities, under
``executor/<cell-id>/arm/``:

================================ ==========================================================
``<link>``                       the link frame's pose (Transform3D) over ``sim_time`` [m]
``<link>/visual_<k>``            the link's geometry in its frame: a mesh (``Asset3D``,
                                 static) or a box/cylinder (the flange)
``part/held``                    the held part's solid in the ``part`` frame (its tip), from
                                 the time it is taken (the cell tab's close-up follows it)
================================ ==========================================================

The base link never moves and is logged once.  The held part's geometry is logged at the
time it is taken, with the archetypes of the other kinds cleared (a viewer draws each
archetype's latest values, so a square peg held before a round one would stay drawn
around it): a cell holding parts of several shapes shows the right one at each time.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pybullet as pb
import rerun as rr

from bridge.recording.layout import HELD_PART, HELD_PART_COLOR, HELD_PART_SOLIDS
from bridge.recording.rows import log_row
from executor.world.scene import link_frame

_ARM_COLOR = [235, 120, 30]
_TOOL_COLOR = [80, 80, 90]
_BASE = -1


class ArmRecorder:
    """Link geometry and poses of the robot ``robot`` in PyBullet client ``client``."""

    def __init__(self, client: int, robot: int) -> None:
        self.client = client
        self.robot = robot
        count = pb.getNumJoints(robot, physicsClientId=client)
        self.links = list(range(count))
        self.names = {_BASE: "base"} | {
            j: pb.getJointInfo(robot, j, physicsClientId=client)[12].decode() for j in self.links
        }
        self._visuals = pb.getVisualShapeData(robot, physicsClientId=client)

    def sample(self) -> np.ndarray:
        """World poses of the moving links' frames now: ``(links, 7)`` rows of position [m]
        and quaternion (x, y, z, w)."""
        states = pb.getLinkStates(self.robot, self.links, computeForwardKinematics=1,
                                  physicsClientId=self.client)
        return np.array([[*s[4], *s[5]] for s in states], dtype=np.float64)

    def log_geometry(self, rec: rr.RecordingStream, root: str, held_part: str | None, with_static: bool,
                     static: bool = True, at: Sequence[rr.TimeColumn] | None = None) -> None:
        """Log the held part's geometry (None: the hand is empty, nothing is logged for it)
        and, ``with_static``, every other link's geometry and the fixed base's pose. The held
        part at the current time, the rest ``static`` (once per recording is enough) or, when
        not, at the current time too; with ``at`` (one-row time columns: one instant on each
        timeline, ``log_time`` included), everything as rows at that instant. Not static,
        nothing is drawn before it (no links piled at the origin before the arm is there)."""
        for k, visual in enumerate(self._visuals):
            link, geom_type, dims, mesh = visual[1], visual[2], visual[3], visual[4]
            is_part = self.names[link] == "part"  # one visual: the part's solid (arm_urdf_text)
            entity = f"{root}/{HELD_PART}" if is_part else f"{root}/arm/{self.names[link]}/visual_{k}"
            pose = rr.Transform3D(translation=list(visual[5]), quaternion=rr.Quaternion(xyzw=list(visual[6])))
            color = list(HELD_PART_COLOR) if is_part else _ARM_COLOR if geom_type == pb.GEOM_MESH else _TOOL_COLOR
            archetype = _archetype(geom_type, dims, mesh, color)
            if archetype is None:
                continue
            if is_part:
                if held_part is not None:  # the other kinds cleared: a box held before is no longer drawn
                    others = [kind.cleared() for kind in HELD_PART_SOLIDS if not isinstance(archetype, kind)]
                    log_row(rec, entity, [pose, archetype, *others, rr.TextDocument(held_part)], at, static=False)
            elif with_static:
                log_row(rec, entity, [pose, archetype], at, static)
        if not with_static:
            return
        base_pos, base_quat = link_frame(self.client, self.robot, _BASE)
        log_row(rec, f"{root}/arm/base", [rr.Transform3D(translation=list(base_pos),
                                                          quaternion=rr.Quaternion(xyzw=list(base_quat)))], at, static)

    def log_now(self, rec: rr.RecordingStream, root: str) -> None:
        """Log every moving link's pose now, at the stream's current time (row by row, for
        a logger that samples rather than buffers)."""
        for row, link in zip(self.sample(), self.links):
            rec.log(f"{root}/arm/{self.names[link]}",
                    rr.Transform3D(translation=row[:3], quaternion=rr.Quaternion(xyzw=row[3:])))

    def send(self, rec: rr.RecordingStream, root: str, indexes: Sequence[rr.TimeColumn], poses: np.ndarray) -> None:
        """Send sampled poses ``(steps, links, 7)`` as one Transform3D column per link."""
        for column, link in enumerate(self.links):
            rec.send_columns(
                f"{root}/arm/{self.names[link]}", indexes=indexes,
                columns=rr.Transform3D.columns(translation=poses[:, column, :3], quaternion=poses[:, column, 3:]),
            )


def _archetype(geom_type: int, dims: Sequence[float], mesh: bytes, color: list[int]) -> rr.AsComponents | None:
    """A Rerun archetype drawing one PyBullet visual shape in its own frame."""
    if geom_type == pb.GEOM_MESH:
        return rr.Asset3D(path=Path(mesh.decode()), albedo_factor=color)
    if geom_type == pb.GEOM_CYLINDER:
        return rr.Cylinders3D(lengths=[dims[0]], radii=[dims[1]], colors=[color], fill_mode="solid")
    if geom_type == pb.GEOM_BOX:
        return rr.Boxes3D(half_sizes=[[d / 2 for d in dims]], colors=[color], fill_mode="solid")
    return None
