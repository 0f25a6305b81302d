"""Cranfield's shaft after its pendulum, measured in the assembling cell.

    PYTHONPATH=$PWD .venv/bin/python examples/unlocated_pendulum.py [SEED ...]

For each seed (default 0; the seed of every step, as ``bench precedence-physics`` runs
them), twice in a fresh cell: the back plate, the pendulum head and the pendulum are
placed (the violating order of sh->pd), then the shaft is inserted into br, once with the
pendulum where the cell put it and once after moving it (with its screwed head) to its
goal and letting it settle. Prints the pendulum's offset from its goal along x (the axis
along which only the shaft locates it) and y [mm], the play the shaft would have along x
through the pendulum's opening and the hole in series if the pendulum stayed put (rigid,
[mm]; negative: it would not pass), and the shaft's outcome. docs/results.md ("A
product from its CAD") holds the figures.
"""

from __future__ import annotations

import sys

import numpy as np
import pybullet as pb

from executor.assembly.step import Assembler
from executor.assembly.step_backend import AssemblyRunner

SHAFT, HOLE, OPENING = 18.7, 20.0, 20.5
"""The shaft's diameter, the br hole's and the side of the pendulum's opening [mm]."""
SETTLE_STEPS = 240
"""Simulation steps the moved pendulum is left to settle."""


def series_play(offset_x: float) -> float:
    """The shaft's play along x [mm] through the opening shifted by ``offset_x`` [mm] over the hole."""
    low = max(-(HOLE - SHAFT) / 2, offset_x - (OPENING - SHAFT) / 2)
    high = min((HOLE - SHAFT) / 2, offset_x + (OPENING - SHAFT) / 2)
    return high - low


def _offset(assembler: Assembler) -> np.ndarray:
    """The pendulum's body origin minus its goal [mm]."""
    return 1000 * (assembler.world.position("pd") - assembler.world.goals["pd"])


def _to_goal(assembler: Assembler) -> None:
    """Move the pendulum and its head by the pendulum's offset, then let them settle."""
    world = assembler.world
    shift = world.goals["pd"] - world.position("pd")
    for part in ("pd", "ph"):
        position, quaternion = world.pose(part)
        world.set_pose(part, position + shift, tuple(quaternion))
    for _ in range(SETTLE_STEPS):
        pb.stepSimulation(physicsClientId=world.client)


def measure(seed: int, to_goal: bool) -> str:
    """One run; the line describing it."""
    runner = AssemblyRunner("cranfield")
    try:
        assembler = runner.assembler(f"pendulum-{seed}-{to_goal}")
        for part in ("bp", "ph", "pd"):
            record = assembler.run_step(part, None, seed)
            if record.outcome != "fit":
                return f"seed {seed}: {part} not placed ({record.outcome})"
        placed = _offset(assembler)
        if to_goal:
            _to_goal(assembler)
        before = _offset(assembler)
        shaft = assembler.run_step("sh", "br", seed)
    finally:
        runner.close()
    how = "moved to its goal" if to_goal else "as placed"
    return (f"seed {seed}, pendulum {how}: placed at x {placed[0]:+.2f} y {placed[1]:+.2f} mm from its goal, "
            f"before the shaft x {before[0]:+.2f} y {before[1]:+.2f} mm; rigid series play along x "
            f"{series_play(float(before[0])):+.2f} mm (the hole alone {HOLE - SHAFT:.2f}); shaft -> br: "
            f"{shaft.outcome}, {shaft.attempts} attempt(s), {shaft.max_force_dev:.1f} N, "
            f"pose error {1000 * shaft.pose_error:.2f} mm")


def main(argv: list[str]) -> None:
    for seed in [int(arg) for arg in argv] or [0]:
        for to_goal in (False, True):
            print(measure(seed, to_goal), flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
