"""The rules of placing: stated assumptions of ``import`` beside the exact blocking.

**Support.** A part resting on other parts is placed onto them: when a moving body moved
:data:`SUPPORT_GAP` down (-z) meets parts and the base is not among them, every part it
meets must precede it (reason ``supports``), unless that part rests on it in turn (a ring
on a horizontal shaft at zero clearance: which holds which the geometry does not say).
Blocking cannot decide this (a lid lifted off its spacer has a free way in whatever the
order); it is gravity's order, and like the locating rule it only removes sequences.

**Model.** In the assembled product, a part X is *located* along a direction by the parts
it meets first when moved :data:`LOCATING_REACH` that way (swept, everything else fixed, as
the blocking is found: :class:`executor.cad.sweep.Sweeper`; of several met, those present
when X goes in met within a quarter of the way, a quarter of that, ...: a coupling on a shaft's
end at zero clearance with a flange 0.5 mm round it is located by the shaft, not by the
flange, and the flange by the coupling, not by the shaft it would reach through the
coupling). X may go in along any of its *ways*: the directions the base leaves it free
along (those the blocking rule tries).
Gone in along a way, X is located along every direction but the way out: across it, and
along the insertion itself by what stops it there. When, whichever way X goes in, one
part Y other than the base is the only one that locates X along some such direction, Y
must precede X (reason ``locates``): placed before Y, X would lie unlocated that way,
where the cell put it within its placing error, and Y would have to thread X's opening
and what lies beyond it in series. A way along which Y locates nothing alone takes the
pair away (a ring slid on along its shaft is located by the shaft across and by the part
it stops against, not by the pulley beside it: no pulley-before-ring pair). A part located by two or more parts (a cover
over several pins) gets no edge: any one of them locates it, which a must-precede pair
cannot say. Parts fixed to another move with it (one body: its members' locators
together, less the members).

This is a model of the process, not a consequence of the geometry: the straight paths
stay free whatever the order, and the cell may well succeed (Cranfield's shaft through
the pendulum placed first failed at one seed of three; docs/results.md). It errs to the
safe side: a superfluous pair removes sequences, never admits one. A locating pair that contradicts
the blocking precedence (the geometry forces the other order) is dropped and reported.
"""

from __future__ import annotations

import networkx as nx
import numpy as np

from executor.cad.sweep import DIRECTIONS, Sweeper

SUPPORT_GAP = 1e-4
"""A part this close above another [m] (0.1 mm) rests on it."""
LOCATING_REACH = 3e-3
"""How far a part is moved sideways to find what locates it [m]: more than the play of
the openings a cell places a part over (Cranfield's widest, the front plate over its
pins, 2.15 mm a side), less than the distance to unrelated neighbours."""
NEARER = 0.25
"""Of several parts a body meets within a reach, those met within this fraction of it are
met first (:func:`locators`)."""
NEARER_STEPS = 3
"""How many times :func:`locators` shortens the reach by :data:`NEARER` (to 1/64 of it:
47 µm of the 3 mm reach, within a zero-clearance fit's tolerance of contact)."""
MAX_REACH = 0.1
"""The largest reach ``import --locating-reach`` takes [m]."""


def beside(way: tuple[float, float, float]) -> list[str]:
    """The directions of :data:`DIRECTIONS` a part that goes in against the removal
    direction ``way`` (a unit vector) is located along: all but the way out itself (along
    it lies what goes in later, over the part: the blocking's to order)."""
    return [name for name, vector in DIRECTIONS.items() if float(np.dot(vector, way)) < 1 - 1e-9]


def locators(sweeper: Sweeper, bodies: dict[str, set[str]], reach: float
             ) -> tuple[dict[str, dict[str, set[str]]], dict[str, dict[str, list[set[str]]]]]:
    """Body -> direction -> the other parts that stop the body (its members moved
    together) within ``reach`` [m] along each direction of :data:`DIRECTIONS`; and, where
    that is several, those met within :data:`NEARER` of the reach, of that, ... (at most
    :data:`NEARER_STEPS` times, while several are met), the nearest first (module docstring)."""
    requests = [(root, name) for root in bodies for name in DIRECTIONS]
    hits = sweeper.blocked([(bodies[root], np.array(DIRECTIONS[name]), reach) for root, name in requests])
    located: dict[str, dict[str, set[str]]] = {root: {} for root in bodies}
    for (root, name), hit in zip(requests, hits):
        located[root][name] = hit
    nearer: dict[str, dict[str, list[set[str]]]] = {root: {} for root in bodies}
    crowded = [(root, name) for root, name in requests if len(located[root][name]) > 1]
    for step in range(1, NEARER_STEPS + 1):
        if not crowded:
            break
        found = sweeper.blocked([(bodies[root], np.array(DIRECTIONS[name]), reach * NEARER ** step)
                                 for root, name in crowded])
        for (root, name), hit in zip(crowded, found):
            nearer[root].setdefault(name, []).insert(0, hit)
        crowded = [(root, name) for (root, name), hit in zip(crowded, found) if len(hit) > 1]
    return located, nearer


def first_met(met: list[set[str]], absent: set[str]) -> set[str]:
    """Of the sets of parts ``met`` within ever longer reaches, the first that holds a part
    not ``absent`` (those going in later), less them; empty: none."""
    return next((hit - absent for hit in met if hit - absent), set())


def support_pairs(sweeper: Sweeper, bodies: dict[str, set[str]], base: str) -> set[tuple[str, str]]:
    """The supporting pairs (Y, X): X a member of a body resting on Y (module docstring)."""
    pairs: set[tuple[str, str]] = set()
    down = np.array(DIRECTIONS["-z"])
    for members, under in zip(bodies.values(), sweeper.blocked([(m, down, SUPPORT_GAP) for m in bodies.values()])):
        if base not in under:
            pairs |= {(y, x) for y in under for x in members}
    return {(y, x) for y, x in pairs if (x, y) not in pairs}


def locating_candidates(located: dict[str, dict[str, set[str]]], ways: dict[str, dict[str, tuple[float, float, float]]],
                        base: str, later: dict[str, set[str]] | None = None,
                        nearer: dict[str, dict[str, list[set[str]]]] | None = None) -> set[tuple[str, str]]:
    """The locating pairs (Y, X) of ``located`` (body -> direction -> its locators),
    ``nearer`` (those met within shorter reaches, :func:`locators`) and ``ways`` (body ->
    its ways in, named removal directions -> unit vectors): along every way, Y (not the
    base) is the one locator X meets first along some direction :func:`beside` it, the
    parts ``later`` puts after X (body -> parts that must follow it) not counted: they
    are not there when X goes in."""
    pairs: set[tuple[str, str]] = set()
    for part, by_direction in located.items():
        after = (later or {}).get(part, set())
        closer = (nearer or {}).get(part, {})
        alone: set[str] | None = None
        for axis in ways[part].values():
            met = {name: first_met([*closer.get(name, []), by_direction[name]], after) for name in beside(axis)}
            here = {next(iter(met[name])) for name in met if len(met[name]) == 1 and base not in by_direction[name]}
            alone = here if alone is None else alone & here
        pairs |= {(locator, part) for locator in alone or ()}
    return pairs


def placing_pairs(supports: set[tuple[str, str]], located: dict[str, dict[str, set[str]]],
                  ways: dict[str, dict[str, tuple[float, float, float]]], bodies: dict[str, set[str]], base: str,
                  edges: set[tuple[str, str]], nearer: dict[str, dict[str, list[set[str]]]] | None = None
                  ) -> tuple[dict[tuple[str, str], str], dict[str, set[str]]]:
    """The supporting and locating pairs with their reasons (``supports``, ``locates``) and
    each body's parts that must follow it by the blocking ``edges`` and the pairs of these
    that :func:`consistent` keeps. A part that must follow X does not locate
    X (it is not there when X goes in): the locating pairs are found again without the
    parts that the pairs kept so far put after each body, until that adds none (a shaft
    located across by a bearing and by the glands on it, which the shaft alone locates,
    goes after the bearing). Each round only removes locators, so this ends."""
    later: dict[str, set[str]] = {root: set() for root in bodies}
    placing = dict.fromkeys(supports, "supports")
    while True:
        # every round's pairs are kept: a later round only adds pairs, or loses ones the
        # pairs kept contradict (a locator after its part), which stay to be reported dropped
        placing |= {pair: "locates" for pair in locating_candidates(located, ways, base, later, nearer)
                    if pair not in placing}
        kept, _ = consistent(sorted(placing), edges)
        graph = nx.DiGraph(edges | kept)
        after = {root: later[root] | (set().union(*(nx.descendants(graph, m) for m in members if m in graph))
                                      - members) for root, members in bodies.items()}
        if after == later:
            return placing, later
        later = after


def consistent(candidates: list[tuple[str, str]], edges: set[tuple[str, str]]
               ) -> tuple[set[tuple[str, str]], set[tuple[str, str]]]:
    """(kept, dropped) ``candidates`` in order: a pair (Y, X) is dropped when X precedes Y
    through ``edges`` (the blocking precedence) and the pairs kept before it."""
    graph = nx.DiGraph(edges)
    kept: set[tuple[str, str]] = set()
    dropped: set[tuple[str, str]] = set()
    for first, then in candidates:  # one by one: kept pairs never close a cycle among themselves either
        if then in graph and first in graph and nx.has_path(graph, then, first):
            dropped.add((first, then))
        else:
            graph.add_edge(first, then)
            kept.add((first, then))
    return kept, dropped
