"""``./run.sh bench executor [--quick] [--json]``: speed of the simulated cell
(``--ablation``: the ablation of the execution layers instead, see docs/results.md).

1. Trial wall time: ``--trials`` (default 3; ``--quick`` 1) trials of every campaign
   pair, fitting and non-fitting, one after the other in this process (one DIRECT
   cell). A trial is search, insertion, detection and the 2nd attempt where there is
   one; its wall time is the cell's ``duration_s``. Prints the median for the fitting
   pairs (target < 1.5 s) and over all pairs (target < 2.5 s), the median sim steps
   per second and real-time factor (target >= 3x).
2. The whole campaign (``executor campaign``, 40 trials per pair; ``--quick`` 4) on
   ``--jobs`` processes (default: the machine's cores): wall time (target < 15 min for 40 trials)
   and whether every outcome was correct.

Timings on a shared machine are noisy: medians are reported.
"""

from __future__ import annotations

import functools
import json
import statistics
from collections.abc import Sequence
from typing import Any

from bridge.cell_settings import add_cell_arguments, cell_settings_of
from bridge.cli_types import (
    MAX_SEED,
    ArgumentParser,
    add_assembly_argument,
    add_jobs_argument,
    int_in,
)
from executor.campaign.ablation import format_ablation, run_ablation
from executor.campaign.pairs import PAIRS_ARGUMENT, campaign_pairs, select_pairs
from executor.campaign.run import CellRunner, run_campaign, stdout_to_stderr, timed_campaign

TARGET_FITTING_TRIAL_S = 1.5
TARGET_ALL_TRIAL_S = 2.5
TARGET_REAL_TIME_FACTOR = 3.0
TARGET_CAMPAIGN_S = 15 * 60.0


def trial_timing(assembly: str, trials: int, seed: int) -> dict[str, Any]:
    """Medians over ``trials`` sequential trials of every campaign pair (one process)."""
    pairs = campaign_pairs()
    results = run_campaign(pairs, trials, seed, 1, functools.partial(CellRunner, assembly))
    fitting = [r for pair, rs in zip(pairs, results) if pair.fits for r in rs]
    every = [r for rs in results for r in rs]
    return {
        "trials": len(every),
        "fitting_trial_median_s": statistics.median(r["duration_s"] for r in fitting),
        "all_trial_median_s": statistics.median(r["duration_s"] for r in every),
        "sim_steps_per_s_median": statistics.median(r["sim_steps_per_s"] for r in every),
        "real_time_factor_median": statistics.median(r["real_time_factor"] for r in every),
    }


def campaign_timing(assembly: str, trials: int, seed: int, workers: int) -> dict[str, Any]:
    """Wall time [s] and correctness of a whole campaign on ``workers`` processes."""
    run = timed_campaign(
        campaign_pairs(), trials, seed, workers, functools.partial(CellRunner, assembly)
    )
    return {
        "campaign_trials_per_pair": trials,
        "campaign_jobs": workers,
        "campaign_wall_s": run.wall_s,
        "campaign_all_correct": all(s.correct == s.trials for s in run.stats),
        "campaign_false_fits": sum(s.false_fits for s in run.stats),
    }


def format_report(report: dict[str, Any]) -> str:
    """Text lines with the measured figures and their targets (docs/results.md)."""
    def verdict(ok: bool) -> str:
        return "ok" if ok else "MISSED"

    lines = [
        f"trial wall time, fitting pairs: median {report['fitting_trial_median_s']:.2f} s "
        f"(target < {TARGET_FITTING_TRIAL_S} s: "
        f"{verdict(report['fitting_trial_median_s'] < TARGET_FITTING_TRIAL_S)})",
        f"trial wall time, all pairs:     median {report['all_trial_median_s']:.2f} s "
        f"(target < {TARGET_ALL_TRIAL_S} s: "
        f"{verdict(report['all_trial_median_s'] < TARGET_ALL_TRIAL_S)}; {report['trials']} trials)",
        f"sim steps per second: median {report['sim_steps_per_s_median']:.0f}",
        f"real-time factor: median {report['real_time_factor_median']:.1f}x "
        f"(target >= {TARGET_REAL_TIME_FACTOR}x: "
        f"{verdict(report['real_time_factor_median'] >= TARGET_REAL_TIME_FACTOR)})",
    ]
    if "campaign_wall_s" in report:
        full = report["campaign_trials_per_pair"] == 40
        target = (
            f" (target < {TARGET_CAMPAIGN_S / 60:.0f} min: "
            f"{verdict(report['campaign_wall_s'] < TARGET_CAMPAIGN_S)})" if full else ""
        )
        lines.append(
            f"campaign, {report['campaign_trials_per_pair']} trials x {len(campaign_pairs())} pairs "
            f"on {report['campaign_jobs']} jobs: {report['campaign_wall_s']:.1f} s wall"
            f"{target}; all correct: {report['campaign_all_correct']}, "
            f"too-big parts reported fitting: {report['campaign_false_fits']}"
        )
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    parser = ArgumentParser(prog="bench executor", description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true",
                        help="1 timed trial per pair and a 4-trial campaign")
    parser.add_argument("--trials", type=int_in(1, 10**4), help="timed trials per pair (default 3)")
    parser.add_argument("--campaign-trials", type=int_in(0, 10**5),
                        help="campaign trials per pair (default 40; 0 skips the campaign)")
    add_jobs_argument(parser, "campaign (or ablation) worker processes")
    parser.add_argument("--seed", type=int_in(0, MAX_SEED), default=1000, help="base seed (default 1000)")
    add_assembly_argument(parser)
    parser.add_argument("--json", action="store_true", help="print JSON")
    parser.add_argument("--ablation", action="store_true",
                        help="instead: every execution-layer variant on the same perturbations "
                        "(--trials per pair, default 40)")
    parser.add_argument("--executions", type=int_in(1, 10**5), default=5,
                        help="--ablation: consecutive executions of a pair per cell (default 5)")
    parser.add_argument("--pairs", type=PAIRS_ARGUMENT,
                        help="--ablation: only these pairs, e.g. p1:r1,p3:r1 (default: all campaign pairs)")
    add_cell_arguments(parser, layer=False)
    args = parser.parse_args(argv)
    if args.pairs and not args.ablation:
        parser.error("--pairs: only with --ablation")
    if args.ablation:
        pairs = select_pairs(args.pairs)
        with stdout_to_stderr():
            ablation = run_ablation(args.assembly, args.trials or 40, args.seed, args.executions, args.jobs,
                                    cell_settings_of(args).magnitudes, pairs)
        print(json.dumps(ablation, indent=2) if args.json else format_ablation(ablation))
        return 0
    trials = args.trials or (1 if args.quick else 3)
    campaign_trials = (
        args.campaign_trials if args.campaign_trials is not None else 4 if args.quick else 40
    )
    with stdout_to_stderr():  # keep PyBullet's banner out of the report
        report = trial_timing(args.assembly, trials, args.seed)
        if campaign_trials > 0:
            report |= campaign_timing(args.assembly, campaign_trials, args.seed, args.jobs)
    print(json.dumps(report, indent=2) if args.json else format_report(report))
    return 0

