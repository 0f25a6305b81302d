"""Shared helpers of the precedence tests: random posets, feasible sequences."""

from __future__ import annotations

import networkx as nx
import numpy as np
from hypothesis import strategies as st

from asp.precedence.relation import Relation


def closed_relation(parts: list[str], edges: list[tuple[int, int]]) -> Relation:
    """The transitive closure (networkx, independent of the code under test)."""
    graph = nx.DiGraph()
    graph.add_nodes_from(range(len(parts)))
    graph.add_edges_from(edges)
    matrix = np.zeros((len(parts), len(parts)), dtype=bool)
    for a, b in nx.transitive_closure_dag(graph).edges:
        matrix[a, b] = True
    return Relation(tuple(parts), matrix)


@st.composite
def posets(draw: st.DrawFn, max_parts: int = 7) -> Relation:
    """A random acyclic relation (closed) over parts ``x0..``; edges go from lower to higher rank."""
    n = draw(st.integers(1, max_parts))
    rank = draw(st.permutations(range(n)))
    pairs = [(i, j) for i in range(n) for j in range(n) if rank[i] < rank[j]]
    chosen = draw(st.lists(st.sampled_from(pairs), unique=True, max_size=len(pairs))) if pairs else []
    return closed_relation([f"x{i}" for i in range(n)], chosen)


def greedy_extension(relation: Relation, priority: list[int]) -> tuple[str, ...]:
    """A feasible sequence: repeatedly the placeable part of highest priority."""
    n = len(relation.parts)
    placed: list[int] = []
    while len(placed) < n:
        free = [x for x in range(n)
                if x not in placed and all(p in placed for p in np.flatnonzero(relation.matrix[:, x]))]
        placed.append(max(free, key=lambda x: priority[x]))
    return tuple(relation.parts[i] for i in placed)


@st.composite
def poset_with_demos(draw: st.DrawFn, max_parts: int = 7, max_demos: int = 6) -> tuple[Relation, list[tuple[str, ...]]]:
    """A random poset and 1..max_demos feasible sequences of it."""
    truth = draw(posets(max_parts))
    n = len(truth.parts)
    priorities = draw(st.lists(st.permutations(range(n)), min_size=1, max_size=max_demos))
    return truth, [greedy_extension(truth, list(p)) for p in priorities]

