"""Reading a product's parts in the assembled pose and checking them.

A source is a folder of ``*.stl``/``*.obj`` meshes (one part per file, the id is the file
name's stem, units given by the caller) or a STEP assembly (one part per leaf of its
assembly tree, the id from its name, the placement of the tree applied, units as the file
states them: the reader converts to mm). Every part becomes a :class:`trimesh.Trimesh` in
metres in the CAD frame, which is taken as the cell frame.

Checks (:func:`check_parts`), each an :class:`assembly_constraints.executor.ExecutorError` naming the part:
a mesh that is not closed (its boundary edges), parts whose sizes differ by a factor the
units explain (one part in mm among parts in m), a product too small or too large for its
stated units, and parts that overlap (intersection volume above :data:`OVERLAP_VOLUME`).
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import trimesh

from assembly_constraints.bridge.assembly import is_id
from assembly_constraints.executor import ExecutorError

UNITS = {"mm": 1e-3, "m": 1.0}
"""``--units``: metres per unit of a mesh file."""
MESH_SUFFIXES = (".stl", ".obj")
STEP_SUFFIXES = (".step", ".stp")
OVERLAP_VOLUME = 1e-9
"""Two parts overlap when their intersection is larger than this [m³] (1 mm³); touching
faces and fits with clearance have none."""
PRODUCT_EXTENT = (0.005, 5.0)
"""A product's largest extent must lie in this range [m] (a cell's products), else its
units are doubted."""
UNIT_RATIO = 300.0
"""A part larger than the median part by this factor (or smaller) is taken as a unit
mismatch (mm vs m is 1000)."""
STEP_DEFLECTION = 1e-6
"""Tessellation of STEP faces: largest distance of a triangle from its surface [m]."""


@dataclass(frozen=True)
class Cylinder:
    """A cylindrical face of a part's B-rep: a ``point`` (3,) [m] on its axis, the axis
    ``direction`` (3,) (unit) and the ``radius`` [m], in the cell frame."""

    point: np.ndarray
    direction: np.ndarray
    radius: float


@dataclass(frozen=True)
class CadPart:
    """One part in the assembled pose: ``id`` (an ASP constant), the ``name`` the source
    gives, its closed ``mesh`` [m] in the cell frame, ``source`` (file, or file#name), the
    ``cylinders`` of its B-rep and ``remesh``, its B-rep tessellated again to a given
    linear deflection [m] (a STEP part's; none for a mesh)."""

    id: str
    name: str
    mesh: trimesh.Trimesh
    source: str
    cylinders: tuple[Cylinder, ...] = ()
    remesh: Callable[[float], trimesh.Trimesh] | None = None


def part_id(name: str, source: str) -> str:
    """An ASP constant from a file stem or a STEP name (lower case, ``_`` for other
    characters); ExecutorError naming ``source`` when none can be made."""
    candidate = re.sub(r"[^a-z0-9_]", "_", name.strip().lower())
    if not is_id(candidate):
        raise ExecutorError(f"{source}: part name {name!r} gives no part id (expected a letter first, "
                            "then letters, digits or _)")
    return candidate


def load_meshes(folder: Path, units: str) -> list[CadPart]:
    """Every ``*.stl``/``*.obj`` of ``folder`` as a part, scaled by ``units`` to metres."""
    files = sorted(p for p in folder.iterdir() if p.suffix.lower() in MESH_SUFFIXES)
    if not files:
        raise ExecutorError(f"{folder}: no mesh files (expected *.stl or *.obj, one per part)")
    parts: list[CadPart] = []
    for path in files:
        try:
            mesh = trimesh.load(path, force="mesh")
        except (ValueError, OSError, IndexError) as exc:
            raise ExecutorError(f"{path}: not a readable mesh ({exc})") from None
        if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
            raise ExecutorError(f"{path}: no triangles (expected one closed mesh per part)")
        mesh.apply_scale(UNITS[units])
        parts.append(CadPart(part_id(path.stem, str(path)), path.stem, mesh, str(path)))
    return parts


def check_parts(parts: list[CadPart], units: str) -> None:
    """The checks of the module docstring, in that order; ExecutorError naming the part."""
    seen: dict[str, str] = {}
    for part in parts:
        if part.id in seen:
            raise ExecutorError(f"{part.source}: part id '{part.id}' also given by {seen[part.id]}")
        seen[part.id] = part.source
        if not part.mesh.is_watertight:
            _, uses = np.unique(part.mesh.edges_sorted, axis=0, return_counts=True)
            raise ExecutorError(f"{part.source}: part '{part.id}' is an open mesh ({int(np.sum(uses == 1))} boundary "
                                f"edges, {int(np.sum(uses > 2))} edges of more than two faces; expected a closed "
                                "manifold solid)")
        if part.mesh.volume <= 0:
            part.mesh.invert()
    extents = {p.id: float(np.max(p.mesh.extents)) for p in parts}
    median = float(np.median(list(extents.values())))
    for part in parts:
        ratio = extents[part.id] / median
        if ratio > UNIT_RATIO or ratio < 1 / UNIT_RATIO:
            raise ExecutorError(f"{part.source}: part '{part.id}' is {ratio:.3g} times the median part's size "
                                f"({1000 * extents[part.id]:.4g} vs {1000 * median:.4g} mm): a unit mismatch "
                                "(expected all parts in one unit)")
    lower, upper = np.min([p.mesh.bounds[0] for p in parts], axis=0), np.max([p.mesh.bounds[1] for p in parts],
                                                                                 axis=0)
    size = float(np.max(upper - lower))
    if not PRODUCT_EXTENT[0] <= size <= PRODUCT_EXTENT[1]:
        raise ExecutorError(f"the product is {size:.4g} m across with --units {units}: a unit mismatch "
                            f"(expected {PRODUCT_EXTENT[0]} to {PRODUCT_EXTENT[1]} m; try the other --units)")
    _check_overlaps(parts)


def _check_overlaps(parts: list[CadPart]) -> None:
    """ExecutorError naming the first pair whose intersection exceeds :data:`OVERLAP_VOLUME`
    (exact booleans by manifold3d on the pairs whose bounding boxes meet)."""
    for i, a in enumerate(parts):
        for b in parts[i + 1:]:
            low = np.maximum(a.mesh.bounds[0], b.mesh.bounds[0])
            high = np.minimum(a.mesh.bounds[1], b.mesh.bounds[1])
            if np.any(high - low <= 0):
                continue
            common = trimesh.boolean.intersection([a.mesh, b.mesh], engine="manifold")
            with np.errstate(divide="ignore", invalid="ignore"):  # an empty intersection has no centre
                volume = float(common.volume) if len(common.faces) else 0.0
            if volume > OVERLAP_VOLUME:
                raise ExecutorError(f"{b.source}: parts '{a.id}' and '{b.id}' overlap by "
                                    f"{volume * 1e9:.4g} mm³ in the assembled pose (expected solids "
                                    "that at most touch)")
