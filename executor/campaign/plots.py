"""Figures of the campaign (``executor campaign --plot DIR``), drawn with matplotlib.

- ``fig18_table.png``: the campaign table as an image, like the paper's Fig. 18, with
  the non-fitting pairs added.
- ``fig17_forces.png``: measured vs desired forces and torques over the DMP phase for a
  successful round-peg insertion (``p1``→``r1``, left) and a failed square-peg one
  (``p3``→``r1``, right), each against its own part's desired profile (dotted): the
  paper's Fig. 17 (``executor trial --plot FILE`` draws the same for its own trials). The traces come from two
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
from executor.rerun_log import AttemptLogger, AttemptTrace, LogTarget  # noqa: E402

FIG17_SUCCESS = ("p1", "r1")
FIG17_FAILURE = ("p3", "r1")
_SEEDS_TO_TRY = 5  # seeds tried to find a successful / failed attempt to show


def traced_trials(assembly: str, seed: int, rrd_path: Path) -> tuple[AttemptTrace, AttemptTrace]:
    """Run Fig. 17's two pairs in a logged cell; the first fitting attempt of
    ``p1``→``r1`` and the first attempt of ``p3``→``r1`` (which must fail)."""
    from executor.trial import Cell

    logger = AttemptLogger("fig17", LogTarget(rrd_path=rrd_path), keep_traces=True)
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


def plot_fig17(success: AttemptTrace | None, failure: AttemptTrace | None, path: Path) -> Path:
    """Forces [N] (top) and torques [Nm] (bottom) over the DMP phase of a successful
    (left) and a failed (right) attempt, measured (solid) against the desired profile of
    the attempt's own part (dotted, same colour per axis), as in the paper's Fig. 17.
    A missing attempt leaves its column with a note."""
    fig, axes = plt.subplots(2, 2, figsize=(11, 6.5), sharex=True, squeeze=False)
    colors = ("tab:red", "tab:green", "tab:blue")
    for column, (label, trace) in enumerate((("success", success), ("failure", failure))):
        top = axes[0][column]
        if trace is None:
            top.set_title(f"{label}: no such attempt in these trials")
        else:
            top.set_title(f"{label}: {PART_NAMES.get(trace.part, trace.part)} {trace.part} → "
                          f"{trace.hole}, seed {trace.trial_seed}, attempt {trace.attempt} ({trace.outcome})",
                          fontsize=9)
        for row, (quantity, unit) in enumerate((("force", "N"), ("torque", "Nm"))):
            ax = axes[row][column]
            names = ("F_x", "F_y", "F_z") if quantity == "force" else ("M_x", "M_y", "M_z")
            if trace is not None:
                steps = trace.insertion()
                phase = trace.array("phase")[steps]
                for axis, (name, color) in enumerate(zip(names, colors)):
                    ax.plot(phase, trace.array(f"{quantity}_mes")[steps, axis], "-", color=color,
                            label=f"${name}$ measured")
                    ax.plot(phase, trace.array(f"{quantity}_des")[steps, axis], ":", color=color,
                            label=f"${name}$ desired")
                ax.legend(loc="best", fontsize=7, ncol=2)
            ax.set_ylabel(f"{quantity} [{unit}]")
            ax.grid(alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel("DMP phase")
    fig.suptitle("Measured vs desired force and torque over the DMP phase (paper Fig. 17)")
    return write_figure(path, fig, dpi=120)


def first_attempts(traces: Sequence[AttemptTrace]) -> tuple[AttemptTrace | None, AttemptTrace | None]:
    """The first fitting and the first failed attempt among ``traces`` that reached the insertion."""
    def first(outcome: str) -> AttemptTrace | None:
        return next((t for t in traces if t.outcome == outcome and len(t.insertion())), None)

    return first("fit"), first("no_fit")


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
