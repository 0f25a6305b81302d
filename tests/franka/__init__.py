"""Tests of the Franka backend against franky-sim, and what they share."""

from __future__ import annotations

import math
import re
import shutil
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

from executor.control.gains import ImpedanceGains

if TYPE_CHECKING:  # franky and mujoco are optional: the tests that need them skip without them
    from executor.cell_description import CellDescription
    from executor.franka.cell import FrankaCell
    from executor.franka.sim_server import SimRobot
    from executor.world.geometry import CellGeometry

SIM_DYNAMICS = "1.0"
"""franky's relative dynamics factor of the tests' carrying moves against franky-sim (the
``dynamics`` backend option): the arm's full limits, which franky plans within; the default
for an arm, 0.2, is not a test's (docs/franka.md, Safety). A simulated arm has no one to
hurt, and the moves are most of these tests' time: 1.0 in place of 0.5 took a teaching's 32
moves from 22.9 s to 16.3 s of robot time."""

GRASP_DEPTH = 0.012
"""[m] how deep the Franka Hand grasps a part: its pads reach 8.5 mm below its TCP, so at
12 mm they clear the plate."""


def franka_cell_description(folder: Path, search_radius: float | None = None, stiffness: float | None = None) -> Path:
    """A cell description of the Franka Hand on the flange (its mass [kg], inertia [kg m²],
    length [m]) and :data:`GRASP_DEPTH`, with the hole search's ``search_radius`` [m] and
    the impedance's translational ``stiffness`` [N/m] if given (the defaults otherwise;
    the damping then scaled with its square root: the same damping ratio), written in
    ``folder``."""
    path = folder / "franka-cell.toml"
    search = "" if search_radius is None else f"[search]\nmax_radius = {search_radius}\n"
    gains = ""
    if stiffness is not None:
        default = ImpedanceGains()
        damping = default.d_trans * math.sqrt(stiffness / default.k_trans)
        gains = f"[gains]\nk_trans = {stiffness}\nd_trans = {damping:.1f}\n"
    path.write_text("[gripper]\nflange_mass = 1.0\nflange_inertia = 0.004\nflange_length = 0.06\n"
                    f"grasp_depth = {GRASP_DEPTH}\n{search}{gains}")
    return path


def parts_moved(folder: Path, to: Path, dx: float, parts: set[str] | None = None) -> Path:
    """A copy of the product ``folder`` at ``to`` whose ``parts`` (default all) wait ``dx``
    [m] along x from their ``start``: the world the simulator builds, while the cell
    believes ``folder``."""
    moved = Path(shutil.copytree(folder, to))
    toml = moved / "assembly.toml"

    def shift(match: re.Match[str]) -> str:
        return f"{match[1]}{float(match[3]) + dx:.4f}" if parts is None or match[2] in parts else match[0]

    text, count = re.subn(r"(^\[parts\.([\w-]+)\]\n(?:[^\[\n].*\n)*?start = \[)([-0-9.]+)", shift,
                          toml.read_text(encoding="utf-8"), flags=re.M)
    assert count > 0, text
    toml.write_text(text, encoding="utf-8")
    return moved


@contextmanager
def franka_on_sim(folder: Path, geometry: CellGeometry, description: CellDescription
                  ) -> Iterator[tuple[FrankaCell, SimRobot]]:
    """A Franka cell of ``geometry`` and ``description`` (the full ILC layer, not in real
    time, :data:`SIM_DYNAMICS`) on franky-sim building the product ``folder``, and the
    simulator; the cell stopped and the simulator ended after the block."""
    from executor.control.ilc import layer_named
    from executor.franka.cell import FrankaCell, FrankaOptions
    from executor.franka.safety import Limits
    from executor.franka.sim_server import sim_robot

    with sim_robot(folder) as sim:
        cell = FrankaCell(geometry, description, layer_named("full"),
                          FrankaOptions(host=sim.host, realtime=False, limits=Limits(dynamics=float(SIM_DYNAMICS))))
        try:
            yield cell, sim
        finally:
            cell.stop()
