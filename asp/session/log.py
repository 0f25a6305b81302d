"""The planner's Rerun log of a session (entities ``planner/...``).

Planner and cells log into ONE recording id (application
:data:`bridge.recording.layout.APPLICATION_ID`), each process to its own ``RUN/*.rrd``; the
files opened together are one recording. The planner sends the blueprint: its views
in a first tab, then one tab per cell (:func:`bridge.recording.layout.cell_blueprint`).

=========================== ==========================================================
``planner/knowledge``       part × hole matrix after every experiment (tensor: 1 fits,
                            0 does not fit, -1 unknown), timeline ``experiment``: the
                            number the experiment was started with, which the cell
                            that ran it logs its attempts under
``planner/experiments``     one text line per experiment (pair, result, cell)
``planner/smaller``         smaller-than graph over parts ∪ holes (its transitive
                            reduction), after every experiment
``planner/precedence``      learned must-precede graph (transitive reduction), static
``planner/assignment``      part → hole graph and a markdown table of the assignment
=========================== ==========================================================
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import rerun as rr

from asp.precedence.relation import Relation, reduction
from asp.sizes.knowledge import Knowledge
from bridge.recording.compaction import compact_recording
from bridge.recording.layout import APPLICATION_ID, cell_blueprint, planner_views
from bridge.recording.sinks import NO_VIEWER, Viewer, finish_stream, open_stream

_PART_COLOR = [70, 130, 220]
_HOLE_COLOR = [230, 150, 40]


class PlannerLog:
    """Logs the planner's entities into ``rrd`` under ``recording_id``, and live to ``viewer``."""

    def __init__(self, rrd: Path, recording_id: str, cell_ids: Sequence[str], viewer: Viewer = NO_VIEWER) -> None:
        self.rrd = rrd
        self.rec = open_stream(APPLICATION_ID, recording_id, rrd, viewer)
        self.rec.send_blueprint(cell_blueprint(cell_ids, extra=[planner_views()]))

    def precedence(self, parts: Sequence[str], edges: Sequence[tuple[str, str]]) -> None:
        """The learned must-precede relation as a directed graph (its reduction)."""
        self.rec.log("planner/precedence", rr.GraphNodes(list(parts), labels=list(parts)), static=True)
        self.rec.log("planner/precedence", rr.GraphEdges(list(edges), graph_type="directed"),
                     static=True)

    def experiment(self, number: int, part: str, hole: str, result: str, cell: str,
                   knowledge: Knowledge) -> None:
        """Experiment ``number`` (in start order) finished; the knowledge after it."""
        self.rec.set_time("experiment", sequence=number)
        self.rec.log("planner/experiments", rr.TextLog(f"#{number} {part} -> {hole}: {result} ({cell})"))
        matrix = np.array([[-1 if v is None else v for v in row] for row in knowledge.matrix()],
                          dtype=np.int8)
        self.rec.log("planner/knowledge", rr.Tensor(matrix, dim_names=["part", "hole"]))
        nodes = [*knowledge.parts, *knowledge.holes]
        colors = [_PART_COLOR] * len(knowledge.parts) + [_HOLE_COLOR] * len(knowledge.holes)
        self.rec.log("planner/smaller", rr.GraphNodes(nodes, labels=nodes, colors=colors))
        edges = reduction(Relation.from_pairs(nodes, knowledge.smaller))
        self.rec.log("planner/smaller", rr.GraphEdges(edges, graph_type="directed"))

    def assignment(self, assignment: Mapping[str, str]) -> None:
        """The hole assignment as a graph part → hole and a table."""
        parts, holes = list(assignment), sorted(set(assignment.values()))
        colors = [_PART_COLOR] * len(parts) + [_HOLE_COLOR] * len(holes)
        self.rec.log("planner/assignment", rr.GraphNodes([*parts, *holes], labels=[*parts, *holes],
                                                         colors=colors), static=True)
        self.rec.log("planner/assignment", rr.GraphEdges(list(assignment.items()),
                                                         graph_type="directed"), static=True)
        table = "| part | hole |\n|---|---|\n" + "".join(f"| {p} | {h} |\n" for p, h in assignment.items())
        self.rec.log("planner/assignment", rr.TextDocument(table, media_type="text/markdown"),
                     static=True)

    def close(self) -> None:
        """Finish the file and compact it; BridgeError naming it if it could not be written."""
        finish_stream(self.rec, self.rrd)
        compact_recording(self.rrd)
