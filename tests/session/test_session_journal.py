"""The session journal: durable lines, a torn last line dropped, corruption reported."""

from __future__ import annotations

from pathlib import Path

import pytest

from asp import PlannerError
from asp.session.journal import Journal, JournalEntry, read_journal


def entry(k: int, retest: bool = False) -> JournalEntry:
    return JournalEntry(id=f"run.p1.r1.{k}", part="p1", hole="r1", result="fit", cell="c1",
                        retest=retest)


def test_entries_survive_and_a_torn_last_line_is_dropped(tmp_path: Path) -> None:
    journal = Journal(tmp_path)
    journal.append(entry(1))
    journal.append(entry(2, retest=True))
    journal.close()
    path = tmp_path / "journal.jsonl"
    with path.open("ab") as file:
        file.write(b'{"id":"run.p1.r1.3","part":"p1","ho')  # killed while writing
    assert [e.id for e in read_journal(path)] == ["run.p1.r1.1", "run.p1.r1.2"]
    resumed = Journal(tmp_path)
    assert [e.retest for e in resumed.entries] == [False, True]
    resumed.append(entry(3))
    resumed.close()
    again = read_journal(path)
    assert [e.id for e in again] == ["run.p1.r1.1", "run.p1.r1.2", "run.p1.r1.3"]
    assert all(e.time > 0 for e in again)


def test_a_corrupted_line_inside_is_reported_with_its_number(tmp_path: Path) -> None:
    path = tmp_path / "journal.jsonl"
    path.write_text('{"id":"a","part":"p1","hole":"r1","result":"fit","cell":"c1"}\n'
                    '{"id":"b","part":"p1","hole":"r1","result":"maybe","cell":"c1"}\n'
                    '{"id":"c","part":"p1","hole":"r1","result":"fit","cell":"c1"}\n')
    with pytest.raises(PlannerError, match="journal.jsonl:2"):
        read_journal(path)
