"""How many experiments a policy needs, over relabelings of an assembly (paper 4.2).

A relabeling permutes the parts and the holes, i.e. their index order; the paper ran
its learner on all 5!·5! = 14400 relabelings of Cranfield. The learner sees the truth
only through the index order, so each run gets canonical names (``q1..``, ``k1..``)
and the truth matrix in relabeled order. For a deterministic policy the experiments
are a function of that matrix alone; identical rows or columns make many relabelings
give the same matrix (900 distinct ones of 14400 for Cranfield), and runs share
their decisions as long as their answers agree, so the policy's decision tree is
walked once over the distinct matrices, each counted with its multiplicity: the
statistics are exactly those of running every relabeling on its own.
Non-deterministic policies (``random``) run every case, case i with seed
``seed * 1_000_003 + i``. With ``noise`` every case is a session of its own too, its
answers flipped by a :class:`NoisyOracle` of the case's seed; the cases that end with
a wrong relation are counted. ``confirm`` is the learner's
(see :class:`asp.sizes.learner.SizeLearner`). Work is spread over the machine's cores.
"""

from __future__ import annotations

import itertools
import multiprocessing
import random
import statistics
from collections import Counter
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass
from typing import Any

from asp import PlannerError
from asp.sizes.learner import LearningOptions, SizeLearner, run_learner
from asp.sizes.policies import get_policy
from asp.sizes.truth_oracle import NoisyOracle, TruthOracle
from bridge.cli_types import forked_worker
from bridge.files import write_figure
from bridge.progress import progress

Matrix = tuple[tuple[bool, ...], ...]
"""Truth in index order: ``matrix[i][j]`` is True when part i+1 fits hole j+1."""


@dataclass(frozen=True)
class Evaluation:
    """Number of experiments per case, as a histogram over all cases; ``wrong`` cases
    ended with a wrong relation (only with ``noise``, the flip probability)."""

    policy: str
    histogram: dict[int, int]
    noise: float = 0.0
    confirm: int = 0
    wrong: int = 0

    @property
    def cases(self) -> int:
        return sum(self.histogram.values())

    @property
    def mean(self) -> float:
        return sum(n * c for n, c in self.histogram.items()) / self.cases

    @property
    def median(self) -> float:
        """Median number of experiments per case."""
        counts = sorted(itertools.chain.from_iterable([n] * c for n, c in self.histogram.items()))
        return statistics.median(counts)

    def as_json(self) -> dict:
        """The JSON contract of ``sizes evaluate --json``; shares are fractions of all cases (0..1). With noise
        or confirm also ``noise``, ``confirm``, ``wrong`` (cases) and ``wrong_share``."""
        low, high = min(self.histogram), max(self.histogram)
        extra = {} if not (self.noise or self.confirm) else {
            "noise": self.noise, "confirm": self.confirm, "wrong": self.wrong,
            "wrong_share": round(self.wrong / self.cases, 6),
        }
        return {
            "policy": self.policy,
            "cases": self.cases,
            "mean": round(self.mean, 4),
            "min": low,
            "min_share": round(self.histogram[low] / self.cases, 6),
            "max": high,
            "max_share": round(self.histogram[high] / self.cases, 6),
            "histogram": {str(n): self.histogram[n] for n in sorted(self.histogram)},
            **extra,
        }


def relabeled_matrices(truth: TruthOracle, relabelings: str | int, seed: int) -> list[Matrix]:
    """The truth matrix under every relabeling (``"all"``) or ``N`` random ones."""
    rows, cols = range(len(truth.parts)), range(len(truth.holes))
    orders: Iterable[tuple[tuple[int, ...], tuple[int, ...]]]
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


Task = tuple[str, int, int, tuple[tuple[str, str, str], ...], dict[Matrix, int]]
"""A subtree of a deterministic policy's decision tree: (policy, seed, confirm, prefix
of (part, hole, result) experiments, matrices reaching it with their multiplicities)."""

Case = tuple[Matrix, str, int, int, float]
"""One whole session: (truth matrix, policy, seed, confirm, noise)."""

_LEARNERS: dict[tuple[str, int, int, int], SizeLearner] = {}
"""Per process: one ground learner per (policy, parts, holes, confirm), reused by reset."""


def _names(matrix: Matrix) -> tuple[list[str], list[str]]:
    """Canonical part and hole names of a matrix's shape."""
    return [f"q{i}" for i in range(1, len(matrix) + 1)], [f"k{j}" for j in range(1, len(matrix[0]) + 1)]


def _learner(policy: str, matrix: Matrix, seed: int, confirm: int) -> SizeLearner:
    """A fresh (reset) learner of the matrix's shape, reused for deterministic policies."""
    parts, holes = _names(matrix)
    key = (policy, len(parts), len(holes), confirm)
    if not get_policy(policy).deterministic:
        return SizeLearner(parts, holes, policy, seed, options=LearningOptions(confirm=confirm))
    if key not in _LEARNERS:
        _LEARNERS[key] = SizeLearner(parts, holes, policy, seed, options=LearningOptions(confirm=confirm))
    learner = _LEARNERS[key]
    learner.reset(seed)
    return learner


def _answer(matrix: Matrix, pair: tuple[str, str]) -> str:
    """The truth of a canonical pair ``(q<i>, k<j>)``."""
    return "fit" if matrix[int(pair[0][1:]) - 1][int(pair[1][1:]) - 1] else "no_fit"


def run_case(case: Case) -> tuple[int, bool]:
    """Experiments of one whole session and whether it ended with a wrong relation
    (without noise that is an error of the learner)."""
    matrix, policy, seed, confirm, noise = case
    parts, holes = _names(matrix)
    fits = {(p, h) for p, row in zip(parts, matrix) for h, f in zip(holes, row) if f}
    truth = TruthOracle(parts, holes, fits)
    oracle = NoisyOracle(truth, noise, seed) if noise else truth
    result = run_learner(_learner(policy, matrix, seed, confirm), oracle)
    wrong = result.knowledge.fits != frozenset(fits)
    if wrong and not noise:
        raise PlannerError(f"policy {policy} learned a wrong relation for {matrix}")
    return result.count, wrong


def _walk(learner: SizeLearner, group: dict[Matrix, int], histogram: Counter[int],
          frontier: list | None = None, depth: int = 0) -> None:
    """Walk the decision tree below the learner's state for the matrices of ``group``.

    Each node is one decision; the matrices split by their answer to it. With
    ``frontier``, nodes ``depth`` levels down are collected instead of walked.
    """
    pair = learner.next_experiment()
    if pair is None:
        histogram[len(learner.experiments)] += sum(group.values())
        return
    if frontier is not None and depth == 0:
        prefix = tuple((e.part, e.hole, e.result) for e in learner.experiments)
        frontier.append((prefix, group))
        return
    for result in ("fit", "no_fit"):
        branch = {m: n for m, n in group.items() if _answer(m, pair) == result}
        if branch:
            learner.record(*pair, result)
            _walk(learner, branch, histogram, frontier, depth - 1)
            learner.undo()


def walk_subtree(task: Task) -> Counter[int]:
    """Histogram of experiment counts of one subtree (worker of the process pool)."""
    policy, seed, confirm, prefix, group = task
    learner = _learner(policy, next(iter(group)), seed, confirm)
    for part, hole, result in prefix:
        learner.record(part, hole, result)
    histogram: Counter[int] = Counter()
    _walk(learner, group, histogram)
    return histogram


def _pool_map(function, tasks: Sequence, processes: int, unit: str) -> list:
    """``map`` over a process pool (serial for few tasks); a progress bar on a terminal."""
    pool = None
    iterator: Iterator[Any]
    if processes > 1 and len(tasks) > 1:
        pool = multiprocessing.get_context("fork").Pool(processes, initializer=forked_worker)
        chunk = max(1, min(64, len(tasks) // (processes * 8)))
        iterator = pool.imap_unordered(function, tasks, chunksize=chunk)
    else:
        iterator = map(function, tasks)
    try:
        iterator = progress(iterator, desc="evaluate", total=len(tasks), unit=unit)
        return list(iterator)
    finally:
        if pool is not None:
            pool.close()
            pool.join()


def evaluate_policy(
    truth: TruthOracle, policy: str, relabelings: str | int = "all", seed: int = 0,
    processes: int | None = None, confirm: int = 0, noise: float = 0.0,
) -> Evaluation:
    """Learn every relabeled truth with ``policy`` (learner option ``confirm``; answers
    flipped with probability ``noise``).

    Without noise a deterministic policy's runs form a decision tree (a decision
    depends only on the answers so far): it is walked once, each node solved once, the
    matrices splitting by their answers; its top levels are cut into subtrees for the
    worker processes. The histogram is exactly that of running every relabeling on its own.
    """
    selection = get_policy(policy)
    matrices = relabeled_matrices(truth, relabelings, seed)
    processes = processes or min(2, multiprocessing.cpu_count())
    histogram: Counter[int] = Counter()
    wrong = 0
    if selection.deterministic and not noise:
        group = dict(Counter(matrices))
        frontier: list = []
        depth = 0
        while len(frontier) < 16 * processes and depth < 12:
            frontier, histogram = [], Counter()
            depth += 1
            _walk(_learner(policy, matrices[0], seed, confirm), group, histogram, frontier, depth)
            if not frontier:
                break
        tasks = [(policy, seed, confirm, prefix, sub) for prefix, sub in frontier]
        for part in _pool_map(walk_subtree, tasks, processes, "subtree"):
            histogram.update(part)
    else:
        cases = [(m, policy, seed * 1_000_003 + i, confirm, noise) for i, m in enumerate(matrices)]
        runs = _pool_map(run_case, cases, processes, "run")
        histogram.update(count for count, _ in runs)
        wrong = sum(bad for _, bad in runs)
    return Evaluation(policy, dict(histogram), noise, confirm, wrong)


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
    ax.set_title(f"Fig. 19: experiments needed to learn the relation, over {evaluations[0].cases} relabelings")
    ax.legend()
    write_figure(path, fig, dpi=120)
