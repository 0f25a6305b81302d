"""The assembly sequences a precedence relation admits: count, enumerate, sample.

A sequence is admitted when it is a linear extension of the relation. Counting is a
dynamic programme over down-sets (sets of parts that can be in place together), with
independent components (connected parts of the comparability graph) counted apart and
combined by a multinomial: exact Python integers of any size, never enumerating.
Sampling is exactly uniform: from a down-set S the next part x is drawn with
probability completions(S + x) / completions(S), components are interleaved by a
uniformly random shuffle. Enumeration streams sequences depth first.

A relation with a cycle (or a part preceding itself) admits no sequence.
"""

from __future__ import annotations

import random
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from functools import lru_cache
from math import factorial, prod

import numpy as np

from asp.relation import Relation


def predecessor_masks(matrix: np.ndarray) -> tuple[int, ...]:
    """Bit i of ``masks[j]`` is set when part i must precede part j."""
    weights = [1 << i for i in range(matrix.shape[0])]
    return tuple(sum(w for w, bit in zip(weights, column) if bit) for column in matrix.T.tolist())


def components(matrix: np.ndarray) -> list[list[int]]:
    """Connected components (lists of part indices) of the comparability graph."""
    linked = (matrix | matrix.T).tolist()
    seen: set[int] = set()
    found = []
    for start in range(len(linked)):
        if start in seen:
            continue
        stack, members = [start], []
        seen.add(start)
        while stack:
            i = stack.pop()
            members.append(i)
            for j, edge in enumerate(linked[i]):
                if edge and j not in seen:
                    seen.add(j)
                    stack.append(j)
        found.append(sorted(members))
    return found


def _local_masks(matrix: np.ndarray, members: Sequence[int]) -> tuple[int, ...]:
    return predecessor_masks(matrix[np.ix_(members, members)])


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


def exact_count(matrix: np.ndarray) -> int:
    """Exact number of linear extensions of a boolean relation matrix (not memoised)."""
    groups = components(matrix)
    interleavings = factorial(len(matrix)) // prod(factorial(len(g)) for g in groups)
    return interleavings * prod(count_downset_paths(_local_masks(matrix, g)) for g in groups)


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
    from asp import PlannerError

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


def _sample_component(table: DownSets, rng: random.Random) -> list[int]:
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
        self.relation = relation
        self.groups = components(relation.matrix)
        self.tables = [down_sets(_local_masks(relation.matrix, g)) for g in self.groups]
        if any(t.completions[0] == 0 for t in self.tables) or np.any(np.diag(relation.matrix)):
            from asp import PlannerError

            raise PlannerError("the relation admits no sequence (it has a cycle)")

    def sample(self, rng: random.Random) -> tuple[str, ...]:
        """One sequence, uniformly among all admitted ones."""
        orders = [iter([g[i] for i in _sample_component(t, rng)]) for g, t in zip(self.groups, self.tables)]
        labels = [k for k, g in enumerate(self.groups) for _ in g]
        rng.shuffle(labels)
        return tuple(self.relation.parts[next(orders[k])] for k in labels)
