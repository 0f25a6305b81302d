"""The locating rule: a stated assumption of ``import`` beside the exact blocking.

**Model.** In the assembled product, a part X is *located* along a direction across its
insertion axis by the parts it meets when moved :data:`LOCATING_REACH` that way (swept,
everything else fixed, as the blocking is found: :class:`assembly_constraints.executor.cad.sweep.Sweeper`).
When, along some such direction, one part Y other than the base is the only one that
locates X, Y must precede X (reason ``locates``): placed before Y, X would lie unlocated
that way, lined up with what lies below only within the cell's placing error, and Y would
have to thread X's opening and the hole under it in series. A part located by two or more
parts (a cover over several pins) gets no edge: any one of them locates it, which a
must-precede pair cannot say. Parts fixed to another move with it (one body: its
members' locators together, less the members).

This is a model of the process, not a consequence of the geometry: the straight paths
stay free whatever the order, and the cell may well succeed (Cranfield's shaft through
the pendulum placed first failed at one seed of three; docs/results.md). It errs to the
safe side: a superfluous pair removes sequences, never admits one. A locating pair that contradicts
the blocking precedence (the geometry forces the other order) is dropped and reported.
"""

from __future__ import annotations

import networkx as nx
import numpy as np

from assembly_constraints.executor.cad.sweep import DIRECTIONS, Sweeper

LOCATING_REACH = 3e-3
"""How far a part is moved sideways to find what locates it [m]: more than the play of
the openings a cell places a part over (Cranfield's widest, the front plate over its
pins, 2.15 mm a side), less than the distance to unrelated neighbours."""
MAX_REACH = 0.1
"""The largest reach ``import --locating-reach`` takes [m]."""


def lateral(axis: str) -> list[str]:
    """The directions of :data:`DIRECTIONS` across the removal direction ``axis``."""
    return [name for name in DIRECTIONS if name[1] != axis[1]]


def locators(sweeper: Sweeper, group: set[str], axis: str, reach: float) -> dict[str, set[str]]:
    """Direction -> the other parts that stop the body ``group`` (its members moved
    together) within ``reach`` [m] along each direction across the removal direction ``axis``."""
    found: dict[str, set[str]] = {}
    for name in lateral(axis):
        hit: set[str] = set()
        for member in sorted(group):
            hit |= sweeper.blockers(member, np.array(DIRECTIONS[name]), reach)
        found[name] = hit - group
    return found


def locating_pairs(located: dict[str, dict[str, set[str]]], base: str, edges: set[tuple[str, str]]
                   ) -> tuple[set[tuple[str, str]], set[tuple[str, str]]]:
    """(kept, dropped) locating pairs (Y, X) of ``located`` (part -> direction -> its
    locators): Y is the one locator of X along some direction and not the base; a pair is
    dropped when X precedes Y through ``edges`` (the blocking precedence)."""
    candidates = sorted({(next(iter(parts)), part) for part, by_direction in located.items()
                         for parts in by_direction.values() if len(parts) == 1 and base not in parts})
    graph = nx.DiGraph(edges)
    kept: set[tuple[str, str]] = set()
    dropped: set[tuple[str, str]] = set()
    for locator, part in candidates:  # one by one: kept pairs never close a cycle among themselves either
        if part in graph and locator in graph and nx.has_path(graph, part, locator):
            dropped.add((locator, part))
        else:
            graph.add_edge(locator, part)
            kept.add((locator, part))
    return kept, dropped
