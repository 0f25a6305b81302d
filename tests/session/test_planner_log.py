"""The planner's Rerun log read back: the knowledge matrix keeps its range and names its
parts and holes at every experiment, the graphs are laid out by levels, the session's
blueprint shows the planner on a timeline its data is on."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from asp.session.layered import SPACING, levels, positions
from asp.session.log import PlannerLog
from asp.sizes.knowledge import Knowledge
from bridge.recording.layout import Contents, write_blueprint
from bridge.recording.reader import column_values, read_blueprint, read_recording

PARTS, HOLES = ("p1", "p2"), ("r1", "r2")


def _knowledge(fits: set[tuple[str, str]], no_fit: set[tuple[str, str]]) -> Knowledge:
    smaller = {("p1", "r1"), ("r1", "p2"), ("p2", "r2"), ("p1", "p2"), ("p1", "r2"), ("r1", "r2")}
    return Knowledge(parts=PARTS, holes=HOLES, smaller=frozenset(smaller), fits=frozenset(fits),
                     no_fit=frozenset(no_fit), conflicts=frozenset())


def test_knowledge_matrix_keeps_its_range_and_labels_to_the_last_experiment(tmp_path: Path) -> None:
    rrd = tmp_path / "planner.rrd"
    log = PlannerLog(rrd, "run-1", ["c1"], _knowledge({("p1", "r2")}, set()))  # demonstrated: p1 fits r2
    log.precedence(["bp", "p1", "p2", "fp"], [("bp", "p1"), ("bp", "p2"), ("p1", "fp"), ("p2", "fp")])
    log.experiment(1, "p1", "r1", "fit", "c1", _knowledge({("p1", "r1")}, set()))
    every = {("p1", "r1"), ("p1", "r2"), ("p2", "r2")}
    log.experiment(2, "p2", "r1", "no_fit", "c1", _knowledge(every, {("p2", "r1")}))
    log.assignment({"p1": "r1", "p2": "r2"})
    log.close()

    # experiment 0: the knowledge learning starts from, logged when the log opens
    assert column_values(rrd, "planner/knowledge", "experiment") == [0, 1, 2]
    starts = column_values(rrd, "planner/knowledge", "log_time")
    assert len(starts) == 3 and starts == sorted(starts)
    for entity in ("planner/experiments", "planner/knowledge_table", "planner/smaller"):
        # each experiment's rows at one instant: paused where one starts, the viewer draws them all
        assert column_values(rrd, entity, "log_time") == starts, entity
    assert column_values(rrd, "planner/knowledge", "Tensor:value_range") == [[[-1.0, 1.0]]] * 3
    tensors = column_values(rrd, "planner/knowledge", "Tensor:data")
    assert [d["names"] for d in tensors[-1]] == [["part: p1 p2", "hole: r1 r2"]]
    assert np.array(tensors[0][0]["buffer"]).reshape(2, 2).tolist() == [[-1, 1], [-1, -1]]
    assert np.array(tensors[-1][0]["buffer"]).reshape(2, 2).tolist() == [[1, 1], [0, 1]]
    tables = [row[0] for row in column_values(rrd, "planner/knowledge_table", "TextDocument:text")]
    assert tables[0].splitlines()[2:] == ["| p1 | ? | fit |", "| p2 | ? | ? |"]  # no experiment's pair in bold
    assert tables[1].splitlines()[:3] == ["| part | r1 | r2 |", "|---|---|---|", "| p1 | **fit** | ? |"]
    assert tables[-1].splitlines()[3] == "| p2 | **no fit** | fit |"
    lines = [row[0] for row in column_values(rrd, "planner/experiments", "TextLog:text")]
    assert lines[0] == "#0 start: fits known p1->r2; 3 pairs unknown"

    nodes = column_values(rrd, "planner/precedence", "GraphNodes:node_ids")[0]
    xy = dict(zip(nodes, column_values(rrd, "planner/precedence", "GraphNodes:positions")[0]))
    assert [xy[n][1] for n in ("bp", "p1", "p2", "fp")] == pytest.approx([0, SPACING[1], SPACING[1], 2 * SPACING[1]])
    assert xy["p1"][0] != xy["p2"][0]
    nodes = column_values(rrd, "planner/assignment", "GraphNodes:node_ids")[0]
    rows = dict(zip(nodes, column_values(rrd, "planner/assignment", "GraphNodes:positions")[0]))
    assert {n: rows[n][1] for n in nodes} == {"p1": 0, "p2": 0, "r1": SPACING[1], "r2": SPACING[1]}

    # the run's blueprint is its view.rbl, written when the session ends: a second one in the
    # planner's file would race it in a viewer opening the folder
    assert read_recording(rrd).blueprints == 0
    layout = read_blueprint(write_blueprint(tmp_path, Contents.of(read_recording(rrd).entities)))
    assert layout.time_panel == {"timeline": "log_time", "play_state": 1}  # paused: at the start when opened
    assert layout.tabs == ["planner"]
    graphs = [v for v in layout.views if v.kind == "Graph"]
    assert graphs and all(v.properties["ForceManyBody"] == {"enabled": False} for v in graphs)
    assert {"/planner/knowledge", "/planner/smaller"} <= set(read_recording(rrd).entities)


def test_levels_are_longest_paths_and_cycles_go_below() -> None:
    assert levels("abcd", [("a", "b"), ("b", "c"), ("a", "c")]) == {"a": 0, "b": 1, "c": 2, "d": 0}
    assert levels("xyz", [("x", "y"), ("y", "x")]) == {"x": 1, "y": 1, "z": 0}
    row = positions("abc", [("a", "c"), ("b", "c")])
    assert row[2] == pytest.approx((0.0, SPACING[1])) and row[0][1] == row[1][1] == 0.0
