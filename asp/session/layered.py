"""Layered drawing of a relation (its transitive reduction) for the Rerun graph views.

A node's level is the length of the longest edge path reaching it (sources at level 0,
drawn on top); within a level the nodes are ordered by the mean position of their
predecessors (one barycentre pass, which untangles most crossings of small graphs).
Nodes on a cycle (an observation contradicting the size model) are put one level below
the rest, in their given order.
"""

from __future__ import annotations

from collections.abc import Sequence

SPACING = (90.0, 70.0)
"""Distance between neighbours in a level and between levels [graph view units]."""


def levels(nodes: Sequence[str], edges: Sequence[tuple[str, str]]) -> dict[str, int]:
    """Longest-path level of each node over the directed ``edges`` (a before b)."""
    incoming = {n: 0 for n in nodes}
    successors: dict[str, list[str]] = {n: [] for n in nodes}
    for a, b in edges:
        successors[a].append(b)
        incoming[b] += 1
    level = {n: 0 for n in nodes}
    ready = [n for n in nodes if incoming[n] == 0]
    done: set[str] = set()
    while ready:
        node = ready.pop()
        done.add(node)
        for nxt in successors[node]:
            level[nxt] = max(level[nxt], level[node] + 1)
            incoming[nxt] -= 1
            if incoming[nxt] == 0:
                ready.append(nxt)
    below = max((level[n] for n in done), default=-1) + 1
    return {n: level[n] if n in done else below for n in nodes}


def positions(nodes: Sequence[str], edges: Sequence[tuple[str, str]]) -> list[tuple[float, float]]:
    """Node centres ``(x, y)`` in ``nodes`` order: one row per level, rows centred on x = 0,
    level k at y = k × the row spacing (y grows downwards in a graph view)."""
    level = levels(nodes, edges)
    predecessors: dict[str, list[str]] = {n: [] for n in nodes}
    for a, b in edges:
        predecessors[b].append(a)
    dx, dy = SPACING
    x: dict[str, float] = {}
    for k in range(max(level.values(), default=-1) + 1):
        row = [n for n in nodes if level[n] == k]
        given = {n: (i - (len(row) - 1) / 2) * dx for i, n in enumerate(row)}  # the order given
        centre = {n: _mean([x[p] for p in predecessors[n] if p in x], given[n]) for n in row}
        row.sort(key=lambda n: (centre[n], given[n]))
        x.update({n: (i - (len(row) - 1) / 2) * dx for i, n in enumerate(row)})
    return [(x[n], level[n] * dy) for n in nodes]


def _mean(values: Sequence[float], default: float) -> float:
    return sum(values) / len(values) if values else default
