"""Experiment-selection policy ``best``: split the still-possible relations most evenly.

With sizes on one line (paper 2.2, last paragraph) the relations still possible after
some experiments are exactly the biorders that contain every known fit and no known
no-fit; under a model of several lines (:mod:`asp.sizes.models`) they are the products
of such biorders, one per section, and each section is weighed on its own. Each
biorder gets the prior weight ``(∏ k!)**ALPHA`` over its classes of k identical parts
(rows) and k identical holes (columns): ∏ k! counts the orders of parts and holes
on the size line inducing the relation (ALPHA = 1: sizes drawn independently;
ALPHA = 0: every relation equally likely). The policy tries the unknown pair whose
outcomes split the total weight most evenly (the most informative experiment under
that prior); ties go to the lowest part, then hole index.

ALPHA = 1/2 was chosen by measurement on all 14400 relabelings of Cranfield, where it
is the only one of 0, 1/2, 1 whose worst case stayed at 20 for index-order and four
random tie-break orders (docs/sizes.md, "The ``best`` policy").

Two paths compute the same rule (a third, in clingo, is the tests' reference:
``tests/select_best.lp``):

- exact (numpy): filter the enumeration of all m×n biorders (when there are at most
  ``EXACT_LIMIT``, e.g. 5×5) — ~ms per decision, memoised per knowledge state;
- sampled (numpy, larger instances such as 8×8 or 20×20): the distinct biorders among
  ``SAMPLES`` random integer size assignments that respect the known order (few size
  levels are as likely as many, so identical parts and holes are common), seeded by
  the knowledge state, stand in for the possible relations, weighted as above; an
  unknown pair the sample does not split scores 0.
"""

from __future__ import annotations

import random
from collections.abc import Sequence
from functools import lru_cache

import numpy as np

from asp import PlannerError
from asp.sizes.biorders import (
    all_biorder_orders,
    all_biorders,
    biorder_count,
    class_weights,
    consistent_index,
    mask_bits,
    sample_biorders,
    weighted_bit_sums,
)
from asp.sizes.knowledge import Knowledge, Pair
from asp.sizes.models import group_by_section
from asp.sizes.policies import SelectionPolicy

ALPHA = 0.5
"""Exponent of the prior weight ∏ k! of a relation (see the module docstring)."""

EXACT_LIMIT = 400_000
"""Largest number of m×n biorders enumerated for the exact path (5×5 has 329 462)."""

SAMPLES = 4096
"""Random size assignments drawn per decision on the sampled path."""

WEIGHT_SCALE = 1000
"""Prior weights are the integers round(WEIGHT_SCALE · (∏ k!)^ALPHA): their sums are exact
in float64 on the exact path (5×5: < 2^46) and equal clingo's ``#sum`` on the tests' ASP path."""


def knowledge_masks(knowledge: Knowledge) -> tuple[int, int]:
    """Bit masks (bit ``p*n + h``, index order) of the pairs known to fit / not to fit."""
    n = len(knowledge.holes)
    part_index = {p: i for i, p in enumerate(knowledge.parts)}
    hole_index = {h: j for j, h in enumerate(knowledge.holes)}

    def mask(pairs: frozenset[Pair]) -> int:
        return sum(1 << (part_index[p] * n + hole_index[h]) for p, h in pairs)

    return mask(knowledge.fits), mask(knowledge.no_fit)


def smaller_matrix(m: int, n: int, fit_mask: int, no_fit_mask: int) -> np.ndarray:
    """The known smaller-than order on items (parts 0..m-1, then holes), from closed
    part-hole knowledge: p < h for a fit; h < p for a no-fit (there: h ≤ p, equal sizes
    allowed); p < q when p fits a hole q does not (eq. 2); h < k when a part does not
    fit h but fits k (eq. 3).
    """
    bits = np.array([(fit_mask >> i) & 1 for i in range(m * n)], dtype=bool).reshape(m, n)
    nobits = np.array([(no_fit_mask >> i) & 1 for i in range(m * n)], dtype=bool).reshape(m, n)
    order = np.zeros((m + n, m + n), dtype=bool)
    order[:m, m:] = bits
    order[m:, :m] = nobits.T
    order[:m, :m] = (bits[:, None, :] & nobits[None, :, :]).any(axis=2)
    order[m:, m:] = (nobits.T[:, None, :] & bits.T[None, :, :]).any(axis=2)
    return order


def prior_weights(orders: np.ndarray) -> np.ndarray:
    """Integer-valued prior weights round(WEIGHT_SCALE · orders^ALPHA), orders = ∏ k!."""
    return np.rint(WEIGHT_SCALE * orders**ALPHA)


def pick(fit_weight: np.ndarray, total: float, candidates: list[int]) -> int:
    """The candidate pair (flat index ``p*n + h``) whose lighter outcome weighs most;
    ties go to the lowest index. ``fit_weight[i]``: weight of the relations where pair
    i fits; ``total``: weight of all possible relations."""
    lighter = np.minimum(fit_weight[candidates], total - fit_weight[candidates])
    return candidates[int(np.argmax(lighter))]


@lru_cache(maxsize=200_000)
def split_weights(m: int, n: int, fit_mask: int, no_fit_mask: int) -> tuple[np.ndarray, float]:
    """Per pair (flat index ``p*n + h``) the weight of the possible relations in which it
    fits, and the total weight of the possible relations, for the knowledge given by its
    masks (exact or sampled path; the masks may add hypothetical outcomes to closed
    knowledge on the exact path)."""
    if biorder_count(m, n) <= EXACT_LIMIT:
        keep = consistent_index(all_biorders(m, n), fit_mask, no_fit_mask)
        weights = _prior_weights(m, n)[keep]
        fit_weight = weighted_bit_sums(all_biorders(m, n)[keep], weights, m * n)
    else:
        weights = _sampled(m, n, fit_mask, no_fit_mask)[1]
        fit_weight = _weighted_sample(m, n, fit_mask, no_fit_mask).sum(axis=0)
    return fit_weight, float(weights.sum())


@lru_cache(maxsize=16)
def _sampled(m: int, n: int, fit_mask: int, no_fit_mask: int) -> tuple[np.ndarray, np.ndarray]:
    """The sampled path's stand-in for the possible relations: a (k, m*n) boolean matrix
    (bit ``p*n + h``: p fits h) and the prior weights, drawn with a generator seeded by
    the knowledge, so the same knowledge always gets the same sample (drawn once: a
    decision and the batch ranking beside it share it; read-only)."""
    rng = np.random.default_rng([fit_mask, no_fit_mask, m, n])
    sample = sample_biorders(smaller_matrix(m, n, fit_mask, no_fit_mask), m, n, SAMPLES, rng)
    relations, weights = sample.reshape(len(sample), m * n), prior_weights(class_weights(sample))
    for array in (relations, weights):
        array.setflags(write=False)
    return relations, weights


@lru_cache(maxsize=4)
def _weighted_sample(m: int, n: int, fit_mask: int, no_fit_mask: int) -> np.ndarray:
    """The rows of :func:`_sampled`, each multiplied by its weight (float64, read-only):
    the decision and every batch ranking beside it sum them."""
    relations, weights = _sampled(m, n, fit_mask, no_fit_mask)
    weighted = relations * weights[:, None]
    weighted.setflags(write=False)
    return weighted


@lru_cache(maxsize=200_000)
def choose_bit(m: int, n: int, fit_mask: int, no_fit_mask: int) -> int:
    """The chosen pair as flat index ``p*n + h`` for closed knowledge given by its masks."""
    candidates = [i for i in range(m * n) if not ((fit_mask | no_fit_mask) >> i) & 1]
    if not candidates:
        raise PlannerError("policy best: every pair is known, nothing to choose")
    fit_weight, total = split_weights(m, n, fit_mask, no_fit_mask)
    if total == 0:
        raise PlannerError("policy best: no biorder agrees with the knowledge (noise left?)")
    return pick(fit_weight, total, candidates)


@lru_cache(maxsize=4)
def _prior_weights(m: int, n: int) -> np.ndarray:
    """Prior weight of every m×n biorder, aligned with :func:`all_biorders`."""
    return prior_weights(all_biorder_orders(m, n))


def section_knowledge(knowledge: Knowledge) -> list[Knowledge]:
    """The knowledge of each section's parts (with every hole), in the parts' order.

    The size model's relations are independent across sections, so the possible
    relations are products of each section's possible biorders: an experiment splits
    the weight of its own section only, and its split is best compared as a share of
    that section's total weight.
    """
    groups = group_by_section({part: knowledge.section_of(part) for part in knowledge.parts})
    if len(groups) == 1:
        return [knowledge]
    return [knowledge.restricted(parts) for parts in groups.values()]


def choose(knowledge: Knowledge, rng: random.Random) -> Pair:
    """The registry's chooser: the unknown pair of most even weighted split (numpy paths),
    per section as a share of the section's weight (:func:`section_knowledge`)."""
    del rng  # deterministic: the choice depends on the knowledge in index order only
    sections = section_knowledge(knowledge)
    if len(sections) == 1:
        m, n = len(knowledge.parts), len(knowledge.holes)
        bit = choose_bit(m, n, *knowledge_masks(knowledge))
        return knowledge.parts[bit // n], knowledge.holes[bit % n]
    order = {pair: i for i, pair in enumerate((p, h) for p in knowledge.parts for h in knowledge.holes)}
    scored: list[tuple[float, int, Pair]] = []
    for sub in sections:
        m, n = len(sub.parts), len(sub.holes)
        fit_mask, no_fit_mask = knowledge_masks(sub)
        if not sub.unknown:
            continue
        fit_weight, total = split_weights(m, n, fit_mask, no_fit_mask)
        if total == 0:
            raise PlannerError("policy best: no biorder agrees with the knowledge (noise left?)")
        for part, hole in sub.unknown:
            w = float(fit_weight[sub.parts.index(part) * n + sub.holes.index(hole)])
            scored.append((-min(w, total - w) / total, order[(part, hole)], (part, hole)))
    if not scored:
        raise PlannerError("policy best: every pair is known, nothing to choose")
    return min(scored)[2]


def possible_relations(m: int, n: int, fit_mask: int, no_fit_mask: int) -> tuple[np.ndarray, np.ndarray]:
    """The possible relations as a (k, m*n) boolean matrix (bit ``p*n + h``: p fits h) and
    their prior weights: every consistent biorder on the exact path, the sample on the
    sampled path (as :func:`split_weights`)."""
    if biorder_count(m, n) <= EXACT_LIMIT:
        keep = consistent_index(all_biorders(m, n), fit_mask, no_fit_mask)
        return mask_bits(all_biorders(m, n)[keep], m * n), _prior_weights(m, n)[keep]
    return _sampled(m, n, fit_mask, no_fit_mask)


def batch_rank(knowledge: Knowledge, pending: Sequence[Pair] = ()) -> list[Pair]:
    """Unknown pairs not in ``pending`` (pairs out at other cells), best first to run
    beside them: by the weight of the lighter outcome summed over the outcome
    combinations of the pending pairs, i.e. the expected split once their results are
    known too (without pending pairs, the split :func:`choose` maximises), as a share of
    the pair's section weight; ties go to the lowest index. The possible relations are
    grouped by the outcomes they give the pending pairs of the section (one pass,
    however many pending pairs; on the sampled path one sample serves every group).
    Scores only; whether a pair is independent of the others is the learner's check.
    """
    order = {pair: i for i, pair in enumerate((p, h) for p in knowledge.parts for h in knowledge.holes)}
    share: dict[Pair, float] = {}
    for sub in section_knowledge(knowledge):
        m, n = len(sub.parts), len(sub.holes)
        index = {(p, h): i * n + j for i, p in enumerate(sub.parts) for j, h in enumerate(sub.holes)}
        masks = knowledge_masks(sub)
        relations, weights = possible_relations(m, n, *masks)
        weighted = (relations * weights[:, None] if biorder_count(m, n) <= EXACT_LIMIT
                    else _weighted_sample(m, n, *masks))
        mine = [index[pair] for pair in pending if pair in index]
        columns = np.array([index[pair] for pair in sub.unknown], dtype=np.int64)  # only unknown pairs score
        score = np.zeros(len(columns))
        if len(relations) and len(columns):
            if len(mine) < 63:  # the outcomes of the pending pairs as the bits of one integer
                groups = relations[:, mine].astype(np.int64) @ (np.int64(1) << np.arange(len(mine), dtype=np.int64))
            else:
                groups = np.unique(relations[:, mine], axis=0, return_inverse=True)[1].reshape(-1)
            # the relations sorted by group, each group's rows summed in one pass
            by_group = np.argsort(groups, kind="stable")
            starts = np.flatnonzero(np.r_[True, np.diff(groups[by_group]) != 0])
            fit_weight = np.add.reduceat(weighted[np.ix_(by_group, columns)], starts, axis=0)
            group_weight = np.add.reduceat(weights[by_group], starts)
            score = np.minimum(fit_weight, group_weight[:, None] - fit_weight).sum(axis=0)
        total = float(weights.sum()) or 1.0
        share.update({pair: float(value) / total for pair, value in zip(sub.unknown, score)})
    candidates = [pair for pair in knowledge.unknown if pair not in pending]
    return sorted(candidates, key=lambda pair: (-share[pair], order[pair]))


def prepare(m: int, n: int) -> None:
    """Build the m×n biorder table, its prior weights and the opening choice (no
    knowledge yet, the heaviest split to compute) once, on the exact path only (~0.1 s
    at 5×5), so that no decision pays for them."""
    if biorder_count(m, n) <= EXACT_LIMIT:
        choose_bit(m, n, 0, 0)


POLICY = SelectionPolicy(
    "best",
    "most even split of the possible relations (biorders), weighted (prod k!)^(1/2)",
    choose=choose,
    batch_rank=batch_rank,
    prepare=prepare,
)
