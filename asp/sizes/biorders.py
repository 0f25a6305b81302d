"""Biorders (Ferrers relations): the part-hole relations possible when sizes lie on a line.

A relation between ``m`` parts and ``n`` holes is a *biorder* when parts and holes can
be placed on one size line so that part p fits hole h iff size(p) < size(h) (ties
allowed, paper 2.2, last paragraph). A relation is held as a bit mask: bit ``p*n + h``
is set when part p (0-based index) fits hole h. Masks are ``numpy.uint64`` (m·n ≤ 64).

- :func:`all_biorders` enumerates every m×n biorder (5×5: 329 462, the poly-Bernoulli
  number B_5^(-5); :func:`biorder_count` gives the count without enumerating) and
  :func:`all_biorder_orders` their ∏ k!;
- :func:`consistent_index` finds those agreeing with known fits and no-fits;
  :func:`weighted_bit_sums` sums weights per pair over masks;
- :func:`sample_biorders` draws biorders (boolean matrices) consistent with the known
  smaller-than closure, for instances too large to enumerate;
- :func:`class_weights` gives each biorder (boolean matrix) ∏ k! over its classes of
  identical rows and of identical columns: the number of orders of the parts and holes
  on the size line that induce it (these weights sum to (m+n)!).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterator
from functools import lru_cache

import numpy as np


def stirling2(n: int, k: int) -> int:
    """Stirling number of the second kind: partitions of n elements into k blocks."""
    return sum((-1) ** (k - j) * math.comb(k, j) * j**n for j in range(k + 1)) // math.factorial(k)


@lru_cache(maxsize=1024)
def biorder_count(m: int, n: int) -> int:
    """Number of m×n biorders: the poly-Bernoulli number B_m^(-n) (Kaneko's formula)."""
    return sum(
        math.factorial(j) ** 2 * stirling2(m + 1, j + 1) * stirling2(n + 1, j + 1)
        for j in range(min(m, n) + 1)
    )


def pair_bits(m: int, n: int) -> np.ndarray:
    """(m, n) array of the mask bit of each part-hole pair."""
    return (np.uint64(1) << np.arange(m * n, dtype=np.uint64)).reshape(m, n)


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
def _enumeration(m: int, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Every m×n biorder (m, n ≥ 1) as sorted masks, with its ∏ k! (see :func:`class_weights`).

    Holes of equal columns form blocks 0..k-1 ordered by size; each part fits exactly
    the holes of the blocks ≥ its level t ∈ 0..k; two neighbouring blocks differ in
    their columns iff some part has the level between them, which makes the
    enumeration free of duplicates. Parts of equal level are the classes of identical
    rows, blocks the classes of identical columns.
    """
    bits = pair_bits(m, n)
    factorial = np.array([math.factorial(i) for i in range(max(m, n) + 1)], dtype=np.float64)
    masks: list[np.ndarray] = []
    orders: list[np.ndarray] = []
    by_blocks: dict[int, list[tuple[int, ...]]] = {}
    for blocks in _ordered_partitions(n, m + 1):
        by_blocks.setdefault(max(blocks) + 1, []).append(blocks)
    for k, partitions in by_blocks.items():
        levels = np.array(list(itertools.product(range(k + 1), repeat=m)), dtype=np.int64)
        hits_every_boundary = np.all([(levels == t).any(axis=1) for t in range(1, k)], axis=0)
        levels = levels[hits_every_boundary] if k > 1 else levels
        row_orders = factorial[(levels[:, :, None] == np.arange(k + 1)).sum(axis=1)].prod(axis=1)
        for blocks in partitions:
            fits = levels[:, :, None] <= np.array(blocks)[None, None, :]
            masks.append((fits * bits).sum(axis=(1, 2), dtype=np.uint64))
            orders.append(row_orders * factorial[np.bincount(blocks)].prod())
    all_masks = np.concatenate(masks)
    by_mask = np.argsort(all_masks)
    result = all_masks[by_mask], np.concatenate(orders)[by_mask]
    for array in result:
        array.setflags(write=False)
    return result


def all_biorders(m: int, n: int) -> np.ndarray:
    """Every m×n biorder as a sorted uint64 mask array (call only for small m, n)."""
    return _enumeration(m, n)[0]


def all_biorder_orders(m: int, n: int) -> np.ndarray:
    """∏ k! of every biorder of :func:`all_biorders`, aligned (float64)."""
    return _enumeration(m, n)[1]


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


def weighted_bit_sums(masks: np.ndarray, weights: np.ndarray, pairs: int) -> np.ndarray:
    """Per bit i < pairs: the sum of the weights of the masks with bit i set.

    Sums per byte value (one ``bincount`` per mask byte), then per bit: fast for many
    masks, and exact for integer-valued weights whose total stays below 2^53.
    """
    as_bytes = np.ascontiguousarray(masks, dtype="<u8").view(np.uint8).reshape(-1, 8)
    bits_of_byte = np.unpackbits(np.arange(256, dtype=np.uint8)[:, None], axis=1, bitorder="little")
    per_byte = [
        np.bincount(as_bytes[:, b], weights=weights, minlength=256) @ bits_of_byte
        for b in range((pairs + 7) // 8)
    ]
    return np.concatenate(per_byte)[:pairs]


def class_weights(fits: np.ndarray) -> np.ndarray:
    """∏ k! over classes of identical rows and of identical columns, per biorder.

    ``fits`` has shape (relations, m, n), each a biorder; the result is float64. The
    rows of a biorder form a chain under inclusion (so do its columns), so two rows are
    identical exactly when they hold as many fits: classes are found by counting.
    """
    log_weight = np.zeros(len(fits))
    longest = max(fits.shape[1:], default=0)
    per_member = np.array([0.0] + [math.lgamma(k + 1) / k for k in range(1, longest + 1)])
    for axis in (2, 1):
        counts = fits.sum(axis=axis, dtype=np.int32)
        same = (counts[:, :, None] == counts[:, None, :]).sum(axis=2)
        # a class of k lines contributes log(k!), i.e. log(k!)/k from each member
        log_weight += per_member[same].sum(axis=1)
    return np.exp(log_weight)


def sample_biorders(smaller: np.ndarray, m: int, n: int, samples: int, rng: np.random.Generator) -> np.ndarray:
    """Distinct biorders, shape (k, m, n), drawn consistent with what is known.

    ``smaller[x, y]`` is True when item x is known smaller than item y (items: parts
    0..m-1, then holes), transitively closed and acyclic; every entry is strict except
    hole < part, which stands for a no-fit and allows equal sizes. Each draw picks a
    number of size levels L uniform in 1..m+n, gives every item a uniform random level
    below L, then, in an order compatible with ``smaller``, lifts each item to at least
    the level of the items known smaller (one above, where strict). A part fits a hole
    iff its level is lower, so ties (identical parts or holes) are common, and every
    consistent biorder can occur. Works for any m, n (no bit masks).
    """
    items = m + n
    strict = smaller.copy()
    strict[m:, :m] = False
    levels = np.floor(rng.random((samples, items)) * rng.integers(1, items + 1, size=(samples, 1)))
    for item in np.argsort(smaller.sum(axis=0), kind="stable"):  # items below come first
        above_strict = np.flatnonzero(strict[:, item])
        if len(above_strict):
            levels[:, item] = np.maximum(levels[:, item], levels[:, above_strict].max(axis=1) + 1)
        at_least = np.flatnonzero(smaller[:, item] & ~strict[:, item])
        if len(at_least):
            levels[:, item] = np.maximum(levels[:, item], levels[:, at_least].max(axis=1))
    fits = levels[:, :m, None] < levels[:, None, m:]
    _, first = np.unique(line_keys(fits.reshape(samples, m * n)), return_index=True)
    return fits[first]
