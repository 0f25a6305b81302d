"""The campaign's bookkeeping with an injected (fake) trial runner: pairs, seeds,
Fig. 18 counts, worker processes; and the figure writers on synthetic data."""

from __future__ import annotations

import functools
import multiprocessing
from pathlib import Path
from typing import Any

import pytest

from executor import ExecutorError
from executor.campaign.pairs import FIG18_FITTING_PAIRS, campaign_pairs, pair_stats, select_pairs
from executor.campaign.run import CampaignRun, campaign_report, format_table, run_campaign


def fake_runner(flaky_every: int, barrier: Any = None) -> Any:
    """A runner that fits exactly the truly fitting pairs; every ``flaky_every``-th
    seed needs the 2nd attempt. Records the seed and the worker's pid. With a
    ``barrier``, workers start only once all are up, so each of them gets trials."""
    import os
    import time

    if barrier is not None:
        barrier.wait(timeout=60)
    fitting = set(FIG18_FITTING_PAIRS)

    def run(part: str, hole: str, seed: int) -> dict[str, Any]:
        fits = (part, hole) in fitting
        time.sleep(0.01)
        return {
            "outcome": "fit" if fits else "no_fit",
            "attempts": 2 if (not fits or seed % flaky_every == 0) else 1,
            "duration_s": 0.001 * (seed % 7 + 1),
            "seed": seed,
            "pid": os.getpid(),
        }

    return run


def test_pairs_are_fig18_rows_then_every_non_fitting_pair() -> None:
    pairs = campaign_pairs()
    assert [(p.part, p.hole) for p in pairs if p.fits] == list(FIG18_FITTING_PAIRS)
    assert len(FIG18_FITTING_PAIRS) == 9
    assert {(p.part, p.hole) for p in pairs if not p.fits} == {("p3", "r1"), ("sh", "r1"), ("sh", "s1")}
    assert [(p.part, p.hole) for p in select_pairs("p1:r1,sh:s1")] == [("p1", "r1"), ("sh", "s1")]
    with pytest.raises(ExecutorError, match="p9:r1"):
        select_pairs("p9:r1")


@pytest.mark.slow
def test_counts_seeds_and_two_workers_match_one() -> None:
    pairs = campaign_pairs()
    serial = run_campaign(pairs, trials=4, seed=100, workers=1,
                          factory=functools.partial(fake_runner, 4))
    barrier = multiprocessing.get_context("spawn").Barrier(2)
    parallel = run_campaign(pairs, trials=4, seed=100, workers=2,
                            factory=functools.partial(fake_runner, 4, barrier))
    def strip(rows: list[list[dict[str, Any]]]) -> list[list[dict[str, Any]]]:
        return [[{k: v for k, v in r.items() if k != "pid"} for r in row] for row in rows]

    assert strip(serial) == strip(parallel)
    assert len({r["pid"] for row in parallel for r in row}) == 2, "both workers did trials"
    seeds = [r["seed"] for row in serial for r in row]
    assert len(set(seeds)) == len(seeds) == 12 * 4
    assert [r["seed"] for r in serial[1]] == list(range(104, 108))

    stats = [pair_stats(p, rs) for p, rs in zip(pairs, serial)]
    p1_r1 = stats[0]
    assert (p1_r1.trials, p1_r1.first_trial, p1_r1.after_second, p1_r1.correct) == (4, 3, 4, 4)
    sh_s1 = next(s for s in stats if (s.part, s.hole) == ("sh", "s1"))
    assert (sh_s1.correct, sh_s1.false_fits, sh_s1.first_trial) == (4, 0, 0)
    report = campaign_report(CampaignRun(pairs, serial, stats, 1.0), 100, 2)
    assert report["all_correct"] and report["false_fits"] == 0
    assert report["trials_per_pair"] == 4 and report["trial_wall_median_s"] == 0.004
    table = format_table(stats)
    assert "tight round peg tp" in table and "H4 square s1" in table
    assert len(table.splitlines()) == 2 + 12


def test_a_too_big_part_reported_fitting_is_counted() -> None:
    pair = next(p for p in campaign_pairs() if (p.part, p.hole) == ("sh", "r1"))
    results = [{"outcome": "fit", "attempts": 1, "duration_s": 1.0},
               {"outcome": "no_fit", "attempts": 2, "duration_s": 2.0}]
    stats = pair_stats(pair, results)
    assert (stats.correct, stats.false_fits) == (1, 1)
    assert not campaign_report(CampaignRun([pair], [results], [stats], 1.0), 0, 1)["all_correct"]


def _trace(part: str, outcome: str, stop_at: float) -> Any:
    from executor.rerun_log import AttemptTrace

    trace = AttemptTrace(part, "r1", 0, 1, 1, outcome)
    import numpy as np

    for phase in np.linspace(0.0, stop_at, 50):
        trace.sim_time.append(float(phase))
        trace.phase.append(float(phase))
        trace.force_mes.append(np.array([0.0, 0.0, -5.0 * phase]))
        trace.force_des.append(np.array([0.0, 0.0, -4.0 * phase]))
        trace.torque_mes.append(np.array([0.01 * phase, 0.0, 0.0]))
        trace.torque_des.append(np.zeros(3))
    return trace


@pytest.mark.slow
def test_figures_are_written(tmp_path: Path) -> None:
    # Imported here: worker processes of the test above import this module.
    from executor.campaign.plots import plot_fig17, plot_fig18

    pairs = campaign_pairs()[:3]
    stats = [pair_stats(p, [{"outcome": "fit", "attempts": 1, "duration_s": 1.0}]) for p in pairs]
    table = plot_fig18(stats, tmp_path / "fig18.png")
    forces = plot_fig17(_trace("p1", "fit", 1.0), _trace("p3", "no_fit", 0.4), tmp_path / "fig17.png")
    for image in (table, forces):
        assert image.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        assert image.stat().st_size > 10_000


def dying_runner() -> Any:
    """A runner whose worker process dies at its first trial."""
    import os

    def run(part: str, hole: str, seed: int) -> dict[str, Any]:
        os._exit(3)

    return run


@pytest.mark.slow
def test_a_dead_worker_is_an_error_not_a_hang() -> None:
    with pytest.raises(ExecutorError, match="worker process died"):
        run_campaign(campaign_pairs()[:2], trials=1, seed=0, workers=2, factory=dying_runner)


def failing_runner() -> Any:
    """A runner whose trials raise an ExecutorError (e.g. a missing demonstration)."""

    def run(part: str, hole: str, seed: int) -> dict[str, Any]:
        raise ExecutorError(f"part '{part}' has no demonstration")

    return run


@pytest.mark.slow
def test_a_failing_trial_stops_the_campaign() -> None:
    with pytest.raises(ExecutorError, match="no demonstration"):
        run_campaign(campaign_pairs(), trials=40, seed=0, workers=2, factory=failing_runner)
