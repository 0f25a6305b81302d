"""The Python API (docs/api.md) and its example script, as a user runs them."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from assembly_constraints import api
from tests.conftest import ROOT, child_env


def test_the_example_script_learns_and_plans_in_the_callers_folder(tmp_path: Path) -> None:
    done = subprocess.run([sys.executable, str(ROOT / "examples" / "learn_and_plan.py"), "."], cwd=tmp_path,
                          env=child_env(), capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "19 experiments" in done.stdout and "plan: bp " in done.stdout
    assert "fits(p3,s1)." in (tmp_path / "learned.lp").read_text()


def test_learn_sizes_takes_a_function_and_rejects_an_answer_that_is_no_result() -> None:
    truth = api.truth_oracle("cranfield")
    sizes = api.learn_sizes(truth.ask, truth.parts, truth.holes, policy="best")
    assert set(sizes.knowledge.fits) == truth.fits
    with pytest.raises(api.PlannerError, match="expected 'fit' or 'no_fit'"):
        api.learn_sizes(lambda part, hole: "maybe", truth.parts, truth.holes)  # type: ignore[arg-type, return-value]


@pytest.mark.slow
def test_a_session_run_from_python_is_read_back_from_its_folder(tmp_path: Path) -> None:
    cell = api.CellSettings(layer="position", cell_seed=5, magnitudes=api.Magnitudes(vision_bias=0.002))
    result = api.run_session("cranfield", api.SessionOptions(backend="truth", out=tmp_path / "run", cell=cell))
    assert result["matches_truth"] is True
    run = api.read_run(tmp_path / "run")
    assert len(run.experiments) == result["experiments"] == 19
    assert run.settings.status == "done" and run.learned is not None
    assert run.settings.cell == cell and run.settings.plans == result["plans"]
    assert sorted(run.fits) == sorted(tuple(pair) for pair in result["fits"])
    assert {p.name for p in run.recordings} == {"planner.rrd", "c1.rrd"}
    with pytest.raises(api.PlannerError, match="not a run folder"):
        api.read_run(tmp_path)


def test_session_settings_out_of_range_are_refused_before_anything_starts(tmp_path: Path) -> None:
    with pytest.raises(api.PlannerError, match='^session settings: "cells": expected `int` <= 64'):
        api.run_session("cranfield", api.SessionOptions(backend="truth", cells=65, out=tmp_path / "run"))
    with pytest.raises(api.PlannerError, match='"cell.magnitudes.vision_bias": expected `float` <= 0.02'):
        api.run_session("cranfield", api.SessionOptions(
            backend="truth", out=tmp_path / "run", cell=api.CellSettings(magnitudes=api.Magnitudes(vision_bias=0.5))))
    assert not (tmp_path / "run").exists()
