"""``./run.sh bench sizes``: time per decision of the size learner and evaluation time.

For each size n×n (parts × holes) and policy, one learning session on a random biorder
with ties (seeded) is timed decision by decision: a decision is choosing the next
experiment and adding its answer, i.e. one solve of the session's ground program
[ms]; grounding (once per session) is reported apart. Then ``sizes evaluate
--relabelings all`` on Cranfield is timed for the heuristic (target < 2 min on 2 cores).
Targets per decision: 5 ms at 5×5, 50 ms at 10×10, 500 ms at 20×20.

With ``--noise P,...`` it measures robustness instead: for each flip probability,
policy and ``--confirm`` K, ``--seeds`` N sessions on Cranfield (random relabeling and
noise seed per session, as ``sizes evaluate --noise P --confirm K --relabelings N``):
the share of sessions that learn a wrong relation and the experiments per session
(mean, median; every physical experiment, re-tests included).

With ``--products A,...`` it counts experiments instead: for each product (a shipped
assembly or a folder with ``sizes.lp``) and policy, the experiments a session needs
under the product's size model (``--model`` overrides it; ``random``: the mean over
``--seeds`` seeds), next to |parts| × |holes| (trying every pair) and the information
bound of the model: log2 of the number of relations it allows (a policy needs at least
that many experiments on average over relations drawn uniformly, each answer being one
bit).

With ``--demos FILE`` it measures what demonstrations that say where each part went
(``p1@r1``) save: for each policy, ``--seeds`` N sessions on Cranfield, session i on a
random relabeling (index order of parts and holes, seed ``--seed`` + i, also the
policy's seed), once from nothing and once from the demonstrated fits; the experiments
per session (mean, median) of both and the mean saved.

With ``--cells K`` it counts the experiments of parallel learning: for each policy,
``--seeds`` N sessions on Cranfield, session i on a random relabeling (seed ``--seed`` +
i; session 0 of seed 0 in Cranfield's own order) with K cells, each finished experiment
drawn at random among the running ones (the same seed), the batches handed out as a
session hands them out (``next_batch(free, pending=running)``); the experiments per
session (min, median, max).
"""

from __future__ import annotations

import argparse
import itertools
import json
import random
import statistics
import time
from collections.abc import Callable, Sequence

import numpy as np

from asp import PlannerError
from asp.sizes.cli import demonstrated_fits
from asp.sizes.evaluate import evaluate_policy
from asp.sizes.knowledge import Pair
from asp.sizes.learner import LearningOptions, SizeLearner, learn_sizes
from asp.sizes.models import MODELS, model_for
from asp.sizes.policies import get_policy
from asp.sizes.truth_oracle import TruthOracle
from bridge.cli_types import (
    MAX_SEED,
    ArgumentParser,
    comma_list,
    int_in,
    number_in,
    strict_float,
    strict_int,
)

CRANFIELD = "cranfield"

TARGETS_MS = {5: 5.0, 10: 50.0, 20: 500.0}


def random_biorder(n: int, seed: int) -> TruthOracle:
    """n parts and n holes with sizes drawn from n//2 + 1 levels (ties likely)."""
    rng = random.Random(seed)
    parts, holes = [f"p{i}" for i in range(1, n + 1)], [f"h{j}" for j in range(1, n + 1)]
    part_size = {p: rng.randint(0, n // 2) for p in parts}
    hole_size = {h: rng.randint(0, n // 2) for h in holes}
    fits = {(p, h) for p in parts for h in holes if part_size[p] < hole_size[h]}
    return TruthOracle(parts, holes, fits)


def time_decisions(n: int, policy: str, seed: int, max_decisions: int) -> dict:
    """Ground time [s] and per-decision times [ms] of one session (first decisions)."""
    truth = random_biorder(n, seed)
    start = time.perf_counter()
    learner = SizeLearner(truth.parts, truth.holes, policy, seed)
    ground_s = time.perf_counter() - start
    times_ms: list[float] = []
    while len(times_ms) < max_decisions:
        start = time.perf_counter()
        pair = learner.next_experiment()
        if pair is None:
            break
        learner.record(*pair, truth.ask(*pair))
        times_ms.append(1e3 * (time.perf_counter() - start))
    return {
        "size": f"{n}x{n}",
        "policy": policy,
        "ground_s": round(ground_s, 3),
        "decisions": len(times_ms),
        "median_ms": round(statistics.median(times_ms), 2),
        "p99_ms": round(float(np.percentile(times_ms, 99)), 2),
        "target_ms": TARGETS_MS.get(n),
    }


def noise_rows(noises: list[float], policies: list[str], confirms: list[int], seeds: int,
               seed: int) -> list[dict]:
    """Wrong-relation share [%] and experiments per session for every setting (Cranfield)."""
    truth = TruthOracle.from_assembly(CRANFIELD)
    rows = []
    for noise, policy, confirm in itertools.product(noises, policies, confirms):
        evaluation = evaluate_policy(truth, policy, seeds, seed, confirm=confirm, noise=noise)
        rows.append({"noise": noise, "policy": policy, "confirm": confirm, "sessions": evaluation.cases,
                     "wrong_pct": round(100 * evaluation.wrong / evaluation.cases, 1),
                     "mean": round(evaluation.mean, 2), "median": evaluation.median})
    return rows


def demos_rows(demos: str, policies: list[str], seeds: int, seed: int) -> list[dict]:
    """Experiments per Cranfield session without and with the fits ``demos`` show (module doc)."""
    truth = TruthOracle.from_assembly(CRANFIELD)
    demonstrated = demonstrated_fits(demos, CRANFIELD)
    rows = []
    for policy in policies:
        counts: dict[str, list[int]] = {"without": [], "with": []}
        for case in range(seed, seed + seeds):
            rng = random.Random(case)
            parts, holes = rng.sample(truth.parts, len(truth.parts)), rng.sample(truth.holes, len(truth.holes))
            for kind, prior in (("without", []), ("with", demonstrated)):
                known = LearningOptions(demonstrated=prior)
                counts[kind].append(learn_sizes(parts, holes, truth, policy, case, options=known).count)
        rows.append({"policy": policy, "sessions": seeds, "demonstrated": len(demonstrated),
                     **{f"{k}_mean": round(statistics.mean(v), 2) for k, v in counts.items()},
                     **{f"{k}_median": statistics.median(v) for k, v in counts.items()},
                     "saved_mean": round(statistics.mean(counts["without"]) - statistics.mean(counts["with"]), 2)})
    return rows


Watch = Callable[[SizeLearner, list[Pair], list[Pair]], None]
"""Called with the learner, the new batch and every running pair (the batch included)."""


def parallel_learning(parts: Sequence[str], holes: Sequence[str], truth: TruthOracle, cells: int, policy: str,
                      seed: int, together: bool = False, watch: Watch | None = None) -> tuple[SizeLearner, int]:
    """Learn with ``cells`` simulated cells that finish in a seeded random order; returns the
    learner and the number of experiments. ``together``: a random number of the running
    experiments finish at once and are recorded with one solve (``record_all``), as a
    session takes them; ``watch`` (:data:`Watch`) is called after every batch."""
    learner = SizeLearner(parts, holes, policy)
    rng = random.Random(seed)
    running: list[Pair] = []
    asked = 0
    while True:
        batch = learner.next_batch(cells - len(running), pending=running)
        running += batch
        asked += len(batch)
        if watch is not None:
            watch(learner, batch, running)
        if not running:
            return learner, asked
        if together:
            rng.shuffle(running)
            count = rng.randint(1, len(running))
            finished, running = running[:count], running[count:]
            learner.record_all([(*pair, truth.ask(*pair)) for pair in finished])
        else:
            pair = running.pop(rng.randrange(len(running)))
            learner.record(*pair, truth.ask(*pair))


def parallel_rows(cells: int, policies: list[str], seeds: int, seed: int) -> list[dict]:
    """Experiments per Cranfield session with ``cells`` cells (module doc), per policy."""
    truth = TruthOracle.from_assembly(CRANFIELD)
    rows = []
    for policy in policies:
        counts = []
        for case in range(seed, seed + seeds):
            rng = random.Random(case)
            parts, holes = ((truth.parts, truth.holes) if case == 0 else
                            (rng.sample(truth.parts, len(truth.parts)), rng.sample(truth.holes, len(truth.holes))))
            learner, asked = parallel_learning(parts, holes, truth, cells, policy, case)
            if learner.knowledge.fits != frozenset(truth.fits):
                raise PlannerError(f"bench sizes: policy {policy} with {cells} cells learned a wrong relation")
            counts.append(asked)
        rows.append({"policy": policy, "cells": cells, "sessions": seeds, "min": min(counts),
                     "median": statistics.median(counts), "max": max(counts)})
    return rows


def product_rows(products: list[str], policies: list[str], model: str | None, seeds: int, seed: int) -> list[dict]:
    """Experiments per policy for each product, with |parts| × |holes| and the bound [bit]."""
    rows = []
    for product in products:
        truth = TruthOracle.from_assembly(product)
        size_model = model_for(truth.parts, model, truth.declared_model, truth.declared_sections)
        row: dict = {"product": product, "model": size_model.name, "parts": len(truth.parts),
                     "holes": len(truth.holes), "pairs": len(truth.parts) * len(truth.holes),
                     "bound_bits": round(size_model.information_bits(len(truth.holes)), 2)}
        for policy in policies:
            runs = range(seed, seed + (seeds if not get_policy(policy).deterministic else 1))
            under = LearningOptions(model=size_model)
            results = [learn_sizes(truth.parts, truth.holes, truth, policy, case, options=under) for case in runs]
            if any(r.knowledge.fits != frozenset(truth.fits) for r in results):
                raise PlannerError(f"bench sizes: policy {policy} learned a wrong relation of {product}")
            row[policy] = round(statistics.mean(r.count for r in results), 2)
        rows.append(row)
    return rows


def _print_products(rows: list[dict], policies: list[str]) -> None:
    print(f"{'product':>12} {'model':>9} {'parts x holes':>13} {'bound[bit]':>10} "
          + " ".join(f"{p:>10}" for p in policies))
    for r in rows:
        print(f"{r['product']:>12} {r['model']:>9} {str(r['parts']) + ' x ' + str(r['holes']):>13} "
              f"{r['bound_bits']:>10.2f} " + " ".join(f"{r[p]:>10}" for p in policies))


def _print_parallel(rows: list[dict]) -> None:
    print(f"{'policy':>11} {'cells':>5} {'sessions':>8} {'min':>4} {'median':>6} {'max':>4}")
    for r in rows:
        print(f"{r['policy']:>11} {r['cells']:>5} {r['sessions']:>8} {r['min']:>4} {r['median']:>6} {r['max']:>4}")


def _print_demos(rows: list[dict]) -> None:
    print(f"{'policy':>11} {'sessions':>8} {'fits shown':>10} {'mean without':>12} {'mean with':>9} "
          f"{'median without':>14} {'median with':>11} {'saved (mean)':>12}")
    for r in rows:
        print(f"{r['policy']:>11} {r['sessions']:>8} {r['demonstrated']:>10} {r['without_mean']:>12.2f} "
              f"{r['with_mean']:>9.2f} {r['without_median']:>14} {r['with_median']:>11} {r['saved_mean']:>12.2f}")


def _print_noise(rows: list[dict]) -> None:
    print(f"{'noise':>5} {'policy':>11} {'confirm':>7} {'sessions':>8} {'wrong[%]':>8} {'mean':>6} {'median':>6}")
    for r in rows:
        print(f"{r['noise']:>5} {r['policy']:>11} {r['confirm']:>7} {r['sessions']:>8} "
              f"{r['wrong_pct']:>8.1f} {r['mean']:>6.2f} {r['median']:>6}")


def main(argv: list[str]) -> int:
    parser = ArgumentParser(prog="bench sizes", description=__doc__,
                            formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes", default="5,10,20",
                        type=comma_list(number_in(strict_int, 1, 1000), "sizes in [1, 1000)"),
                        help="n of the n×n instances (default 5,10,20)")
    parser.add_argument("--policies", default="systematic,random,heuristic,best", type=comma_list(str, "policy names"),
                        help="policies to time (default systematic,random,heuristic,best)")
    parser.add_argument("--decisions", type=int_in(1, 10**6), default=60,
                        help="decisions timed per session (default 60)")
    parser.add_argument("--seed", type=int_in(0, MAX_SEED), default=1, help="seed (default 1)")
    parser.add_argument("--evaluate", default="heuristic",
                        help="policy whose all-relabelings evaluation of Cranfield is timed ('' skips)")
    parser.add_argument("--noise", type=comma_list(number_in(strict_float, 0.0, 0.5), "probabilities in [0, 0.5)"),
                        metavar="P,...",
                        help="measure wrong relations and experiments under these flip probabilities "
                             "instead of timing (Cranfield; with --confirm, --seeds, --policies)")
    parser.add_argument("--confirm", type=comma_list(number_in(strict_int, 0, 100), "integers in [0, 100)"),
                        default=[0],
                        metavar="K,...",
                        help="with --noise: the learner's confirm values (default 0)")
    parser.add_argument("--seeds", type=int_in(1, 10**5), default=30, metavar="N",
                        help="with --noise, --demos or --cells: sessions per setting (default 30)")
    parser.add_argument("--demos", metavar="FILE",
                        help="measure the experiments saved by the fits these demonstrations show (p1@r1) "
                             "instead of timing (Cranfield; with --seeds, --policies)")
    parser.add_argument("--products", type=comma_list(str, "assembly names or folders"), metavar="A,...",
                        help="count experiments per policy on these products instead of timing "
                             "(with --policies, --model, --seeds)")
    parser.add_argument("--cells", type=int_in(1, 64), metavar="K",
                        help="count experiments of sessions with K cells instead of timing "
                             "(Cranfield; with --seeds, --policies)")
    parser.add_argument("--model", choices=MODELS, default=None,
                        help="with --products: the size model (default: each product's own)")
    parser.add_argument("--json", action="store_true", help="print JSON")
    args = parser.parse_args(argv)
    for name in args.policies:
        get_policy(name)
    counts: list[tuple[str, Callable[[], list[dict]], Callable[[list[dict]], None]]] = [
        ("products", lambda: product_rows(args.products, args.policies, args.model, args.seeds, args.seed),
         lambda rows: _print_products(rows, args.policies)),
        ("parallel", lambda: parallel_rows(args.cells, args.policies, args.seeds, args.seed), _print_parallel),
        ("demos", lambda: demos_rows(args.demos, args.policies, args.seeds, args.seed), _print_demos),
        ("noise", lambda: noise_rows(args.noise, args.policies, args.confirm, args.seeds, args.seed), _print_noise),
    ]
    chosen = {"products": args.products, "parallel": args.cells, "demos": args.demos, "noise": args.noise}
    for key, count, show in counts:
        if chosen[key]:
            found = count()
            if args.json:
                print(json.dumps({key: found}))
            else:
                show(found)
            return 0
    rows = [
        time_decisions(int(n), policy, args.seed, args.decisions)
        for n in args.sizes
        for policy in args.policies
    ]
    report: dict = {"decisions": rows}
    if args.evaluate:
        start = time.perf_counter()
        evaluation = evaluate_policy(TruthOracle.from_assembly(CRANFIELD), args.evaluate)
        report["evaluate"] = {"policy": args.evaluate, "cases": evaluation.cases,
                              "mean": round(evaluation.mean, 4),
                              "seconds": round(time.perf_counter() - start, 1), "target_s": 120}
    if args.json:
        print(json.dumps(report))
        return 0
    print(f"{'size':>6} {'policy':>11} {'ground[s]':>9} {'n':>4} {'median[ms]':>10} {'p99[ms]':>8} {'target[ms]':>10}")
    for r in rows:
        print(f"{r['size']:>6} {r['policy']:>11} {r['ground_s']:>9.3f} {r['decisions']:>4} "
              f"{r['median_ms']:>10.2f} {r['p99_ms']:>8.2f} {r['target_ms'] or '-':>10}")
    if args.evaluate:
        e = report["evaluate"]
        print(f"sizes evaluate --policy {e['policy']} --relabelings all (Cranfield, {e['cases']} cases): "
              f"{e['seconds']} s (target < {e['target_s']} s), mean {e['mean']:.2f}")
    return 0
