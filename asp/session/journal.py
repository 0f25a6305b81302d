"""``RUN/journal.jsonl``: every finished experiment, durable before it is used.

One JSON object a line: ``id`` (the request id), ``part``, ``hole``, ``result``
(``fit``/``no_fit``), ``cell`` (who ran it), ``retest`` (true on a deliberate re-test of
a pair already tried), ``evidence`` (the cell's measurements or null), ``wall_s`` (the
cell's wall time [s]), ``time`` (Unix time [s] it was journaled) and ``experiment`` (its
number in the order experiments were started: the Rerun timeline ``experiment``). Each line is
flushed and fsynced before the result reaches the learner, so a session killed at any
moment can be resumed (``session --resume RUN``) by replaying the journal: no finished
experiment is run again. A torn last line (killed while writing) is ignored: its
result was never used.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

import msgspec

from asp import PlannerError
from bridge.messages import AspId, Evidence, RequestId, Result

JOURNAL_NAME = "journal.jsonl"


class JournalEntry(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """One finished experiment."""

    id: RequestId
    part: AspId
    hole: AspId
    result: Result
    cell: str
    retest: bool = False
    evidence: Evidence | None = None
    wall_s: float = 0.0
    time: float = 0.0
    experiment: int = 0


_DECODER = msgspec.json.Decoder(JournalEntry)


def read_journal(path: Path) -> list[JournalEntry]:
    """The entries of a journal (none if it does not exist); PlannerError on a bad line.

    Only the last line may be torn (then it is dropped); a bad line elsewhere means the
    file was edited or corrupted and is reported with its line number.
    """
    if not path.is_file():
        return []
    lines = path.read_bytes().split(b"\n")
    entries: list[JournalEntry] = []
    for number, line in enumerate(lines, start=1):
        if not line.strip():
            continue
        try:
            entries.append(_DECODER.decode(line))
        except msgspec.DecodeError as exc:
            if number == len(lines):  # no newline after it: a torn write
                break
            raise PlannerError(f"{path}:{number}: not a journal entry: {exc}") from None
    return entries


class Journal:
    """Appends entries durably (write, flush, fsync) to ``RUN/journal.jsonl``."""

    def __init__(self, run: Path) -> None:
        self.path = run / JOURNAL_NAME
        self.entries = read_journal(self.path)
        self._truncate_torn_tail()
        self._file = self.path.open("ab")

    def _truncate_torn_tail(self) -> None:
        if self.path.is_file():
            data = self.path.read_bytes()
            if data and not data.endswith(b"\n"):
                with self.path.open("r+b") as file:
                    file.truncate(data.rfind(b"\n") + 1)

    def append(self, entry: JournalEntry) -> None:
        """Write one entry and make it durable before returning."""
        if entry.time == 0.0:
            entry = msgspec.structs.replace(entry, time=time.time())
        self._file.write(msgspec.json.encode(entry) + b"\n")
        self._file.flush()
        os.fsync(self._file.fileno())
        self.entries.append(entry)

    def close(self) -> None:
        self._file.close()
