"""A tilted tight peg wedged in the hole's entry chamfer is a jam the wiggle resolves.

The campaign's one false negative (`executor campaign --trials 40 --seed 0`, before the
fix): `tp` in `r1`, trial 26 of the pair (seed 146, cell seed 0, full layer, the ILC
correction the 26 executions before it had learned, stored in
``data/ilc_tight_peg_r1_after_26.json``).  Eq. (6) fires with the peg about 1 mm deep in
the chamfer; when that was counted as "on the surface" no wiggle ran and both attempts
failed."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from assembly_constraints.executor.trial import Cell, trial_rng

STATE = Path(__file__).parent / "data" / "ilc_tight_peg_r1_after_26.json"


@pytest.mark.slow
def test_peg_wedged_in_the_chamfer_is_freed_by_the_wiggle(tmp_path):
    state = tmp_path / "ilc.json"
    shutil.copy(STATE, state)
    cell = Cell(ilc_state=state)  # full layer, cell seed 0: the campaign's cell
    try:
        setup = cell.draw_setup(trial_rng(146, "tp", "r1"), "tp", "r1")
        stuck = cell.run_attempt("tp", "r1", setup, wiggle_enabled=False)
        assert stuck.outcome == "no_fit" and stuck.max_force_dev >= cell.thresholds.f_stop
        assert stuck.jammed  # in the chamfer, past JAM_DEPTH: a jam, not a part on the surface
        assert stuck.phase_reached < 0.8
        freed = cell.run_attempt("tp", "r1", setup)
        assert freed.jammed and freed.wiggles == 1
        assert freed.outcome == "fit" and freed.end_error < cell.thresholds.goal_tolerance
        assert freed.ilc_iteration == 26  # the stored state was used
    finally:
        cell.close()
