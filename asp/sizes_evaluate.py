"""How many experiments a policy needs, over relabelings of an assembly (paper 4.2).

A relabeling permutes the parts and the holes, i.e. their index order; the paper ran
its learner on all 5!·5! = 14400 relabelings of Cranfield. The learner sees the truth
only through the index order, so each run gets canonical names (``q1..``, ``k1..``)
and the truth matrix in relabeled order. For a deterministic policy the number of
experiments is a function of that matrix alone; identical rows or columns make many
relabelings give the same matrix, so each distinct matrix is run once and counted
with its multiplicity: the statistics are exactly those of running every relabeling.
Non-deterministic policies (``random``) run every case, case i with seed
``seed * 1_000_003 + i``. Runs are spread over the machine's cores.
"""

from __future__ import annotations

import itertools
import math
import multiprocessing
import random
import sys
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass

from asp import PlannerError
from asp.oracle import TruthOracle
from asp.size_learner import SizeLearner, run_learner
from asp.size_policies import get_policy

Matrix = tuple[tuple[bool, ...], ...]
"""Truth in index order: ``matrix[i][j]`` is True when part i+1 fits hole j+1."""


@dataclass(frozen=True)
class Evaluation:
    """Number of experiments per case, as a histogram over all cases."""

    policy: str
    histogram: dict[int, int]

    @property
    def cases(self) -> int:
        return sum(self.histogram.values())

    @property
    def mean(self) -> float:
        return sum(n * c for n, c in self.histogram.items()) / self.cases

    def as_json(self) -> dict:
        """The issue's JSON contract; shares are fractions of all cases (0..1)."""
        low, high = min(self.histogram), max(self.histogram)
        return {
            "policy": self.policy,
            "cases": self.cases,
            "mean": round(self.mean, 4),
            "min": low,
            "min_share": round(self.histogram[low] / self.cases, 6),
            "max": high,
            "max_share": round(self.histogram[high] / self.cases, 6),
            "histogram": {str(n): self.histogram[n] for n in sorted(self.histogram)},
        }


def relabeled_matrices(truth: TruthOracle, relabelings: str | int, seed: int) -> list[Matrix]:
    """The truth matrix under every relabeling (``"all"``) or ``N`` random ones."""
    rows, cols = range(len(truth.parts)), range(len(truth.holes))
    if relabelings == "all":
        orders = itertools.product(itertools.permutations(rows), itertools.permutations(cols))
    else:
        rng = random.Random(seed)
        orders = (
            (tuple(rng.sample(rows, len(rows))), tuple(rng.sample(cols, len(cols))))
            for _ in range(int(relabelings))
        )
    fits = [[(p, h) in truth.fits for h in truth.holes] for p in truth.parts]
    return [tuple(tuple(fits[i][j] for j in col) for i in row) for row, col in orders]


_LEARNERS: dict[tuple[str, int, int], SizeLearner] = {}
"""Per worker process: one ground learner per (policy, parts, holes), reused by reset."""


def count_experiments(task: tuple[Matrix, str, int]) -> int:
    """Experiments ``policy`` needs to learn ``matrix`` (worker of the process pool).

    Deterministic policies reuse one ground program per shape (canonical names make
    every case of a shape the same program); others get a fresh learner per seed.
    """
    matrix, policy, seed = task
    parts = [f"q{i}" for i in range(1, len(matrix) + 1)]
    holes = [f"k{j}" for j in range(1, len(matrix[0]) + 1)]
    fits = {(p, h) for p, row in zip(parts, matrix) for h, f in zip(holes, row) if f}
    oracle = TruthOracle(parts, holes, fits)
    key = (policy, len(parts), len(holes))
    if get_policy(policy).deterministic and key in _LEARNERS:
        learner = _LEARNERS[key]
        learner.reset(seed)
    else:
        learner = SizeLearner(parts, holes, policy, seed)
        if get_policy(policy).deterministic:
            _LEARNERS[key] = learner
    result = run_learner(learner, oracle)
    if result.knowledge.fits != frozenset(fits):
        raise PlannerError(f"policy {policy} learned a wrong relation for {matrix}")
    return result.count


def _map(tasks: Sequence[tuple[Matrix, str, int]], processes: int) -> list[int]:
    show = sys.stderr.isatty()
    if processes <= 1 or len(tasks) < 50:
        iterator = map(count_experiments, tasks)
        pool = None
    else:
        pool = multiprocessing.get_context("fork").Pool(processes)
        chunk = max(1, min(64, len(tasks) // (processes * 8)))
        iterator = pool.imap(count_experiments, tasks, chunksize=chunk)
    try:
        if show:
            from tqdm import tqdm

            iterator = tqdm(iterator, total=len(tasks), unit="run", file=sys.stderr)
        return list(iterator)
    finally:
        if pool is not None:
            pool.close()
            pool.join()


def evaluate_policy(
    truth: TruthOracle, policy: str, relabelings: str | int = "all", seed: int = 0,
    processes: int | None = None,
) -> Evaluation:
    """Learn every relabeled truth with ``policy``; memoised for deterministic policies."""
    selection = get_policy(policy)
    matrices = relabeled_matrices(truth, relabelings, seed)
    processes = processes or min(2, multiprocessing.cpu_count())
    histogram: Counter[int] = Counter()
    if selection.deterministic:
        multiplicity = Counter(matrices)
        distinct = list(multiplicity)
        counts = _map([(m, policy, seed) for m in distinct], processes)
        for matrix, n in zip(distinct, counts):
            histogram[n] += multiplicity[matrix]
    else:
        tasks = [(m, policy, seed * 1_000_003 + i) for i, m in enumerate(matrices)]
        histogram.update(_map(tasks, processes))
    return Evaluation(policy, dict(histogram))


def plot_comparison(evaluations: Sequence[Evaluation], path: str) -> None:
    """Fig. 19 style: share of cases [%] per number of experiments, one bar set per policy."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    low = min(min(e.histogram) for e in evaluations)
    high = max(max(e.histogram) for e in evaluations)
    xs = list(range(low, high + 1))
    width = 0.8 / len(evaluations)
    fig, ax = plt.subplots(figsize=(8, 4.5))
    for k, evaluation in enumerate(evaluations):
        shares = [100 * evaluation.histogram.get(x, 0) / evaluation.cases for x in xs]
        offset = (k - (len(evaluations) - 1) / 2) * width
        ax.bar([x + offset for x in xs], shares, width,
               label=f"{evaluation.policy} (mean {evaluation.mean:.2f})")
    ax.set_xlabel("number of experiments to learn the whole relation")
    ax.set_ylabel("share of relabelings [%]")
    ax.set_xticks(xs)
    ax.set_title(f"Experiments needed over {evaluations[0].cases} relabelings")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def percent(share: float) -> str:
    return f"{100 * share:.2f} %" if not math.isnan(share) else "n/a"
