"""Tests of the simulated cell (executor)."""

from __future__ import annotations

from pathlib import Path

import pybullet as p
import trimesh

from executor.world.meshes import eroded_text


def load_piece(folder: Path, piece: trimesh.Trimesh, name: str, mass: float) -> int:
    """The body of ``piece`` as the cell writes a mesh part's collision asset (its convex
    piece eroded by the hull margin, in ``folder``) and loads it: a fixed URDF link of
    ``mass`` [kg], in the connected PyBullet client."""
    (folder / "piece.obj").write_text(eroded_text([piece], name, f"{name}.convex.obj"))
    (folder / f"{name}.urdf").write_text(
        f'<?xml version="1.0"?><robot name="{name}"><link name="part"><inertial><mass value="{mass:g}"/>'
        '<inertia ixx="1e-5" ixy="0" ixz="0" iyy="1e-5" iyz="0" izz="1e-5"/></inertial><collision><geometry>'
        f'<mesh filename="{folder / "piece.obj"}"/></geometry></collision></link></robot>')
    return p.loadURDF(str(folder / f"{name}.urdf"), useFixedBase=True)
