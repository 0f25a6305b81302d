"""Generated assets that follow their sources.

``<assembly>/assets/`` (plate mesh, part URDFs) is generated from ``geometry.toml`` and
``assembly.toml`` by :func:`assembly_constraints.executor.world.geometry.write_assets`. The folder records the
SHA-256 of the values it was made from (``assets/sources.sha256``: the ``[plate]`` table,
every hole and part as loaded, as canonical JSON; comments and the keys the assets do
not use leave it unchanged), written after the assets, so an interrupted regeneration is
regenerated again. :func:`current_assets`, called before a cell loads any asset,
regenerates the folder when a generated file is missing or the digest differs: an edited
hole is never simulated with its old mesh. When the folder cannot be written (a
read-only install), the error names the file.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import logging
from pathlib import Path

import msgspec

from assembly_constraints.bridge import BridgeError
from assembly_constraints.bridge.files import write_atomic
from assembly_constraints.executor import ExecutorError
from assembly_constraints.executor.world.geometry import CellGeometry, write_assets

STAMP = "sources.sha256"

logger = logging.getLogger(__name__)


def sources_digest(geometry: CellGeometry) -> str:
    """Hex SHA-256 of the canonical JSON of what the assets are generated from: the
    ``[plate]`` table and every hole and part (their dataclass fields). The values come
    from decimal text, so the digest is the same on every machine."""
    inputs = {"plate": msgspec.structs.asdict(geometry.plate),
              "holes": [dataclasses.asdict(h) for _, h in sorted(geometry.holes.items())],
              "parts": [dataclasses.asdict(p) for _, p in sorted(geometry.parts.items())]}
    return hashlib.sha256(json.dumps(inputs, sort_keys=True, default=str).encode()).hexdigest()


def _generated_names(geometry: CellGeometry) -> list[str]:
    return ["plate.obj", *sorted({f"part_{p.shape}.urdf" for p in geometry.parts.values()})]


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
