"""``./run.sh bench rates``: the joint rates the assembling cell's moves in free space
(:mod:`executor.assembly.transfer`) ask of the arm, against its joints' speed limits.

    ./run.sh bench rates --plan bp,p1:r1,p2:r2,p3:s1 [--assembly spare] [--seed S] [--json]

Runs the plan's steps (``PART`` or ``PART:HOLE``, in order) in one assembling cell, each
with step seed S, and reads the simulated arm's joint rates after every control step of
every move (:func:`executor.assembly.transfer.move_line`, :func:`~executor.assembly.transfer.reorient`
and :func:`~executor.assembly.transfer.move_joints`; the insertions are not counted), a
:class:`Recorder` told of them as the cell's motion's observer
(:class:`executor.control.motion.MoveObserver`). A
move's kind is how its tool tip went (its real tip, in the cell frame): ``slow`` the last
part of a descent (:data:`executor.assembly.transfer.DESCENT_SPEED`), else ``across``
where it went farther sideways than up or down, else ``down`` or ``up``; ``joint`` a move
in joint space. Prints per kind the moves, their simulated time [s] and the peak rate of
each joint [rad/s]; then the limits (:attr:`executor.world.arm.Arm.rate_limit`, the arm's
URDF) and each step's outcome, distance from its goal [mm] and simulated time [s]. Exit
code 1 when a joint went faster than its limit, or a step did not fit.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pybullet as pb

from bridge.cli_types import MAX_SEED, ArgumentParser, add_assembly_argument, comma_list, int_in
from executor.assembly.product import load_product
from executor.assembly.step import Assembler, StepRecord, check_product_step
from executor.campaign.run import stdout_to_stderr
from executor.cell_description import CellDescription
from executor.control.motion import MoveKind
from executor.world.arm import N_JOINTS, Arm
from executor.world.scene import TIME_STEP

KINDS = ("up", "across", "down", "slow", "joint")


@dataclass
class Rates:
    """The moves of one kind: how many, their simulated time [s], each joint's peak rate [rad/s]."""

    moves: int = 0
    seconds: float = 0.0
    peak: np.ndarray = field(default_factory=lambda: np.zeros(N_JOINTS))


class Recorder:
    """Reads the joint rates of every move an arm's motion makes (a
    :class:`executor.control.motion.MoveObserver`: set it as the motion's ``observer``), by kind."""

    def __init__(self, arm: Arm) -> None:
        self.arm = arm
        self.kinds = {kind: Rates() for kind in KINDS}
        self._kind: MoveKind = "line"
        self._start = np.zeros(3)  # [m] the real tip where the move began
        self._peak = np.zeros(N_JOINTS)  # [rad/s] each joint's peak rate in the move so far
        self._steps = 0

    def _rates(self) -> np.ndarray:
        """The joints' rates now [rad/s] (not :meth:`Arm.read`, whose wrench filter a read advances)."""
        return np.abs([s[1] for s in pb.getJointStates(self.arm.robot, self.arm.joints,
                                                       physicsClientId=self.arm.client)])

    def _tip(self) -> np.ndarray:
        """The real tool tip now [m, cell frame]."""
        return np.array(pb.getLinkState(self.arm.robot, self.arm.sensor, computeForwardKinematics=1,
                                        physicsClientId=self.arm.client)[4])

    def begin(self, kind: MoveKind) -> None:
        """A move of ``kind`` starts: its tip and its peaks from here."""
        self._kind, self._start, self._peak, self._steps = kind, self._tip(), np.zeros(N_JOINTS), 0

    def step(self) -> None:
        """After a control step of the move: the joints' rates now into its peaks."""
        self._peak = np.maximum(self._peak, self._rates())
        self._steps += 1

    def end(self) -> None:
        """Count the move under its kind: ``joint``, ``slow`` (a ``descent``), else by its tip's travel."""
        rates = self.kinds[self._bench_kind(self._tip() - self._start)]
        rates.moves += 1
        rates.seconds += self._steps * TIME_STEP
        rates.peak = np.maximum(rates.peak, self._peak)

    def _bench_kind(self, moved: np.ndarray) -> str:
        """The kind of the move just ended, its real tip having moved by ``moved`` [m]."""
        if self._kind == "joint":
            return "joint"
        if self._kind == "descent":
            return "slow"
        if np.linalg.norm(moved[:2]) > abs(moved[2]):
            return "across"
        return "down" if moved[2] < 0 else "up"


def _step(text: str) -> tuple[str, str | None]:
    """A plan step: ``"bp"`` → ``("bp", None)``, ``"p1:r1"`` → ``("p1", "r1")`` (ValueError otherwise)."""
    part, sep, hole = text.partition(":")
    if not part or (sep and not hole) or ":" in hole:
        raise ValueError(text)
    return part, hole or None


def measure(assembly: str, plan: list[tuple[str, str | None]], seed: int) -> tuple[Recorder, list[StepRecord]]:
    """The plan's steps run in one assembling cell of ``assembly``, their moves recorded
    (a step the product does not allow is refused before anything moves)."""
    description = CellDescription()
    product = load_product(assembly, description)
    for k, (part, hole) in enumerate(plan):
        check_product_step(product, part, hole, [p for p, _ in plan[:k]])
    assembler = Assembler(product, description=description)
    try:
        recorder = Recorder(assembler.world.arm)
        assembler.world.motion.observer = recorder
        records = [assembler.run_step(part, hole, seed) for part, hole in plan]
    finally:
        assembler.close()
    return recorder, records


def main(argv: list[str]) -> int:
    parser = ArgumentParser(prog="bench rates", description="The joint rates the assembling cell's moves in free "
                            "space ask of the arm, against its joints' speed limits (docs/cell.md).")
    add_assembly_argument(parser, "spare")
    parser.add_argument("--plan", required=True, type=comma_list(_step, "steps PART or PART:HOLE"),
                        metavar="PART[:HOLE],...",
                        help="the steps in order, e.g. bp,p1:r1,p2:r2,p3:s1")
    parser.add_argument("--seed", type=int_in(0, MAX_SEED), default=0, help="each step's seed (default 0)")
    parser.add_argument("--json", action="store_true", help="print JSON")
    args = parser.parse_args(argv)
    with stdout_to_stderr():
        recorder, records = measure(args.assembly, args.plan, args.seed)
    limit = recorder.arm.rate_limit
    over = any(np.any(rates.peak > limit) for rates in recorder.kinds.values())
    failed = any(r.outcome != "fit" for r in records)
    report: dict[str, Any] = {
        "assembly": args.assembly, "seed": args.seed, "limit_rad_s": np.round(limit, 3).tolist(),
        "moves": {kind: {"moves": r.moves, "sim_s": round(r.seconds, 3), "peak_rad_s": np.round(r.peak, 3).tolist(),
                         "peak_over_limit": round(float(np.max(r.peak / limit)), 3)}
                  for kind, r in recorder.kinds.items() if r.moves},
        "steps": [{"part": r.part, "hole": r.hole, "outcome": r.outcome, "pose_error_mm": round(1e3 * r.pose_error, 3),
                   "sim_time_s": round(r.sim_time_s, 3)} for r in records],
        "over_limit": over,
    }
    if args.json:
        print(json.dumps(report))
    else:
        print(f"limits [rad/s] A1-A7: {' '.join(f'{v:.3f}' for v in limit)}")
        for kind, r in report["moves"].items():
            print(f"{kind:<7} {r['moves']:>3} moves {r['sim_s']:7.2f} s  peak [rad/s] "
                  f"{' '.join(f'{v:.3f}' for v in r['peak_rad_s'])}  peak/limit {r['peak_over_limit']:.2f}")
        for r in report["steps"]:
            print(f"{r['part']}{':' + r['hole'] if r['hole'] else ''} {r['outcome']} {r['pose_error_mm']:.2f} mm "
                  f"{r['sim_time_s']:.2f} s simulated")
    return 1 if over or failed else 0
