"""``./run.sh bench engines``: the same part-hole pairs in the PyBullet cell's physics and in
the MuJoCo scene that franky-sim serves the Franka arm from, side by side.

Per pair and engine, one straight force-stopped insertion of the part alone: the part
(free rigid body, its mass, the cell's part-plate friction) starts upright with its
bottom 5 mm above the hole's entry, centred on the hole and turned to it, and a stiff
drive (PyBullet: a fixed constraint of at most 500 N; MuJoCo: a weld to a moving body)
moves it straight down at 20 mm/s toward 12 mm below the entry (less when the hole is
shallower). The drive stops and holds where the part is once the plate's contact force
on the part (z, normal and friction forces, each engine's own contacts) exceeds 10 N: the outcome is **fit**
when the part's bottom got deeper than 6 mm below the entry, else **no fit**. The plate
is each engine's own build of geometry.toml: PyBullet's concave triangle mesh, MuJoCo's
convex pieces; the same surfaces.

It prints one row per pair (the geometry's answer, each engine's outcome, depth and
largest force), the pairs where the engines disagree (or disagree with the geometry),
and each engine's physics steps per second (wall and CPU time) of one insertion, the
median over the pairs, the arm left out of both.
"""

from __future__ import annotations

import json
import statistics
import time
from dataclasses import asdict, dataclass
from typing import Any

import mujoco
import numpy as np
import pybullet as pb

from bridge.cli_types import ArgumentParser, add_assembly_argument
from executor import ExecutorError
from executor.campaign.run import stdout_to_stderr
from executor.franka.sim_scene import TIME_STEP, contact_force, product_model
from executor.world.assets import current_assets
from executor.world.frames import aligned_yaw, yaw_quat
from executor.world.geometry import CellGeometry, HoleSpec, PartSpec, load_geometry, passes
from executor.world.scene import PART_FRICTION, TEACH_FRICTION, connect, load_plate

START_ABOVE = 0.005
"""Where the part's bottom starts above the hole's entry [m]."""
TARGET_DEPTH = 0.012
"""How far below the entry the drive aims [m] (less in a shallower hole: 2 mm above its bottom)."""
FIT_DEPTH = 0.006
"""A part whose bottom got this far below the entry [m] is in the hole (the chamfer is under 1 mm)."""
SPEED = 0.02
"""The drive's speed down [m/s]."""
STOP_FORCE = 10.0
"""The drive stops when the plate pushes the part up by more than this [N]."""
DRIVE_FORCE = 500.0
"""PyBullet's drive: the most force its constraint applies [N]."""
SOLVER_ITERATIONS = 200
"""PyBullet's constraint solver iterations per step here (its default, the cell's, is 50).
The drive is a stiff constraint on a free part of a few grams, unlike the cell's arm
driven by joint torques: with 50 iterations the 5 g square peg of ``taskboard`` is pushed
through 0.26 mm of interference at its corners (``rect4:hole4``) with under 7 N of the
plate's push, with 200 it stops on force at the entry (docs/results/franka.md)."""
SETTLE = 0.1
"""Time [s] the part is held at its start before the drive moves (contacts settle)."""


@dataclass(frozen=True)
class Insertion:
    """One engine's insertion: ``fits`` (the bottom got deeper than :data:`FIT_DEPTH`),
    ``depth`` [m] of the part's bottom below the entry at the end, ``force`` [N] the
    plate's largest push up, ``steps`` simulated, ``wall_s`` and ``cpu_s`` they took."""

    fits: bool
    depth: float
    force: float
    steps: int
    wall_s: float
    cpu_s: float


def _path(hole: HoleSpec) -> tuple[float, int]:
    """The depth the drive aims at [m] and the steps it takes to get there."""
    target = min(TARGET_DEPTH, hole.depth - 0.002)
    return target, int(round((START_ABOVE + target) / SPEED / TIME_STEP))


def _result(depth: float, force: float, steps: int, wall: float, cpu: float) -> Insertion:
    return Insertion(depth > FIT_DEPTH, depth, force, steps, time.perf_counter() - wall, time.process_time() - cpu)


def pybullet_insertion(geometry: CellGeometry, part: PartSpec, hole: HoleSpec) -> Insertion:
    """The insertion in PyBullet: the cell's plate and part URDF, the cell's step and
    friction, :data:`SOLVER_ITERATIONS`."""
    client = connect()
    try:
        pb.setPhysicsEngineParameter(numSolverIterations=SOLVER_ITERATIONS, physicsClientId=client)
        pb.setTimeStep(TIME_STEP, physicsClientId=client)
        pb.setGravity(0, 0, -9.81, physicsClientId=client)
        plate = load_plate(client, geometry, current_assets(geometry) / "plate.obj")
        pb.changeDynamics(plate, -1, lateralFriction=TEACH_FRICTION / PART_FRICTION, physicsClientId=client)
        quat = yaw_quat(aligned_yaw(part.kind, hole.kind, hole.yaw))
        start = np.array([*hole.position, hole.top_z + START_ABOVE])
        body = pb.loadURDF(str(geometry.assets / f"part_{part.shape}.urdf"), basePosition=list(start),
                           baseOrientation=quat, flags=pb.URDF_USE_IMPLICIT_CYLINDER, physicsClientId=client)
        com = pb.getDynamicsInfo(body, -1, physicsClientId=client)[3]
        drive = pb.createConstraint(body, -1, -1, -1, pb.JOINT_FIXED, (0, 0, 0), (0, 0, 0), list(start + com),
                                    childFrameOrientation=quat, physicsClientId=client)
        target, steps = _path(hole)
        settle = int(SETTLE / TIME_STEP)
        wall, cpu = time.perf_counter(), time.process_time()
        aim, peak = start.copy(), 0.0
        for step in range(settle + steps):
            bottom = np.array(pb.getBasePositionAndOrientation(body, physicsClientId=client)[0]) - com
            if peak > STOP_FORCE:  # stopped: hold where the part is
                aim[2] = min(aim[2], bottom[2])
            elif step >= settle:
                aim[2] = max(aim[2] - SPEED * TIME_STEP, hole.top_z - target)
            pb.changeConstraint(drive, list(aim + com), jointChildFrameOrientation=quat, maxForce=DRIVE_FORCE,
                                physicsClientId=client)
            pb.stepSimulation(physicsClientId=client)
            peak = max(peak, _pybullet_push(client, body, plate))
        bottom = np.array(pb.getBasePositionAndOrientation(body, physicsClientId=client)[0]) - com
        return _result(hole.top_z - float(bottom[2]), peak, settle + steps, wall, cpu)
    finally:
        pb.disconnect(client)


def _pybullet_push(client: int, body: int, plate: int) -> float:
    """The plate's contact force on the part, z [N]: the normal forces and the friction
    (each contact's normal on the plate points to the part; its friction forces act on the
    part), as MuJoCo's :func:`executor.franka.sim_scene.contact_force` counts it. The
    friction matters: a part squeezed into a wall meets horizontal normals, and only the
    friction pushes it up."""
    return sum(c[9] * c[7][2] + c[10] * c[11][2] + c[12] * c[13][2]
               for c in pb.getContactPoints(body, plate, physicsClientId=client))


def mujoco_insertion(geometry: CellGeometry, part: PartSpec, hole: HoleSpec) -> Insertion:
    """The insertion in MuJoCo: franky-sim's scene of the product without the arm
    (:func:`executor.franka.sim_scene.product_model`), the part welded to a mocap body."""
    model, data, bodies = product_model(geometry, drive=part.id)
    body, plate = bodies[part.id], bodies["plate"]
    mocap = model.body_mocapid[bodies["drive"]]
    yaw = aligned_yaw(part.kind, hole.kind, hole.yaw)
    quat = np.array([np.cos(yaw / 2), 0.0, 0.0, np.sin(yaw / 2)])  # w x y z
    start = np.array([*hole.position, hole.top_z + START_ABOVE])
    joint = model.body_jntadr[body]
    data.qpos[model.jnt_qposadr[joint]:model.jnt_qposadr[joint] + 7] = [*start, *quat]
    data.mocap_pos[mocap], data.mocap_quat[mocap] = start, quat
    mujoco.mj_forward(model, data)
    target, steps = _path(hole)
    settle = int(SETTLE / TIME_STEP)
    wall, cpu = time.perf_counter(), time.process_time()
    aim, peak = data.mocap_pos[mocap], 0.0
    for step in range(settle + steps):
        if peak > STOP_FORCE:  # stopped: hold where the part is
            aim[2] = min(aim[2], data.xpos[body][2])
        elif step >= settle:
            aim[2] = max(aim[2] - SPEED * TIME_STEP, hole.top_z - target)
        mujoco.mj_step(model, data)
        peak = max(peak, float(contact_force(model, data, body, plate)[2]))
    return _result(hole.top_z - float(data.xpos[body][2]), peak, settle + steps, wall, cpu)


def compare(assembly: str, pairs: list[tuple[str, str]] | None = None) -> dict[str, Any]:
    """Both engines' insertions of ``pairs`` (default: every part with every hole entered
    down; a hole entered sideways is refused) of an assembly: rows, the pairs where they
    disagree, each engine's steps per second (the median over the insertions)."""
    geometry = load_geometry(assembly)
    if pairs is None:
        down = [hid for hid, spec in sorted(geometry.holes.items()) if not spec.sideways]
        pairs = [(p, h) for p in sorted(geometry.parts) for h in down]
    for pid, hid in pairs:
        if pid not in geometry.parts or hid not in geometry.holes:
            raise ExecutorError(f"--pair {pid}:{hid}: expected a part of {' '.join(sorted(geometry.parts))} and a "
                                f"hole of {' '.join(sorted(geometry.holes))}")
        if geometry.holes[hid].sideways:
            raise ExecutorError(f"--pair {pid}:{hid}: hole {hid} is entered along {geometry.holes[hid].axis}; the "
                                "engines' comparison drops parts down into holes entered down (-z) only")
    rows: list[dict[str, Any]] = []
    for pid, hid in pairs:
        part, hole = geometry.parts[pid], geometry.holes[hid]
        rows.append({"part": pid, "hole": hid, "geometry": passes(part, hole),
                     "pybullet": asdict(pybullet_insertion(geometry, part, hole)),
                     "mujoco": asdict(mujoco_insertion(geometry, part, hole))})
    differ = [f"{r['part']}:{r['hole']}" for r in rows if r["pybullet"]["fits"] != r["mujoco"]["fits"]]
    wrong = {engine: [f"{r['part']}:{r['hole']}" for r in rows if r[engine]["fits"] != r["geometry"]]
             for engine in ("pybullet", "mujoco")}
    rates = {engine: _rates([row[engine] for row in rows]) for engine in ("pybullet", "mujoco")}
    return {"assembly": geometry.folder.name, "rows": rows, "engines_differ": differ, "differ_from_geometry": wrong,
            "steps_per_s": rates}


def _rates(insertions: list[dict[str, Any]]) -> dict[str, float]:
    """The median over ``insertions`` of their steps per second of wall and of CPU time."""
    return {"wall": statistics.median(i["steps"] / i["wall_s"] for i in insertions),
            "cpu": statistics.median(i["steps"] / max(i["cpu_s"], 1e-9) for i in insertions)}


def format_report(report: dict[str, Any]) -> str:
    """The report as text: one row per pair, the disagreements, the steps per second."""

    def outcome(result: dict[str, Any]) -> str:
        return f"{'fit' if result['fits'] else 'no fit':>6} {result['depth'] * 1000:6.1f} mm {result['force']:6.1f} N"

    lines = [f"{report['assembly']}: a straight force-stopped insertion per pair (stop above {STOP_FORCE:g} N, "
             f"fit deeper than {FIT_DEPTH * 1000:g} mm)",
             f"{'pair':<14} {'geometry':>8}  {'PyBullet: outcome, depth, force':>31}  "
             f"{'MuJoCo: outcome, depth, force':>31}"]
    for row in report["rows"]:
        lines.append(f"{row['part'] + ':' + row['hole']:<14} {'fit' if row['geometry'] else 'no fit':>8}  "
                     f"{outcome(row['pybullet']):>31}  {outcome(row['mujoco']):>31}")
    lines.append("engines differ on: " + (" ".join(report["engines_differ"]) or "no pair"))
    for engine, pairs in report["differ_from_geometry"].items():
        lines.append(f"{engine} differs from the geometry on: " + (" ".join(pairs) or "no pair"))
    rates = report["steps_per_s"]
    lines.append("physics steps per second of one insertion (median over the pairs): "
                 f"PyBullet {rates['pybullet']['wall']:.0f} wall / {rates['pybullet']['cpu']:.0f} CPU, "
                 f"MuJoCo {rates['mujoco']['wall']:.0f} wall / {rates['mujoco']['cpu']:.0f} CPU")
    return "\n".join(lines)


def _pair(text: str) -> tuple[str, str]:
    part, sep, hole = text.partition(":")
    if not sep or not part or not hole:
        raise ExecutorError(f"--pair {text!r}: expected PART:HOLE, e.g. p1:r1")
    return part, hole


def main(argv: list[str]) -> int:
    parser = ArgumentParser(prog="bench engines", description=__doc__)
    add_assembly_argument(parser, "spare")
    parser.add_argument("--pair", action="append", metavar="PART:HOLE",
                        help="a pair to insert (repeatable; default: every part with every hole)")
    parser.add_argument("--json", action="store_true", help="print JSON")
    args = parser.parse_args(argv)
    pairs = None if args.pair is None else [_pair(text) for text in args.pair]
    with stdout_to_stderr():
        report = compare(args.assembly, pairs)
    print(json.dumps(report, indent=1) if args.json else format_report(report))
    return 0
