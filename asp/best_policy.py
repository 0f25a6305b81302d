"""Experiment-selection policy ``best``: split the still-possible relations most evenly.

With sizes on one line (paper 2.2, last paragraph) the relations still possible after
some experiments are exactly the biorders that contain every known fit and no known
no-fit. Each gets the prior weight ``(∏ k!)**ALPHA`` over its classes of k identical
parts (rows) and k identical holes (columns): ∏ k! counts the orders of parts and
holes on the size line inducing the relation (ALPHA = 1: sizes drawn independently;
ALPHA = 0: every relation equally likely). The policy tries the unknown pair whose
outcomes split the total weight most evenly (the most informative experiment under
that prior); ties go to the lowest part, then hole index.

ALPHA = 1/2 was chosen by measurement on all 14400 relabelings of Cranfield, where it
is the only one of 0, 1/2, 1 whose worst case stayed at 20 for index-order and four
random tie-break orders (README, "The ``best`` policy").

Three paths compute the same rule:

- exact (numpy): filter the enumeration of all m×n biorders (when there are at most
  ``EXACT_LIMIT``, e.g. 5×5) — ~ms per decision, memoised per knowledge state;
- sampled (numpy, larger instances such as 8×8 or 20×20): ``SAMPLES`` random linear
  extensions of the known smaller-than order, seeded by the knowledge state, stand in
  for the possible relations; an unknown pair the sample does not split scores 0;
- ASP (``select_best.lp``): clingo enumerates the possible relations and their classes;
  the reference path for small instances, used by the tests to check the numpy paths.
"""

from __future__ import annotations

import math
import random
from functools import lru_cache
from importlib.resources import as_file, files

import clingo
import numpy as np

from asp import PlannerError
from asp.biorders import (
    all_biorders,
    biorder_count,
    class_weights,
    consistent_index,
    mask_bits,
    sample_biorders,
)
from asp.facts import fact, format_facts
from asp.size_knowledge import Knowledge, Pair
from asp.size_policies import SelectionPolicy

ALPHA = 0.5
"""Exponent of the prior weight ∏ k! of a relation (see the module docstring)."""

EXACT_LIMIT = 400_000
"""Largest number of m×n biorders enumerated for the exact path (5×5 has 329 462)."""

SAMPLES = 1024
"""Random linear extensions drawn per decision on the sampled path."""

SCORE_DECIMALS = 9
"""Split shares are rounded so that float summation order cannot change a tie."""


def knowledge_masks(knowledge: Knowledge) -> tuple[int, int]:
    """Bit masks (bit ``p*n + h``, index order) of the pairs known to fit / not to fit."""
    n = len(knowledge.holes)
    part_index = {p: i for i, p in enumerate(knowledge.parts)}
    hole_index = {h: j for j, h in enumerate(knowledge.holes)}

    def mask(pairs: frozenset[Pair]) -> int:
        return sum(1 << (part_index[p] * n + hole_index[h]) for p, h in pairs)

    return mask(knowledge.fits), mask(knowledge.no_fit)


def smaller_matrix(m: int, n: int, fit_mask: int, no_fit_mask: int) -> np.ndarray:
    """Strict order on items (parts 0..m-1, then holes) from closed part-hole knowledge.

    p < h for a fit, h < p for a no-fit; p < q when p fits a hole q does not (eq. 2);
    h < k when a part does not fit h but fits k (eq. 3).
    """
    bits = np.array([(fit_mask >> i) & 1 for i in range(m * n)], dtype=bool).reshape(m, n)
    nobits = np.array([(no_fit_mask >> i) & 1 for i in range(m * n)], dtype=bool).reshape(m, n)
    order = np.zeros((m + n, m + n), dtype=bool)
    order[:m, m:] = bits
    order[m:, :m] = nobits.T
    order[:m, :m] = (bits[:, None, :] & nobits[None, :, :]).any(axis=2)
    order[m:, m:] = (nobits.T[:, None, :] & bits.T[None, :, :]).any(axis=2)
    return order


def split_scores(fits: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """Per column of ``fits`` (relations × candidate pairs): the smaller weight share of
    the two outcomes (0..0.5), rounded to SCORE_DECIMALS."""
    total = weights.sum()
    fit_weight = weights @ fits
    return np.round(np.minimum(fit_weight, total - fit_weight) / total, SCORE_DECIMALS)


def pick(fits: np.ndarray, weights: np.ndarray, candidates: list[int]) -> int:
    """The candidate pair (flat index ``p*n + h``) of best split score; ties go to the
    lowest index. ``fits`` has one row per possible relation, one column per pair."""
    return candidates[int(np.argmax(split_scores(fits[:, candidates], weights)))]


@lru_cache(maxsize=200_000)
def choose_bit(m: int, n: int, fit_mask: int, no_fit_mask: int) -> int:
    """The chosen pair as flat index ``p*n + h`` for closed knowledge given by its masks."""
    candidates = [i for i in range(m * n) if not ((fit_mask | no_fit_mask) >> i) & 1]
    if not candidates:
        raise PlannerError("policy best: every pair is known, nothing to choose")
    if biorder_count(m, n) <= EXACT_LIMIT:
        everything = all_biorders(m, n)
        keep = consistent_index(everything, fit_mask, no_fit_mask)
        fits, weights = mask_bits(everything[keep], m * n), _prior_weights(m, n)[keep]
    else:
        rng = np.random.default_rng([fit_mask, no_fit_mask, m, n])
        sample = sample_biorders(smaller_matrix(m, n, fit_mask, no_fit_mask), m, n, SAMPLES, rng)
        fits, weights = sample.reshape(len(sample), m * n), class_weights(sample) ** ALPHA
    if len(fits) == 0:
        raise PlannerError("policy best: no biorder agrees with the knowledge (noise left?)")
    return pick(fits, weights, candidates)


@lru_cache(maxsize=4)
def _prior_weights(m: int, n: int) -> np.ndarray:
    """Prior weight of every m×n biorder, aligned with :func:`all_biorders`."""
    masks = all_biorders(m, n)
    return class_weights(mask_bits(masks, m * n).reshape(len(masks), m, n)) ** ALPHA


def choose(knowledge: Knowledge, rng: random.Random) -> Pair:
    """The registry's chooser: the unknown pair of most even weighted split (numpy paths)."""
    del rng  # deterministic: the choice depends on the knowledge in index order only
    m, n = len(knowledge.parts), len(knowledge.holes)
    bit = choose_bit(m, n, *knowledge_masks(knowledge))
    return knowledge.parts[bit // n], knowledge.holes[bit % n]


def possible_relations_asp(knowledge: Knowledge) -> tuple[np.ndarray, np.ndarray]:
    """ASP path: masks of the possible relations (sorted) and their prior weights."""
    parts, holes = knowledge.parts, knowledge.holes
    n = len(holes)
    atoms = [fact("part", p) for p in parts] + [fact("hole", h) for h in holes]
    atoms += [fact("fits", p, h) for p, h in sorted(knowledge.fits)]
    atoms += [fact("no_fit", p, h) for p, h in sorted(knowledge.no_fit)]
    atoms += [fact("unknown", p, h) for p, h in knowledge.unknown]
    ctl = clingo.Control(["--models=0", "--warn=none"])
    ctl.add("base", [], format_facts(atoms))
    with as_file(files("asp") / "encodings" / "select_best.lp") as path:
        ctl.load(str(path))
    ctl.ground([("base", [])])
    found: dict[int, float] = {}

    def on_model(model: clingo.Model) -> None:
        mask, log_weight = 0, 0.0
        for symbol in model.symbols(shown=True):
            args = [str(a) for a in symbol.arguments]
            if symbol.name == "rel":
                mask |= 1 << (parts.index(args[0]) * n + holes.index(args[1]))
            else:
                log_weight += math.lgamma(symbol.arguments[1].number + 1)
        found[mask] = math.exp(ALPHA * log_weight)

    ctl.solve(on_model=on_model)
    masks = np.array(sorted(found), dtype=np.uint64)
    return masks, np.array([found[int(k)] for k in masks])


def choose_by_asp(knowledge: Knowledge) -> Pair:
    """The same rule as :func:`choose`, over the relations clingo enumerates."""
    n = len(knowledge.holes)
    index = {(p, h): i * n + j for i, p in enumerate(knowledge.parts) for j, h in enumerate(knowledge.holes)}
    candidates = [index[pair] for pair in knowledge.unknown]
    if not candidates:
        raise PlannerError("policy best: every pair is known, nothing to choose")
    masks, weights = possible_relations_asp(knowledge)
    bit = pick(mask_bits(masks, len(index)), weights, candidates)
    return knowledge.parts[bit // n], knowledge.holes[bit % n]


POLICY = SelectionPolicy(
    "best",
    "most even split of the possible relations (biorders), weighted (prod k!)^(1/2)",
    choose=choose,
)
