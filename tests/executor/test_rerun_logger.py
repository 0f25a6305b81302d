"""AttemptLogger writes a real .rrd that is read back: entities, timelines, values."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from bridge import BridgeError
from bridge.recording.reader import (
    blueprint_origins,
    column_values,
    format_summary,
    read_blueprint,
    read_recording,
)
from executor import ExecutorError
from executor.rerun_log import PATH_COLOR, TIP_RADIUS_UI, AttemptLogger, LogTarget
from executor.rerun_plots import FIT_COLOR, GROWTH_ROWS, HEIGHT, WIDTH, growth_ends


@dataclass
class Evidence:
    outcome: str
    max_force_dev: float = 4.0
    max_torque_dev: float = 0.2
    end_error: float = 0.0005
    duration_s: float = 0.4
    sim_time_s: float = 1.0
    jammed: bool = False
    wiggles: int = 0
    phase_reached: float = 1.0


def _attempt(logger: AttemptLogger, part: str, hole: str, seed: int, attempt: int,
             outcome: str, steps: int = 1000) -> None:
    """One synthetic attempt at 1 kHz whose clock restarts at 0 (as a cell may do): a
    search at phase 0 for the first fifth of the steps, then the DMP (phase 0 → 1)."""
    logger.begin_attempt(part, hole, seed, attempt)
    logger.log_search_path(np.array([[0.5, 0.0, 0.2], [0.501, 0.001, 0.2], [0.5, 0.002, 0.2]]))
    for k in range(steps):
        search = steps // 5
        phase = max(0.0, (k - search) / (steps - 1 - search))
        logger.log_step(
            k * 0.001, phase, np.array([0.5, 0.0, 0.2 - 0.02 * phase]),
            np.array([0.0, 0.0, -10.0 * phase]), np.array([0.0, 0.0, -8.0 * phase]),
            np.zeros(3), np.zeros(3),
        )
    logger.end_attempt(Evidence(outcome))


def test_attempts_are_read_back(tmp_path: Path) -> None:
    rrd = tmp_path / "c1.rrd"
    logger = AttemptLogger("c1", LogTarget(recording_id="run-1", rrd_path=rrd), period_s=0.01)
    logger.log_scene([
        ("plate", "box", (0.1, 0.12, 0.01), (0.59, 0.0, 0.08)),
        ("peg_p1", "cylinder", (0.006, 0.006, 0.025), (0.3, 0.1, 0.125), (0, 0, 0, 1), (200, 90, 40)),
    ])
    _attempt(logger, "p3", "r1", 7, 1, "no_fit")
    _attempt(logger, "p3", "r1", 7, 2, "no_fit")
    _attempt(logger, "p1", "r1", 8, 1, "fit")
    logger.close()

    summary = read_recording(rrd)
    assert summary.application_ids == {"assembly_constraints"}
    assert summary.recording_ids == {"run-1"}
    assert summary.blueprints == 1
    assert {"executor/c1", "executor/c1/wrench/force", "executor/c1/by_phase"} <= blueprint_origins(rrd)
    entities = summary.under("executor/c1")
    for name in ("scene/plate", "scene/peg_p1", "tool/tip", "tool/force", "tool/path", "search/path",
                 "wrench/force/measured", "wrench/force/desired", "wrench/torque/measured",
                 "deviation/force/e0002_p1_r1_s8_a1", "phase", "outcome", "result/fit"):
        assert f"/executor/c1/{name}" in entities, name
    plate = entities["/executor/c1/scene/plate"]
    assert plate.static_rows == plate.rows == 1 and "Boxes3D:half_sizes" in plate.components
    # 1000 steps at 1 kHz kept every 10 ms plus the last: 101 rows per attempt, 3 attempts
    # (and the points' style, static).
    tip = entities["/executor/c1/tool/tip"]
    assert tip.rows - tip.static_rows == 303 and tip.static_rows == 1
    assert entities["/executor/c1/outcome"].rows == 3
    assert {"experiment", "sim_time", "log_time"} <= entities["/executor/c1/wrench/force/measured"].timelines

    texts = [row[0] for row in column_values(rrd, "executor/c1/outcome", "TextLog:text")]
    assert texts[0].startswith("p3→r1 seed 7 attempt 1: no_fit")
    assert texts[2].startswith("p1→r1 seed 8 attempt 1: fit")
    assert column_values(rrd, "executor/c1/result/fit", "Scalars:scalars") == [[0.0], [0.0], [1.0]]
    # Both attempts of trial 1 are experiment 1; the next trial is experiment 2.
    assert column_values(rrd, "executor/c1/outcome", "experiment") == [1, 1, 2]
    # The cell restarts its clock each attempt: the logged sim_time keeps increasing.
    times = column_values(rrd, "executor/c1/tool/tip", "sim_time")
    assert all(b > a for a, b in zip(times, times[1:]))
    assert times[-1] == pytest.approx(3 * 0.999 + 2 * 0.001, abs=1e-6)
    forces = column_values(rrd, "executor/c1/wrench/force/measured", "Scalars:scalars")
    assert forces[-1] == pytest.approx([0.0, 0.0, -10.0])
    # One deviation series per attempt, coloured by its outcome (green fit, red no fit).
    deviation = "executor/c1/deviation/force/e0002_p1_r1_s8_a1"
    assert column_values(rrd, deviation, "Scalars:scalars")[-1] == pytest.approx([2.0])
    assert column_values(rrd, deviation, "SeriesLines:colors") != column_values(
        rrd, "executor/c1/deviation/force/e0001_p3_r1_s7_a1", "SeriesLines:colors")
    assert column_values(rrd, deviation, "SeriesLines:names") == [["p1→r1 s8 a1 fit"]]
    wall = column_values(rrd, "executor/c1/tool/tip", "log_time")
    assert all(b >= a for a, b in zip(wall, wall[1:]))
    # the trail's points: a few pixels in every view (negative radii are UI points)
    assert column_values(rrd, "executor/c1/tool/tip", "Points3D:radii") == [[-TIP_RADIUS_UI]]

    # Fig. 17: a 2D plot per attempt, x the DMP phase 0..1 (WIDTH units), the search left out.
    by_phase = summary.under("executor/c1/by_phase")
    assert len([p for p in by_phase if p.endswith("/measured")]) == 3
    strips = column_values(rrd, "executor/c1/by_phase/fit/e0002_p1_r1_s8_a1/measured", "LineStrips2D:strips")
    x = [point[0] for point in strips[-1][2]]  # Fz, whole
    assert 0 < x[0] < 5 and x[-1] == pytest.approx(WIDTH)
    assert "/executor/c1/by_phase" in format_summary(summary)

    # The single trial's blueprint: one tab, paused on sim_time, the arm in the 3D views:
    # the whole cell from a set camera, a close-up that follows the held part, and the tool
    # alone through the same camera, the held part see-through, nothing else to hide the tip.
    layout = read_blueprint(rrd)
    assert layout.time_panel == {"timeline": "sim_time", "play_state": 1} and layout.tabs == ["c1"]
    cell_3d, close_up, tool = (next(v for v in layout.views if v.kind == "3D" and name in v.name)
                               for name in ("cell", "close-up", "tool"))
    assert "$origin/arm/**" in cell_3d.contents and "position" in cell_3d.properties["EyeControls3D"]
    assert "tracking_entity" not in cell_3d.properties["EyeControls3D"]
    assert close_up.contents == cell_3d.contents and set(close_up.overrides) == {"executor/c1/tool/tip"}
    assert close_up.properties["EyeControls3D"]["tracking_entity"] == "/executor/c1/arm/part/held"
    assert tool.properties["EyeControls3D"] == close_up.properties["EyeControls3D"]
    assert sorted(tool.contents) == ["$origin/arm/part/held", "$origin/scene/hole_rims", "$origin/search/**",
                                     "$origin/tool/**"]
    assert tool.overrides["executor/c1/tool/tip"] == close_up.overrides["executor/c1/tool/tip"]  # the trail
    held = tool.overrides["executor/c1/arm/part/held"]
    assert len(held["ActiveVisualizers:instruction_ids"]) == 3  # a mesh, a round or a square part
    for component in ("Asset3D:albedo_factor", "Cylinders3D:colors", "Boxes3D:colors"):
        assert 0 < held[component] & 0xFF < 255, component  # RGBA: see-through


def test_two_cells_in_one_process_share_a_recording(tmp_path: Path) -> None:
    loggers = [AttemptLogger(cell, LogTarget(recording_id="shared", rrd_path=tmp_path / f"{cell}.rrd"))
               for cell in ("c1", "c2")]
    _attempt(loggers[0], "p1", "br", 1, 1, "fit", steps=100)
    _attempt(loggers[1], "sh", "r1", 2, 1, "no_fit", steps=100)
    for logger in loggers:
        logger.close()
    summary = read_recording(sorted(tmp_path.glob("*.rrd")))
    assert summary.recording_ids == {"shared"}
    assert set(summary.under("executor")) >= {"/executor/c1/outcome", "/executor/c2/outcome"}
    assert not any(p.startswith("/executor/c2") for p in read_recording(tmp_path / "c1.rrd").entities)


def test_misuse_is_reported() -> None:
    logger = AttemptLogger("c1")
    with pytest.raises(ExecutorError, match="begin_attempt"):
        logger.log_step(0.0, 0.0, np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3))
    with pytest.raises(ExecutorError, match="'box' or 'cylinder'"):
        logger.log_scene([("x", "sphere", (1, 1, 1), (0, 0, 0))])
    with pytest.raises(BridgeError, match="no such recording"):
        read_recording("/nonexistent/x.rrd")
    logger.close()


def test_loggers_on_a_callers_stream(tmp_path: Path) -> None:
    import rerun as rr

    stream = rr.RecordingStream("assembly_constraints", recording_id="mine")
    stream.save(str(tmp_path / "both.rrd"))
    for cell in ("a", "b"):
        logger = AttemptLogger(cell, LogTarget(recording=stream, send_blueprint=False))
        _attempt(logger, "p1", "s1", 5, 1, "fit", steps=50)
        logger.close()  # flushes, but leaves the caller's stream open
    stream.log("planner/note", rr.TextLog("still open"))
    stream.disconnect()
    summary = read_recording(tmp_path / "both.rrd")
    assert summary.blueprints == 0
    assert {"/executor/a/outcome", "/executor/b/outcome", "/planner/note"} <= set(summary.entities)


def test_the_plan_steps_of_a_session_keep_its_experiment_timeline(tmp_path: Path) -> None:
    import rerun as rr

    from executor.assembly.recording import AssemblyRecorder

    stream = rr.RecordingStream("assembly_constraints", recording_id="steps")
    stream.save(str(tmp_path / "steps.rrd"))
    stream.set_time("experiment", sequence=19)  # a session's cell assembles after its last experiment
    recorder = AssemblyRecorder(stream, "c1")
    for part in ("p1", "p2"):
        recorder.log_plan_step(part, "r1", "fit", 1, 0.5)
    stream.disconnect()
    rrd = tmp_path / "steps.rrd"
    assert column_values(rrd, "/executor/c1/assembly/steps", "plan_step") == [1, 2]
    assert column_values(rrd, "/executor/c1/assembly/steps", "experiment") == [19, 19]


def test_the_plots_of_an_attempt_grow_with_it(tmp_path: Path) -> None:
    """Fig. 17 and the tool path, read back at a time inside the attempt: the latest row
    before it holds the attempt up to then, drawn to the scale of what was measured so far."""
    rrd = tmp_path / "c1.rrd"
    logger = AttemptLogger("c1", LogTarget(recording_id="grow", rrd_path=rrd), period_s=0.01)
    _attempt(logger, "p1", "r1", 8, 1, "fit")
    logger.close()
    fig17 = "executor/c1/by_phase/fit/e0001_p1_r1_s8_a1"
    times = column_values(rrd, "executor/c1/phase", "sim_time")
    phase = [row[0] for row in column_values(rrd, "executor/c1/phase", "Scalars:scalars")]
    insertion = [t for t, p in zip(times, phase) if p > 0]
    rows = column_values(rrd, f"{fig17}/measured", "sim_time")
    assert len(rows) == len(growth_ends(len(insertion))) == GROWTH_ROWS and rows == sorted(rows)
    assert rows[-1] == insertion[-1] and rows[0] > insertion[0]  # whole at the insertion's last step
    for name in ("desired", "axes", "ticks"):
        assert column_values(rrd, f"{fig17}/{name}", "sim_time") == rows, name
    inside = (insertion[0] + insertion[-1]) / 2  # [s] a viewer paused in the middle of the insertion
    row = max(k for k, t in enumerate(rows) if t <= inside)
    assert 0 < row < len(rows) - 1
    fz = column_values(rrd, f"{fig17}/measured", "LineStrips2D:strips")[row][2]
    shown = phase[times.index(rows[row])]  # the phase at the row's time
    assert fz[-1][0] == pytest.approx(shown * WIDTH) and shown < 0.6  # up to then, not beyond
    span = 10.0 * shown  # [N] the largest |F| measured so far: |F_mes| = 10 N × phase
    assert fz[-1][1] == pytest.approx(HEIGHT / 2)  # Fz = −span at the bottom of the plot (2D y points down)
    assert f"+{span:.1f} N" in column_values(rrd, f"{fig17}/ticks", "Points2D:labels")[row]
    paths = column_values(rrd, "executor/c1/tool/path", "LineStrips3D:strips")
    path_times = column_values(rrd, "executor/c1/tool/path", "sim_time")
    assert paths[0] == [] and path_times[0] == times[0]  # the previous attempt's path is not drawn in this one
    assert [len(strip[0]) for strip in paths[1:]] == list(growth_ends(len(times))) and path_times[-1] == times[-1]
    colors = column_values(rrd, "executor/c1/tool/path", "LineStrips3D:colors")
    grey, green = (int.from_bytes(bytes([*c, 255]), "big") for c in (PATH_COLOR, FIT_COLOR))
    assert colors == [[]] + [[grey]] * (len(paths) - 2) + [[green]]  # the outcome's colour once it is known
    at = max(k for k, t in enumerate(path_times) if t <= inside)
    assert len(paths[at][0]) == times.index(path_times[at]) + 1  # the path up to that step


def test_an_attempt_shows_its_own_search_path(tmp_path: Path) -> None:
    """The search path appears when the search ends; before, in the same attempt, none (not
    the previous attempt's)."""
    rrd = tmp_path / "c1.rrd"
    logger = AttemptLogger("c1", LogTarget(recording_id="search", rrd_path=rrd), period_s=0.01)
    for attempt in (1, 2):
        logger.begin_attempt("p1", "r1", 8, attempt)
        for k in range(100):
            if k == 40:  # the search ran during the first 40 steps
                logger.log_search_path(np.array([[0.5, 0.0, 0.1], [0.501, 0.0, 0.1], [0.501, 0.001, 0.1]]) * attempt)
            logger.log_step(0.01 * k, 0.0, np.array([0.5, 0.0, 0.1]), np.zeros(3), np.zeros(3), np.zeros(3),
                            np.zeros(3))
        logger.end_attempt(Evidence("no_fit"))
    logger.close()
    steps = column_values(rrd, "executor/c1/phase", "sim_time")
    rows = sorted(zip(column_values(rrd, "executor/c1/search/path", "sim_time"),
                      column_values(rrd, "executor/c1/search/path", "LineStrips3D:strips")), key=lambda row: row[0])
    assert [(time, len(strips)) for time, strips in rows] == [
        (steps[0], 0), (steps[39], 1), (steps[100], 0), (steps[139], 1)]  # each search ended after step 40
    assert rows[3][1][0][1] == pytest.approx([1.002, 0.0, 0.2])  # the second attempt's own path
