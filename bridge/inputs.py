"""Reading input files under one set of rules, for the planner and the cell alike.

- a file is read whole but never more than ``limit`` bytes (default :data:`MAX_INPUT_BYTES`);
- a missing, unreadable (permissions, I/O error), non-regular or oversized file raises
  the caller's error class with one line naming the path and what was expected;
- :func:`duplicate_key` finds a key given twice in one JSON object (Python's ``json`` and
  msgspec both keep the last silently), so a reader can refuse it;
- :func:`shorten` cuts an echoed token to :data:`TOKEN_CHARS` characters, so a huge
  token never makes a huge message.
"""

from __future__ import annotations

import json
import os
import stat
from pathlib import Path

from bridge import BridgeError

MAX_INPUT_BYTES = 10 * 1024 * 1024
"""The largest input file read [bytes] (10 MiB): demonstrations, facts, assembly files."""

TOKEN_CHARS = 40
"""Echoed input tokens are cut to this many characters (with "…")."""


def shorten(text: object, width: int = TOKEN_CHARS) -> str:
    """``str(text)`` cut to ``width`` characters, the last being "…" when cut."""
    text = str(text)
    return text if len(text) <= width else text[: width - 1] + "…"


def duplicate_key(data: bytes | str) -> str | None:
    """A key that appears twice in one object of the JSON ``data``, else None. ``data``
    must be valid JSON (ValueError otherwise; RecursionError when nested too deeply):
    call it after the reader accepted the document."""
    twice: list[str] = []

    def pairs(items: list[tuple[str, object]]) -> dict[str, object]:
        keys = [key for key, _value in items]
        twice.extend(key for k, key in enumerate(keys) if key in keys[:k])
        return dict(items)

    json.loads(data, object_pairs_hook=pairs)
    return twice[0] if twice else None


def file_kind(mode: int) -> str:
    """What a file of ``st_mode`` ``mode`` is, in words: ``a FIFO``, ``a directory``..."""
    kinds = ((stat.S_ISREG, "a regular file"), (stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO"),
             (stat.S_ISSOCK, "a socket"), (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"))
    return next((name for test, name in kinds if test(mode)), "a special file")


def read_bytes(path: Path | str, what: str, *, limit: int = MAX_INPUT_BYTES,
               error: type[Exception] = BridgeError) -> bytes:
    """The bytes of the regular file ``path``, at most ``limit`` [bytes].

    ``what`` names the file in messages (e.g. ``"facts file"``); every problem raises
    ``error`` with one line: no such file, a directory or other non-regular file (a FIFO
    would block), unreadable (``strerror``), larger than ``limit``.
    """
    path = Path(path)
    try:
        mode = path.stat().st_mode
        if stat.S_ISDIR(mode):
            raise error(f"{path}: is a directory, expected a {what}")
        if not stat.S_ISREG(mode):
            raise error(f"{path}: not a regular file ({file_kind(mode)}), expected a {what}")
        with path.open("rb") as file:
            data = file.read(limit + 1)
    except FileNotFoundError:
        raise error(f"{path}: no such {what}") from None
    except OSError as exc:
        reason = exc.strerror or os.strerror(exc.errno or 0) or type(exc).__name__
        raise error(f"{path}: cannot read the {what}: {reason}") from None
    if len(data) > limit:
        raise error(f"{path}: larger than {limit} bytes; expected a {what} of at most {limit} bytes")
    return data


def read_text(path: Path | str, what: str, *, limit: int = MAX_INPUT_BYTES,
              error: type[Exception] = BridgeError) -> str:
    """:func:`read_bytes` decoded as UTF-8; binary data raises ``error`` naming file:line."""
    data = read_bytes(path, what, limit=limit, error=error)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        raise error(f"{path}:{line}: binary data (not UTF-8 text), expected a {what}") from None
