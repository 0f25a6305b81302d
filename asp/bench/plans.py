"""Timing of optimal plans (``./run.sh bench plan``): Cranfield, and random cells.

Prints the CPU time [s] (this process, clingo included) to prove the least total tool
travel and enumerate every optimal plan: the median of ``--repeat`` runs on Cranfield
(its true precedence and Fig. 5 sizes), then one run per random cell: ``--parts``
parts of which ``--holes`` need one of ``--holes`` holes (sizes on a line, so the
assignment may be unsolvable: then the bench says so), each pair of parts
ordered with probability 0.15, start and hole positions uniform in the cell.
"""

from __future__ import annotations

import random
import statistics
import tempfile
import time
from pathlib import Path

import clingo

from asp import MAX_IDS, PlannerError
from asp.plans.assign import LearnedFacts, load_learned_facts
from asp.plans.plans import plans, travel_facts
from asp.precedence.relation import precedence_facts, true_relation
from asp.solve import fact, load_atoms, write_facts
from bridge.assembly import Assembly, Hole, Part, load_assembly
from bridge.cli_types import ArgumentParser, finite_float, int_in


def _learned(atoms: list[clingo.Symbol]) -> LearnedFacts:
    with tempfile.TemporaryDirectory() as tmp:
        write_facts(Path(tmp) / "learned.lp", atoms)
        return load_learned_facts([Path(tmp) / "learned.lp"])


def random_cell(n_parts: int, n_holes: int, seed: int) -> tuple[LearnedFacts, Assembly]:
    """A random cell (see the module docstring) and its learned facts."""
    rng = random.Random(seed)
    parts = [f"q{i}" for i in range(n_parts)]
    holes = [f"g{i}" for i in range(n_holes)]
    hole_size = {h: rng.randint(3, 6) for h in holes}
    atoms = [fact("part", p) for p in parts] + [fact("hole", h) for h in holes]
    for part in parts[:n_holes]:
        size = rng.randint(0, max(hole_size.values()) - 1)
        atoms += [fact("fits" if size < hole_size[h] else "no_fit", part, h) for h in holes]
    order = rng.sample(parts, len(parts))
    atoms += [
        fact("must_precede", a, b)
        for i, a in enumerate(order) for b in order[i + 1:] if rng.random() < 0.15
    ]
    cell = Assembly(
        folder=Path("."), name=f"random cell {seed}",
        parts=tuple(Part(p, p, "peg", (rng.uniform(0.2, 0.7), rng.choice([-0.4, 0.4]))) for p in parts),
        holes=tuple(Hole(h, h, "round", (rng.uniform(0.5, 0.7), rng.uniform(-0.1, 0.1))) for h in holes),
    )
    return _learned(atoms), cell


def _optimal_cpu_s(facts: LearnedFacts, cell: Assembly, time_limit_s: float) -> tuple[float, str]:
    started = time.process_time()
    try:
        found = plans(facts, 0, optimal=True, travel=travel_facts(cell, facts), time_limit_s=time_limit_s)
    except PlannerError as exc:
        return time.process_time() - started, str(exc)
    return time.process_time() - started, f"{len(found)} optimal plans, {found[0].cost} mm"


def main(argv: list[str]) -> int:
    parser = ArgumentParser(prog="bench plan", description=__doc__)
    parser.add_argument("--repeat", type=int_in(1, 1000), default=5, help="Cranfield runs (default 5)")
    parser.add_argument("--parts", type=int_in(1, MAX_IDS), default=11, help="parts of a random cell (default 11)")
    parser.add_argument("--holes", type=int_in(1, MAX_IDS), default=6, help="holes of a random cell (default 6)")
    parser.add_argument("--products", type=int_in(0, 1000), default=5,
                        help="random products (a cell layout each), seeds 1.. (default 5)")
    parser.add_argument("--time-limit", type=finite_float(0, 1e6, low_open=True), default=60.0, metavar="S",
                        help="give up on a cell after S seconds (default 60)")
    args = parser.parse_args(argv)
    cranfield = load_assembly("cranfield")
    facts = _learned([*precedence_facts(true_relation(cranfield)), *load_atoms([cranfield.file("sizes.lp")])])
    runs = [_optimal_cpu_s(facts, cranfield, args.time_limit) for _ in range(args.repeat)]
    print(f"cranfield: median {statistics.median(cpu for cpu, _ in runs):.3f} s CPU ({runs[0][1]})")
    for seed in range(1, args.products + 1):
        cpu, outcome = _optimal_cpu_s(*random_cell(args.parts, args.holes, seed), args.time_limit)
        print(f"cell {seed} ({args.parts} parts, {args.holes} holes): {cpu:.3f} s CPU ({outcome})")
    return 0

