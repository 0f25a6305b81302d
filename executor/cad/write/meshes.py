"""The meshes an import writes (``meshes/``, :mod:`executor.cad.convex`): each part's frame
(:func:`part_frames`), the base as the cell collides with it (:func:`cell_base`: a STEP base
tessellated again to :data:`CELL_DEFLECTION`), the meshes of the parts that are no primitive
with the convex pieces of those that move (:func:`write_meshes`), and those pieces read back
(:func:`mesh_pieces`). Lengths in metres."""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

import numpy as np
import trimesh

from bridge.product import Mesh
from bridge.product.nominal import NOMINAL_FIT_ROOM
from executor.cad.convex import MESH_FOLDER, NEAR, fitted, peg_frame, peg_is_primitive, write_mesh
from executor.cad.covers import Mapped
from executor.cad.derive import Derived
from executor.cad.operations.frames import bore_frame, feature_turn, upright
from executor.cad.operations.pins import bore_pieces
from executor.cad.operations.plate import builds_plate
from executor.cad.operations.resolution import narrows_peg
from executor.cad.operations.rooms import margins
from executor.world.meshes import read_objects

CELL_DEFLECTION = 1e-5
"""The largest distance [m] of a STEP base's faces from the triangles the cell collides
with (its own mesh is measured at :data:`executor.cad.parts.STEP_DEFLECTION`)."""


def mesh_pieces(out: Path, written: Iterable[Path]) -> dict[str, list[np.ndarray]]:
    """Part -> the vertices [m] of each convex piece of its ``convex`` file among the files
    ``written`` into the assembly folder ``out`` (a part simulated from its mesh)."""
    return {path.name.removesuffix(".convex.obj"): read_objects(out / MESH_FOLDER / path.name)
            for path in written if path.name.endswith(".convex.obj")}


def cell_base(derived: Derived) -> tuple[trimesh.Trimesh, str]:
    """The base's mesh as the cell simulates it and a line saying how it was made: a STEP
    base tessellated again to :data:`CELL_DEFLECTION` (or a tenth of the least room of a
    peg that fits a hole, if that is less), else the mesh the import measured."""
    base = derived.parts[derived.base]
    rooms = [room for holes in margins(derived).values() for room in holes.values() if room > 0]
    deflection = min([CELL_DEFLECTION, *(room / 10 for room in rooms)])
    coarse = None if base.remesh is None else base.remesh(deflection)
    if coarse is None or not coarse.is_watertight:
        return base.mesh, "as measured"
    if coarse.volume < 0:
        coarse.invert()
    return coarse, (f"tessellated to {1e6 * deflection:.3g} um for the cell: a round hole's polygon has its corners on "
                    "the circle, its sides within that of it")


def manual_origin(mesh: trimesh.Trimesh) -> tuple[float, float, float]:
    """The frame origin of a part placed by hand: the centre of its bounding box's bottom face [m]."""
    (x0, y0, z0), (x1, y1, _) = mesh.bounds
    return (float(x0 + x1) / 2, float(y0 + y1) / 2, float(z0))


def part_frames(derived: Derived, mapped: Mapped) -> dict[str, np.ndarray]:
    """Each part's transform (4 × 4) from the cell frame to its part frame (the base's: its
    bounding box's centre at its plate's ``base_center``)."""
    frames = {pid: peg_frame(fit.section, upright(derived, fit)) @ feature_turn(fit)
              for pid, fit in derived.hole_of.items() if fit.section is not None}
    frames |= {pid: bore_frame(derived, pid) for pid in derived.bores}
    (x0, y0, _), (x1, y1, _) = derived.parts[derived.base].mesh.bounds
    origins = {pid: fit.origin for pid, fit in mapped.covers.items()} | {pid: fit.origin for pid, fit in
                                                                         mapped.heads.items()}
    origins |= {pid: manual_origin(derived.parts[pid].mesh) for pid in mapped.manual}
    origins[derived.base] = ((x0 + x1) / 2, (y0 + y1) / 2, 0.0)
    return frames | {pid: trimesh.transformations.translation_matrix(np.negative(origin))
                     for pid, origin in origins.items()}


def write_meshes(derived: Derived, mapped: Mapped, out: Path, written: list[Path]
                 ) -> tuple[dict[str, Mesh], dict[str, str]]:
    """The meshes of the parts of a mapped product that are no primitive, written into
    ``out`` (the base in the cell frame, the others in their part frames, the moving ones
    with their convex pieces; each file written is appended to ``written``); returns their
    ``mesh`` entries by part, and the moving parts that have no pieces that fit, each with
    why (:func:`executor.cad.convex.fitting_pieces`)."""
    meshes: dict[str, Mesh] = {}
    refused: dict[str, str] = {}
    if not builds_plate(derived):
        done = write_mesh(out, derived.base, *cell_base(derived), None, "the cell frame")
        assert not isinstance(done, str)  # the base has no pieces
        meshes[derived.base], files = done
        written += files
    frames = part_frames(derived, mapped)
    for pid in sorted(mapped.manual):  # static where it is placed: no pieces
        done = write_mesh(out, pid, derived.parts[pid].mesh.copy().apply_transform(frames[pid]), "as measured", None)
        assert not isinstance(done, str)
        meshes[pid], files = done
        written += files
    moving = [pid for pid, fit in derived.hole_of.items() if not peg_is_primitive(fit, upright(derived, fit))]
    moving += [pid for pid, cover in mapped.covers.items() if not cover.primitive]
    moving += [pid for pid, head in mapped.heads.items() if not head.primitive]
    moving += list(derived.bores)
    for pid in sorted(moving):
        mesh = derived.parts[pid].mesh
        near = {other: part.mesh.copy().apply_transform(frames[pid]) for other, part in derived.parts.items()
                if other != pid and np.all(np.minimum(mesh.bounds[1], part.mesh.bounds[1])
                                           - np.maximum(mesh.bounds[0], part.mesh.bounds[0]) > -NEAR)}
        done = write_mesh(out, pid, mesh.copy().apply_transform(frames[pid]), "as measured", near,
                          exact=bore_pieces(derived, pid) if pid in derived.bores else None,
                          fits=frozenset(fitted(derived, pid)), prisms=pid in derived.hole_of,
                          narrow=NOMINAL_FIT_ROOM if narrows_peg(derived, pid) else 0.0)
        if isinstance(done, str):
            written.append(out / MESH_FOLDER / f"{pid}.obj")  # written before its pieces were sought
            refused[pid] = done
            continue
        meshes[pid], files = done
        written += files
    return meshes, refused
