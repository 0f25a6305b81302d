"""The generated products of the load benchmark, and a small load run of real sessions."""

from __future__ import annotations

from pathlib import Path

import pytest

from asp.bench.products import write_product
from asp.bench.session import load_runs
from asp.sizes.truth_oracle import TruthOracle
from executor.world.geometry import load_geometry, passes


def test_a_generated_product_is_a_biorder_its_cell_geometry_agrees_with(tmp_path: Path) -> None:
    ids = write_product(tmp_path / "p", 7, seed=3)
    truth = TruthOracle.from_assembly(str(tmp_path / "p"))  # validates the biorder
    geometry = load_geometry(str(tmp_path / "p"))
    assert sorted(truth.parts) == ids["parts"] and sorted(truth.holes) == ids["holes"]
    assert {(p, h) for p in truth.parts for h in truth.holes
            if passes(geometry.parts[p], geometry.holes[h])} == truth.fits
    for part in truth.parts:  # peg i fits hole i: a complete assignment exists
        assert any((part, hole) in truth.fits for hole in truth.holes)
    assert write_product(tmp_path / "q", 7, seed=3) == ids
    assert (tmp_path / "q" / "sizes.lp").read_text() == (tmp_path / "p" / "sizes.lp").read_text()


@pytest.mark.slow
def test_sessions_with_more_cells_on_a_product_run_nothing_twice() -> None:
    """One cell, then two (each a cell process; the pools of more cells are the bench's
    ``--cell-counts``, docs/results/session.md)."""
    figures = load_runs(6, [1, 2], "best", delay_s=0.05, seed=2)
    assert [run["cells"] for run in figures["runs"]] == [1, 2]
    assert all(run["duplicates"] == 0 for run in figures["runs"])
    assert figures["runs"][1]["experiments_ratio"] <= 1.5
