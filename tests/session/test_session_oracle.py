"""ZenohOracle behind the size learner's Oracle protocol (learn_sizes), one truth cell."""

from __future__ import annotations

from pathlib import Path

import pytest

from assembly_constraints.asp import PlannerError
from assembly_constraints.asp.session.cells import start_cell
from assembly_constraints.asp.session.journal import Journal, read_journal
from assembly_constraints.asp.session.zenoh_oracle import ZenohOracle
from assembly_constraints.asp.sizes.learner import learn_sizes
from assembly_constraints.asp.sizes.truth_oracle import TruthOracle
from assembly_constraints.bridge.cell_settings import ServeSettings
from assembly_constraints.bridge.client import CellDirectory, CellPool, PoolLimits
from assembly_constraints.bridge.session import free_loopback_endpoint, open_session


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
        oracle = ZenohOracle(pool, directory, journal, run_id="t", seed=1)
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
