"""Measure the margins the detector thresholds are chosen from.

``./run.sh executor margins [--trials N] [--seed S] [--pairs P:H,...]`` runs every pair of the
cell with eqs. (6)/(7) switched off (F_stop = M_stop = ∞, so nothing is interrupted)
and prints, per pair and over the trials, the largest sustained wrench deviation
(the statistic eqs. 6 and 7 are tested on) and the end error ‖p_end − p_goal‖, under
the cell's uncertainty and execution layer (the same options as ``executor trial``).
Fitting pairs give the floor F_stop and M_stop must stay above; the end errors give the
goal tolerance.  Too-big parts are stopped only by the insertion time-out here.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

import msgspec

from assembly_constraints.bridge.cell_settings import add_cell_arguments, cell_settings_of
from assembly_constraints.bridge.cli_types import MAX_SEED, ArgumentParser, int_in
from assembly_constraints.executor.campaign.pairs import PAIRS_ARGUMENT
from assembly_constraints.executor.trial import Cell, cell_setup, trial_rng


def main(argv: Sequence[str] | None = None) -> int:
    parser = ArgumentParser(prog="executor margins", description=__doc__.split("\n\n")[0])
    parser.add_argument("--trials", type=int_in(1, 10**5), default=10, help="attempts per pair (default 10)")
    parser.add_argument("--seed", type=int_in(0, MAX_SEED), default=0, help="first seed")
    parser.add_argument("--pairs", type=PAIRS_ARGUMENT, help="comma-separated part:hole pairs (default: all)")
    add_cell_arguments(parser)
    args = parser.parse_args(argv)
    setup = cell_setup(cell_settings_of(args))
    described = setup.description
    unstopped = msgspec.structs.replace(described.thresholds, f_stop=math.inf, m_stop=math.inf)
    setup = dataclasses.replace(setup, description=msgspec.structs.replace(described, thresholds=unstopped))
    cell = Cell(setup=setup)
    pairs = args.pairs or [(p, h) for p in sorted(cell.geometry.parts) for h in sorted(cell.geometry.holes)]
    try:
        for part, hole in pairs:  # an unknown part or hole is an error before any trial runs
            cell.check_pair(part, hole)
        print(f"{'pair':8s} {'max dF [N]':>10s} {'max dM [Nm]':>11s} {'end error [mm] min..max':>24s}  found")
        for part, hole in pairs:
            evidence = [cell.run_attempt(part, hole, cell.draw_setup(trial_rng(args.seed + k, part, hole), part, hole))
                        for k in range(args.trials)]
            errors = [1000 * e.end_error for e in evidence]
            print(f"{part}:{hole:5s} {max(e.max_force_dev for e in evidence):10.2f} "
                  f"{max(e.max_torque_dev for e in evidence):11.3f} {min(errors):11.2f} .. {max(errors):8.2f}  "
                  f"{sum(e.hole_found for e in evidence)}/{len(evidence)}", flush=True)
    finally:
        cell.close()
    return 0

