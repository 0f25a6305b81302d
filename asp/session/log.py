"""The planner's Rerun log of a session (entities ``planner/...``).

Planner and cells log into ONE recording id (application
:data:`bridge.recording.layout.APPLICATION_ID`), each process to its own ``RUN/*.rrd``; the
files opened together are one recording. Their blueprint is ``RUN/view.rbl``, which the
session writes from what was recorded when it ends; the planner's file holds none (a
viewer opening the folder would take whichever it read last). A viewer watching live gets
the session's blueprint (:func:`bridge.recording.layout.blueprint`)
with what is certain when it starts: the planner's views in a first tab, then one tab per
cell it starts (whether a cell will assemble is not known yet). The knowledge learning
starts from is logged as experiment 0, so a viewer opened paused at the start of a
timeline shows it.

=========================== ==========================================================
``planner/knowledge``       part × hole matrix at the start (experiment 0: the
                            demonstrated fits and their closure, the rest unknown)
                            and after every experiment (tensor: 1 fits,
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

import queue
import threading
import time
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import rerun as rr

from asp.precedence.relation import Relation, reduction
from asp.session.layered import positions
from asp.sizes.knowledge import Knowledge
from bridge.recording.compaction import compact_recording
from bridge.recording.layout import APPLICATION_ID, SESSION_TIMELINE, Contents, blueprint, opening
from bridge.recording.rows import log_row
from bridge.recording.sinks import (
    NO_VIEWER,
    Viewer,
    finish_stream,
    open_stream,
    send_live_blueprint,
)

_PART_COLOR = [70, 130, 220]
_HOLE_COLOR = [230, 150, 40]
_CELL_TEXT = {1: "fit", 0: "no fit", -1: "?"}


class PlannerLog:
    """Logs the planner's entities into ``rrd`` under ``recording_id``, and live to
    ``viewer``, starting with ``start``, the knowledge before any experiment (experiment 0);
    ``viewer`` gets a blueprint with a tab for the planner and for each of ``cell_ids``."""

    def __init__(self, rrd: Path, recording_id: str, cell_ids: Sequence[str], start: Knowledge,
                 viewer: Viewer = NO_VIEWER) -> None:
        self.rrd = rrd
        self.rec = open_stream(APPLICATION_ID, recording_id, rrd, viewer)
        send_live_blueprint(APPLICATION_ID, recording_id, viewer,
                            blueprint(Contents(planner=True, cells=tuple(cell_ids)), play_state=opening(live=True)))
        self._smaller: tuple[Knowledge, list[tuple[str, str]], list[tuple[float, float]]] | None = None
        """The last knowledge logged, the reduction of its smaller-than graph and the graph's
        layout: experiments recorded together share one knowledge, laid out once."""
        self._experiments: queue.SimpleQueue[tuple[int, str, str, str, str, Knowledge] | None] = queue.SimpleQueue()
        self._failure: BaseException | None = None
        known = " ".join(f"{p}->{h}" for p, h in sorted(start.fits)) or "none"
        self._write_knowledge(0, f"#0 start: fits known {known}; {len(start.unknown)} pairs unknown", start, None)
        self._writer = threading.Thread(target=self._write_experiments, name="planner-log", daemon=True)
        self._writer.start()

    def precedence(self, parts: Sequence[str], edges: Sequence[tuple[str, str]]) -> None:
        """The learned must-precede relation as a directed graph (its reduction), by levels."""
        self.rec.log("planner/precedence", rr.GraphNodes(list(parts), labels=list(parts),
                                                         positions=positions(parts, edges)), static=True)
        self.rec.log("planner/precedence", rr.GraphEdges(list(edges), graph_type="directed"),
                     static=True)

    def experiment(self, number: int, part: str, hole: str, result: str, cell: str,
                   knowledge: Knowledge) -> None:
        """Experiment ``number`` (in start order) finished; the knowledge after it. Queued:
        the log's own thread writes it (reducing and laying out the smaller-than graph takes
        longer than the planner may wait while cells finish); :meth:`close` waits for it
        and raises what went wrong there."""
        if self._failure is not None:
            raise self._failure
        self._experiments.put((number, part, hole, result, cell, knowledge))

    def _write_experiments(self) -> None:
        """The log's thread: write queued experiments in order until :meth:`close`; the
        first failure stops the writing and is kept for the planner's thread."""
        while (item := self._experiments.get()) is not None:
            if self._failure is None:
                try:
                    self._write_experiment(*item)
                except BaseException as exc:  # handed to the planner's thread, raised there
                    self._failure = exc

    def _write_experiment(self, number: int, part: str, hole: str, result: str, cell: str,
                          knowledge: Knowledge) -> None:
        self._write_knowledge(number, f"#{number} {part} -> {hole}: {result} ({cell})", knowledge, (part, hole))

    def _write_knowledge(self, number: int, line: str, knowledge: Knowledge, pair: tuple[str, str] | None) -> None:
        """At experiment ``number`` and one instant of ``log_time`` (now): ``line`` in the
        experiment log, ``knowledge`` as matrix, table (``pair`` in bold) and smaller-than
        graph. One instant, so that a viewer paused where this experiment's rows start shows
        all of them."""
        matrix = np.array([[-1 if v is None else v for v in row] for row in knowledge.matrix()],
                          dtype=np.int8).reshape(len(knowledge.parts), len(knowledge.holes))
        dims = [f"part: {' '.join(knowledge.parts)}", f"hole: {' '.join(knowledge.holes)}"]
        nodes = [*knowledge.parts, *knowledge.holes]
        colors = [_PART_COLOR] * len(knowledge.parts) + [_HOLE_COLOR] * len(knowledge.holes)
        if self._smaller is None or self._smaller[0] is not knowledge:
            reduced = reduction(Relation.from_pairs(nodes, knowledge.smaller))
            self._smaller = knowledge, reduced, positions(nodes, reduced)
        _, edges, layout = self._smaller
        at = [rr.TimeColumn("experiment", sequence=[number]), rr.TimeColumn(SESSION_TIMELINE, timestamp=[time.time()])]
        log_row(self.rec, "planner/experiments", [rr.TextLog(line)], at)
        log_row(self.rec, "planner/knowledge", [rr.Tensor(matrix, dim_names=dims, value_range=(-1, 1))], at)
        log_row(self.rec, "planner/knowledge_table",
                [rr.TextDocument(_knowledge_table(knowledge, matrix, pair), media_type="text/markdown")], at)
        log_row(self.rec, "planner/smaller", [rr.GraphNodes(nodes, labels=nodes, colors=colors, positions=layout),
                                              rr.GraphEdges(edges, graph_type="directed")], at)

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
        """Write what is queued, finish the file and compact it; BridgeError naming it if it
        could not be written (or what the log's thread raised)."""
        self._experiments.put(None)
        self._writer.join()
        finish_stream(self.rec, self.rrd)
        compact_recording(self.rrd)
        if self._failure is not None:
            raise self._failure


def _knowledge_table(knowledge: Knowledge, matrix: np.ndarray, pair: tuple[str, str] | None) -> str:
    """``matrix`` (1 fit, 0 no fit, -1 unknown) as a markdown table, ``pair`` (if any) in bold."""
    lines = ["| part | " + " | ".join(knowledge.holes) + " |", "|---" * (len(knowledge.holes) + 1) + "|"]
    for part, row in zip(knowledge.parts, matrix):
        cells = [_CELL_TEXT[int(v)] for v in row]
        cells = [f"**{c}**" if (part, hole) == pair else c for hole, c in zip(knowledge.holes, cells)]
        lines.append(f"| {part} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"
