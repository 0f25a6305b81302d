"""The geometric precedence as a graph (:func:`order`) and the parts in place when a part goes
to its goal: whenever (:func:`in_place_before`: the base and those the precedence puts
before it) or possibly (:func:`maybe_in_place`: all but those it puts after it)."""

from __future__ import annotations

import networkx as nx

from executor.cad.derive import Derived


def order(derived: Derived) -> nx.DiGraph:
    """The geometric precedence as a graph: every part a node, each derived pair an edge."""
    graph = nx.DiGraph()
    graph.add_nodes_from(derived.parts)
    graph.add_edges_from(derived.edges)
    return graph


def maybe_in_place(derived: Derived, pid: str) -> set[str]:
    """The parts that may be in place when part ``pid`` goes to its goal: all but ``pid``
    and those the geometric precedence puts after it."""
    return set(derived.parts) - nx.descendants(order(derived), pid) - {pid}


def in_place_before(derived: Derived, pid: str) -> set[str]:
    """The parts in place whenever part ``pid`` goes to its goal: the base and those the
    geometric precedence puts before it."""
    return (nx.ancestors(order(derived), pid) | {derived.base}) - {pid}
