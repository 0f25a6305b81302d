"""Tests of the Franka backend against franky-sim, and what they share."""

from __future__ import annotations

from pathlib import Path

GRASP_DEPTH = 0.012
"""[m] how deep the Franka Hand grasps a part: its pads reach 8.5 mm below its TCP, so at
12 mm they clear the plate."""


def franka_cell_description(folder: Path) -> Path:
    """A cell description of the Franka Hand on the flange (its mass [kg], inertia [kg m²],
    length [m]) and :data:`GRASP_DEPTH`, written in ``folder``."""
    path = folder / "franka-cell.toml"
    path.write_text("[gripper]\nflange_mass = 1.0\nflange_inertia = 0.004\nflange_length = 0.06\n"
                    f"grasp_depth = {GRASP_DEPTH}\n")
    return path
