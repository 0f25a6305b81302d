"""Figures of the campaign (``executor campaign --plot DIR``), drawn with matplotlib.

- ``fig18_table.png``: the campaign table as an image, like the paper's Fig. 18, with
  the non-fitting pairs added.
- ``fig17_forces.png``: measured vs desired force over the DMP phase for a successful
  round-peg insertion (``p1``→``r1``, red) and a failed square-peg one (``p3``→``r1``,
  green), desired force blue dotted: the paper's Fig. 17. The traces come from two
  extra trials run here with an :class:`~executor.rerun_log.AttemptLogger`, which also
  saves them as ``fig17.rrd``.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from bridge.files import make_folder, write_figure  # noqa: E402
from executor import ExecutorError  # noqa: E402
from executor.campaign.pairs import HOLE_NAMES, PART_NAMES, PairStats  # noqa: E402
from executor.rerun_log import AttemptLogger, AttemptTrace  # noqa: E402

FIG17_SUCCESS = ("p1", "r1")
FIG17_FAILURE = ("p3", "r1")
_SEEDS_TO_TRY = 5  # seeds tried to find a successful / failed attempt to show


def traced_trials(assembly: str, seed: int, rrd_path: Path) -> tuple[AttemptTrace, AttemptTrace]:
    """Run Fig. 17's two pairs in a logged cell; the first fitting attempt of
    ``p1``→``r1`` and the first attempt of ``p3``→``r1`` (which must fail)."""
    from executor.trial import Cell

    logger = AttemptLogger("fig17", rrd_path=rrd_path, keep_traces=True)
    cell = Cell(assembly, logger=logger)
    try:
        found: dict[str, AttemptTrace] = {}
        for label, (part, hole), wanted in (
            ("success", FIG17_SUCCESS, "fit"), ("failure", FIG17_FAILURE, "no_fit"),
        ):
            for trial_seed in range(seed, seed + _SEEDS_TO_TRY):
                cell.run_trial(part, hole, seed=trial_seed, max_attempts=2)
                match = [t for t in logger.traces if (t.part, t.hole) == (part, hole)
                         and t.outcome == wanted and t.sim_time]
                if match:
                    found[label] = match[0]
                    break
            else:
                raise ExecutorError(
                    f"Fig. 17: no '{wanted}' attempt of {part}->{hole} in seeds "
                    f"{seed}..{seed + _SEEDS_TO_TRY - 1}"
                )
    finally:
        cell.close()
        logger.close()
    return found["success"], found["failure"]


def plot_fig17(success: AttemptTrace, failure: AttemptTrace, path: Path) -> Path:
    """Fx, Fy, Fz [N] over the DMP phase: desired (blue dotted), success (red),
    failure (green), as in the paper's Fig. 17."""
    fig, axes = plt.subplots(3, 1, figsize=(7, 7), sharex=True)
    for axis, name, ax in zip(range(3), ("F_x", "F_y", "F_z"), axes):
        for trace, signal, style, color, label in (
            (success, "force_des", ":", "tab:blue", "desired"),
            (success, "force_mes", "-", "tab:red", f"success {success.part}→{success.hole}"),
            (failure, "force_mes", "-", "tab:green", f"failure {failure.part}→{failure.hole}"),
        ):
            steps = trace.insertion()
            ax.plot(trace.array("phase")[steps], trace.array(signal)[steps, axis], style,
                    color=color, label=label)
        ax.set_ylabel(f"${name}$ [N]")
        ax.grid(alpha=0.3)
    axes[0].legend(loc="best", fontsize=8)
    axes[-1].set_xlabel("DMP phase")
    fig.suptitle("Measured vs desired force over the DMP phase (paper Fig. 17)")
    return write_figure(path, fig, dpi=120)


def plot_fig18(stats: Sequence[PairStats], path: Path) -> Path:
    """The campaign table as an image (paper Fig. 18 plus the non-fitting pairs)."""
    columns = ["object", "hole", "fits", "executions", "1st trial", "after 2nd trial",
               "correct", "ratio %"]
    rows = [
        [
            PART_NAMES.get(s.part, s.part), HOLE_NAMES.get(s.hole, s.hole),
            "yes" if s.fits else "no", str(s.trials),
            str(s.first_trial) if s.fits else "-", str(s.after_second) if s.fits else "-",
            str(s.correct) if s.fits else f"{s.correct} no_fit",
            f"{100 * s.correct_ratio:.0f}",
        ]
        for s in stats
    ]
    fig, ax = plt.subplots(figsize=(10, 0.4 * len(rows) + 1.2))
    ax.axis("off")
    table = ax.table(cellText=rows, colLabels=columns, loc="center", cellLoc="center")
    table.auto_set_font_size(False)
    table.set_fontsize(9)
    table.scale(1, 1.3)
    ax.set_title("Success ratio of insertions (paper Fig. 18; non-fitting pairs added)")
    return write_figure(path, fig, dpi=120)


def write_plots(folder: Path, stats: Sequence[PairStats], assembly: str, seed: int) -> list[Path]:
    """Write Fig. 18 (table image), Fig. 17 (forces) and ``fig17.rrd`` into ``folder``
(created if missing); the images are written atomically."""
    make_folder(folder)
    rrd_path = folder / "fig17.rrd"
    success, failure = traced_trials(assembly, seed, rrd_path)
    return [
        plot_fig18(stats, folder / "fig18_table.png"),
        plot_fig17(success, failure, folder / "fig17_forces.png"),
        rrd_path,
    ]
