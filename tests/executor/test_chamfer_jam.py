"""A tilted tight peg wedged in the hole's entry chamfer is a jam the wiggle resolves.

`executor campaign --trials 40 --seed 0`: `tp` in `r1`, trial 12 of the pair (seed 132,
cell seed 0, full layer, the ILC correction the 12 executions before it had learned,
stored in ``data/ilc_tight_peg_r1_after_12.json``; `executor trial --part tp --hole r1
--trials 40 --seed 120` replays the pair).  Eq. (6) fires with the peg about 1.5 mm deep
in the chamfer (23.5 mm short of the goal); counted as "on the surface" (the old 3 mm
jam depth) no wiggle would run and the attempt would fail."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from executor.trial import Cell, trial_rng

STATE = Path(__file__).parent / "data" / "ilc_tight_peg_r1_after_12.json"


@pytest.mark.slow
def test_peg_wedged_in_the_chamfer_is_freed_by_the_wiggle(tmp_path):
    state = tmp_path / "ilc.json"
    shutil.copy(STATE, state)
    cell = Cell(ilc_state=state)  # full layer, cell seed 0: the campaign's cell
    try:
        setup = cell.draw_setup(trial_rng(132, "tp", "r1"), "tp", "r1")
        stuck = cell.run_attempt("tp", "r1", setup, wiggle_enabled=False)
        assert stuck.outcome == "no_fit" and stuck.max_force_dev >= cell.thresholds.f_stop
        assert stuck.jammed  # in the chamfer, past JAM_DEPTH: a jam, not a part on the surface
        assert stuck.phase_reached < 0.8
        freed = cell.run_attempt("tp", "r1", setup)
        assert freed.jammed and freed.wiggles == 1
        assert freed.outcome == "fit" and freed.end_error < cell.thresholds.goal_tolerance
        assert freed.ilc_iteration == 12  # the stored state was used
    finally:
        cell.close()
