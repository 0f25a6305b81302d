"""Recordings with a torn tail: read up to the last whole message.

A ``.rrd`` file whose writer died (a full disk, a killed process) ends inside a message;
Rerun's reader then rejects the whole file. The file is a stream of frames: a 12-byte
stream header (``RRF2``, version, options), then messages of a 16-byte header (kind and
payload length, little-endian u64) and the payload; a finished file ends with an end
message (kind 0) and a footer ending in ``RRF2FOOT`` and 4 bytes. :func:`readable` scans
the headers only (no payload is read) and, when the last message is cut, hands the
reader a copy of the whole messages and logs a warning naming the file.
"""

from __future__ import annotations

import logging
import struct
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

STREAM_MAGIC = b"RRF2"
STREAM_HEADER_BYTES = 12
MESSAGE_HEADER = struct.Struct("<QQ")  # kind, payload length [bytes]
FOOTER_MAGIC = STREAM_MAGIC + b"FOOT"
FOOTER_TAIL_BYTES = len(FOOTER_MAGIC) + 4
COPY_BLOCK_BYTES = 1 << 20

logger = logging.getLogger(__name__)


def whole_length(path: Path) -> int | None:
    """The length [bytes] of the whole messages of ``path`` when its tail is torn; None
    when the file is finished, ends on a message boundary or is no Rerun stream at all
    (Rerun's reader then says what is wrong)."""
    with path.open("rb") as file:
        size = file.seek(0, 2)
        if size < STREAM_HEADER_BYTES:
            return None
        file.seek(size - FOOTER_TAIL_BYTES)
        if file.read(len(FOOTER_MAGIC)) == FOOTER_MAGIC:
            return None
        offset = 0
        while offset < size:
            file.seek(offset)
            head = file.read(MESSAGE_HEADER.size)
            if head[:4] == STREAM_MAGIC:  # a (further) stream header
                offset += STREAM_HEADER_BYTES
                continue
            if offset == 0:
                return None
            if len(head) < MESSAGE_HEADER.size:
                return offset
            kind, length = MESSAGE_HEADER.unpack(head)
            if offset + MESSAGE_HEADER.size + length > size:
                return offset  # cut inside this message (the end message too)
            if kind == 0:  # the whole end message: finished
                return None
            offset += MESSAGE_HEADER.size + length
    return None


@contextmanager
def readable(path: Path) -> Iterator[Path]:
    """``path``, or a temporary copy of its whole messages when its tail is torn (with a
    warning ``<path>: torn tail: ...``); the copy is removed on exit."""
    try:
        whole = whole_length(path)
    except OSError:
        whole = None  # the reader reports the file
    if whole is None:
        yield path
        return
    size = path.stat().st_size
    logger.warning("%s: torn tail: read up to its last whole message (%d of %d bytes; the writer stopped "
                   "mid-message)", path, whole, size)
    with tempfile.TemporaryDirectory(prefix="rrd-torn-") as folder:
        copy = Path(folder) / path.name
        with path.open("rb") as source, copy.open("wb") as target:
            left = whole
            while left > 0 and (block := source.read(min(left, COPY_BLOCK_BYTES))):
                target.write(block)
                left -= len(block)
        yield copy
