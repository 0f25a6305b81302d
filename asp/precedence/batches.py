"""Vectorised sampling and counting over the down-sets of one fixed poset.

The paper's evaluation (4.1) draws thousands of random feasible sequences and counts
the sequences each learned relation admits. Every learned relation contains the true
one (paper eq. 10), so its down-sets are down-sets of the true poset: one table of the
true poset's down-sets serves all trials, and counting becomes a few numpy operations
per layer of that table, batched over trials. Counts are int64 (exact while the true
poset admits fewer than 2**63 sequences).
"""

from __future__ import annotations

import numpy as np

from asp import PlannerError
from asp.precedence.count import DownSets, down_sets
from asp.precedence.decompose import predecessor_masks
from asp.precedence.relation import Relation

_INT64_LIMIT = 2**62

GENERATORS: dict[str, str] = {
    "uniform": "every feasible sequence equally likely (the paper's evaluation)",
    "stepwise": "each step, a part whose predecessors are placed, uniformly (a naive demonstrator)",
}


class ExtensionBatches:
    """Random sampling of a poset's sequences and counting of its refinements, in batches."""

    def __init__(self, relation: Relation) -> None:
        self.relation = relation
        self.table: DownSets = down_sets(predecessor_masks(relation.matrix))
        total = self.table.completions[0]
        if total == 0:
            raise PlannerError("the true relation admits no sequence (it has a cycle)")
        if total >= _INT64_LIMIT:
            raise PlannerError(f"the relation admits {total} sequences; the evaluation handles fewer than 2**62")
        self.total = total
        nxt = self.table.nxt
        completions = np.array(self.table.completions, dtype=np.int64)
        # Per down-set, cumulative weights of the parts that can be placed next: the
        # completions after placing them (uniform over sequences) or 1 each (stepwise).
        self._cumulative = {
            "uniform": np.cumsum(np.where(nxt >= 0, completions[nxt], 0), axis=1),
            "stepwise": np.cumsum(nxt >= 0, axis=1),
        }
        source, part = np.nonzero(nxt >= 0)
        target = nxt[source, part]
        order = np.lexsort((target, source))  # sources are grouped by layer already
        self._source, self._part, self._target = source[order], part[order], target[order]
        self._state_masks = np.array(self.table.states, dtype=np.uint64)
        sizes = np.array([bin(s).count("1") for s in self.table.states])
        self._layers = [self._layer(np.nonzero(sizes[self._source] == k)[0]) for k in range(len(relation.parts))]

    def _layer(self, edges: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Edges of one layer sorted by target, with reduceat starts and unique targets."""
        edges = edges[np.argsort(self._target[edges], kind="stable")]
        targets = self._target[edges]
        starts = np.flatnonzero(np.r_[True, targets[1:] != targets[:-1]])
        return edges, starts, targets[starts]

    def sample_orders(self, rng: np.random.Generator, count: int, generator: str = "uniform") -> np.ndarray:
        """``count`` random feasible sequences as part indices, shape (count, n).

        ``generator`` is a key of :data:`GENERATORS`: ``uniform`` draws every feasible
        sequence with probability 1/total; ``stepwise`` places, at each step, one of the
        currently placeable parts uniformly (sequences are then not equally likely).
        """
        if generator not in GENERATORS:
            raise PlannerError(f"generator '{generator}': expected one of {', '.join(GENERATORS)}")
        cumulative = self._cumulative[generator]
        n = len(self.relation.parts)
        state = np.zeros(count, dtype=np.int64)
        orders = np.empty((count, n), dtype=np.int16)
        for step in range(n):
            pick = rng.integers(0, cumulative[state, -1])
            part = np.argmax(cumulative[state] > pick[:, None], axis=1)
            orders[:, step] = part
            state = self.table.nxt[state, part]
        return orders

    def count(self, learned: np.ndarray) -> np.ndarray:
        """Sequences admitted by each relation ``learned[t]`` (bool (T, n, n)), int64 (T,).

        Each learned relation must contain the table's relation (PlannerError if not).
        """
        if not np.all(learned >= self.relation.matrix):
            raise PlannerError("a learned relation misses a true constraint; batch counting needs supersets")
        n = len(self.relation.parts)
        weights = np.left_shift(np.uint64(1), np.arange(n, dtype=np.uint64))
        predecessors = np.bitwise_or.reduce(np.where(learned, weights[:, None], np.uint64(0)), axis=-2)
        ways = np.zeros((learned.shape[0], len(self.table.states)), dtype=np.int64)
        ways[:, 0] = 1
        for edges, starts, targets in self._layers:
            source = self._source[edges]
            blocked = predecessors[:, self._part[edges]] & ~self._state_masks[source]
            contribution = np.where(blocked == 0, ways[:, source], 0)
            ways[:, targets] += np.add.reduceat(contribution, starts, axis=1)
        return ways[:, -1]


def positions_of(orders: np.ndarray) -> np.ndarray:
    """Inverse permutations: ``pos[..., i]`` is the step of part i in ``orders[...]``."""
    return np.argsort(orders, axis=-1).astype(np.int16)
