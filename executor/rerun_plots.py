"""Plot styles of the cell's recording and the paper's Fig. 17 drawn for the Rerun viewer.

Rerun 0.41 plots a time series only over the time panel's one timeline, so a force over
the DMP phase would hide every other plot. :func:`log_fig17` draws it instead as a 2D
plot (``LineStrips2D``): x is the phase 0..1 (:data:`WIDTH` units), y the force scaled to
:data:`HEIGHT` units for the largest |F| of the attempt, with the axes and their tick
labels drawn too; the view shows it whatever the timeline.
"""

from __future__ import annotations

import numpy as np
import rerun as rr

AXIS_NAMES = {"force": ["Fx", "Fy", "Fz"], "torque": ["Mx", "My", "Mz"]}
MEASURED_COLORS = [[230, 60, 60], [60, 170, 60], [60, 90, 230]]
DESIRED_COLORS = [[250, 170, 170], [160, 225, 160], [160, 180, 250]]
FIT_COLOR = [40, 180, 60]
NO_FIT_COLOR = [220, 50, 40]
WIDTH = 100.0
"""Plot units from phase 0 to phase 1."""
HEIGHT = 60.0
"""Plot units from −|F|max to +|F|max."""
_AXES_COLOR = [150, 150, 150]
_LINE_RADIUS = 0.35  # plot units


def outcome_color(outcome: str) -> list[int]:
    """Green for ``fit``, red otherwise."""
    return FIT_COLOR if outcome == "fit" else NO_FIT_COLOR


def log_fig17(rec: rr.RecordingStream, entity: str, phase: np.ndarray, force_mes: np.ndarray,
              force_des: np.ndarray) -> None:
    """Draw F_des (pale) and F_mes (x, y, z) [N] of one insertion against its DMP ``phase``
    (``(N,)`` in 0..1, forces ``(N, 3)``) under ``entity`` at the stream's current time."""
    span = max(float(np.abs(force_mes).max(initial=0.0)), float(np.abs(force_des).max(initial=0.0)), 1.0)  # [N]
    scale = HEIGHT / 2 / span
    x = np.asarray(phase, dtype=np.float64) * WIDTH

    def strips(force: np.ndarray) -> list[np.ndarray]:
        return [np.column_stack([x, -force[:, k] * scale]) for k in range(3)]  # 2D views: y points down

    rec.log(f"{entity}/desired", rr.LineStrips2D(strips(force_des), colors=DESIRED_COLORS, radii=_LINE_RADIUS,
                                                 labels=[f"{n} des" for n in AXIS_NAMES["force"]]))
    rec.log(f"{entity}/measured", rr.LineStrips2D(strips(force_mes), colors=MEASURED_COLORS, radii=_LINE_RADIUS,
                                                  labels=AXIS_NAMES["force"]))
    half = HEIGHT / 2
    rec.log(f"{entity}/axes", rr.LineStrips2D([[[0.0, 0.0], [WIDTH, 0.0]], [[0.0, -half], [0.0, half]]],
                                              colors=[_AXES_COLOR], radii=_LINE_RADIUS / 2))
    rec.log(f"{entity}/ticks", rr.Points2D(
        [[0.0, 3.0], [WIDTH / 2, 3.0], [WIDTH, 3.0], [0.0, -half], [0.0, half]],
        labels=["phase 0", "0.5", "1", f"+{span:.1f} N", f"−{span:.1f} N"], colors=[_AXES_COLOR], radii=0.6))
