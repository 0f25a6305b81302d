"""``./run.sh view RUN``: prints what a real recording holds; errors exit 2."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from rerun.chunk import RrdReader

from asp.session.view import cell_ids, write_blueprint
from bridge.recording.reader import blueprint_origins
from executor.rerun_log import AttemptLogger


def _run_folder(folder: Path) -> Path:
    """A run with two cells' recordings sharing one recording id."""
    folder.mkdir()
    for cell in ("c1", "c2"):
        logger = AttemptLogger(cell, recording_id="run-7", rrd_path=folder / f"{cell}.rrd")
        logger.log_scene([("plate", "box", (0.1, 0.1, 0.01), (0.6, 0.0, 0.09))])
        logger.begin_attempt("p1", "r1", 3, 1)
        for k in range(20):
            logger.log_step(0.01 * k, k / 19, np.array([0.6, 0.0, 0.2]), np.zeros(3), np.zeros(3),
                            np.zeros(3), np.zeros(3))
        logger.close()
    return folder


@pytest.mark.slow
def test_view_prints_the_recording_without_display(tmp_path: Path, run_cli) -> None:
    run = _run_folder(tmp_path / "run")
    text = run_cli("view", str(run))
    assert text.returncode == 0, text.stderr
    assert "no display" in text.stderr
    assert "/executor/c1/scene/plate" in text.stdout and "/executor/c2/scene/plate" in text.stdout
    assert "recording ids: run-7" in text.stdout

    as_json = run_cli("view", str(run / "c2.rrd"), "--json")
    data = json.loads(as_json.stdout)
    assert data["recording_ids"] == ["run-7"]
    assert data["entities"]["/executor/c2/scene/plate"]["static_rows"] == 1
    assert not any(p.startswith("/executor/c1") for p in data["entities"])


@pytest.mark.slow
def test_view_without_recording_exits_2(tmp_path: Path, run_cli) -> None:
    empty = run_cli("view", str(tmp_path), "--print")
    assert empty.returncode == 2 and "holds no Rerun recording" in empty.stderr
    missing = run_cli("view", str(tmp_path / "nope"))
    assert missing.returncode == 2 and "no such run folder" in missing.stderr


def test_blueprint_has_the_planner_and_a_tab_per_cell(tmp_path: Path) -> None:
    paths = ["/executor/c1/outcome", "/executor/c2/scene/plate", "/planner/knowledge", "/executor"]
    assert cell_ids(paths) == ["c1", "c2"]
    blueprint = write_blueprint(tmp_path, ["c1", "c2"], planner=True)
    stores = RrdReader(blueprint).blueprints()
    assert [s.application_id for s in stores] == ["assembly_constraints"]
    origins = blueprint_origins(blueprint)
    for cell in ("c1", "c2"):
        assert {f"executor/{cell}", f"executor/{cell}/wrench/force", f"executor/{cell}/by_phase",
                f"executor/{cell}/outcome"} <= origins
    assert {"planner/knowledge", "planner/precedence"} <= origins
    assert not any(o.startswith("planner") for o in blueprint_origins(write_blueprint(tmp_path, ["c1"], False)))
