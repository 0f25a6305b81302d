"""Cells on other hosts: a planner and two cells in network namespaces of their own, joined
only through ``./run.sh router`` (:mod:`asp.session.hosts` makes the namespaces and links
and removes them after the test, also when it fails; skipped where namespaces cannot be
made). One cell's link is cut mid-session: the session drops it and finishes with the
other, the relation exact, no experiment lost or run twice."""

from __future__ import annotations

import json
import subprocess
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from asp.session.cells import LineProcess
from asp.session.hosts import CLIENT_CONFIG, Hosts, unavailable
from asp.session.journal import read_journal
from asp.sizes.truth_oracle import TruthOracle
from tests.conftest import TRUTH_SESSION

pytestmark = [pytest.mark.timeout(150), pytest.mark.slow]  # real namespaces and processes, 15-40 s
TRUTH = TruthOracle.from_assembly("cranfield")


@pytest.fixture
def hosts() -> Iterator[Hosts]:
    why_not = unavailable()
    if why_not is not None:
        pytest.skip(why_not)
    with Hosts(2) as made:
        yield made


@pytest.fixture
def client(tmp_path: Path) -> Path:
    path = tmp_path / "client.json5"
    path.write_text(CLIENT_CONFIG, encoding="utf-8")
    return path


@pytest.fixture
def fleet(hosts: Hosts, client: Path) -> Iterator[list[LineProcess]]:
    """The router and cells c1, c2 (truth, 0.1 s per experiment), each in its namespace."""
    started = hosts.start_fleet(client, delay_s=0.1)
    yield started
    for process in started:
        process.kill()


def test_a_cell_whose_link_is_cut_is_dropped_and_the_session_finishes(
        tmp_path: Path, hosts: Hosts, fleet: list[LineProcess], client: Path, root: Path, cli_argv, cli_env) -> None:
    run = tmp_path / "run"
    argv = cli_argv(*TRUTH_SESSION, "--cells", "0", "--zenoh-config", str(client),
                    "--connect", hosts.router_endpoints()[0],
                    "--allow-cells", "c1,c2", "--timeout", "2", "--out", str(run), "--policy", "best")
    planner = subprocess.Popen(hosts.argv(hosts.router, argv), cwd=root, env=cli_env,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 60
        journal = run / "journal.jsonl"
        while not (journal.is_file() and {e.cell for e in read_journal(journal)} == {"c1", "c2"}):
            assert planner.poll() is None and time.monotonic() < deadline, "no experiment on both cells"
            time.sleep(0.05)
        hosts.cut(1)
        cut = time.time()
        out, err = planner.communicate(timeout=120)
    finally:
        planner.kill()
    assert planner.returncode == 0, err
    result = json.loads(out)
    assert result["matches_truth"] is True
    entries = read_journal(journal)
    assert len(entries) == result["experiments"]
    assert len({e.id for e in entries}) == len(entries)  # nothing doubled...
    assert len({(e.part, e.hole) for e in entries}) == len(entries)
    assert all(e.result == TRUTH.ask(e.part, e.hole) for e in entries)
    assert {tuple(pair) for pair in result["fits"]} == TRUTH.fits  # ...nor lost
    late = [e for e in entries if e.time > cut + 1.0]
    assert late and {e.cell for e in late} == {"c2"}
    assert "c1" in err  # the pool names what happened to it (missed replies, dropped)
