"""``--jobs N``: the commands that run work in parallel give the same results for any N
(each command in the test's process; its jobs are processes of their own)."""

from __future__ import annotations

import json
from typing import Any

import pytest

TIMINGS = {"duration_s", "wall_s", "median_wall_s", "median_duration_s", "trial_wall_median_s", "jobs", "pid",
           "sim_steps_per_s", "real_time_factor"}
"""Keys that measure the run (wall time, processes), not its result."""


def _results(value: Any) -> Any:
    """``value`` without its timing keys, at every depth."""
    if isinstance(value, dict):
        return {k: _results(v) for k, v in value.items() if k not in TIMINGS}
    if isinstance(value, list):
        return [_results(v) for v in value]
    return value


@pytest.mark.slow
def test_two_drawn_plans_in_two_truth_cells_at_once_give_the_json_of_one_cell(run_main) -> None:
    """``bench assemble --jobs 2``: two plans in two truth cells at once, each assembled, the
    report that of ``--jobs 1``; on a stderr that is no terminal, no progress bar (on a
    terminal: ``tests/bridge/test_progress.py``). (The campaign's workers, one against two,
    are compared in ``tests/executor/test_campaign_cell.py``, where ``--jobs`` reaches
    ``run_campaign``.)"""
    reports = []
    for jobs in ("1", "2"):
        done = run_main("bench", "assemble", "--plans", "2", "--seed", "5", "--backend", "truth", "--jobs", jobs,
                        "--json", timeout=300)
        assert done.returncode == 0, done.stderr
        assert "100%" not in done.stderr and "100%" not in done.stdout
        reports.append(json.loads(done.stdout))
    assert _results(reports[0]) == _results(reports[1])
    assert [r["seed"] for r in reports[1]["plans"]] == [6, 7]
    assert reports[1]["summary"]["assembled"] == 2
    assert all(len(r["steps"]) == 10 for r in reports[1]["plans"])


@pytest.mark.slow
def test_jobs_defaults_to_the_cores_and_is_bounded(run_main) -> None:
    done = run_main("executor", "campaign", "--help")
    assert "--jobs N" in done.stdout and "default: the machine's" in " ".join(done.stdout.split())
    done = run_main("bench", "assemble", "--jobs", "65")
    assert done.returncode == 2 and "--jobs" in done.stderr
