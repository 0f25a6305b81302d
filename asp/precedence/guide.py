"""Guided demonstration (beyond the paper, its future work): suggest the next sequence.

Protocol: the demonstrator follows a suggested order, placing at each step the
earliest suggested part that can be placed (:func:`teacher_order` simulates this).
Then the part suggested last is placed as late as possible: every part still
missing at that moment truly succeeds it. More generally, when part x is placed, a
part z suggested before x but not yet placed truly succeeds x unless z may succeed
one of the not-yet-placed parts suggested after x (the learned relation bounds what
"may" means, since it contains the true one).

So a suggestion *tests* a learned pair (x, z) for sure when z comes before x and z
may not succeed anything suggested after x: the demonstration either reverses the
pair (Algorithm 1 drops it) or proves it true. :class:`Guide` keeps the learned
relation and the proven pairs and builds each suggestion from the back, putting last
the part with the most untested pairs tested for sure (ties: most untested pairs
overall, then a seeded random choice). Suggestions depend only on the earlier
demonstrations and the seed, so replaying a demonstrations file reproduces them.
"""

from __future__ import annotations

import random
from collections.abc import Sequence
from typing import Any

import numpy as np

from asp.precedence.batches import ExtensionBatches, positions_of
from asp.precedence.decompose import predecessor_masks, transitive_closure
from asp.precedence.relation import Relation
from bridge.progress import progress


def teacher_order(suggestion: Sequence[int], truth: Relation) -> list[int]:
    """The simulated teacher: at each step the earliest suggested part that can be placed."""
    masks = predecessor_masks(truth.matrix)
    remaining, placed, order = list(suggestion), 0, []
    while remaining:
        for k, x in enumerate(remaining):
            if not masks[x] & ~placed:
                order.append(remaining.pop(k))
                placed |= 1 << x
                break
        else:
            raise ValueError("the true relation has a cycle")
    return order


class Guide:
    """Learned relation, proven pairs and the next suggestion (part indices)."""

    def __init__(self, parts: Sequence[str], seed: int = 0) -> None:
        self.parts = tuple(parts)
        n = len(self.parts)
        self.learned = np.ones((n, n), dtype=bool)  # Algorithm 1 with no demonstration
        self.proven = np.zeros((n, n), dtype=bool)
        self.demonstrations = 0
        self.seed = seed
        self._suggestion: list[int] | None = None

    def undecided(self) -> np.ndarray:
        """Learned pairs neither reversed by a demonstration nor proven true."""
        return self.learned & ~self.proven

    def suggestion(self) -> list[int]:
        """The order to suggest next (part indices), fixed until the next observation."""
        if self._suggestion is None:
            self._suggestion = self._build()
        return self._suggestion

    def _build(self) -> list[int]:
        rng = random.Random(f"{self.seed}:{self.demonstrations}")
        n, open_pairs = len(self.parts), self.undecided()
        remaining, later = list(range(n)), np.zeros(n, dtype=bool)
        may_follow_later = np.zeros(n, dtype=bool)
        backwards = []
        while remaining:
            candidates = open_pairs[remaining] & ~later
            sure = (candidates & ~may_follow_later).sum(axis=1)
            keys = [(int(s), int(c), rng.random()) for s, c in zip(sure, candidates.sum(axis=1))]
            x = remaining.pop(max(range(len(remaining)), key=keys.__getitem__))
            backwards.append(x)
            later[x] = True
            may_follow_later |= self.learned[x]
        return backwards[::-1]

    def observe(self, order: Sequence[int]) -> None:
        """Learn from a demonstration (part indices) made after the current suggestion."""
        suggestion = self.suggestion()
        rank = np.empty(len(self.parts), dtype=np.int64)
        rank[suggestion] = np.arange(len(self.parts))
        placed = np.zeros(len(self.parts), dtype=bool)
        for x in order:
            waiting_after = ~placed & (rank > rank[x])
            may_follow = self.learned[waiting_after].any(axis=0)
            self.proven[x] |= ~placed & (rank < rank[x]) & ~may_follow & self.learned[x]
            placed[x] = True
        position = np.empty(len(self.parts), dtype=np.int64)
        position[list(order)] = np.arange(len(self.parts))
        self.learned &= position[:, None] < position[None, :]
        self.proven = transitive_closure(self.proven) & self.learned
        self.demonstrations += 1
        self._suggestion = None


def suggest(parts: Sequence[str], sequences: Sequence[Sequence[str]], seed: int = 0) -> tuple[Guide, list[str]]:
    """Replay the demonstrations through a :class:`Guide`; return it and the next suggestion."""
    guide = Guide(parts, seed)
    index = {p: i for i, p in enumerate(parts)}
    for sequence in sequences:
        guide.observe([index[p] for p in sequence])
    return guide, [guide.parts[i] for i in guide.suggestion()]


def guided_demonstrations(truth: Relation, seed: int) -> int:
    """Demonstrations a simulated teacher following the guide needs until exact."""
    guide = Guide(truth.parts, seed)
    while not np.array_equal(guide.learned, truth.matrix):
        guide.observe(teacher_order(guide.suggestion(), truth))
    return guide.demonstrations


def random_demonstrations(batches: ExtensionBatches, trials: int, rng: np.random.Generator) -> np.ndarray:
    """Per trial, uniformly random demonstrations needed until exact (int array (trials,))."""
    truth = batches.relation.matrix
    learned = np.ones((trials, *truth.shape), dtype=bool)
    needed = np.zeros(trials, dtype=np.int64)
    active = np.arange(trials)
    while active.size:
        orders = batches.sample_orders(rng, active.size)
        position = positions_of(orders)
        learned[active] &= position[:, :, None] < position[:, None, :]
        needed[active] += 1
        active = active[np.any(learned[active] != truth, axis=(1, 2))]
    return needed


def evaluate_guided(truth: Relation, trials: int, seed: int) -> dict[str, Any]:
    """``{"total", "demos_to_exact", "mean", "random_mean"}`` over ``trials`` simulated teachers.

    ``demos_to_exact`` maps a number of demonstrations to how many guided trials
    needed exactly that many; ``random_mean`` is measured in the same run with
    uniformly random feasible demonstrations.
    """

    batches = ExtensionBatches(truth)
    rng = np.random.default_rng(seed)
    guided = [guided_demonstrations(truth, seed * 1_000_003 + t)
              for t in progress(range(trials), desc="guided trials", total=trials)]
    histogram = np.bincount(guided)
    return {
        "total": batches.total,
        "demos_to_exact": {str(k): int(c) for k, c in enumerate(histogram) if c},
        "mean": float(np.mean(guided)),
        "random_mean": float(np.mean(random_demonstrations(batches, trials, rng))),
    }
