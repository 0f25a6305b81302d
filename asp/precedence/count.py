"""The assembly sequences a precedence relation admits: count, enumerate, sample.

A sequence is admitted when it is a linear extension of the relation. Counting splits the
relation into independent and consecutive groups (:mod:`asp.precedence.decompose`):
independent groups combine by a multinomial, consecutive ones by a product, and each
remaining prime group is counted by a dynamic programme over its down-sets (sets of
parts that can be in place together): exact Python integers of any size, never
enumerating. Sampling is exactly uniform: in a prime group the next part x is drawn
from down-set S with probability completions(S + x) / completions(S); independent
groups are interleaved by a uniformly random shuffle, consecutive ones concatenated.
Enumeration streams sequences depth first.

A relation with a cycle (or a part preceding itself) admits no sequence.
"""

from __future__ import annotations

import random
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from functools import lru_cache
from math import factorial, prod

import numpy as np

from asp import PlannerError
from asp.precedence.decompose import (
    Decomposition,
    decompose,
    predecessor_masks,
    transitive_closure,
)
from asp.precedence.relation import Relation


def count_downset_paths(masks: Sequence[int]) -> int:
    """Linear extensions of one poset given by predecessor bit masks (down-set DP)."""
    n = len(masks)
    full = (1 << n) - 1
    layer = {0: 1}
    for _ in range(n):
        following: dict[int, int] = {}
        for placed, ways in layer.items():
            missing = ~placed
            for x in range(n):
                bit = 1 << x
                if not placed & bit and not masks[x] & missing:
                    following[placed | bit] = following.get(placed | bit, 0) + ways
        layer = following
    return layer.get(full, 0)


def _count(node: Decomposition) -> int:
    if node.kind == "prime":
        return count_downset_paths(node.masks)
    counts = prod(_count(child) for child in node.children)
    if node.kind == "series":
        return counts
    return counts * factorial(len(node.members)) // prod(factorial(len(c.members)) for c in node.children)


def exact_count(matrix: np.ndarray) -> int:
    """Exact number of linear extensions of a boolean relation matrix (not memoised)."""
    closed = transitive_closure(matrix)
    if np.any(np.diag(closed)):
        return 0
    return _count(decompose(closed))


@lru_cache(maxsize=65536)
def _count_cached(parts: tuple[str, ...], packed: bytes) -> int:
    n = len(parts)
    return exact_count(np.unpackbits(np.frombuffer(packed, dtype=np.uint8), count=n * n).reshape(n, n).astype(bool))


def count_linear_extensions(relation: Relation) -> int:
    """Exact number of sequences the relation admits (memoised by relation)."""
    return _count_cached(*relation.key())


def linear_extensions(relation: Relation) -> Iterator[tuple[str, ...]]:
    """Stream every admitted sequence, depth first, in part order."""
    masks = predecessor_masks(relation.matrix)
    parts, n = relation.parts, len(relation.parts)
    chosen: list[int] = []

    def extend(placed: int) -> Iterator[tuple[str, ...]]:
        if len(chosen) == n:
            yield tuple(parts[i] for i in chosen)
            return
        for x in range(n):
            if not placed >> x & 1 and not masks[x] & ~placed:
                chosen.append(x)
                yield from extend(placed | 1 << x)
                chosen.pop()

    yield from extend(0)


@dataclass(frozen=True)
class DownSets:
    """The down-sets of one poset and, for each, the number of ways to complete it.

    ``states`` lists down-sets as bit masks by size; ``nxt[s, x]`` is the index of
    ``states[s] + x`` or -1 when x cannot be placed; ``completions[s]`` counts the
    sequences finishing ``states[s]`` (Python ints).
    """

    masks: tuple[int, ...]
    states: tuple[int, ...]
    nxt: np.ndarray
    completions: tuple[int, ...]


def down_sets(masks: Sequence[int], limit: int = 2_000_000) -> DownSets:
    """All down-sets of the poset given by predecessor masks (at most ``limit``)."""
    n = len(masks)
    states, index, frontier, edges = [0], {0: 0}, [0], []
    while frontier:
        following = []
        for placed in frontier:
            for x in range(n):
                if not placed >> x & 1 and not masks[x] & ~placed:
                    target = placed | 1 << x
                    if target not in index:
                        index[target] = len(states)
                        states.append(target)
                        following.append(target)
                    edges.append((index[placed], x, index[target]))
        if len(states) > limit:
            raise PlannerError(f"the relation has more than {limit} down-sets; too free for a sampling table")
        frontier = following
    nxt = np.full((len(states), n), -1, dtype=np.int64)
    for source, x, target in edges:
        nxt[source, x] = target
    completions = [0] * len(states)
    for s in range(len(states) - 1, -1, -1):
        row = [t for t in nxt[s].tolist() if t >= 0]
        completions[s] = sum(completions[t] for t in row) if row else 1
    return DownSets(tuple(masks), tuple(states), nxt, tuple(completions))


def _sample_prime(table: DownSets, rng: random.Random) -> list[int]:
    state, order = 0, []
    for _ in range(len(table.masks)):
        pick = rng.randrange(table.completions[state])
        for x, target in enumerate(table.nxt[state].tolist()):
            if target < 0:
                continue
            if pick < table.completions[target]:
                order.append(x)
                state = target
                break
            pick -= table.completions[target]
    return order


class UniformSampler:
    """Exactly uniform sampling of the sequences a relation admits (tables built once)."""

    def __init__(self, relation: Relation) -> None:
        closed = transitive_closure(relation.matrix)
        if np.any(np.diag(closed)):
            raise PlannerError("the relation admits no sequence (it has a cycle)")
        self.relation = relation
        self.root = decompose(closed)
        self.tables = {node.members: down_sets(node.masks) for node in _primes(self.root)}

    def _sample(self, node: Decomposition, rng: random.Random) -> list[int]:
        if node.kind == "prime":
            return [node.members[i] for i in _sample_prime(self.tables[node.members], rng)]
        orders = [self._sample(child, rng) for child in node.children]
        if node.kind == "series":
            return [x for order in orders for x in order]
        labels = [k for k, order in enumerate(orders) for _ in order]
        rng.shuffle(labels)  # a uniformly random interleaving
        streams = [iter(order) for order in orders]
        return [next(streams[k]) for k in labels]

    def sample(self, rng: random.Random) -> tuple[str, ...]:
        """One sequence, uniformly among all admitted ones."""
        return tuple(self.relation.parts[i] for i in self._sample(self.root, rng))


def _primes(node: Decomposition) -> list[Decomposition]:
    return [node] if node.kind == "prime" else [p for child in node.children for p in _primes(child)]
