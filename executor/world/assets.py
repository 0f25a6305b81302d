"""Generated assets that follow their sources.

``<assembly>/assets/`` (plate mesh, part URDFs, a mesh part's eroded convex pieces, a polygon
peg's prism pieces, the URDF of a
cover or head simulated from its mesh) is
generated from ``geometry.toml`` and ``assembly.toml`` by
:func:`executor.world.geometry.write_assets`. The folder records the
SHA-256 of the values it was made from (``assets/sources.sha256``: the ``[plate]`` table,
every hole (its entry height and depth where they are its own) and part as loaded, as
canonical JSON, a part's, cover's, head's or the base's ``mesh`` with the digest of its
file; comments and the keys the assets do not use leave it unchanged), written after the
assets, so an interrupted regeneration is regenerated again.
:func:`current_assets`, called before a cell loads any asset, regenerates the folder
when a generated file is missing or the digest differs: an edited hole is never simulated
with its old mesh. When the folder cannot be written (a read-only install), the error
names the file.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import logging
from pathlib import Path

import msgspec

from bridge import BridgeError
from bridge.files import write_atomic
from bridge.product import Plate
from executor import ExecutorError
from executor.world.geometry import (
    CellGeometry,
    HoleSpec,
    PartSpec,
    is_prism,
    peg_body,
    prism_names,
    product_bodies,
    write_assets,
)

STAMP = "sources.sha256"

logger = logging.getLogger(__name__)


def sources_digest(geometry: CellGeometry) -> str:
    """Hex SHA-256 of the canonical JSON of what the assets are generated from: the
    ``[plate]`` table, every hole and part (their dataclass fields; a hole's level where it
    is not the plate's, a part's ``mesh``, the base's and the ``mesh`` and ``mass`` of
    covers and heads only where there is one, so a product of primitives at one level keeps
    its digest). The values come from decimal text, and a mesh is named by its file's
    SHA-256 (the loader checked it), so the digest is the same on every machine and in
    every folder."""
    inputs: dict[str, object] = {"plate": msgspec.structs.asdict(geometry.plate),
                                 "holes": [_hole_fields(h, geometry.plate) for _, h in sorted(geometry.holes.items())],
                                 "parts": [_part_fields(p) for _, p in sorted(geometry.parts.items())]}
    base = geometry.tables.base
    if base is not None and base.mesh is not None:
        inputs["base_mesh"] = msgspec.structs.asdict(base.mesh)
    bodies = product_bodies(geometry)
    if bodies:
        inputs["meshes"] = {pid: {"mesh": msgspec.structs.asdict(body.mesh), "mass": body.mass}
                            for pid, body in bodies.items()}
    return hashlib.sha256(json.dumps(inputs, sort_keys=True, default=str).encode()).hexdigest()


def _hole_fields(hole: HoleSpec, plate: Plate) -> dict[str, object]:
    """A hole's fields, its entry height and depth only where they are not the plate's,
    ``pin`` only for a pin, ``axis`` only for a hole entered sideways, ``tile`` only for a
    boss of its own, ``owner`` only for a pin of another part than the base, ``widened``
    only where it names a part and ``inner`` only for a hole around islands (so a product
    whose holes are all at the plate's level keeps its digest);
    not ``near_miss``, which names pairs no cell tries and shapes no asset."""
    fields = {key: value for key, value in dataclasses.asdict(hole).items() if key != "near_miss"}
    for key, default in (("top_z", plate.top_z), ("depth", plate.tile_thickness), ("pin", False), ("axis", "-z"),
                         ("tile", None), ("owner", None), ("widened", ()), ("inner", ())):
        if fields[key] == default:
            del fields[key]
    return fields


def _part_fields(part: PartSpec) -> dict[str, object]:
    """A part's fields, ``bore`` only for a part with a bore, ``grasp_depth`` only where
    it is set and ``inner`` only where its section has rings cut out (so a peg held as deep
    as the gripper holds keeps its digest)."""
    fields = {key: value for key, value in dataclasses.asdict(part).items()
              if key != "mesh" and (key not in ("bore", "inner") or value)
              and (key != "grasp_depth" or value is not None)}
    return fields if part.mesh is None else fields | {"mesh": msgspec.structs.asdict(part.mesh)}


def _generated_names(geometry: CellGeometry) -> list[str]:
    shapes = {p.shape: p for p in geometry.parts.values()}
    bodies = [body for body in map(peg_body, shapes.values()) if body is not None]
    others = list(product_bodies(geometry).values())
    prisms = [name for s, p in shapes.items() if is_prism(p) for name in prism_names(s)]
    return ["plate.obj", *sorted(f"part_{s}.urdf" for s in shapes), *sorted(f"{b.stem}.urdf" for b in others),
            *sorted(body.convex_asset for body in bodies + others), *sorted(prisms)]


def regenerate_assets(geometry: CellGeometry) -> list[Path]:
    """Write the assets and then their :data:`STAMP`; returns the written paths."""
    written = write_assets(geometry)
    written.append(write_atomic(geometry.assets / STAMP, sources_digest(geometry) + "\n"))
    return written


def current_assets(geometry: CellGeometry) -> Path:
    """The assets folder, regenerated first if a generated file is missing or the sources
    changed since it was made. ExecutorError ``<file>: cannot write (<reason>)`` when
    stale assets cannot be replaced."""
    folder = geometry.assets
    stamp = folder / STAMP
    expected = sources_digest(geometry) + "\n"
    try:
        recorded: str | None = stamp.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        recorded = None
    if recorded == expected and all((folder / name).is_file() for name in _generated_names(geometry)):
        return folder
    if recorded is not None:  # a first generation (no stamp yet) is no news
        logger.warning("%s: stale (made from other values of geometry.toml or assembly.toml, or incomplete); "
                       "regenerating", folder)
    try:
        regenerate_assets(geometry)
    except BridgeError as exc:
        raise ExecutorError(f"{exc}; the generated assets there are missing or stale, not used") from None
    return folder
