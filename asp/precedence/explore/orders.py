"""The exact number of strict partial orders T with ``lower`` ⊆ T ⊆ ``upper`` (the
relations consistent with what is known: known pairs in, excluded pairs out), for the
information bound (:mod:`.bound`).

With ``upper`` acyclic its parts have a linear order every T respects (a topological
order of ``upper``). The last part z of that order is maximal in every T; its predecessors
D are a down-set of T on the other parts, with z's known predecessors ⊆ D ⊆ its allowed
ones. D is a down-set of T exactly when T holds no pair from outside D into D, so

    count(parts, allowed) = Σ_D count(parts − z, allowed − (not D) × D)

for the D that hold every known pair into them (a known pair (x, y) with y in D needs x in
D). The subproblems are keyed by what is still allowed (per part, the bit mask of its
allowed predecessors); equal ones are counted once, their multiplicities added, part by
part from the last (numpy: a subproblem is a row of masks).

Counting partial orders is hard in general: the count gives up at a deadline (None). T is
a set of pairs of ``upper`` − ``lower``, so the count is at most 2^|upper − lower|; more
than :data:`MAX_FREE_PAIRS` such pairs would overflow the 64-bit counts and are not counted.
"""

from __future__ import annotations

import time
from collections.abc import Collection

import numpy as np

from asp.precedence.relation import Pair

CELLS = 1 << 21
"""How many (subproblem, D) pairs are made at once (memory: 8 bytes per part each)."""
MAX_FREE_PAIRS = 62


def _topological(parts: Collection[str], upper: set[Pair]) -> list[str] | None:
    """A linear order of ``parts`` that every pair of ``upper`` goes forward in (the
    first part by name among those ready); None when ``upper`` has a cycle."""
    order: list[str] = []
    left = set(parts)
    while left:
        ready = [p for p in left if not any((q, p) in upper for q in left)]
        if not ready:
            return None
        order.append(min(ready))
        left.remove(order[-1])
    return order


def _choices(may: int, must: list[int], last: int) -> np.ndarray:
    """Every bit mask D with ``must[last]`` ⊆ D ⊆ ``may`` that holds the known predecessors
    of each part in it."""
    subsets = np.zeros(1, dtype=np.int64)
    for bit in range(last):
        if may >> bit & 1:
            subsets = np.concatenate([subsets, subsets | (1 << bit)])
    keep = (subsets & must[last]) == must[last]
    for part in range(last):
        keep &= ((subsets >> part) & 1 == 0) | ((subsets & must[part]) == must[part])
    return subsets[keep]


def _merge(rows: np.ndarray, counts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Equal rows as one, their counts added. Part y's mask has y bits, so a row of up to
    11 parts packs into one 64-bit key (faster to sort than rows)."""
    width = rows.shape[1]
    keys: np.ndarray
    if width * (width - 1) // 2 <= 63:
        keys = np.zeros(len(rows), dtype=np.int64)
        for part in range(1, width):
            keys |= rows[:, part] << (part * (part - 1) // 2)
    else:
        keys = np.ascontiguousarray(rows).view(np.dtype((np.void, rows.dtype.itemsize * width))).reshape(-1)
    _, first, inverse = np.unique(keys, return_index=True, return_inverse=True)
    merged = np.zeros(len(first), dtype=np.int64)
    np.add.at(merged, inverse.reshape(-1), counts)
    return rows[first], merged


def count_orders(parts: Collection[str], lower: Collection[Pair], upper: Collection[Pair],
                 time_limit_s: float) -> int | None:
    """The number of strict partial orders T on ``parts`` with ``lower`` ⊆ T ⊆ ``upper``
    (``lower`` transitively closed and within ``upper``); None when ``upper`` has a cycle,
    more than :data:`MAX_FREE_PAIRS` pairs of it are not in ``lower``, or the count takes
    longer than ``time_limit_s`` [s]."""
    deadline = time.monotonic() + time_limit_s
    upper_set = set(upper)
    order = _topological(parts, upper_set)
    if order is None or len(upper_set - set(lower)) > MAX_FREE_PAIRS:
        return None
    index = {p: i for i, p in enumerate(order)}
    n = len(order)
    may, must = [0] * n, [0] * n  # per part: bit masks of its allowed and its known predecessors
    for a, b in upper_set:
        may[index[b]] |= 1 << index[a]
    for a, b in lower:
        must[index[b]] |= 1 << index[a]
    rows = np.array([may], dtype=np.int64)
    counts = np.ones(1, dtype=np.int64)
    for last in range(n - 1, 0, -1):
        choices = _choices(may[last], must, last)
        step = max(1, CELLS // max(1, len(choices)))
        made_rows, made_counts = [], []
        for start in range(0, len(rows), step):
            if time.monotonic() > deadline:
                return None
            chunk, weights = rows[start:start + step], counts[start:start + step]
            which, pick = np.nonzero((choices[None, :] & ~chunk[:, last][:, None]) == 0)
            chosen = choices[pick][:, None]
            rest = chunk[which, :last]
            inside = (chosen >> np.arange(last)) & 1 == 1  # the parts in D: their predecessors within D
            made = _merge(np.where(inside, rest & chosen, rest), weights[which])
            made_rows.append(made[0])
            made_counts.append(made[1])
        if not made_rows or not sum(len(r) for r in made_rows):
            return 0
        rows, counts = _merge(np.concatenate(made_rows), np.concatenate(made_counts))
    return int(counts.sum()) if n else 1
