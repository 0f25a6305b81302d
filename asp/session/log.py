"""The planner's Rerun log of a session (entities ``planner/...``).

Planner and cells log into ONE recording id (application
:data:`bridge.recording.layout.APPLICATION_ID`), each process to its own ``RUN/*.rrd``; the
files opened together are one recording. The planner sends the session's blueprint
(:func:`bridge.recording.layout.blueprint`): its views in a first tab, then one tab per
cell, and an assembly tab for the cell that assembles.

=========================== ==========================================================
``planner/knowledge``       part × hole matrix after every experiment (tensor: 1 fits,
                            0 does not fit, -1 unknown; value range -1..1, its
                            dimensions named with the part and hole ids in order),
                            timelines ``experiment`` (the number the experiment was
                            started with, which the cell that ran it logs its attempts
                            under) and ``log_time`` (when it ended)
``planner/knowledge_table`` the same as a markdown table, rows the parts, columns the
                            holes, the experiment's own pair in bold
``planner/experiments``     one text line per experiment (pair, result, cell)
``planner/smaller``         smaller-than graph over parts ∪ holes (its transitive
                            reduction), after every experiment, laid out by levels
                            (:mod:`asp.session.layered`: smallest on top)
``planner/precedence``      learned must-precede graph (transitive reduction), static,
                            laid out by levels (first parts on top)
``planner/assignment``      part → hole graph (parts above their holes) and a markdown
                            table of the assignment
=========================== ==========================================================
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import rerun as rr

from asp.precedence.relation import Relation, reduction
from asp.session.layered import positions
from asp.sizes.knowledge import Knowledge
from bridge.recording.compaction import compact_recording
from bridge.recording.layout import APPLICATION_ID, Contents, blueprint
from bridge.recording.sinks import NO_VIEWER, Viewer, finish_stream, open_stream

_PART_COLOR = [70, 130, 220]
_HOLE_COLOR = [230, 150, 40]
_CELL_TEXT = {1: "fit", 0: "no fit", -1: "?"}


class PlannerLog:
    """Logs the planner's entities into ``rrd`` under ``recording_id``, and live to ``viewer``;
    ``assembling``: the cells that will execute a plan (their assembly tabs)."""

    def __init__(self, rrd: Path, recording_id: str, cell_ids: Sequence[str], viewer: Viewer = NO_VIEWER,
                 assembling: Sequence[str] = ()) -> None:
        self.rrd = rrd
        self.rec = open_stream(APPLICATION_ID, recording_id, rrd, viewer)
        self.rec.send_blueprint(blueprint(Contents(planner=True, cells=tuple(cell_ids),
                                                   assembly_cells=tuple(assembling))))

    def precedence(self, parts: Sequence[str], edges: Sequence[tuple[str, str]]) -> None:
        """The learned must-precede relation as a directed graph (its reduction), by levels."""
        self.rec.log("planner/precedence", rr.GraphNodes(list(parts), labels=list(parts),
                                                         positions=positions(parts, edges)), static=True)
        self.rec.log("planner/precedence", rr.GraphEdges(list(edges), graph_type="directed"),
                     static=True)

    def experiment(self, number: int, part: str, hole: str, result: str, cell: str,
                   knowledge: Knowledge) -> None:
        """Experiment ``number`` (in start order) finished; the knowledge after it."""
        self.rec.set_time("experiment", sequence=number)
        self.rec.log("planner/experiments", rr.TextLog(f"#{number} {part} -> {hole}: {result} ({cell})"))
        matrix = np.array([[-1 if v is None else v for v in row] for row in knowledge.matrix()],
                          dtype=np.int8)
        dims = [f"part: {' '.join(knowledge.parts)}", f"hole: {' '.join(knowledge.holes)}"]
        self.rec.log("planner/knowledge", rr.Tensor(matrix, dim_names=dims, value_range=(-1, 1)))
        self.rec.log("planner/knowledge_table",
                     rr.TextDocument(_knowledge_table(knowledge, matrix, (part, hole)), media_type="text/markdown"))
        nodes = [*knowledge.parts, *knowledge.holes]
        colors = [_PART_COLOR] * len(knowledge.parts) + [_HOLE_COLOR] * len(knowledge.holes)
        edges = reduction(Relation.from_pairs(nodes, knowledge.smaller))
        self.rec.log("planner/smaller", rr.GraphNodes(nodes, labels=nodes, colors=colors,
                                                      positions=positions(nodes, edges)))
        self.rec.log("planner/smaller", rr.GraphEdges(edges, graph_type="directed"))

    def assignment(self, assignment: Mapping[str, str]) -> None:
        """The hole assignment as a graph part → hole (parts above their holes) and a table."""
        parts, holes = list(assignment), sorted(set(assignment.values()))
        colors = [_PART_COLOR] * len(parts) + [_HOLE_COLOR] * len(holes)
        nodes = [*parts, *holes]
        self.rec.log("planner/assignment", rr.GraphNodes(nodes, labels=nodes, colors=colors, positions=positions(
            nodes, list(assignment.items()))), static=True)
        self.rec.log("planner/assignment", rr.GraphEdges(list(assignment.items()),
                                                         graph_type="directed"), static=True)
        table = "| part | hole |\n|---|---|\n" + "".join(f"| {p} | {h} |\n" for p, h in assignment.items())
        self.rec.log("planner/assignment", rr.TextDocument(table, media_type="text/markdown"),
                     static=True)

    def close(self) -> None:
        """Finish the file and compact it; BridgeError naming it if it could not be written."""
        finish_stream(self.rec, self.rrd)
        compact_recording(self.rrd)


def _knowledge_table(knowledge: Knowledge, matrix: np.ndarray, pair: tuple[str, str]) -> str:
    """``matrix`` (1 fit, 0 no fit, -1 unknown) as a markdown table, ``pair`` in bold."""
    lines = ["| part | " + " | ".join(knowledge.holes) + " |", "|---" * (len(knowledge.holes) + 1) + "|"]
    for part, row in zip(knowledge.parts, matrix):
        cells = [_CELL_TEXT[int(v)] for v in row]
        cells = [f"**{c}**" if (part, hole) == pair else c for hole, c in zip(knowledge.holes, cells)]
        lines.append(f"| {part} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"
