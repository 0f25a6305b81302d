"""Plot styles of the cell's recording and the paper's Fig. 17 drawn for the Rerun viewer.

Rerun 0.41 plots a time series only over the time panel's one timeline, so a force over
the DMP phase would hide every other plot. :func:`send_fig17` draws it instead as a 2D
plot (``LineStrips2D``): x is the phase 0..1 (:data:`WIDTH` units), y the force scaled to
:data:`HEIGHT` units for the largest |F| drawn, with the axes, their tick labels and a
colour key above them (drawn text rather than strip labels, which Rerun puts in the middle
of each strip, over the data); the view shows it whatever the timeline.

The plot grows with the attempt: it is sent as rows at a few times during the insertion
(:func:`growth_ends`), each row the insertion up to then, so a viewer paused inside an
attempt shows it up to its last row before the cursor.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import rerun as rr

from bridge.recording.layout import FIG17_HEIGHT as HEIGHT
from bridge.recording.layout import FIG17_MARGIN
from bridge.recording.layout import FIG17_WIDTH as WIDTH

AXIS_NAMES = {"force": ["Fx", "Fy", "Fz"], "torque": ["Mx", "My", "Mz"]}
MEASURED_COLORS = [[230, 60, 60], [60, 170, 60], [60, 90, 230]]
DESIRED_COLORS = [[250, 170, 170], [160, 225, 160], [160, 180, 250]]
FIT_COLOR = [40, 180, 60]
NO_FIT_COLOR = [220, 50, 40]
GROWTH_ROWS = 8
"""Rows an attempt's growing plots are sent as, at most (the last one whole): the data they
take is about ``(GROWTH_ROWS + 1) / 2`` times that of the whole plot alone."""
_AXES_COLOR = [150, 150, 150]
_LINE_RADIUS = 0.35  # plot units


def outcome_color(outcome: str) -> list[int]:
    """Green for ``fit``, red otherwise."""
    return FIT_COLOR if outcome == "fit" else NO_FIT_COLOR


def growth_ends(count: int, rows: int = GROWTH_ROWS) -> np.ndarray:
    """How many of ``count`` samples each row of a growing plot draws: evenly spaced, at
    least two (a line needs two points), at most ``rows`` rows, the last all ``count``."""
    step = max(-(-count // rows), 1)
    ends = [end for end in range(step, count, step) if end >= 2]
    return np.array([*ends, count], dtype=np.int64)


def send_fig17(rec: rr.RecordingStream, entity: str, indexes: Sequence[rr.TimeColumn], ends: np.ndarray,
               phase: np.ndarray, force_mes: np.ndarray, force_des: np.ndarray) -> None:
    """Draw F_des (pale) and F_mes (x, y, z) [N] of one insertion against its DMP ``phase``
    (``(N,)`` in 0..1, forces ``(N, 3)``) under ``entity``: row k at the k-th time of
    ``indexes`` (one-row-per-end time columns) draws the first ``ends[k]`` samples, scaled
    to the largest |F| among them (the tick labels say it)."""
    x = np.asarray(phase, dtype=np.float64) * WIDTH
    largest = np.maximum.accumulate(np.maximum(np.abs(force_mes).max(axis=1), np.abs(force_des).max(axis=1)))
    spans = np.maximum(largest[ends - 1], 1.0)  # [N] per row
    rows = len(ends)

    def strips(force: np.ndarray) -> list[np.ndarray]:
        return [np.column_stack([x[:end], -force[:end, k] * (HEIGHT / 2 / span)])  # 2D views: y points down
                for end, span in zip(ends, spans) for k in range(3)]

    for name, force, colors in (("desired", force_des, DESIRED_COLORS), ("measured", force_mes, MEASURED_COLORS)):
        rec.send_columns(f"{entity}/{name}", indexes=indexes, columns=rr.LineStrips2D.columns(
            strips=strips(force), colors=colors * rows, radii=[_LINE_RADIUS] * (3 * rows)).partition([3] * rows))
    half = HEIGHT / 2
    axes = [[[0.0, 0.0], [WIDTH, 0.0]], [[0.0, -half], [0.0, half]],
            *([[x_tick, -1.0], [x_tick, 1.0]] for x_tick in (WIDTH / 2, WIDTH))]
    rec.send_columns(f"{entity}/axes", indexes=indexes, columns=rr.LineStrips2D.columns(
        strips=axes * rows, colors=[_AXES_COLOR] * (len(axes) * rows), radii=[_LINE_RADIUS / 2] * (len(axes) * rows))
        .partition([len(axes)] * rows))
    # The labels (drawn below their points) sit outside the data, in the view's margin
    # (FIG17_MARGIN): the phase below the plot, |F| left of the force axis, the key above.
    below, left, above = half + 2.0, -0.8 * FIG17_MARGIN, -half - 0.9 * FIG17_MARGIN
    ticks = [[0.0, below], [WIDTH / 2, below], [WIDTH, below], [left, -half - 4.0], [left, half - 4.0],
             *([WIDTH * x, above] for x in (0.05, 0.2, 0.35, 0.7))]
    labels = [["phase 0", "0.5", "1", f"+{span:.1f} N", f"−{span:.1f} N", *AXIS_NAMES["force"], "F_des: pale"]
              for span in spans]
    colors = [_AXES_COLOR] * 5 + MEASURED_COLORS + [_AXES_COLOR]
    rec.send_columns(f"{entity}/ticks", indexes=indexes, columns=rr.Points2D.columns(
        positions=ticks * rows, labels=[label for row in labels for label in row], colors=colors * rows,
        radii=[0.6] * (len(ticks) * rows)).partition([len(ticks)] * rows))
