"""``./run.sh sizes learn|evaluate``: which part fits which hole (paper 2.2, 4.2).

``learn`` runs one learning session against a truth oracle and prints the experiments
(``--json``: the contract of docs/cli.md), optionally writing the learned facts (``--out``);
``--demos FILE`` starts it from the fits the demonstrations show (``p1@r1``).
``evaluate`` counts the experiments a policy needs over relabelings of an assembly.
Both take ``--noise P`` (answers flipped with probability P) and ``--confirm K`` (re-test
each essential observation until its result leads by K+1 answers; docs/sizes.md, "Noise").
"""

from __future__ import annotations

import argparse
import json
import sys

from assembly_constraints.asp import PlannerError
from assembly_constraints.asp.precedence.demos import load_demos
from assembly_constraints.asp.sizes.cad_prior import MAX_TOLERANCE_M, NOMINAL_FILE, cad_prior, prior_text
from assembly_constraints.asp.sizes.evaluate import evaluate_policy, plot_comparison
from assembly_constraints.asp.sizes.knowledge import Knowledge
from assembly_constraints.asp.sizes.learner import MAX_CONFIRM, Experiment, LearningOptions, learn_sizes
from assembly_constraints.asp.sizes.models import MODELS, SizeModel, model_for
from assembly_constraints.asp.sizes.policies import get_policy, policy_names
from assembly_constraints.asp.sizes.truth_oracle import NoisyOracle, Oracle, Result, TruthOracle
from assembly_constraints.asp.solve import write_facts
from assembly_constraints.bridge.assembly import load_assembly
from assembly_constraints.bridge.cli_types import (
    MAX_SEED,
    ArgumentParser,
    add_assembly_argument,
    comma_list,
    int_in,
    nonempty_path,
    number_in,
)


def _truth(args: argparse.Namespace) -> TruthOracle:
    if args.truth:
        return TruthOracle.from_facts(args.truth)
    return TruthOracle.from_assembly(args.assembly)


def _add_truth_options(parser: argparse.ArgumentParser) -> None:
    source = parser.add_mutually_exclusive_group(required=True)
    add_assembly_argument(source, None, purpose="the truth is its sizes.lp")
    source.add_argument("--truth", metavar="FILE.lp", help="truth facts: part/1, hole/1, fits/2 (closed world)")


def _probability(text: str) -> float:
    """A flip probability in [0, 0.5)."""
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not 0.0 <= value < 0.5:
        raise argparse.ArgumentTypeError(f"{text!r}: expected a probability in [0, 0.5)")
    return value


def add_model_option(parser: argparse.ArgumentParser) -> None:
    """``--model``: the size model (default: the product's declared one, else sections)."""
    parser.add_argument("--model", choices=MODELS, default=None,
                        help="size model: line (the paper's one size line), sections (one line per "
                             "cross-section), pairs (nothing entailed); default: the product's [sizes] "
                             "model, else sections (docs/sizes.md)")


def add_prior_options(parser: argparse.ArgumentParser) -> None:
    """``--prior cad`` and ``--tolerance T`` [m]: the size prior from the nominal CAD
    (:mod:`assembly_constraints.asp.sizes.cad_prior`); :func:`check_prior_options` refuses a tolerance alone."""
    parser.add_argument("--prior", choices=["cad"],
                        help="cad: start from the outcomes the nominal cross-sections decide beyond --tolerance "
                             "(the assembly's nominal_sizes.lp, written by the import subcommand)")
    parser.add_argument("--tolerance", type=number_in(float, 0.0, MAX_TOLERANCE_M), default=0.0, metavar="T",
                        help="with --prior cad: margins within T [m] of zero are left to the experiments (default 0)")


def check_prior_options(args: argparse.Namespace) -> None:
    """PlannerError when ``--tolerance`` is given without ``--prior cad``."""
    if args.prior is None and args.tolerance:
        raise PlannerError("--tolerance applies to --prior cad only")


def _model(args: argparse.Namespace, truth: TruthOracle) -> SizeModel:
    return model_for(truth.parts, args.model, truth.declared_model, truth.declared_sections)


def _add_noise_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--noise", type=_probability, default=0.0, metavar="P",
                        help="probability that an answer is flipped (simulated noise; default 0)")
    parser.add_argument("--confirm", type=int_in(0, MAX_CONFIRM), default=0, metavar="K",
                        help="once every pair is known, re-test each essential observation (its pair "
                             "unknown without it) until its result leads the other by K+1 answers "
                             "(default 0: no confirmation)")


def _parser() -> argparse.ArgumentParser:
    parser = ArgumentParser(prog="sizes", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    learn = sub.add_parser("learn", help="learn the relation from a truth by experiments")
    _add_truth_options(learn)
    learn.add_argument("--policy", choices=policy_names(), default="heuristic",
                       help="experiment selection (default heuristic)")
    learn.add_argument("--seed", type=int_in(0, MAX_SEED), default=0,
                       help="seed of random choices and noise (default 0)")
    add_model_option(learn)
    add_prior_options(learn)
    learn.add_argument("--demos", metavar="FILE",
                       help="demonstrations; the parts they place into holes (p1@r1) are fits to start from")
    _add_noise_options(learn)
    learn.add_argument("--out", metavar="FILE.lp", type=nonempty_path,
                       help="write learned facts (tried/4, smaller/2, fits/2, no_fit/2)")
    learn.add_argument("--json", action="store_true", help="print JSON")
    evaluate = sub.add_parser("evaluate", help="experiments needed over relabelings of parts and holes")
    _add_truth_options(evaluate)
    evaluate.add_argument("--policy", choices=policy_names(), required=True, help="the policy to evaluate")
    evaluate.add_argument("--relabelings", default="all", metavar="all|N",
                          help="every relabeling (default) or N random ones")
    evaluate.add_argument("--seed", type=int_in(0, MAX_SEED), default=0,
                          help="seed of relabelings, random choices, noise")
    _add_noise_options(evaluate)
    evaluate.add_argument("--json", action="store_true", help="print JSON")
    evaluate.add_argument("--plot", metavar="FILE.png", type=nonempty_path, help="Fig. 19-style comparison plot")
    evaluate.add_argument("--compare", default="random", metavar="P,...",
                          type=comma_list(str, "policy names", allow_empty=True),
                          help="policies drawn beside --policy in the plot (default random)")
    return parser


def _print_matrix(knowledge: Knowledge) -> None:
    width = max(len(x) for x in (*knowledge.parts, *knowledge.holes)) + 1
    print("part/hole".ljust(width + 2) + "".join(h.rjust(width) for h in knowledge.holes))
    for part, row in zip(knowledge.parts, knowledge.matrix()):
        cells = "".join(("?" if v is None else str(v)).rjust(width) for v in row)
        print(part.ljust(width + 2) + cells)


def demonstrated_fits(path: str, assembly: str | None) -> list[tuple[str, str]]:
    """The (part, hole) placements of the demonstrations in ``path``, checked against the
    parts and holes of ``assembly`` when given."""
    folder = load_assembly(assembly) if assembly else None
    demos = load_demos(path, folder.part_ids if folder else None, folder.hole_ids if folder else None)
    return demos.placements()


def _cad_prior(args: argparse.Namespace, truth: TruthOracle) -> list[tuple[tuple[str, str], Result]]:
    """The outcomes ``--prior cad`` decides (none without it); PlannerError without an
    assembly folder holding nominal_sizes.lp."""
    check_prior_options(args)
    if args.prior is None:
        return []
    if not args.assembly:
        raise PlannerError(f"--prior cad: expected --assembly A with {NOMINAL_FILE} (./run.sh import writes it)")
    return cad_prior(load_assembly(args.assembly), args.tolerance, truth.parts, truth.holes)


def _learn(args: argparse.Namespace) -> int:
    truth = _truth(args)
    model = _model(args, truth)
    demonstrated = demonstrated_fits(args.demos, args.assembly) if args.demos else []
    prior = _cad_prior(args, truth)
    oracle: Oracle = NoisyOracle(truth, args.noise, args.seed) if args.noise else truth
    if not args.json:
        print(f"assumes: {model.assumption()}")

    def show(experiment: Experiment, _knowledge: Knowledge) -> None:
        if not args.json:
            note = " (re-test)" if experiment.retest else ""
            print(f"{experiment.number:3d}: {experiment.part} -> {experiment.hole}: {experiment.result}{note}")

    if demonstrated and not args.json:
        print(f"starting from {len(demonstrated)} fits seen in the demonstrations: "
              + " ".join(f"{p}->{h}" for p, h in demonstrated))
    if prior and not args.json:
        print(prior_text(prior, args.tolerance, len(truth.parts) * len(truth.holes)))
    options = LearningOptions(confirm=args.confirm, demonstrated=demonstrated, model=model, prior=prior)
    result = learn_sizes(truth.parts, truth.holes, oracle, args.policy, args.seed, show, options)
    saved = None
    if args.prior:
        # The same session without the prior, against the same truth (and noise seed):
        # what the prior saved is the difference.
        again: Oracle = NoisyOracle(truth, args.noise, args.seed) if args.noise else truth
        without_prior = LearningOptions(confirm=args.confirm, demonstrated=demonstrated, model=model)
        saved = learn_sizes(truth.parts, truth.holes, again, args.policy, args.seed,
                            options=without_prior).count - result.count
        if not args.json:
            print(f"the CAD prior saved {saved} experiments (same policy, seed and truth without it)")
    if not args.json:
        for change in result.model_changes:
            print(f"model changed: {change}")
    if args.out:
        write_facts(args.out, result.facts(), header=f"learned by `sizes learn --policy {args.policy}`\n"
                                                      f"assumes: {result.model.assumption()}")
    if args.json:
        print(json.dumps({
            "policy": args.policy,
            "model": result.model.name,
            "assumption": result.model.assumption(),
            "model_changes": list(result.model_changes),
            "experiments": [e.as_json() for e in result.experiments],
            "count": result.count,
            "fits": [[p, h] for p in truth.parts for h in truth.holes if (p, h) in result.knowledge.fits],
            **({"demonstrated": [list(pair) for pair in result.demonstrated]} if args.demos else {}),
            **({"prior": [[p, h, r] for (p, h), r in result.prior], "saved": saved} if args.prior else {}),
        }))
    else:
        retests = sum(e.retest for e in result.experiments)
        print(f"{result.count} experiments ({retests} re-tests) with policy {args.policy}; "
              "learned relation (1 = fits):")
        _print_matrix(result.knowledge)
    return 0


def _evaluate(args: argparse.Namespace) -> int:
    from assembly_constraints.bridge.files import check_writable

    if args.plot:
        check_writable(args.plot)  # before the evaluation, which may take minutes
    truth = _truth(args)
    relabelings: str | int = args.relabelings
    if relabelings != "all":
        if not str(relabelings).isdigit() or int(relabelings) < 1:
            raise PlannerError(f"--relabelings {relabelings}: expected 'all' or a positive integer")
        relabelings = int(relabelings)
    options = {"confirm": args.confirm, "noise": args.noise}
    evaluation = evaluate_policy(truth, args.policy, relabelings, args.seed, **options)
    report = evaluation.as_json()
    if args.plot:
        others = [p for p in args.compare if p != args.policy]
        for name in others:
            get_policy(name)
        evaluations = [evaluation] + [evaluate_policy(truth, p, relabelings, args.seed, **options)
                                      for p in others]
        plot_comparison(evaluations, args.plot)
    if args.json:
        print(json.dumps(report))
    else:
        print(f"policy {args.policy} over {report['cases']} relabelings: mean {report['mean']:.2f}, "
              f"min {report['min']} ({100 * report['min_share']:.2f} %), "
              f"max {report['max']} ({100 * report['max_share']:.2f} %)")
        print("histogram (experiments: cases): " + ", ".join(f"{n}: {c}" for n, c in report["histogram"].items()))
        if args.noise:
            print(f"noise {args.noise}, confirm {args.confirm}: wrong relation in {report['wrong']} of "
                  f"{report['cases']} cases ({100 * report['wrong_share']:.1f} %)")
        if args.plot:
            print(f"plot written to {args.plot}", file=sys.stderr)
    return 0


def main(argv: list[str]) -> int:
    args = _parser().parse_args(argv)
    return _learn(args) if args.command == "learn" else _evaluate(args)
