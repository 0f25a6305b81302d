"""``./run.sh bench precedence-explore``: precedence experiments needed after two demonstrations.

Per product and seed: two uniformly random feasible demonstrations (and the product's
geometric precedence with ``--prior``), then experiments chosen by each policy, answered
by the truth oracle (the product's ``precedence.lp``), until nothing is open. Reported:
the experiments (median, quartiles, range; failures confirm a pair, successes exclude
one), the information bound at the start (log2 of the relations consistent with the two
demonstrations and the prior, counted exactly within ``--bound-seconds``, else enumerated by
clingo as long again: a lower bound when cut short, :mod:`asp.precedence.explore.bound`),
the experiments minus the bound per seed (the bound holds for the worst case over the
consistent relations, so a seed may need fewer), the learned pairs not in the true
relation (must be 0, and the relation exact: exit code 1 otherwise), next to
demonstrations alone: random and guided (:func:`asp.precedence.guide.evaluate_guided`,
``--demo-trials`` trials).
"""

from __future__ import annotations

import json
import random
import statistics
import time
from typing import Any

from asp import PlannerError
from asp.precedence.count import UniformSampler
from asp.precedence.demos import Demonstrations
from asp.precedence.explore.bound import information_bound
from asp.precedence.explore.knowledge import Evidence, know
from asp.precedence.explore.learner import geometric_reasons, learn_sources
from asp.precedence.explore.oracle import TruthOracle
from asp.precedence.explore.select import POLICIES, explore
from asp.precedence.guide import evaluate_guided
from asp.precedence.relation import Relation, load_relation, true_relation
from bridge.assembly import load_assembly
from bridge.cli_types import ASSEMBLY_HELP, ArgumentParser, comma_list, int_in, number_in, strict_int
from bridge.progress import progress


def _spread(values: list[int]) -> dict[str, float]:
    quartiles = statistics.quantiles(values, n=4) if len(values) > 1 else [values[0]] * 3
    return {"median": statistics.median(values), "q1": quartiles[0], "q3": quartiles[2],
            "min": min(values), "max": max(values), "mean": statistics.fmean(values)}


def run_seed(truth: Relation, prior: tuple[tuple[str, str], ...], prior_file: str | None, seed: int,
             policy: str, bound_seconds: float) -> dict[str, Any]:
    """One seed: two random demonstrations, experiments until nothing is open."""
    rng = random.Random(seed)
    sampler = UniformSampler(truth)
    sequences = tuple(tuple(sampler.sample(rng)) for _ in range(2))
    evidence = Evidence(Demonstrations(truth.parts, sequences, (f"seed {seed} demo 1", f"seed {seed} demo 2")),
                        prior, prior_file or "", geometric_reasons(prior_file))
    start = know(evidence)
    bound = information_bound(start, bound_seconds) if bound_seconds > 0 else None
    oracle = TruthOracle(truth)
    for _knowledge, trial in explore(evidence, oracle, policy, run_id=f"s{seed}"):
        evidence = evidence.with_trial(trial)
    learned = learn_sources(evidence)
    wrong = [pair for pair in learned.relation.pairs() if not truth.matrix[truth.parts.index(pair[0]),
                                                                           truth.parts.index(pair[1])]]
    failures = sum(1 for t in evidence.trials if t.outcome.outcome == "failed")
    return {"seed": seed, "experiments": len(evidence.trials), "failures": failures,
            "open_at_start": len(start.open), "bound_bits": bound.bits if bound else None,
            "bound_complete": bound.complete if bound else None, "wrong": len(wrong),
            "exact": learned.relation.same_as(truth), "physics_s": sum(t.outcome.sim_s for t in evidence.trials)}


def bench_product(name: str, prior_file: str | None, seeds: int, policies: list[str], bound_seconds: float,
                  demo_trials: int) -> dict[str, Any]:
    """Every policy over ``seeds`` seeds on assembly ``name``, and demonstrations alone."""
    assembly = load_assembly(name)
    truth = true_relation(assembly)
    prior: tuple[tuple[str, str], ...] = ()
    if prior_file is not None:
        relation = load_relation([prior_file], data=True)
        if set(relation.parts) != set(truth.parts):
            raise PlannerError(f"--prior {prior_file}: its parts are not those of {name}")
        prior = tuple(relation.pairs())
    result: dict[str, Any] = {"product": name, "prior": prior_file, "parts": len(truth.parts),
                              "true_pairs": int(truth.matrix.sum()), "prior_pairs": len(prior), "policies": {}}
    for policy in policies:
        started = time.perf_counter()
        runs = [run_seed(truth, prior, prior_file, seed, policy, bound_seconds if policy == policies[0] else 0)
                for seed in progress(range(seeds), desc=f"{name} {policy}", total=seeds)]
        result["policies"][policy] = {
            "experiments": _spread([r["experiments"] for r in runs]),
            "failures": _spread([r["failures"] for r in runs]),
            "open_at_start": _spread([r["open_at_start"] for r in runs]),
            "wrong_pairs": sum(r["wrong"] for r in runs), "exact": sum(r["exact"] for r in runs),
            "physics_s": sum(r["physics_s"] for r in runs), "wall_s": time.perf_counter() - started,
        }
        bounds = [r["bound_bits"] for r in runs if r["bound_bits"] is not None]
        if bounds:
            over = [r["experiments"] - r["bound_bits"] for r in runs]
            result["bound_bits"] = {"median": statistics.median(bounds), "min": min(bounds), "max": max(bounds),
                                    "complete": sum(bool(r["bound_complete"]) for r in runs),
                                    "experiments_over": {"policy": policy, "median": statistics.median(over),
                                                         "min": min(over), "max": max(over),
                                                         "below": sum(d < 0 for d in over)}}
    if demo_trials:
        alone = evaluate_guided(truth, demo_trials, seed=0)
        result["demonstrations_alone"] = {"random": alone["random_mean"], "guided": alone["mean"],
                                          "trials": demo_trials}
    return result


def _print(result: dict[str, Any], seeds: int) -> None:
    prior = f", geometric prior {result['prior']} ({result['prior_pairs']} pairs)" if result["prior"] else ""
    print(f"{result['product']}: {result['parts']} parts, {result['true_pairs']} true pairs{prior}; "
          f"{seeds} seeds, 2 random demonstrations each")
    if "bound_bits" in result:
        b = result["bound_bits"]
        exact = "exact" if b["complete"] == seeds else f"a lower bound in {seeds - b['complete']} seeds (cut short)"
        o = b["experiments_over"]
        print(f"  information bound at the start: median {b['median']:.1f} bits (range {b['min']:.1f}-{b['max']:.1f}; "
              f"{exact}); {o['policy']} experiments minus the bound per seed: median {o['median']:.1f} (range "
              f"{o['min']:.1f} to {o['max']:.1f}), below it in {o['below']} seeds")
    for policy, p in result["policies"].items():
        e, f = p["experiments"], p["failures"]
        print(f"  {policy:>11}: experiments median {e['median']:g} (quartiles {e['q1']:g}-{e['q3']:g}, range "
              f"{e['min']}-{e['max']}, mean {e['mean']:.2f}; failures median {f['median']:g}), exact "
              f"{p['exact']}/{seeds}, wrong pairs {p['wrong_pairs']}, physics {p['physics_s']:.0f} s, "
              f"{p['wall_s']:.0f} s wall")
    if "demonstrations_alone" in result:
        d = result["demonstrations_alone"]
        print(f"  demonstrations alone to the exact relation ({d['trials']} trials): random {d['random']:.2f}, "
              f"guided {d['guided']:.2f}")


def main(argv: list[str]) -> int:
    parser = ArgumentParser(prog="bench precedence-explore", description=__doc__.splitlines()[0])
    parser.add_argument("--assembly", action="append", metavar="A[:PRIOR]",
                        help=f"{ASSEMBLY_HELP}, with precedence.lp; after a colon its geometric_precedence.lp "
                             "(repeatable; default cranfield)")
    parser.add_argument("--seeds", type=int_in(1, 10**5), default=100, help="seeds per product (default 100)")
    parser.add_argument("--policies", default="informative,first",
                        type=comma_list(str, "policies such as informative,first"),
                        help=f"experiment policies, comma separated ({', '.join(POLICIES)}; default both)")
    parser.add_argument("--bound-seconds", type=number_in(float, 0, 3600), default=2.0,
                        help="time to count the consistent relations per seed [s], exactly, then as long to "
                             "enumerate them where that gives up (0: no bound; default 2)")
    parser.add_argument("--demo-trials", type=number_in(strict_int, 0, 10**6), default=1000,
                        help="trials of demonstrations alone (0: none; default 1000)")
    parser.add_argument("--json", action="store_true", help="print JSON")
    args = parser.parse_args(argv)
    unknown = [p for p in args.policies if p not in POLICIES]
    if unknown:
        raise PlannerError(f"--policies {','.join(args.policies)}: {unknown[0]} is not one of {', '.join(POLICIES)}")
    failed = False
    for spec in args.assembly or ["cranfield"]:
        name, _, prior = spec.partition(":")
        result = bench_product(name, prior or None, args.seeds, args.policies, args.bound_seconds, args.demo_trials)
        failed |= any(p["wrong_pairs"] or p["exact"] != args.seeds for p in result["policies"].values())
        if args.json:
            print(json.dumps(result))
        else:
            _print(result, args.seeds)
    return 1 if failed else 0
