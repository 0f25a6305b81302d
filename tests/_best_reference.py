"""The ASP reference path of the ``best`` policy (``select_best.lp`` beside this file).

clingo enumerates the possible relations and their classes (program part ``base``), then
sums the weights per pair and selects (part ``split``); exact for small instances (total
weight < 2^31, e.g. 4x4). The tests check the numpy paths of :mod:`asp.sizes.best`
against it.
"""

from __future__ import annotations

import math
from pathlib import Path

import clingo
import numpy as np

from asp import PlannerError
from asp.sizes.best import ALPHA, WEIGHT_SCALE
from asp.sizes.knowledge import Knowledge, Pair
from asp.solve import fact, format_facts

ENCODING = Path(__file__).with_name("select_best.lp")
ASP_WEIGHT_LIMIT = 2**31 - 1
"""clingo integers are 32 bit: this path handles total weights up to this (4x4: ~10^8)."""


def possible_relations_asp(knowledge: Knowledge) -> tuple[np.ndarray, np.ndarray]:
    """ASP path, part ``base``: masks of the possible relations (sorted), prior weights."""
    parts, holes = knowledge.parts, knowledge.holes
    n = len(holes)
    atoms = [fact("part", p) for p in parts] + [fact("hole", h) for h in holes]
    atoms += [fact("fits", p, h) for p, h in sorted(knowledge.fits)]
    atoms += [fact("no_fit", p, h) for p, h in sorted(knowledge.no_fit)]
    atoms += [fact("unknown", p, h) for p, h in knowledge.unknown]
    ctl = clingo.Control(["--models=0", "--warn=none"])
    ctl.add("base", [], format_facts(atoms) + ENCODING.read_text(encoding="utf-8"))
    ctl.ground([("base", [])])
    found: dict[int, float] = {}

    def on_model(model: clingo.Model) -> None:
        mask, orders = 0, 1
        for symbol in model.symbols(shown=True):
            args = [str(a) for a in symbol.arguments]
            if symbol.name == "rel":
                mask |= 1 << (parts.index(args[0]) * n + holes.index(args[1]))
            else:
                orders *= math.factorial(symbol.arguments[1].number)
        found[mask] = round(WEIGHT_SCALE * orders**ALPHA)

    ctl.solve(on_model=on_model)
    masks = np.array(sorted(found), dtype=np.uint64)
    return masks, np.array([found[int(k)] for k in masks], dtype=np.float64)


def choose_by_asp(knowledge: Knowledge) -> Pair:
    """The same rule as :func:`choose`, entirely in clingo: part ``base`` enumerates the
    possible relations, part ``split`` sums their weights per pair and selects."""
    if not knowledge.unknown:
        raise PlannerError("policy best: every pair is known, nothing to choose")
    masks, weights = possible_relations_asp(knowledge)
    if weights.sum() > ASP_WEIGHT_LIMIT:
        raise PlannerError(f"policy best: total weight {weights.sum():.0f} exceeds clingo's "
                           f"integers ({ASP_WEIGHT_LIMIT}); use the numpy path")
    parts, holes = knowledge.parts, knowledge.holes
    n = len(holes)
    atoms = [fact("unknown", p, h) for p, h in knowledge.unknown]
    atoms += [fact("part_index", p, i) for i, p in enumerate(parts, 1)]
    atoms += [fact("hole_index", h, j) for j, h in enumerate(holes, 1)]
    for r, (mask, weight) in enumerate(zip(masks.tolist(), weights.tolist())):
        atoms.append(fact("weight", r, int(weight)))
        atoms += [fact("holds", r, parts[i // n], holes[i % n]) for i in range(len(parts) * n) if mask >> i & 1]
    ctl = clingo.Control(["--warn=none"])
    ctl.add("split", [], format_facts(atoms))
    ctl.add("base", [], ENCODING.read_text(encoding="utf-8"))
    ctl.ground([("split", [])])
    selected: list[Pair] = []
    ctl.solve(on_model=lambda m: selected.extend(
        (str(s.arguments[0]), str(s.arguments[1])) for s in m.symbols(shown=True) if s.name == "select"))
    if len(selected) != 1:
        raise PlannerError(f"policy best: the ASP split selected {selected}, expected one pair")
    return selected[0]
