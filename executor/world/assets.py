"""Generated assets that follow their sources.

``<assembly>/assets/`` (plate mesh, part URDFs) is generated from ``geometry.toml`` and
``assembly.toml`` by :func:`executor.world.geometry.write_assets`. The folder records the
SHA-256 of those two files it was made from (``assets/sources.sha256``, written after the
assets, so an interrupted regeneration is regenerated again). :func:`current_assets`,
called before a cell loads any asset, regenerates the folder when a generated file is
missing or the digest differs: an edited hole is never simulated with its old mesh. When
the folder cannot be written (a read-only install), the error names the file.
"""

from __future__ import annotations

import hashlib
import logging
from pathlib import Path

from bridge import BridgeError
from bridge.files import write_atomic
from executor import ExecutorError
from executor.world.geometry import CellGeometry, write_assets

STAMP = "sources.sha256"
SOURCES = ("assembly.toml", "geometry.toml")

logger = logging.getLogger(__name__)


def sources_digest(geometry: CellGeometry) -> str:
    """Hex SHA-256 over the names and bytes of the assembly folder's :data:`SOURCES`."""
    digest = hashlib.sha256()
    for name in SOURCES:
        data = (geometry.folder / name).read_bytes()
        digest.update(f"{name}\0{len(data)}\0".encode())
        digest.update(data)
    return digest.hexdigest()


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
        logger.warning("%s: stale (made from another %s or incomplete); regenerating", folder, " or ".join(SOURCES))
    try:
        regenerate_assets(geometry)
    except BridgeError as exc:
        raise ExecutorError(f"{exc}; the generated assets there are missing or stale, not used") from None
    return folder
