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
@pytest.mark.parametrize("argv", [
    ("bench", "assemble", "--plans", "2", "--backend", "truth", "--seed", "4"),
    ("executor", "campaign", "--trials", "1", "--seed", "3", "--pairs", "p1:br,p3:r1"),
])
def test_one_and_two_jobs_give_the_same_json(run_main, argv: tuple[str, ...]) -> None:
    reports = []
    for jobs in ("1", "2"):
        done = run_main(*argv, "--jobs", jobs, "--json", timeout=300)
        assert done.returncode == 0, done.stderr
        reports.append(json.loads(done.stdout))
    assert _results(reports[0]) == _results(reports[1])


@pytest.mark.slow
def test_jobs_defaults_to_the_cores_and_is_bounded(run_main) -> None:
    done = run_main("executor", "campaign", "--help")
    assert "--jobs N" in done.stdout and "default: the machine's" in " ".join(done.stdout.split())
    done = run_main("bench", "assemble", "--jobs", "65")
    assert done.returncode == 2 and "--jobs" in done.stderr
