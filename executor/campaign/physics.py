"""``./run.sh bench physics``: how far the cell is from the cost of its own physics.

Three figures in one run, each the median over ``--repeats`` runs, as simulated steps
per second (one step of the cell's clock, 1 ms):

a. **bare**: ``stepSimulation`` of the cell's scene for one part shape (floor, plate,
   tray, the arm holding the part), the arm held by PyBullet's own joint motors at the
   approach pose 3 cm above the hole: no contact, no Python control;
b. **contact**: the same with the part pushed into a hole it fits, against the hole's
   wall and bottom (the motors aim 2 mm below the bottom and one clearance sideways):
   the cost of the peg-in-hole contact itself;
c. **trial**: whole trials (search, insertion, detection, the second attempt where there
   is one) of the part in that hole, as the cell runs them: simulated steps over wall time,
   each in a fresh cell whose PyBullet scene and taught skill are loaded before the clock
   starts (a cell is made once and runs many trials: its making is no part of a trial).

It prints the three and the ratio c/b (time per step of a trial over that of the
contact physics: 1 would be a free controller), by wall time and by this process's CPU
time (on a machine shared with other work, the CPU figures do not count the waiting).
``--baseline S`` compares the trial's steps per CPU second with a kept figure S
(docs/results.md) and says when it fell by more than a third (exit code 1): per CPU
second, so that other work on the machine does not pass for a regression.
"""

from __future__ import annotations

import json
import statistics
import time
from typing import Any

import numpy as np
import pybullet as pb

from bridge.cli_types import MAX_SEED, ArgumentParser, add_assembly_argument, int_in, number_in
from executor import ExecutorError
from executor.campaign.run import stdout_to_stderr
from executor.trial import Cell
from executor.world import TIME_STEP
from executor.world.arm import Arm
from executor.world.geometry import feature_passes, load_geometry
from executor.world.scene import Scene

TOOL_DOWN = np.array([1.0, 0.0, 0.0, 0.0])
"""Tool orientation pointing down (xyzw quaternion), as the skills hold it."""

FALL_LIMIT = 1 / 3
"""--baseline: a trial slower than (1 - this) x the kept figure is a regression."""


def _hold(scene: Scene, arm: Arm, tip: np.ndarray) -> None:
    """Put the believed tool tip at ``tip`` [m] and hold the joints there with PyBullet's
    position motors (stiff enough to press a peg into a wall)."""
    q = arm.inverse_kinematics(tip, TOOL_DOWN)
    pb.setJointMotorControlArray(scene.robot, arm.joints, pb.POSITION_CONTROL, targetPositions=list(q),
                                 forces=[300.0] * len(arm.joints), physicsClientId=scene.client)


def _steps_per_s(client: int, steps: int) -> tuple[float, float]:
    """Steps per second of wall time and of this process's CPU time."""
    wall, cpu = time.perf_counter(), time.process_time()
    for _ in range(steps):
        pb.stepSimulation(physicsClientId=client)
    return steps / (time.perf_counter() - wall), steps / (time.process_time() - cpu)


def physics_rates(assembly: str, part: str, hole: str, steps: int) -> dict[str, Any]:
    """Steps per second (wall, CPU) of (a) the bare scene and (b) the part in contact with
    the hole, and the contact points the part has with the plate in (b)."""
    geometry = load_geometry(assembly)
    spec, hole_spec = geometry.parts[part], geometry.holes[hole]
    if hole_spec.sideways:
        raise ExecutorError(f"hole {hole} is entered along {hole_spec.axis}: the contact rate is measured in a hole "
                            "entered down (-z)")
    scene = Scene(geometry, spec.shape)
    try:
        scene.hold(spec)
        arm = Arm(scene.client, scene.robot)
        depth = hole_spec.depth
        center = np.array([*hole_spec.position, hole_spec.top_z])
        _hold(scene, arm, center + [0.0, 0.0, 0.03])
        for _ in range(200):
            pb.stepSimulation(physicsClientId=scene.client)
        bare = _steps_per_s(scene.client, steps)
        clearance = max(hole_spec.size - spec.size, 0.0)
        _hold(scene, arm, center + [clearance, 0.0, -depth - 0.002])
        for _ in range(500):
            pb.stepSimulation(physicsClientId=scene.client)
        contacts = len(pb.getContactPoints(scene.robot, scene.plate, physicsClientId=scene.client))
        contact = _steps_per_s(scene.client, steps)
    finally:
        scene.close()
    return {"bare": bare, "contact": contact, "contact_points": contacts}


def trial_rate(assembly: str, part: str, hole: str, seed: int) -> tuple[float, float]:
    """Simulated steps per wall second and per CPU second of one whole trial, in a fresh
    cell whose scene and skill are loaded before the clocks start (what every trial after
    a cell's first costs)."""
    cell = Cell(assembly)
    try:
        cell.check_pair(part, hole)
        cell.motion_for(part)
        cpu = time.process_time()
        result = cell.run_trial(part, hole, seed)
        cpu = time.process_time() - cpu
    finally:
        cell.close()
    steps = sum(e.sim_time_s for e in result.evidence) / TIME_STEP
    return steps / result.duration_s, steps / cpu


def main(argv: list[str]) -> int:
    parser = ArgumentParser(prog="bench physics", description=__doc__)
    add_assembly_argument(parser, "cranfield")
    parser.add_argument("--part", default="p1", help="the part (default p1)")
    parser.add_argument("--hole", default="r1", help="a hole it fits (default r1)")
    parser.add_argument("--steps", type=int_in(100, 10**6), default=3000, help="steps per figure a, b (default 3000)")
    parser.add_argument("--repeats", type=int_in(1, 100), default=5, help="runs per figure; medians (default 5)")
    parser.add_argument("--seed", type=int_in(0, MAX_SEED), default=8811, help="first trial seed (default 8811)")
    parser.add_argument("--baseline", type=number_in(float, 1.0, 1e9), metavar="STEPS_PER_CPU_S",
                        help="the kept trial figure (steps per CPU second): exit 1 when the trial fell by more "
                             "than a third")
    parser.add_argument("--json", action="store_true", help="print JSON")
    args = parser.parse_args(argv)
    geometry = load_geometry(args.assembly)
    if args.part not in geometry.parts or args.hole not in geometry.holes:
        raise ExecutorError(f"--part {args.part} --hole {args.hole}: expected a part of "
                            f"{' '.join(sorted(geometry.parts))} and a hole of {' '.join(sorted(geometry.holes))}")
    if not feature_passes(geometry.parts[args.part], geometry.holes[args.hole]):
        raise ExecutorError(f"--part {args.part} --hole {args.hole}: the part does not fit that hole; "
                            "expected a fitting pair (the contact figure presses the part into the hole)")
    with stdout_to_stderr():
        runs = [physics_rates(args.assembly, args.part, args.hole, args.steps) for _ in range(args.repeats)]
        trials = [trial_rate(args.assembly, args.part, args.hole, args.seed + k) for k in range(args.repeats)]
    bare, contact = (statistics.median(r[key][0] for r in runs) for key in ("bare", "contact"))
    trial = statistics.median(t[0] for t in trials)
    cpu_contact = statistics.median(r["contact"][1] for r in runs)
    cpu_trial = statistics.median(t[1] for t in trials)
    report: dict[str, Any] = {
        "assembly": args.assembly, "part": args.part, "hole": args.hole, "repeats": args.repeats,
        "bare_steps_per_s": round(bare), "contact_steps_per_s": round(contact), "trial_steps_per_s": round(trial),
        "contact_points": min(r["contact_points"] for r in runs),
        "ratio_trial_over_contact": round(contact / trial, 2),
        "trial_real_time_factor": round(trial * TIME_STEP, 2),
        # Per CPU second of this process: what a loaded machine's waiting does not change.
        "cpu_bare_steps_per_s": round(statistics.median(r["bare"][1] for r in runs)),
        "cpu_contact_steps_per_s": round(cpu_contact), "cpu_trial_steps_per_s": round(cpu_trial),
        "cpu_ratio_trial_over_contact": round(cpu_contact / cpu_trial, 2),
    }
    regressed = False
    if args.baseline is not None:
        report["baseline_steps_per_s"] = args.baseline
        report["ratio_to_baseline"] = round(cpu_trial / args.baseline, 2)
        regressed = cpu_trial < (1 - FALL_LIMIT) * args.baseline
        report["regressed"] = regressed
    if args.json:
        print(json.dumps(report))
    else:
        print(f"{args.part} -> {args.hole} on {args.assembly}, medians of {args.repeats} runs [simulated steps/s]:")
        print(f"  a. bare scene (no contact, no control): {report['bare_steps_per_s']:>8}")
        print(f"  b. part in contact with the hole:       {report['contact_steps_per_s']:>8}  "
              f"({report['contact_points']} contact points)")
        print(f"  c. whole trial:                         {report['trial_steps_per_s']:>8}  "
              f"(real-time factor {report['trial_real_time_factor']})")
        print(f"  ratio c/b (time per step, trial over contact physics): {report['ratio_trial_over_contact']}")
        print(f"  per CPU second: a {report['cpu_bare_steps_per_s']}, b {report['cpu_contact_steps_per_s']}, "
              f"c {report['cpu_trial_steps_per_s']}, ratio c/b {report['cpu_ratio_trial_over_contact']}")
        if args.baseline is not None:
            verdict = "fell by more than a third" if regressed else "within a third"
            print(f"  trial per CPU second versus the kept {args.baseline:.0f} steps/s: "
                  f"{report['ratio_to_baseline']} ({verdict})")
    return 1 if regressed else 0
