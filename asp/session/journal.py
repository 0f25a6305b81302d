"""``RUN/journal.jsonl``: every experiment started and finished, durable before it matters.

One JSON object a line, of two kinds:

- a finished experiment (:class:`JournalEntry`): ``id`` (the request id), ``part``,
  ``hole``, ``result`` (``fit``/``no_fit``), ``cell`` (who ran it), ``retest`` (true on a
  deliberate re-test of a pair already tried), ``evidence`` (the cell's measurements or
  null), ``wall_s`` (the cell's wall time [s]), ``time`` (Unix time [s] it was journaled)
  and ``experiment`` (its number in the order experiments were started: the Rerun
  timeline ``experiment``);
- an event (:class:`JournalEvent`, with an ``event`` key): ``started`` when the request
  ``id`` with number ``experiment`` for ``part``, ``hole`` is sent to ``cell`` (again on
  failover to another cell), ``abandoned`` when a resumed session finds an experiment
  started but never finished (the planner died meanwhile): its number is never used
  again, and the learner asks for the pair again, if still needed, under a new number.

Each line is appended with one ``write`` of the whole line, then fsynced, before the
request goes out or the result reaches the learner; so a session killed at any moment
can be resumed (``session --resume RUN``) by replaying the journal: no finished
experiment is run again and no experiment number is used twice. A failed append (full
disk) cuts the file back to its last whole line and raises a PlannerError. A torn last
line (a line without its newline: killed while writing) is ignored with a warning: its
result was never used.

A journal says one thing (checked when read and when appended, PlannerError naming
journal:line): one result per request id; one result per (part, hole) pair, unless a
later one is marked ``retest`` (a deliberate re-test, whose result may differ: noise);
experiment numbers from 1 to :data:`MAX_EXPERIMENT` (0 on a finished experiment: none).
:meth:`Journal.check_ids` refuses ids that are not a part or hole of the assembly.

Bound: a journal holds at most :data:`MAX_JOURNAL_BYTES`. A bigger one is refused when
read (``--resume``, ``bench``), and an append that would pass the bound is refused, so a
session never writes a journal it could not read back.
"""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Literal

import msgspec

from asp import PlannerError
from bridge.files import os_reason
from bridge.inputs import duplicate_key, read_bytes
from bridge.messages import MAX_COUNT, AspId, Evidence, RequestId, Result

JOURNAL_NAME = "journal.jsonl"

MAX_JOURNAL_BYTES = 64 * 1024 * 1024
"""The largest journal read or written [bytes] (64 MiB; a finished experiment and its
start take about 450 bytes, so over 100 000 experiments)."""


MAX_EXPERIMENT = MAX_COUNT
"""The largest experiment number a journal holds (far above what fits in its bound), the
largest a message carries."""

Experiment = Annotated[int, msgspec.Meta(ge=0, le=MAX_EXPERIMENT)]
Started = Annotated[int, msgspec.Meta(ge=1, le=MAX_EXPERIMENT)]


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
    experiment: Experiment = 0


class JournalEvent(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """Experiment ``experiment`` (request ``id``) ``started`` at ``cell``, or ``abandoned``."""

    event: Literal["started", "abandoned"]
    experiment: Started
    id: RequestId
    part: AspId
    hole: AspId
    cell: str = ""
    time: float = 0.0


Record = JournalEntry | JournalEvent


def _decode(line: bytes) -> Record:
    data = msgspec.json.decode(line)
    if isinstance(data, dict) and "event" in data:
        return msgspec.convert(data, JournalEvent)
    return msgspec.convert(data, JournalEntry)


class _Consistency:
    """What the lines of journal ``path`` said so far: the line of each request id's result
    and of each pair's first result; :meth:`check` refuses a line that contradicts them."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self._ids: dict[str, int] = {}
        self._pairs: dict[tuple[str, str], tuple[int, str]] = {}

    def check(self, record: Record, line: int) -> None:
        """PlannerError naming ``path:line`` for a second result of one request, or a
        second result of one pair without the retest marker."""
        if isinstance(record, JournalEvent):
            return
        if record.id in self._ids:
            raise PlannerError(f"{self.path}:{line}: a second result of request {record.id} (the first is on line "
                               f"{self._ids[record.id]}); expected one result per request")
        pair = (record.part, record.hole)
        earlier = self._pairs.get(pair)
        if earlier is not None and not record.retest:
            raise PlannerError(f"{self.path}:{line}: {record.part},{record.hole} {record.result} after "
                               f"{earlier[1]} on line {earlier[0]}, without the retest marker; expected one "
                               'result per pair unless a later one has "retest": true')

    def add(self, record: Record, line: int) -> None:
        """Remember a record on ``line`` (after :meth:`check`)."""
        if isinstance(record, JournalEntry):
            self._ids[record.id] = line
            self._pairs.setdefault((record.part, record.hole), (line, record.result))


@dataclass(frozen=True)
class _Contents:
    """A journal as read: its records with their line numbers, what they say
    (:class:`_Consistency`), the number of its torn last line (None: none), and its whole
    lines' count and length [bytes]."""

    records: list[tuple[int, Record]]
    consistency: _Consistency
    torn: int | None
    whole_lines: int
    whole_bytes: int


def _read(path: Path, limit: int = MAX_JOURNAL_BYTES) -> _Contents:
    """The contents of a journal (none when it does not exist); PlannerError naming
    path:line if it is unreadable or over ``limit``, or a line is not a record or
    contradicts an earlier one (:class:`_Consistency`)."""
    consistency = _Consistency(path)
    if not path.exists():
        return _Contents([], consistency, None, 0, 0)
    data = read_bytes(path, "session journal", limit=limit, error=PlannerError)
    lines = data.split(b"\n")
    torn = len(lines) if lines[-1] else None  # the last line has no newline: a torn write
    records: list[tuple[int, Record]] = []
    for number, line in enumerate(lines[:-1], start=1):
        if not line.strip():
            continue
        try:
            record = _decode(line)
            twice = duplicate_key(line)
        except (msgspec.DecodeError, msgspec.ValidationError) as exc:
            raise PlannerError(f"{path}:{number}: not a journal entry: {exc}") from None
        except RecursionError:
            raise PlannerError(f"{path}:{number}: not a journal entry: nested too deeply") from None
        if twice is not None:
            raise PlannerError(f"{path}:{number}: not a journal entry: the key {twice!r} appears twice")
        consistency.check(record, number)
        consistency.add(record, number)
        records.append((number, record))
    return _Contents(records, consistency, torn, len(lines) - 1, data.rfind(b"\n") + 1)


def _warn_torn(path: Path, torn: int | None) -> None:
    if torn is not None:
        print(f"warning: {path}:{torn}: ignoring a torn last line (the planner was killed while writing it)",
              file=sys.stderr)


def read_records(path: Path) -> list[Record]:
    """Every record of a journal (none if it does not exist), in order; PlannerError on a
    bad line. Only the last line may be torn (then it is dropped with a warning on
    stderr); a bad line elsewhere means the file was edited or corrupted and is
    reported with its line number."""
    contents = _read(path)
    _warn_torn(path, contents.torn)
    return [record for _line, record in contents.records]


def read_journal(path: Path) -> list[JournalEntry]:
    """The finished experiments of a journal, in order (see :func:`read_records`)."""
    return [r for r in read_records(path) if isinstance(r, JournalEntry)]


class Journal:
    """Appends records durably (one write, fsync) to ``RUN/journal.jsonl``, at most
    ``limit`` bytes in all.

    ``entries``: the finished experiments; ``events``: the started and abandoned ones.
    """

    def __init__(self, run: Path, limit: int = MAX_JOURNAL_BYTES) -> None:
        self.path = run / JOURNAL_NAME
        self.limit = limit
        contents = _read(self.path, limit)
        self._records, self._consistency, self._lines = contents.records, contents.consistency, contents.whole_lines
        self.entries = [r for _line, r in self._records if isinstance(r, JournalEntry)]
        self.events = [r for _line, r in self._records if isinstance(r, JournalEvent)]
        try:
            self._fd = os.open(self.path, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o666)
            if contents.torn is not None:
                _warn_torn(self.path, contents.torn)
                os.ftruncate(self._fd, contents.whole_bytes)
        except OSError as exc:
            raise PlannerError(f"{self.path}: cannot write ({os_reason(exc)})") from None

    def check_ids(self, parts: Sequence[str], holes: Sequence[str]) -> None:
        """PlannerError naming journal:line at the first record whose part or hole is not
        one of ``parts`` / ``holes`` (a journal of another assembly, or edited)."""
        for line, record in self._records:
            if record.part not in parts or record.hole not in holes:
                raise PlannerError(f"{self.path}:{line}: ({record.part},{record.hole}): expected a part of "
                                   f"{' '.join(parts)} and a hole of {' '.join(holes)}")

    @property
    def highest_started(self) -> int:
        """The highest experiment number ever started (finished, started or abandoned); 0: none."""
        numbers = [e.experiment for e in self.entries] + [e.experiment for e in self.events]
        return max(numbers, default=0)

    def in_flight(self) -> list[JournalEvent]:
        """Experiments started but neither finished nor abandoned (the last start of each)."""
        closed = {e.experiment for e in self.entries}
        closed |= {e.experiment for e in self.events if e.event == "abandoned"}
        last = {e.experiment: e for e in self.events if e.event == "started" and e.experiment not in closed}
        return [last[n] for n in sorted(last)]

    def _write(self, record: Record) -> None:
        """Append one line with one write and fsync it; on failure cut back to the last whole
        line. A record that contradicts the journal is refused (PlannerError) unwritten."""
        self._consistency.check(record, self._lines + 1)
        line = msgspec.json.encode(record) + b"\n"
        size = os.fstat(self._fd).st_size
        if size + len(line) > self.limit:
            raise PlannerError(f"{self.path}: full: a session journal holds at most {self.limit} bytes; "
                               "the session stops here (what it learned so far is journaled)")
        try:
            view = memoryview(line)
            while view:  # one write, unless the disk fills up in the middle (then the next one fails)
                view = view[os.write(self._fd, view):]
            os.fsync(self._fd)
        except OSError as exc:
            try:
                os.ftruncate(self._fd, size)
            except OSError:
                pass  # the torn line is dropped when the journal is read again
            raise PlannerError(f"{self.path}: cannot write ({os_reason(exc)})") from None
        self._lines += 1
        self._consistency.add(record, self._lines)

    def append(self, entry: JournalEntry) -> None:
        """Write one finished experiment and make it durable before returning."""
        if entry.time == 0.0:
            entry = msgspec.structs.replace(entry, time=time.time())
        self._write(entry)
        self.entries.append(entry)

    def started(self, experiment: int, request_id: str, part: str, hole: str, cell: str) -> None:
        """Record durably that experiment ``experiment`` goes to ``cell`` (before it is sent)."""
        event = JournalEvent("started", experiment, request_id, part, hole, cell, time.time())
        self._write(event)
        self.events.append(event)

    def abandon_in_flight(self) -> list[JournalEvent]:
        """Record every experiment in flight (see :meth:`in_flight`) as abandoned; returns them."""
        abandoned = []
        for start in self.in_flight():
            event = JournalEvent("abandoned", start.experiment, start.id, start.part, start.hole, start.cell,
                                 time.time())
            self._write(event)
            self.events.append(event)
            abandoned.append(event)
        return abandoned

    def close(self) -> None:
        if self._fd >= 0:
            os.close(self._fd)
            self._fd = -1
