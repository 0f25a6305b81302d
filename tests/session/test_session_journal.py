"""The session journal: durable lines, started/abandoned events, a torn last line dropped with a
warning, a full disk leaving it whole, corruption reported."""

from __future__ import annotations

import sys
from pathlib import Path

import msgspec
import pytest

from asp import PlannerError
from asp.session.journal import Journal, JournalEntry, read_journal, read_records
from tests._files_helpers import run_with_file_limit


def entry(k: int, retest: bool | None = None) -> JournalEntry:
    """Experiment ``k`` of the pair p1,r1: a re-test from the second one on (unless told)."""
    return JournalEntry(id=f"run.p1.r1.{k}", part="p1", hole="r1", result="fit", cell="c1",
                        retest=k > 1 if retest is None else retest)


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
    resumed.append(entry(3, retest=True))
    resumed.close()
    again = read_journal(path)
    assert [e.id for e in again] == ["run.p1.r1.1", "run.p1.r1.2", "run.p1.r1.3"]
    assert all(e.time > 0 for e in again)


def test_a_corrupted_line_inside_is_reported_with_its_number(tmp_path: Path) -> None:
    path = tmp_path / "journal.jsonl"
    path.write_text('{"id":"a","part":"p1","hole":"r1","result":"fit","cell":"c1"}\n'
                    '{"id":"b","part":"p1","hole":"r1","result":"maybe","cell":"c1","retest":true}\n'
                    '{"id":"c","part":"p1","hole":"r1","result":"fit","cell":"c1","retest":true}\n')
    with pytest.raises(PlannerError, match="journal.jsonl:2"):
        read_journal(path)


def test_a_last_line_without_its_newline_is_dropped_with_a_warning(tmp_path: Path, capsys) -> None:
    journal = Journal(tmp_path)
    journal.append(entry(1))
    journal.close()
    path = tmp_path / "journal.jsonl"
    whole_but_unterminated = path.read_bytes().replace(b"r1.1", b"r1.2").rstrip(b"\n")
    with path.open("ab") as file:
        file.write(whole_but_unterminated)  # killed before the newline went out
    assert [e.id for e in read_journal(path)] == ["run.p1.r1.1"]
    assert capsys.readouterr().err == f"warning: {path}:2: ignoring a torn last line " \
                                      "(the planner was killed while writing it)\n"
    resumed = Journal(tmp_path)  # what is in memory is what is on disk
    assert [e.id for e in resumed.entries] == ["run.p1.r1.1"]
    resumed.close()
    assert [e.id for e in read_journal(path)] == ["run.p1.r1.1"]


def test_started_finished_abandoned(tmp_path: Path) -> None:
    journal = Journal(tmp_path)
    journal.started(1, "run.p1.r1.1", "p1", "r1", "c1")
    journal.started(2, "run.p1.r2.1", "p1", "r2", "c2")
    journal.append(msgspec.structs.replace(entry(1), experiment=1))
    journal.started(3, "run.p2.r1.1", "p2", "r1", "c1")
    journal.started(2, "run.p1.r2.1", "p1", "r2", "c1")  # c2 died: re-sent to c1
    journal.close()
    resumed = Journal(tmp_path)
    assert resumed.highest_started == 3
    assert [(e.experiment, e.cell) for e in resumed.in_flight()] == [(2, "c1"), (3, "c1")]
    assert [e.experiment for e in resumed.abandon_in_flight()] == [2, 3]
    assert resumed.in_flight() == [] and resumed.highest_started == 3
    resumed.close()
    records = read_records(tmp_path / "journal.jsonl")
    assert [getattr(r, "event", "finished") for r in records] == [
        "started", "started", "finished", "started", "started", "abandoned", "abandoned"]
    assert [e.id for e in read_journal(tmp_path / "journal.jsonl")] == ["run.p1.r1.1"]


def test_a_full_disk_keeps_the_journal_whole(tmp_path: Path) -> None:
    journal = Journal(tmp_path)
    journal.append(entry(1))
    journal.close()
    path = tmp_path / "journal.jsonl"
    before = path.read_bytes()
    program = ("import sys; from pathlib import Path; from asp import PlannerError\n"
               "from asp.session.journal import Journal, JournalEntry\n"
               "journal = Journal(Path(sys.argv[1]))\n"
               "try:\n"
               "    journal.append(JournalEntry(id='run.p1.r1.2', part='p1', hole='r1', result='fit',\n"
               "                                cell='c1' * 200, retest=True))\n"
               "except PlannerError as exc:\n    print(exc)\n")
    done = run_with_file_limit([sys.executable, "-c", program, str(tmp_path)], limit=len(before) + 100)
    assert done.returncode == 0, done.stderr
    assert done.stdout == f"{path}: cannot write (File too large)\n"
    assert path.read_bytes() == before  # cut back to its last whole line


def test_the_journal_is_bounded_when_written_and_when_read(tmp_path: Path) -> None:
    journal = Journal(tmp_path, limit=1000)
    with pytest.raises(PlannerError, match="full: a session journal holds at most 1000 bytes"):
        for k in range(1, 100):
            journal.append(entry(k))
    journal.close()
    path = tmp_path / "journal.jsonl"
    written = path.read_bytes()
    assert 0 < len(written) <= 1000 and written.endswith(b"\n")  # whole lines, under the bound
    assert len(read_journal(path)) == written.count(b"\n")
    with pytest.raises(PlannerError, match="larger than 500 bytes"):
        Journal(tmp_path, limit=500)


LINE = '{{"id":"{id}","part":"{part}","hole":"{hole}","result":"{result}","cell":"c1"{extra}}}\n'


@pytest.mark.parametrize(("lines", "expected"), [
    ([LINE.format(id="a", part="p1", hole="br", result="fit", extra=""),
      LINE.format(id="b", part="p1", hole="br", result="no_fit", extra="")],
     "journal.jsonl:2: p1,br no_fit after fit on line 1, without the retest marker"),
    ([LINE.format(id="a", part="p1", hole="br", result="fit", extra="")] * 2,
     "journal.jsonl:2: a second result of request a (the first is on line 1)"),
    ([LINE.format(id="a", part="p1", hole="br", result="fit", extra=',"experiment":-1')],
     "journal.jsonl:1: not a journal entry: Expected `int` >= 0"),
    (['{"event":"started","experiment":0,"id":"a","part":"p1","hole":"br"}\n'],
     "journal.jsonl:1: not a journal entry: Expected `int` >= 1"),
    ([LINE.format(id="a", part="p1", hole="br", result="fit", extra=',"experiment":99999999999999999999')],
     "journal.jsonl:1: not a journal entry"),
    (["[" * 100_000 + "]" * 100_000 + "\n"], "journal.jsonl:1: not a journal entry"),
    ([LINE.format(id="a", part="p1", hole="br", result="fit", extra=',"result":"no_fit"')],
     "journal.jsonl:1: not a journal entry: the key 'result' appears twice"),
])
def test_a_journal_that_contradicts_itself_is_refused_naming_the_line(tmp_path: Path, lines: list[str],
                                                                     expected: str) -> None:
    path = tmp_path / "journal.jsonl"
    path.write_text("".join(lines))
    before = path.read_bytes()
    for read in (read_journal, lambda p: Journal(p.parent)):
        with pytest.raises(PlannerError) as refused:
            read(path)
        assert expected in str(refused.value)
    assert path.read_bytes() == before


def test_a_retest_may_differ_and_a_contradiction_is_never_appended(tmp_path: Path) -> None:
    journal = Journal(tmp_path)
    journal.append(entry(1))
    journal.append(msgspec.structs.replace(entry(2), result="no_fit"))  # a re-test: noise, kept
    with pytest.raises(PlannerError, match="journal.jsonl:3: p1,r1 fit after fit on line 1, without the retest"):
        journal.append(entry(3, retest=False))
    with pytest.raises(PlannerError, match="journal.jsonl:3: a second result of request run.p1.r1.2"):
        journal.append(entry(2))
    journal.append(entry(3))
    journal.close()
    assert [(e.result, e.retest) for e in read_journal(tmp_path / "journal.jsonl")] == [
        ("fit", False), ("no_fit", True), ("fit", True)]


def test_a_journal_of_other_ids_is_refused_naming_the_line(tmp_path: Path) -> None:
    journal = Journal(tmp_path)
    journal.append(entry(1))
    journal.started(2, "run.zz.r1.1", "zz", "r1", "c1")
    journal.close()
    resumed = Journal(tmp_path)
    resumed.check_ids(["p1", "zz"], ["r1"])
    with pytest.raises(PlannerError, match=r"journal.jsonl:2: \(zz,r1\): expected a part of p1 p2"):
        resumed.check_ids(["p1", "p2"], ["r1"])
    resumed.close()


@pytest.mark.parametrize("second", [
    LINE.format(id="b", part="p1", hole="br", result="no_fit", extra=""),  # a contradiction
    LINE.format(id="b", part="zz", hole="br", result="fit", extra=""),  # not a part of the assembly
])
@pytest.mark.slow
def test_a_refused_resume_starts_no_cell_and_changes_nothing(tmp_path: Path, run_main, second: str) -> None:
    run = tmp_path / "run"
    run.mkdir()
    (run / "session.json").write_text('{"assembly": "cranfield", "policy": "best", "seed": 0, "recording_id": "r"}')
    (run / "journal.jsonl").write_text(LINE.format(id="a", part="p1", hole="br", result="fit", extra="") + second)
    before = {path.name: path.read_bytes() for path in run.iterdir()}
    done = run_main("session", "--resume", str(run), "--backend", "truth", timeout=60)
    assert done.returncode == 2 and f"{run / 'journal.jsonl'}:2: " in done.stderr
    assert {path.name: path.read_bytes() for path in run.iterdir() if path.name != ".lock"} == before
