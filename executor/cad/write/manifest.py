"""``.import-manifest.json`` (:data:`MANIFEST`): the files an import wrote with their SHA-256. A
later import into the folder replaces or removes only those of them that are still as
written (:func:`claim_folder`), and refuses a folder holding any other file it would write
(a product it did not write, a mesh at its name) unless told to replace it; nothing else in
the folder is ever removed."""

from __future__ import annotations

import hashlib
import json
import re
from collections.abc import Iterable
from pathlib import Path

from bridge.files import os_reason
from bridge.inputs import read_text, shorten
from executor import ExecutorError
from executor.cad.convex import MESH_FOLDER

MANIFEST = ".import-manifest.json"
"""The files the last import into a folder wrote: ``{"written_by": "./run.sh import",
"title": the product's name, "files": {path relative to the folder: SHA-256 of its content}}``."""
PRODUCT_FILES = ("assembly.toml", "sizes.lp", "nominal_sizes.lp", "geometric_precedence.lp", "geometry.toml",
                 "cell_order.lp")
"""The product's files an import writes (``geometry.toml`` only where the cell builds the product,
``cell_order.lp`` only where it does and its fingers' grip orders parts)."""
_MESH_NAME = re.compile(rf"{MESH_FOLDER}/[a-z][a-z0-9_]*(\.convex)?\.obj")
"""The name of a mesh file an import writes, relative to the folder (a part id is an ASP constant)."""


def file_digest(path: Path) -> str | None:
    """The SHA-256 of the file at ``path`` (hex), None when there is none."""
    try:
        return hashlib.sha256(path.read_bytes()).hexdigest()
    except FileNotFoundError:
        return None
    except OSError as exc:
        raise ExecutorError(f"{path}: cannot read ({os_reason(exc)})") from None


def _manifest(out: Path) -> dict[str, str]:
    """The files the last import into ``out`` wrote and their SHA-256 (none without a
    manifest); ExecutorError naming it when it is no import's manifest."""
    path = out / MANIFEST
    if not path.exists():
        return {}
    try:
        files = json.loads(read_text(path, "import manifest (JSON)", error=ExecutorError)).get("files")
    except (ValueError, AttributeError):  # not JSON, or not an object
        files = None
    if not isinstance(files, dict) or not all(isinstance(name, str) and (name in PRODUCT_FILES or _MESH_NAME.fullmatch(
            name)) and isinstance(digest, str) for name, digest in files.items()):
        raise ExecutorError(f"{path}: not an import manifest (expected JSON with \"files\": {{path: sha256}} of the "
                            "files import writes); --replace replaces it")
    return files


def claim_folder(out: Path, ids: Iterable[str], replace: bool) -> set[str]:
    """The files of the assembly folder ``out`` (paths relative to it) that an import of
    the parts ``ids`` may remove: those its manifest lists that are still as written,
    and with ``replace`` the product's files (:data:`PRODUCT_FILES`) whoever wrote them.
    ExecutorError naming the folder and the files when, without ``replace``, one it may
    write (the product's files, ``meshes/<id>.obj`` and ``meshes/<id>.convex.obj``)
    exists and was not written by the last import, or has changed since."""
    try:
        owned = _manifest(out)
    except ExecutorError:
        if not replace:
            raise
        owned = {}
    mine = {name for name, digest in owned.items() if file_digest(out / name) == digest}
    targets = [*PRODUCT_FILES, *(f"{MESH_FOLDER}/{pid}{suffix}" for pid in sorted(ids)
                                 for suffix in (".obj", ".convex.obj"))]
    foreign = [name for name in targets if name not in mine and (out / name).exists()]
    if foreign and not replace:
        what = "a product" if "assembly.toml" in foreign else "files"
        raise ExecutorError(f"{out}: holds {what} that import did not write or that changed since "
                            f"({shorten(', '.join(foreign), 200)}); expected a new folder or one import wrote "
                            "(--replace replaces them)")
    return mine | {name for name in foreign if name in PRODUCT_FILES}
