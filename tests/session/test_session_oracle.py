"""ZenohOracle behind the size learner's Oracle protocol (learn_sizes), one truth cell; the
cells it counts for its batches are only those its pool may use."""

from __future__ import annotations

from pathlib import Path

import pytest

from asp import PlannerError
from asp.session.cells import start_cell
from asp.session.journal import Journal, read_journal
from asp.session.zenoh_oracle import ZenohOracle
from asp.sizes.learner import learn_sizes
from asp.sizes.truth_oracle import TruthOracle
from bridge.cell_settings import ServeSettings
from bridge.client import CellDirectory, CellPool, CellTimeout, PoolLimits
from bridge.keys import alive_key
from bridge.session import free_loopback_endpoint, open_session


@pytest.mark.timeout(60)
@pytest.mark.slow
def test_learn_sizes_through_the_zenoh_oracle(tmp_path: Path) -> None:
    truth = TruthOracle.from_assembly("cranfield")
    endpoint = free_loopback_endpoint()
    cell = start_cell(ServeSettings(cell_id="c1", backend="truth", listen=(endpoint,)))
    session = open_session(connect=(endpoint,))
    directory = CellDirectory(session)
    pool = CellPool(session, directory, PoolLimits(timeout=10.0, wait_for_cell=10.0))
    journal = Journal(tmp_path)
    try:
        directory.wait_for(1, timeout=20)
        oracle = ZenohOracle(pool, journal, run_id="t", seed=1)
        result = learn_sizes(truth.parts, truth.holes, oracle, policy="systematic")
        assert result.knowledge.fits == truth.fits
        oracle.submit("p1", "r1")
        with pytest.raises(PlannerError, match="still running"):
            oracle.ask("p2", "r1")
        assert oracle.next_result().result == "fit"
    finally:
        journal.close()
        pool.close()
        directory.close()
        session.close()
        cell.stop()
    entries = read_journal(tmp_path / "journal.jsonl")
    assert [(e.part, e.hole, e.result) for e in entries[:-1]] == [
        (e.part, e.hole, e.result) for e in result.experiments]
    assert entries[-1].id == "t.p1.r1.2" and entries[-1].retest


@pytest.mark.timeout(30)
def test_a_token_of_a_cell_the_pool_does_not_use_sizes_no_batch(tmp_path: Path) -> None:
    """A session using only c1 sees tokens of c1 and of a rogue ``evil``: it plans batches
    for one cell, and waiting for its cells does not count the rogue."""
    endpoint = free_loopback_endpoint()
    session = open_session(listen=(endpoint,))
    others = open_session(connect=(endpoint,))
    directory = CellDirectory(session)
    pool = CellPool(session, directory, allowed=["c1"])
    journal = Journal(tmp_path)
    try:
        tokens = [others.liveliness().declare_token(alive_key(cell)) for cell in ("evil", "c1")]
        assert directory.wait_for(2, timeout=20) == {"c1", "evil"}
        assert ZenohOracle(pool, journal, run_id="t").alive_cells() == 1
        assert pool.usable_alive() == {"c1"}
        with pytest.raises(CellTimeout, match="alive cell\\(s\\) of c1, c2 within"):
            directory.wait_for(2, timeout=0.2, among=["c1", "c2"])
        del tokens
    finally:
        journal.close()
        pool.close()
        directory.close()
        others.close()
        session.close()
