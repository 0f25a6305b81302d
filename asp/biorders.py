"""Biorders (Ferrers relations): the part-hole relations possible when sizes lie on a line.

A relation between ``m`` parts and ``n`` holes is a *biorder* when parts and holes can
be placed on one size line so that part p fits hole h iff size(p) < size(h) (ties
allowed, paper 2.2, last paragraph). A relation is held as a bit mask: bit ``p*n + h``
is set when part p (0-based index) fits hole h. Masks are ``numpy.uint64`` (m·n ≤ 64).

- :func:`all_biorders` enumerates every m×n biorder (5×5: 329 462, the poly-Bernoulli
  number B_5^(-5); :func:`biorder_count` gives the count without enumerating);
- :func:`consistent_index` finds those agreeing with known fits and no-fits;
- :func:`sample_biorders` draws biorders (boolean matrices) consistent with a strict
  smaller-than closure, for instances too large to enumerate;
- :func:`class_weights` gives each biorder (boolean matrix) ∏ k! over its classes of identical rows and
  of identical columns: the number of orders of the parts and holes on the size line
  that induce it (these weights sum to (m+n)!).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterator
from functools import lru_cache

import numpy as np

ONE = np.uint64(1)


def stirling2(n: int, k: int) -> int:
    """Stirling number of the second kind: partitions of n elements into k blocks."""
    return sum((-1) ** (k - j) * math.comb(k, j) * j**n for j in range(k + 1)) // math.factorial(k)


def biorder_count(m: int, n: int) -> int:
    """Number of m×n biorders: the poly-Bernoulli number B_m^(-n) (Kaneko's formula)."""
    return sum(
        math.factorial(j) ** 2 * stirling2(m + 1, j + 1) * stirling2(n + 1, j + 1)
        for j in range(min(m, n) + 1)
    )


def bit_weights(m: int, n: int) -> np.ndarray:
    """(m, n) array of the mask bit of each part-hole pair."""
    return (ONE << np.arange(m * n, dtype=np.uint64)).reshape(m, n)


def _ordered_partitions(n: int, max_blocks: int) -> Iterator[tuple[int, ...]]:
    """Block index of each of n elements, over all ordered partitions into ≤ max_blocks blocks."""

    def growth(prefix: list[int], blocks: int) -> Iterator[tuple[list[int], int]]:
        if len(prefix) == n:
            yield prefix, blocks
            return
        for b in range(min(blocks + 1, max_blocks)):
            yield from growth(prefix + [b], max(blocks, b + 1))

    for labels, blocks in growth([], 0):
        for order in itertools.permutations(range(blocks)):
            yield tuple(order[b] for b in labels)


@lru_cache(maxsize=4)
def all_biorders(m: int, n: int) -> np.ndarray:
    """Every m×n biorder as a sorted uint64 mask array (call only for small m, n).

    Holes of equal columns form blocks 0..k-1 ordered by size; each part fits exactly
    the holes of the blocks ≥ its level t ∈ 0..k; two neighbouring blocks differ in
    their columns iff some part has the level between them, which makes the
    enumeration free of duplicates.
    """
    weights = bit_weights(m, n)
    chunks: list[np.ndarray] = [np.zeros(1, dtype=np.uint64)] if n == 0 or m == 0 else []
    by_blocks: dict[int, list[tuple[int, ...]]] = {}
    for blocks in _ordered_partitions(n, m + 1):
        by_blocks.setdefault(max(blocks) + 1, []).append(blocks)
    for k, partitions in by_blocks.items():
        levels = np.array(list(itertools.product(range(k + 1), repeat=m)), dtype=np.int64)
        hits_every_boundary = np.all([(levels == t).any(axis=1) for t in range(1, k)], axis=0)
        levels = levels[hits_every_boundary] if k > 1 else levels
        for blocks in partitions:
            fits = levels[:, :, None] <= np.array(blocks)[None, None, :]
            chunks.append((fits * weights).sum(axis=(1, 2), dtype=np.uint64))
    masks = np.sort(np.concatenate(chunks))
    masks.setflags(write=False)
    return masks


def consistent_index(masks: np.ndarray, fit_mask: int, no_fit_mask: int) -> np.ndarray:
    """Indices of the masks that contain every known fit and no known no-fit."""
    fit, no_fit = np.uint64(fit_mask), np.uint64(no_fit_mask)
    return np.flatnonzero(((masks & fit) == fit) & ((masks & no_fit) == 0))


def mask_bits(masks: np.ndarray, pairs: int) -> np.ndarray:
    """(len(masks), pairs) boolean matrix: bit i of each mask."""
    as_bytes = np.ascontiguousarray(masks, dtype="<u8").view(np.uint8).reshape(-1, 8)
    return np.unpackbits(as_bytes, axis=1, count=pairs, bitorder="little").astype(bool)


def line_keys(lines: np.ndarray) -> np.ndarray:
    """One comparable key per boolean vector along the last axis (packed bytes, void dtype)."""
    packed = np.ascontiguousarray(np.packbits(lines, axis=-1))
    return packed.view(f"V{packed.shape[-1]}")[..., 0]


def class_weights(fits: np.ndarray) -> np.ndarray:
    """∏ k! over classes of identical rows and of identical columns, per relation.

    ``fits`` has shape (relations, m, n); the result is float64.
    """
    log_weight = np.zeros(len(fits))
    longest = max(fits.shape[1:], default=0)
    per_member = np.array([0.0] + [math.lgamma(k + 1) / k for k in range(1, longest + 1)])
    for lines in (fits, fits.transpose(0, 2, 1)):
        keys = line_keys(lines)
        same = (keys[:, :, None] == keys[:, None, :]).sum(axis=2)
        # a class of k lines contributes log(k!), i.e. log(k!)/k from each member
        log_weight += per_member[same].sum(axis=1)
    return np.exp(log_weight)


def sample_biorders(smaller: np.ndarray, m: int, n: int, samples: int, rng: np.random.Generator) -> np.ndarray:
    """Distinct biorders, shape (k, m, n), drawn consistent with a strict order on items.

    ``smaller[x, y]`` is True when item x is known smaller than item y (items: parts
    0..m-1, then holes); it must be transitively closed and acyclic. Each draw gives
    every item a uniform random size, lifts it to the largest size among the item and
    everything below it, and breaks ties by the number of items below, which yields a
    random linear extension (every one can occur); the biorder is "part below hole".
    Works for any m, n (no bit masks).
    """
    below = smaller.T | np.eye(m + n, dtype=bool)  # below[y, x]: x ≤ y
    height = smaller.sum(axis=0)  # number of items below: increases along smaller
    raw = rng.random((samples, m + n))
    size = np.where(below[None, :, :], raw[:, None, :], -1.0).max(axis=2)
    part_size, hole_size = size[:, :m, None], size[:, None, m:]
    fits = (part_size < hole_size) | (
        (part_size == hole_size) & (height[:m, None] < height[None, m:])[None, :, :]
    )
    _, first = np.unique(line_keys(fits.reshape(samples, m * n)), return_index=True)
    return fits[first]
