"""``./run.sh view RUN``: prints what a real recording holds; errors exit 2."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import rerun as rr
from rerun.chunk import RrdReader

from bridge.recording.layout import TRAIL_S, Contents, TimePoint, tab_names, write_blueprint
from bridge.recording.reader import blueprint_origins, read_blueprint, read_recording
from executor.evidence import AttemptEvidence
from executor.rerun_log import AttemptLogger, LogTarget


def _run_folder(folder: Path) -> Path:
    """A run with two cells' recordings sharing one recording id."""
    folder.mkdir()
    for cell in ("c1", "c2"):
        logger = AttemptLogger(cell, LogTarget(recording_id="run-7", rrd_path=folder / f"{cell}.rrd"))
        logger.log_scene([("plate", "box", (0.1, 0.1, 0.01), (0.6, 0.0, 0.09))])
        logger.begin_attempt("p1", "r1", 3, 1)
        for k in range(20):
            logger.log_step(0.01 * k, k / 19, np.array([0.6, 0.0, 0.2]), np.zeros(3), np.zeros(3),
                            np.zeros(3), np.zeros(3))
        logger.end_attempt(AttemptEvidence(outcome="fit", max_force_dev=0.0, max_torque_dev=0.0, end_error=0.0,
                                           duration_s=0.2, sim_time_s=0.19, jammed=False, wiggles=0,
                                           phase_reached=1.0))
        logger.close()
    return folder


@pytest.mark.slow
def test_view_prints_the_recording_without_display(tmp_path: Path, run_main) -> None:
    run = _run_folder(tmp_path / "run")
    text = run_main("view", str(run))
    assert text.returncode == 0, text.stderr
    assert "no display" in text.stderr
    assert "/executor/c1/scene/plate" in text.stdout and "/executor/c2/scene/plate" in text.stdout
    assert "recording ids: run-7" in text.stdout

    as_json = run_main("view", str(run / "c2.rrd"), "--json")
    data = json.loads(as_json.stdout)
    assert data["recording_ids"] == ["run-7"]
    assert data["entities"]["/executor/c2/scene/plate"]["static_rows"] == 1
    assert not any(p.startswith("/executor/c1") for p in data["entities"])


@pytest.mark.slow
def test_view_without_recording_exits_2(tmp_path: Path, run_main) -> None:
    empty = run_main("view", str(tmp_path), "--print")
    assert empty.returncode == 2 and "holds no Rerun recording" in empty.stderr
    missing = run_main("view", str(tmp_path / "nope"))
    assert missing.returncode == 2 and "no such run folder" in missing.stderr


def test_blueprint_has_a_tab_per_cell_of_a_real_recording(tmp_path: Path) -> None:
    run = _run_folder(tmp_path / "run")
    contents = Contents.of(read_recording(sorted(run.glob("*.rrd"))).entities)
    assert contents == Contents(cells=("c1", "c2"), fig17=(("c1", "fit/e0001_p1_r1_s3_a1"),
                                                            ("c2", "fit/e0001_p1_r1_s3_a1")))  # no planner, no assembly
    blueprint = write_blueprint(run, contents)
    stores = RrdReader(blueprint).blueprints()
    assert [s.application_id for s in stores] == ["assembly_constraints"]
    origins = blueprint_origins(blueprint)
    for cell in ("c1", "c2"):
        assert {f"executor/{cell}", f"executor/{cell}/wrench/force", f"executor/{cell}/by_phase",
                f"executor/{cell}/outcome"} <= origins
    assert not any(o.startswith("planner") for o in origins)
    layout = read_blueprint(blueprint)
    assert layout.tabs == ["c1", "c2"] and layout.time_panel["timeline"] == "sim_time"


def test_a_session_blueprint_shows_what_the_session_holds(tmp_path: Path) -> None:
    attempts = "/executor/c1/by_phase/{}/measured"
    paths = ["/planner/knowledge", "/executor/c1/outcome", "/executor/c1/assembly/force", "/executor/c2/outcome",
             "/executor/a1/scene/plate", "/executor/a1/arm/base", "/executor/a1/arm/lbr_iiwa_link_1",
             "/executor/a1/assembly/force",  # a1 only stood at rest and assembled: no cell tab
             attempts.format("no_fit/e0001_p3_r1_s0_a1"), attempts.format("fit/e0003_p1_r1_s0_a1"),
             attempts.format("fit/e0002_p2_r2_s0_a1"), "/executor"]
    contents = Contents.of(paths)
    assert contents == Contents(planner=True, cells=("c1", "c2"), assembly_cells=("a1", "c1"),
                                fig17=(("c1", "fit/e0002_p2_r2_s0_a1"),))
    layout = read_blueprint(write_blueprint(tmp_path, contents))
    assert layout.tabs == ["planner", "c1", "c2", "a1 assembly", "c1 assembly"] == tab_names(contents)
    assert layout.time_panel == {"timeline": "log_time", "play_state": 1}  # paused: opens at the start
    fig17 = [v for v in layout.views if v.origin == "executor/c1/by_phase"]
    assert fig17[0].contents == ["$origin/fit/e0002_p2_r2_s0_a1/**"] and "e0002_p2_r2_s0_a1" in fig17[0].name
    spatial = [v for v in layout.views if v.kind == "3D"]
    assert {v.origin for v in spatial} == {"executor/c1", "executor/c2", "executor/a1/assembly", "executor/c1/assembly"}
    assert all("EyeControls3D" in v.properties for v in spatial)
    assert all("$origin/arm/**" in v.contents for v in spatial if "tool" not in v.name)  # the tool view: no arm
    second = round(TRAIL_S * 1e9)
    for cell in ("c1", "c2"):  # the tool tip's trail: the last TRAIL_S up to the cursor, the whole experiment
        cell_views = [v for v in spatial if v.origin == f"executor/{cell}"]
        assert len(cell_views) == 3  # the cell, its close-up, the tool path
        for view in cell_views:
            ranges = {r["timeline"]: r["range"] for r in view.overrides[f"executor/{cell}/tool/tip"][
                "VisibleTimeRanges:ranges"]}
            assert ranges == {"sim_time": {"start": -second, "end": 0}, "log_time": {"start": -second, "end": 0},
                              "experiment": {"start": 0, "end": 0}}, view.name
            see_through = {f"executor/{cell}/arm/part/held"} if "tool" in view.name else set()
            assert set(view.overrides) == {f"executor/{cell}/tool/tip"} | see_through, view.name
    assert {"planner/knowledge", "planner/knowledge_table", "planner/precedence"} <= blueprint_origins(
        tmp_path / "view.rbl")


@pytest.mark.slow
def test_a_session_learns_plans_assembles_and_opens_with_an_assembly_tab_only_when_it_recorded_one(
        tmp_path: Path, run_session) -> None:
    """Truth cells answer the plan's steps from the product's truth and record no assembly:
    with ``--assemble`` the session's report has the assembly of its first plan, its
    recording none (a session without ``--assemble`` has none in its report:
    ``tests/session/test_session_cells.py``)."""
    run = tmp_path / "run"
    result = run_session("--cells", "1", "--out", str(run), "--assemble")
    assert result["assembly"]["assembled"] is True
    assert [s["part"] for s in result["assembly"]["steps"]] == [s["part"] for s in result["plans"][0]]
    settings = json.loads((run / "session.json").read_text())
    assert settings["assembly"] == "cranfield"  # the assembly's name stays (a resume reads it)
    assert settings["assembly_run"] == result["assembly"]
    files = sorted(run.glob("*.rrd"))
    assert [f.name for f in files] == ["c1.rrd", "planner.rrd"]
    assert not any("/assembly/" in path for path in read_recording(files).entities)
    layout = read_blueprint(run / "view.rbl")  # the folder's one blueprint: no file of it holds another
    assert layout.tabs == ["planner", "c1"]
    assert layout.time_panel == {"timeline": "log_time", "play_state": 1}
    assert read_recording(files).blueprints == 0


def test_the_view_blueprint_of_a_session_that_assembled_has_its_assembly_tab(tmp_path: Path) -> None:
    """The session's ``view.rbl`` comes from the entities its files hold: a cell that logged
    an assembly gets its tab, without the planner having announced it."""
    from asp.session.run import view_blueprint

    run = _run_folder(tmp_path / "run")
    logger = AttemptLogger("c1", LogTarget(recording_id="run-7", rrd_path=run / "c1-assembly.rrd",
                                              send_blueprint=False))
    logger.rec.log("executor/c1/assembly/steps", rr.TextLog("p1 -> r1: fit"))
    logger.close()
    layout = read_blueprint(view_blueprint(run))
    assert layout.tabs == ["c1", "c2", "c1 assembly"]
    assert layout.time_panel == {"timeline": "sim_time", "play_state": 1}


@pytest.mark.parametrize(("text", "point", "viewer_time"), [
    ("experiment=1", TimePoint("experiment", 1), 1), ("sim_time=2.5", TimePoint("sim_time", 2.5), 2_500_000_000),
    ("log_time=1764633600", TimePoint("log_time", 1764633600), 1764633600 * 10**9)])
def test_a_time_point_is_parsed_with_its_timeline_kind(text: str, point: TimePoint, viewer_time: int) -> None:
    assert TimePoint.parse(text) == point and point.viewer_time == viewer_time


@pytest.mark.parametrize(("text", "message"), [
    ("experiment", "expected TIMELINE=VALUE"), ("frame=3", "expected TIMELINE=VALUE"),
    ("experiment=1.5", "sequence timeline, expected a whole number"), ("sim_time=x", "a number of seconds"),
    ("sim_time=-1", "finite time >= 0"), ("sim_time=nan", "finite time >= 0")])
def test_a_bad_time_point_says_what_is_expected(text: str, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        TimePoint.parse(text)


@pytest.mark.slow
def test_view_at_needs_a_timeline_of_the_recording(tmp_path: Path, run_main) -> None:
    run = _run_folder(tmp_path / "run")
    missing = run_main("view", str(run), "--screenshot", str(tmp_path / "shots"), "--at", "plan_step=1")
    assert missing.returncode == 2 and missing.stderr.splitlines() == [
        f"error: --at plan_step=1: {run} has no timeline 'plan_step'; it has experiment, log_time, sim_time"]
    malformed = run_main("view", str(run), "--at", "experiment=first")
    assert malformed.returncode == 2
    assert "experiment is a sequence timeline, expected a whole number" in malformed.stderr
    alone = run_main("view", str(run), "--at", "experiment=1")
    assert alone.returncode == 2 and "--at: only with --screenshot DIR" in alone.stderr
    assert not (tmp_path / "shots").exists()
