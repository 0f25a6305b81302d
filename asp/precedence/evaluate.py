"""The paper's evaluation of Algorithm 1 (4.1, Figs. 12 and 13).

For each number m of demonstrations, ``trials`` times: draw m feasible sequences
from the true relation (uniformly by default; see ``GENERATORS``), learn the must-precede relation and count the
sequences M it admits. Reported per m: the mean of M, P(M = all), P(M > all/2) and
the distribution of M in bins of 200 sequences (key: the bin's lower bound; the key
``"all"`` holds M = all, the paper's last column). Probabilities are fractions of
the trials. Sampling and counting are batched over trials
(:class:`asp.precedence.batches.ExtensionBatches`).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from asp import PlannerError
from asp.precedence.batches import GENERATORS, ExtensionBatches, positions_of
from asp.precedence.learn import intersect_orders
from asp.precedence.relation import Relation
from bridge.files import write_figure
from bridge.progress import progress

BIN = 200  # width of a histogram bin [sequences], as in the paper
PAPER_M = (5, 7, 10, 15, 20, 30)


def _histogram(admitted: np.ndarray, total: int) -> dict[str, float]:
    trials = len(admitted)
    partial = admitted[admitted < total]
    counts = np.bincount(partial // BIN, minlength=(total - 1) // BIN + 1) if total > 1 else np.zeros(0, int)
    histogram = {str(k * BIN): float(c) / trials for k, c in enumerate(counts)}
    histogram["all"] = float(np.mean(admitted == total))
    return histogram


def evaluate(
    truth: Relation, ms: Sequence[int], trials: int, seed: int, generator: str = "uniform"
) -> dict[str, Any]:
    """``{"total": N, "generator": g, "results": [{"m", "mean", "p_all", "p_more_than_half", "histogram"}]}``."""

    if trials < 1 or any(m < 1 for m in ms):
        raise PlannerError(f"--trials {trials} --demonstrations {','.join(map(str, ms))}: expected positive integers")
    if generator not in GENERATORS:
        raise PlannerError(f"--generator {generator}: expected one of {', '.join(GENERATORS)}")
    batches = ExtensionBatches(truth)
    rng = np.random.default_rng(seed)
    n, total, results = len(truth.parts), batches.total, []
    for m in progress(ms, desc="evaluate m", total=len(ms), unit="m"):
        orders = batches.sample_orders(rng, trials * m, generator).reshape(trials, m, n)
        admitted = batches.count(intersect_orders(positions_of(orders)))
        results.append(
            {
                "m": int(m),
                "mean": float(admitted.mean()),
                "p_all": float(np.mean(admitted == total)),
                "p_more_than_half": float(np.mean(2 * admitted > total)),
                "histogram": _histogram(admitted, total),
            }
        )
    return {"total": total, "generator": generator, "trials": trials, "results": results}


def plot(evaluation: dict, path: Path | str) -> None:
    """Bar charts as Figs. 12/13: P over M/100 in bins of 200; m <= 10 and m > 10 side by
    side, on one y scale, each titled with its figure and the trials per m."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    results = evaluation["results"]
    panels = [group for group in ([r for r in results if r["m"] <= 10], [r for r in results if r["m"] > 10]) if group]
    figure, axes = plt.subplots(1, len(panels), figsize=(7 * len(panels), 4.4), squeeze=False, sharey=True)
    for axis, group in zip(axes[0], panels):
        figure_number, which = (12, "m ≤ 10") if group[0]["m"] <= 10 else (13, "m > 10")
        axis.set_title(f"Fig. {figure_number}: admitted sequences after {which} demonstrations\n"
                       f"({evaluation['trials']} trials per m, {evaluation['generator']} demonstrations)",
                       fontsize=10)
        keys = list(group[0]["histogram"])
        labels = [f"{int(k) / 100:g}" if k != "all" else "all" for k in keys]
        width = 0.8 / len(group)
        for k, result in enumerate(group):
            shade = str(0.75 - 0.6 * k / max(1, len(group) - 1))
            values = [result["histogram"][key] for key in keys]
            axis.bar(np.arange(len(keys)) + k * width, values, width, color=shade, label=f"m = {result['m']}")
        axis.set_xticks(np.arange(len(keys)) + 0.4 - width / 2, labels, rotation=90, fontsize=7)
        axis.set_xlabel(f"M/100 (bins of {BIN}; total {evaluation['total']})")
        axis.set_ylabel("probability")
        axis.legend()
    write_figure(path, figure, dpi=120)
