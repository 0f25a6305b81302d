"""Series-parallel decomposition of a precedence relation, for counting and sampling.

Parts in different connected components of the comparability graph are independent
(parallel: their sequences interleave freely). When the incomparability graph falls
apart instead, every part of one group precedes every part of the next (series:
sequences concatenate). What is left (prime) needs the down-set dynamic programme.
"Base plate first, front plate last, free parts in between" thus never enumerates
the down-sets of the free parts.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np


def transitive_closure(matrix: np.ndarray) -> np.ndarray:
    """Transitive closure of a boolean relation matrix (Warshall, numpy rows)."""
    closed = matrix.copy()
    for k in range(len(closed)):
        closed |= closed[:, k : k + 1] & closed[k : k + 1, :]
    return closed


def predecessor_masks(matrix: np.ndarray) -> tuple[int, ...]:
    """Bit i of ``masks[j]`` is set when part i must precede part j."""
    weights = [1 << i for i in range(matrix.shape[0])]
    return tuple(sum(w for w, bit in zip(weights, column) if bit) for column in matrix.T.tolist())


def components(linked: np.ndarray) -> list[list[int]]:
    """Connected components (sorted index lists) of a symmetric boolean adjacency matrix."""
    rows = linked.tolist()
    seen: set[int] = set()
    found = []
    for start in range(len(rows)):
        if start in seen:
            continue
        stack, members = [start], []
        seen.add(start)
        while stack:
            i = stack.pop()
            members.append(i)
            for j, edge in enumerate(rows[i]):
                if edge and j not in seen:
                    seen.add(j)
                    stack.append(j)
        found.append(sorted(members))
    return found


@dataclass(frozen=True)
class Decomposition:
    """A node of the decomposition; ``members`` are part indices of the whole relation.

    ``kind`` is ``"parallel"`` or ``"series"`` (``children`` in order) or ``"prime"``
    (``masks``: predecessor bit masks local to ``members``; one part is prime too).
    """

    kind: str
    members: tuple[int, ...]
    children: tuple[Decomposition, ...] = ()
    masks: tuple[int, ...] = ()


def decompose(closed: np.ndarray, members: Sequence[int] | None = None) -> Decomposition:
    """Decompose a transitively closed acyclic relation (restricted to ``members``)."""
    members = list(range(len(closed))) if members is None else list(members)
    sub = closed[np.ix_(members, members)]
    comparable = sub | sub.T
    groups = components(comparable)
    kind = "parallel"
    if len(groups) == 1 and len(members) > 1:
        groups = components(~comparable & ~np.eye(len(members), dtype=bool))
        groups.sort(key=lambda g: int(sub[:, g[0]].sum()) - int(sub[np.ix_(g, g)][:, 0].sum()))
        kind = "series"
    if len(groups) == 1:
        return Decomposition("prime", tuple(members), masks=predecessor_masks(sub))
    children = tuple(decompose(closed, [members[i] for i in g]) for g in groups)
    return Decomposition(kind, tuple(members), children)
