"""Rerun recording of an assembly: every part and the arm moving over ``sim_time``, the plan
steps on their own timeline ``plan_step``, the measured force.

Entities (under ``executor/<cell-id>/assembly/``):

=============================== ===================================================
``parts/<id>``                  the part's pose (``Transform3D``) over ``sim_time``; its
                                solid (boxes, cylinders or its own mesh, in its frame)
                                logged when the world is attached
``arm/<link>``                  the arm's links (meshes, as in a cell's recording:
                                :class:`executor.rerun_arm.ArmRecorder`) over ``sim_time``,
                                their geometry logged when the world is attached
``force``                       measured contact force at the TCP (series Fx, Fy, Fz [N])
``steps``                       one text line per plan step (timelines ``plan_step``
                                and ``sim_time``)
=============================== ===================================================

The recorder is the Motion's step logger (:class:`executor.control.motion.StepLogger`):
it samples the world every ``period_s`` of simulated time. The solids and meshes are logged
at the time the world is attached with the poses then, not static: in a session's
recording the assembly comes after learning, and before it nothing of it is drawn (static
solids would stand at the origin until their first pose).
"""

from __future__ import annotations

import numpy as np
import rerun as rr
import trimesh

from bridge.recording.layout import assembly_root
from executor.assembly.world import AssemblyWorld
from executor.rerun_arm import ArmRecorder
from executor.rerun_plots import AXIS_NAMES, MEASURED_COLORS

PERIOD_S = 0.04  # [s] of sim time between two samples of the poses


def _part_solids(world: AssemblyWorld, part: str) -> list[rr.AsComponents]:
    """The part's solid in its body frame, as Rerun archetypes: a peg, cover, head or part
    placed by hand with its own mesh as that mesh, the others as their boxes and cylinders."""
    p = world.product
    color = [200, 150, 60]
    own = p.pegs[part].mesh if part in p.pegs else p.covers[part].mesh if part in p.covers else \
        p.heads[part].mesh if part in p.heads else p.manual[part].mesh if part in p.manual else None
    if own is not None:
        mesh = trimesh.load(p.folder / own.file, force="mesh")
        assert isinstance(mesh, trimesh.Trimesh)  # the loader checked the file
        return [rr.Mesh3D(vertex_positions=mesh.vertices, triangle_indices=mesh.faces,
                          albedo_factor=[80, 130, 210] if part in p.covers else color)]
    if part == p.base.id:
        plate = p.geometry.plate
        (sx, sy), (cx, cy) = plate.base_size, plate.base_center
        top = plate.top_z
        return [rr.Boxes3D(half_sizes=[[sx / 2, sy / 2, top / 2]], centers=[[cx, cy, top / 2]],
                           colors=[[150, 160, 175]], fill_mode="solid")]
    if part in p.covers:
        boxes = p.covers[part].boxes
        return [rr.Boxes3D(half_sizes=[b.half for b in boxes], centers=[b.centre for b in boxes],
                           colors=[[80, 130, 210]] * len(boxes), fill_mode="solid")]
    if part in p.heads:
        h = p.heads[part]
        kind, (a, b), length, color = h.kind, (h.size, h.size), h.length, [210, 80, 80]
    else:
        s = p.pegs[part]
        kind, (a, b), length = s.kind, s.sides, s.length
    if kind == "round":
        return [rr.Cylinders3D(radii=[a / 2], lengths=[length], centers=[[0, 0, length / 2]], colors=[color],
                               fill_mode="solid")]
    return [rr.Boxes3D(half_sizes=[[a / 2, b / 2, length / 2]], centers=[[0, 0, length / 2]], colors=[color],
                       fill_mode="solid")]


class AssemblyRecorder:
    """Logs one assembling world into ``recording`` under the cell ``cell_id``."""

    def __init__(self, recording: rr.RecordingStream, cell_id: str, period_s: float = PERIOD_S) -> None:
        self.rec, self.root, self.period_s = recording, assembly_root(cell_id), period_s
        self.world: AssemblyWorld | None = None
        self._arm: ArmRecorder | None = None
        self._next = 0.0
        self._offset = 0.0  # [s] sim time of the worlds before this one
        self._step = 0

    def attach(self, world: AssemblyWorld) -> None:
        """Record ``world`` from now on (a new plan run: its sim time continues the last one's)."""
        if self.world is not None:
            self._offset = self._next
        self.world = world
        self._arm = ArmRecorder(world.client, world.robot)
        self.rec.set_time("sim_time", duration=self._offset)
        self._arm.log_geometry(self.rec, self.root, "gripper", with_static=True, static=False)
        for part in world.product.parts:
            for solid in _part_solids(world, part):
                self.rec.log(f"{self.root}/parts/{part}", solid)
        self._log_poses()
        self.rec.log(f"{self.root}/force", rr.SeriesLines(names=[f"{n} [N]" for n in AXIS_NAMES["force"]],
                                                         colors=MEASURED_COLORS), static=True)

    def _log_poses(self) -> None:
        """Every part's and the arm's pose now, at the stream's current time."""
        assert self.world is not None and self._arm is not None
        for part in self.world.frames:
            pos, quat = self.world.pose(part)
            self.rec.log(f"{self.root}/parts/{part}",
                         rr.Transform3D(translation=pos, quaternion=rr.Quaternion(xyzw=list(quat))))
        self._arm.log_now(self.rec, self.root)

    def log_step(self, sim_time: float, phase: float, tool_pos: np.ndarray, force_mes: np.ndarray,
                 force_des: np.ndarray, torque_mes: np.ndarray, torque_des: np.ndarray) -> None:
        """Motion's step logger: a sample of every pose each ``period_s`` [s] of sim time."""
        t = self._offset + sim_time
        if self.world is None or t < self._next:
            return
        self._next = t + self.period_s
        self.rec.set_time("sim_time", duration=t)
        self._log_poses()
        self.rec.log(f"{self.root}/force", rr.Scalars(np.asarray(force_mes, dtype=float)))

    def log_plan_step(self, part: str, hole: str | None, outcome: str, attempts: int, error_mm: float) -> None:
        """One line per plan step on the ``plan_step`` timeline."""
        self._step += 1
        self.rec.set_time("plan_step", sequence=self._step)
        self.rec.set_time("sim_time", duration=self._next)
        into = f"->{hole}" if hole else ""
        self.rec.log(f"{self.root}/steps", rr.TextLog(
            f"step {self._step}: {part}{into}: {outcome} ({attempts} attempt(s), {error_mm:.2f} mm from its goal)",
            level="INFO" if outcome == "fit" else "WARN"))
        # only the step's own timeline ends here: the others (a session's experiment) go on
        self.rec.disable_timeline("plan_step")

    def flush(self) -> None:
        self.rec.flush()
