"""Parts stacked in one hole of the base along a horizontal axis (two bearings and a
spacer in a housing's bore, as in the corpus's ``cubefactory_cutting_unit``): one hole,
every part of the stack in it, and each empty hole beside it once."""

from __future__ import annotations

import numpy as np
import trimesh

from executor.cad.derive.base_holes import holes
from executor.cad.parts import CadPart


def _part(pid: str, mesh: trimesh.Trimesh) -> CadPart:
    return CadPart(pid, pid, mesh, f"{pid}.stl")


def _along_y(mesh: trimesh.Trimesh, y: float, x: float = 0.0, z: float = 0.02) -> trimesh.Trimesh:
    """``mesh`` (made along z) turned to lie along y, its middle at (x, y, z) [m]."""
    turned = mesh.copy()
    turned.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, (1, 0, 0)))
    turned.apply_translation((x, y, z))
    return turned


def _ring(outside: float, bore: float, length: float) -> trimesh.Trimesh:
    return trimesh.boolean.difference([trimesh.creation.cylinder(outside / 2, length, sections=64),
                                       trimesh.creation.cylinder(bore / 2, 2 * length, sections=64)],
                                      engine="manifold")


def test_a_stack_in_a_horizontal_bore_is_one_hole_holding_every_part_and_an_empty_hole_is_listed_once() -> None:
    # A 60 x 30 x 40 mm block, a d 20 bore along y through it at z 20 and a d 4 hole 20 mm
    # beside it; two rings 10 mm long on each side of a 5 mm spacer fill the bore's far
    # part. Each part is sliced at its own level: the holes met at every level are one.
    block = trimesh.creation.box((0.06, 0.03, 0.04))
    block.apply_translation((0.0, 0.015, 0.02))
    base = trimesh.boolean.difference([block, _along_y(trimesh.creation.cylinder(0.01, 0.05, sections=64), 0.015),
                                       _along_y(trimesh.creation.cylinder(0.002, 0.05, sections=32), 0.015, x=0.02)],
                                      engine="manifold")
    parts = {"ring_far": _along_y(_ring(0.02, 0.01, 0.01), 0.025),
             "spacer": _along_y(_ring(0.014, 0.01, 0.005), 0.0175),
             "ring_near": _along_y(_ring(0.02, 0.01, 0.01), 0.01)}
    found = holes(_part("block", base), [_part(pid, mesh) for pid, mesh in sorted(parts.items())],
                  dict.fromkeys(parts, "-y"), {})
    assert len(found) == 2, [(fit.position, list(fit.occupants)) for fit in found]
    bore = next(fit for fit in found if fit.occupants)
    assert list(bore.occupants) == ["ring_far", "spacer", "ring_near"]  # the deepest first, along -y
    assert bore.hole.kind == "round" and abs(bore.hole.a - 0.02) < 2e-4
