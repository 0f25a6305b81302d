"""``./run.sh precedence ...``: learn, count, enumerate, sample, evaluate, explore, suggest.

JSON keys are a contract (docs/cli.md). Sequences are printed one per line,
ids separated by spaces: the demonstrations format, so output can be fed back.
"""

from __future__ import annotations

import argparse
import json
import logging
import random
from itertools import islice
from pathlib import Path
from typing import TYPE_CHECKING

from asp import PlannerError
from asp.precedence.batches import GENERATORS
from asp.precedence.count import UniformSampler, count_linear_extensions, linear_extensions
from asp.precedence.demos import Demonstrations, load_demos
from asp.precedence.relation import (
    Relation,
    load_relation,
    precedence_facts,
    reduction,
    true_relation,
)
from asp.solve import write_facts
from bridge.assembly import load_assembly
from bridge.cli_types import (
    MAX_SEED,
    ArgumentParser,
    add_assembly_argument,
    comma_list,
    int_in,
    non_negative_int,
    nonempty_path,
    number_in,
    png_path,
    strict_int,
)

if TYPE_CHECKING:
    from asp.precedence.explore.knowledge import Evidence
    from asp.precedence.explore.learner import Learned

LOG = logging.getLogger(__name__)


def _parser() -> argparse.ArgumentParser:
    parser = ArgumentParser(prog="precedence", description="Precedence constraints (paper 2.1, 4.1).")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    learn = commands.add_parser("learn", help="learn the must-precede relation from demonstrations (Algorithm 1)")
    learn.add_argument("demos", nargs="?",
                       help="demonstrations file (text, or demo/3 facts *.lp); default: the assembly's demos.txt")
    add_assembly_argument(learn, None, purpose="gives the parts, the default demonstrations and, with "
                          "--experiments, the cell's own orders (cell_order.lp)")
    learn.add_argument("--out", type=nonempty_path,
                       help="write part/1, must_precede/2, precedence_edge/2 facts to this .lp file")
    learn.add_argument("--dot", type=nonempty_path, help="write the transitive-reduction graph as Graphviz DOT")
    learn.add_argument("--png", type=png_path, help="draw the relation to a PNG file (FILE.png)")
    learn.add_argument("--min-support", type=int_in(1, 10**6), default=1, metavar="K",
                       help="drop a constraint only when >= K demonstrations contradict it "
                            "(default 1: plain intersection)")
    learn.add_argument("--prior", metavar="FILE",
                       help="a precedence the demonstrations refine (part/1, must_precede/2: the "
                            "geometric_precedence.lp the import subcommand writes); a demonstration breaking it "
                            "is an error; without demonstrations the prior alone is the relation")
    learn.add_argument("--experiments", metavar="FILE",
                       help="precedence experiments and their outcomes (experiments.lp, as precedence explore "
                            "writes it): learn from demonstrations, --prior and experiments, each pair with its "
                            "support (support/3 facts in --out)")
    learn.add_argument("--evidence", action="store_true",
                       help="add per-pair support/contradiction counts and suspect demonstrations "
                            "(JSON keys evidence, suspects)")
    learn.add_argument("--json", action="store_true", help="print JSON {parts, must_precede, reduction, admitted}")

    for name, text in (("count", "count the sequences a relation admits (exact)"),
                       ("enumerate", "print every admitted sequence (streaming)"),
                       ("sample", "print uniformly random admitted sequences")):
        sub = commands.add_parser(name, help=text)
        sub.add_argument("facts", nargs="*", help="facts files with part/1 and must_precede/2 (or precedence_edge/2)")
        add_assembly_argument(sub, None, purpose="use its true constraints (precedence.lp)")
        if name == "count":
            sub.add_argument("--json", action="store_true", help='print JSON {"admitted": N}')
        if name == "enumerate":
            sub.add_argument("--limit", type=non_negative_int, help="stop after this many sequences")
        if name == "sample":
            sub.add_argument("-n", type=non_negative_int, default=1, help="number of sequences (default 1)")
            sub.add_argument("--seed", type=int_in(0, MAX_SEED), default=0, help="random seed (default 0)")

    evaluate = commands.add_parser("evaluate", help="the paper's evaluation (Figs. 12/13), or --guided demonstration")
    add_assembly_argument(evaluate, None, required=True, purpose="one with true constraints (precedence.lp)")
    evaluate.add_argument("--demonstrations", default="5,7,10,15,20,30", metavar="M,...",
                          type=comma_list(number_in(strict_int, 1, 10**6), "positive integers such as 5,7,10"),
                          help="numbers m of demonstrations per trial, comma separated (default 5,7,10,15,20,30)")
    evaluate.add_argument("--trials", type=int_in(1, 10**8), default=1000, help="trials per m (default 1000)")
    evaluate.add_argument("--seed", type=int_in(0, MAX_SEED), default=0, help="random seed (default 0)")
    evaluate.add_argument("--generator", choices=sorted(GENERATORS), default="uniform",
                          help="random feasible sequences: uniform over all (the paper's; default) "
                               "or stepwise (a placeable part uniformly each step)")
    evaluate.add_argument("--guided", action="store_true",
                          help="demonstrations to the exact relation, guided vs random")
    evaluate.add_argument("--json", action="store_true", help="print JSON")
    evaluate.add_argument("--plot", type=nonempty_path, help="write the Figs. 12/13 bar charts to this PNG file")

    explore = commands.add_parser("explore", help="settle what demonstrations and geometry leave open by "
                                                  "experiments chosen by ASP (answered from the assembly's "
                                                  "precedence.lp)")
    explore.add_argument("demos", nargs="?", help="demonstrations file; default: the assembly's demos.txt")
    add_assembly_argument(explore, None, required=True, purpose="gives the parts, the truth oracle's relation "
                          "and the cell's own orders (cell_order.lp)")
    explore.add_argument("--prior", metavar="FILE", help="the geometric precedence (geometric_precedence.lp)")
    explore.add_argument("--policy", choices=("informative", "first"), default="informative",
                         help="informative: the experiment deciding the most pairs whatever its outcome (default); "
                              "first: the first candidate in part order")
    explore.add_argument("--limit", type=non_negative_int, help="run at most this many experiments")
    explore.add_argument("--experiments", type=nonempty_path, help="write the experiments and outcomes here (.lp)")
    explore.add_argument("--out", type=nonempty_path, help="write the learned facts (with support/3) here")

    suggest = commands.add_parser("suggest", help="propose the next sequence to demonstrate")
    suggest.add_argument("demos", nargs="?",
                         help="demonstrations so far, made following earlier suggestions "
                              "(none: the first suggestion; needs --assembly)")
    add_assembly_argument(suggest, None, purpose="gives the parts and the default demonstrations")
    suggest.add_argument("--seed", type=int_in(0, MAX_SEED), default=0, help="seed of the tie-breaking (default 0)")
    suggest.add_argument("--json", action="store_true", help="print JSON {suggestion, undecided}")
    return parser


def _demonstrations(args: argparse.Namespace, prior: Relation | None = None) -> Demonstrations:
    assembly = load_assembly(args.assembly) if args.assembly else None
    if args.demos is None:
        if prior is not None and (assembly is None or not assembly.has_file("demos.txt")):
            return Demonstrations(prior.parts, (), ())
        if assembly is None:
            raise PlannerError("learn: expected a demonstrations file or --assembly with demos.txt")
        return load_demos(assembly.file("demos.txt"), assembly.part_ids, assembly.hole_ids)
    return load_demos(args.demos, *((assembly.part_ids, assembly.hole_ids) if assembly else (None, None)))


def _relation(args: argparse.Namespace) -> Relation:
    if bool(args.assembly) == bool(args.facts):
        raise PlannerError(f"{args.command}: expected either --assembly A or facts files, not both or neither")
    return true_relation(load_assembly(args.assembly)) if args.assembly else load_relation(args.facts)


def _print_json(data: object) -> None:
    print(json.dumps(data))


def _learn(args: argparse.Namespace) -> None:
    from asp.precedence.draw import draw_png, to_dot
    from asp.precedence.learn import learn_must_precede, pair_evidence, suspects
    from bridge.files import check_writable, write_atomic

    for path in (args.out, args.dot, args.png):  # before the learning and the drawing
        if path:
            check_writable(path)
    prior = load_relation([args.prior], data=True) if args.prior else None
    demos = _demonstrations(args, prior)
    if args.experiments is not None:
        _learn_sources(args, demos, prior)
        return
    if prior is None:
        relation = learn_must_precede(demos, args.min_support)
    else:
        from asp.precedence.learn import learn_with_prior

        relation = learn_with_prior(demos, prior, args.prior, args.min_support)
        LOG.info("%d demonstration(s) refine the prior %s (%d pairs)", len(demos.sequences), args.prior,
                 int(prior.matrix.sum()))
    edges = reduction(relation)
    flagged = suspects(demos)
    for suspect in flagged:
        pairs = " ".join(f"{a}<{b}" for a, b in suspect.removes)
        LOG.warning("%s: this demonstration alone removes %s, which all others support", suspect.origin, pairs)
    if args.out:
        header = f"must-precede relation learned from {len(demos.sequences)} demonstrations"
        write_facts(args.out, precedence_facts(relation), header=header)
    if args.dot:
        write_atomic(args.dot, to_dot(relation, edges))
    if args.png:
        draw_png(relation, edges, args.png, title=f"learned from {len(demos.sequences)} demonstrations")
    result: dict[str, object] = {
        "parts": list(relation.parts),
        "must_precede": [list(p) for p in relation.pairs()],
        "reduction": [list(p) for p in edges],
        "admitted": count_linear_extensions(relation),
    }
    if args.evidence:
        result["evidence"] = pair_evidence(demos)
        result["suspects"] = [{"line": s.origin, "removes": [list(p) for p in s.removes]} for s in flagged]
    if args.json:
        _print_json(result)
        return
    print(relation.matrix_text())
    print("must_precede:", " ".join(f"{a}<{b}" for a, b in relation.pairs()))
    print("reduction:   ", " ".join(f"{a}<{b}" for a, b in edges))
    print("admitted:    ", result["admitted"])


def _evidence(demos: Demonstrations, prior: Relation | None, prior_file: str | None,
              experiments: str | None = None, assembly: str | None = None) -> Evidence:
    """The three sources: demonstrations, the geometric prior (and its file) and the
    experiments file, if any; with the cell's own orders of ``assembly`` (its ``cell_order.lp``)."""
    from asp.plans.assign import cell_orders
    from asp.precedence.explore.knowledge import Evidence
    from asp.precedence.explore.learner import geometric_reasons
    from asp.precedence.explore.trials import load_trials

    geometry = tuple(prior.pairs()) if prior is not None else ()
    trials = load_trials(experiments, demos.parts) if experiments else ()
    return Evidence(demos, geometry, prior_file or "the geometric precedence", geometric_reasons(prior_file),
                    trials, () if assembly is None else cell_orders(load_assembly(assembly)))


def _report(learned: Learned, out: Path | None) -> None:
    from asp.solve import write_facts

    if out:
        write_facts(out, learned.facts(), header="precedence learned from demonstrations, geometry and experiments")
    print(learned.summary())
    print("admitted:", count_linear_extensions(learned.relation))


def _learn_sources(args: argparse.Namespace, demos: Demonstrations, prior: Relation | None) -> None:
    from asp.precedence.explore.learner import learn_sources

    if args.json or args.dot or args.png or args.evidence or args.min_support != 1:
        raise PlannerError("--experiments: expected none of --json, --dot, --png, --evidence, --min-support")
    _report(learn_sources(_evidence(demos, prior, args.prior, args.experiments, args.assembly)), args.out)


def _explore(args: argparse.Namespace) -> None:
    from asp.precedence.explore.learner import learn_sources
    from asp.precedence.explore.oracle import TruthOracle
    from asp.precedence.explore.select import explore
    from asp.precedence.explore.trials import write_trials
    from bridge.files import check_writable

    for path in (args.out, args.experiments):
        if path:
            check_writable(path)
    assembly = load_assembly(args.assembly)
    prior = load_relation([args.prior], data=True) if args.prior else None
    demos = load_demos(args.demos or assembly.file("demos.txt"), assembly.part_ids, assembly.hole_ids)
    evidence = _evidence(demos, prior, args.prior, assembly=args.assembly)
    oracle = TruthOracle(true_relation(assembly))
    for _knowledge, trial in explore(evidence, oracle, args.policy, limit=args.limit):
        evidence = evidence.with_trial(trial)
        print(trial.describe())
    if args.experiments:
        write_trials(args.experiments, evidence.trials)
    print(f"{len(evidence.trials)} experiments")
    _report(learn_sources(evidence), args.out)


def _evaluate(args: argparse.Namespace) -> None:
    from bridge.files import check_writable

    if args.plot:
        check_writable(args.plot)  # before the evaluation, which may take minutes
    truth = true_relation(load_assembly(args.assembly))
    if args.guided:
        from asp.precedence.guide import evaluate_guided

        if args.generator != "uniform":
            raise PlannerError("--generator applies to the evaluation over m, not to --guided "
                               "(its random baseline is uniform)")

        result = evaluate_guided(truth, args.trials, args.seed)
        if not args.json:
            print(f"{args.trials} trials: guided mean {result['mean']:.2f} demonstrations to the exact relation, "
                  f"random {result['random_mean']:.2f}")
            print("histogram (demonstrations: trials):", result["demos_to_exact"])
    else:
        from asp.precedence.evaluate import evaluate, plot

        result = evaluate(truth, args.demonstrations, args.trials, args.seed, args.generator)
        if args.plot:
            plot(result, args.plot)
        if not args.json:
            print(f"total admitted by the true constraints: {result['total']} ({args.generator} demonstrations)")
            for r in result["results"]:
                share = 100 * r["mean"] / result["total"]
                print(f"m={r['m']:>3}: mean {r['mean']:8.1f} ({share:5.1f} %)  P(all) {r['p_all']:.3f}  "
                      f"P(> half) {r['p_more_than_half']:.3f}")
    if args.json:
        _print_json(result)


def _suggest(args: argparse.Namespace) -> None:
    from asp.precedence.guide import suggest

    parts = load_assembly(args.assembly).part_ids if args.assembly else None
    if args.demos is None and parts is None:
        raise PlannerError("suggest: expected a demonstrations file or --assembly A (for the first suggestion)")
    demos = load_demos(args.demos, parts) if args.demos else Demonstrations(tuple(parts or ()), (), ())
    guide, sequence = suggest(demos.parts, demos.sequences, args.seed)
    undecided = [(a, b) for a, b in Relation(demos.parts, guide.undecided()).pairs() if a != b]
    if args.json:
        _print_json({"suggestion": sequence, "undecided": [list(p) for p in undecided]})
    else:
        print(" ".join(sequence))
        LOG.info("%d learned pairs still undecided; place at each step the earliest listed part that can be placed",
                 len(undecided))


def main(argv: list[str]) -> int:
    args = _parser().parse_args(argv)
    if args.command == "learn":
        _learn(args)
    elif args.command == "count":
        admitted = count_linear_extensions(_relation(args))
        if args.json:
            _print_json({"admitted": admitted})
        else:
            print(admitted)
    elif args.command == "enumerate":
        for sequence in islice(linear_extensions(_relation(args)), args.limit):
            print(" ".join(sequence))
    elif args.command == "sample":
        sampler, rng = UniformSampler(_relation(args)), random.Random(args.seed)
        for _ in range(args.n):
            print(" ".join(sampler.sample(rng)))
    elif args.command == "evaluate":
        _evaluate(args)
    elif args.command in ("explore",):
        _explore(args)
    else:
        _suggest(args)
    return 0
