"""``bench physics``: the three figures, the ratio, the contact it claims, the regression check."""

from __future__ import annotations

import json

import pytest


@pytest.mark.slow
def test_bench_physics_measures_bare_contact_and_trial_steps(run_main) -> None:
    done = run_main("bench", "physics", "--repeats", "1", "--steps", "500", "--baseline", "1e8", "--json")
    assert done.returncode == 1, done.stderr  # nothing steps 1e8 times per second: a regression
    report = json.loads(done.stdout)
    assert report["contact_points"] > 0  # figure b is really the part in contact with the hole
    assert report["bare_steps_per_s"] > report["contact_steps_per_s"] > 0 and report["trial_steps_per_s"] > 0
    assert report["ratio_trial_over_contact"] == pytest.approx(
        report["contact_steps_per_s"] / report["trial_steps_per_s"], rel=0.01)
    assert report["cpu_contact_steps_per_s"] > 0 and report["cpu_trial_steps_per_s"] > 0
    assert report["cpu_ratio_trial_over_contact"] == pytest.approx(
        report["cpu_contact_steps_per_s"] / report["cpu_trial_steps_per_s"], rel=0.01)
    assert report["regressed"] is True


@pytest.mark.slow
def test_bench_physics_refuses_a_pair_that_does_not_fit(run_main) -> None:
    done = run_main("bench", "physics", "--part", "sh", "--hole", "r1", "--repeats", "1")
    assert done.returncode == 2 and "the part does not fit that hole" in done.stderr
    assert "Traceback" not in done.stderr
