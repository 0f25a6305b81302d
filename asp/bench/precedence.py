"""``./run.sh bench precedence``: timings of learning, counting and evaluation.

Prints medians over repetitions and ratios measured in the same run:
the full Cranfield evaluation (6 values of m x 1000 trials), exact counting against
``networkx.all_topological_sorts`` on Cranfield, counting assemblies of 20, 30 and
40 parts (a few chains plus free parts), and guided against random demonstration.
"""

from __future__ import annotations

import functools
import statistics
import time
from collections.abc import Callable

import networkx as nx

from asp.precedence.count import exact_count
from asp.precedence.evaluate import PAPER_M, evaluate
from asp.precedence.relation import Relation, close, true_relation
from bridge.assembly import load_assembly
from bridge.cli_types import ArgumentParser, int_in


def median_seconds(work: Callable[[], object], repeat: int) -> float:
    """Median wall-clock time of ``work()`` over ``repeat`` runs [s]."""
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        work()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def chains_and_free_parts(parts: int, chains: int = 3, chain_length: int = 5) -> Relation:
    """``chains`` chains of ``chain_length`` parts each; the other parts are free."""
    names = [f"q{i}" for i in range(parts)]
    pairs = [
        (names[c * chain_length + k], names[c * chain_length + k + 1])
        for c in range(chains)
        for k in range(chain_length - 1)
    ]
    return close(Relation.from_pairs(names, pairs))


def main(argv: list[str]) -> int:
    parser = ArgumentParser(prog="bench precedence", description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int_in(1, 1000), default=5, help="repetitions per figure (median reported)")
    parser.add_argument("--guided-trials", type=int_in(1, 10**6), default=1000, help="trials of the guided evaluation")
    args = parser.parse_args(argv)
    truth = true_relation(load_assembly("cranfield"))

    seconds = median_seconds(lambda: evaluate(truth, PAPER_M, 1000, seed=1), args.repeat)
    print(f"Cranfield evaluation, 6 values of m x 1000 trials: {seconds:.3f} s "
          f"(median of {args.repeat}; required < 1 s)")

    graph = nx.DiGraph(truth.pairs())
    graph.add_nodes_from(truth.parts)
    ours = median_seconds(lambda: exact_count(truth.matrix), max(args.repeat, 21))
    theirs = median_seconds(lambda: sum(1 for _ in nx.all_topological_sorts(graph)), args.repeat)
    print(f"count Cranfield: ours {exact_count(truth.matrix)} in {1e3 * ours:.3f} ms, "
          f"networkx.all_topological_sorts {sum(1 for _ in nx.all_topological_sorts(graph))} in {1e3 * theirs:.1f} ms: "
          f"{theirs / ours:.0f}x faster (required >= 300x)")

    for parts in (20, 30, 40):
        matrix = chains_and_free_parts(parts).matrix
        seconds = median_seconds(functools.partial(exact_count, matrix), args.repeat)
        print(f"count {parts} parts (3 chains of 5 + {parts - 15} free): {exact_count(matrix)} "
              f"in {1e3 * seconds:.3f} ms (required < 1 s)")

    from asp.precedence.guide import evaluate_guided

    start = time.perf_counter()
    guided = evaluate_guided(truth, args.guided_trials, seed=1)
    seconds = time.perf_counter() - start
    print(f"guided demonstration, {args.guided_trials} trials: mean {guided['mean']:.2f} demonstrations to the exact "
          f"relation vs random {guided['random_mean']:.2f} ({guided['random_mean'] / guided['mean']:.1f}x fewer; "
          f"required <= 4.5) in {seconds:.2f} s")
    return 0
