"""The geometric precedence of the disassembly: the moving bodies (:func:`bodies`), the
``blocks`` pairs (:func:`forced`: A cannot go in once B is there) and the ``feature`` pairs
(:func:`owner_pairs`: the owner of a hole or pin before the parts going into or onto it)."""

from __future__ import annotations

from collections.abc import Iterable

import networkx as nx

from executor.cad.derive.derived import Derived
from executor.cad.parts import CadPart


def bodies(parts: dict[str, CadPart], base: str, fixed_to: dict[str, str]) -> dict[str, set[str]]:
    """The moving bodies: each part not fixed to another (not the base) -> it and the
    parts fixed to it, directly or through others."""
    def root(pid: str) -> str:
        seen = {pid}
        while pid in fixed_to and fixed_to[pid] not in seen:
            pid = fixed_to[pid]
            seen.add(pid)
        return pid
    found: dict[str, set[str]] = {}
    for pid in parts:
        if pid != base:
            found.setdefault(root(pid), set()).add(pid)
    return found


def forced(derived: Derived, seeds: Iterable[tuple[str, str]] = ()) -> dict[tuple[str, str], str]:
    """The ``blocks`` pairs: A before B when, of the directions the base leaves A free
    along, B blocks one and B or the parts present whenever B is (its body, the base, the
    bodies already found to precede it, or put before it by ``seeds``: (part, part) pairs
    of the support rule) block every one; repeated until no pair is added,
    then every pair the rule gives with those, also where A already precedes B through
    others (so the pairs do not depend on the order of the ids). Each pair's blockers per
    direction in ``derived.detail``."""
    rep = {root: min(members) for root, members in derived.bodies.items()}
    before: dict[str, set[str]] = {root: set() for root in derived.bodies}
    root_of = {pid: root for root, members in derived.bodies.items() for pid in members}
    for first, then in seeds:
        if first in root_of and then in root_of and root_of[first] != root_of[then]:
            before[root_of[then]].add(root_of[first])
    pairs: dict[tuple[str, str], str] = {}

    def ahead(root: str) -> set[str]:
        seen: set[str] = set()
        todo = [root]
        while todo:
            for prior in before[todo.pop()] - seen:
                seen.add(prior)
                todo.append(prior)
        return seen

    def found(a: str, b: str, known: bool) -> bool:
        """Whether the rule puts body ``a`` before body ``b`` (recorded); ``known``: also
        where ``a`` is already found to precede ``b``."""
        ways, prior = list(derived.ways(rep[a])), ahead(b)
        if b == a or (a in prior and not known) or not ways:
            return False
        present = derived.bodies[b].union(*(derived.bodies[p] for p in prior - {a}))
        blocking = {d: derived.blockers[(rep[a], d)] & present for d in ways}
        if not all(blocking.values()) or not any(hit & derived.bodies[b] for hit in blocking.values()):
            return False
        detail = "; ".join(f"{d} {' '.join(sorted(hit))}" for d, hit in blocking.items())
        for x in sorted(derived.bodies[a]):
            for y in sorted(derived.bodies[b] & set().union(*blocking.values())):
                pairs[(x, y)] = "blocks"
                derived.detail[(x, y)] = detail
        return True

    grown = True
    while grown:
        grown = False
        for a in derived.bodies:
            for b in derived.bodies:
                if found(a, b, known=False):
                    before[b].add(a)
                    grown = True
    # every pair the rule gives once nothing is added, those already ordered through others
    # too: which ones the loop skipped depends on the order of the ids
    for a in derived.bodies:
        for b in derived.bodies:
            if a in ahead(b):
                found(a, b, known=True)
    return pairs


def owner_pairs(derived: Derived) -> dict[tuple[str, str], str]:
    """The ``feature`` pairs: the owner of a feature before each part that goes into or
    onto it (the base, or the moving part a hole is in, before the part in the hole; a
    pin's owner before the parts on it), where ``derived.edges`` do not order them already.
    The cell inserts a part into its feature, so the feature's owner must be in place
    first: a precondition of the insertion, not a consequence of the blocking (a peg
    standing on the floor through a hole of the base, touching none of it, has every way in
    free whatever the order, and the base would be carried into its fixture over it)."""
    order = nx.DiGraph(list(derived.edges))
    wanted = [(derived.base if fit.owner is None else fit.owner, part)
              for fit in [*derived.holes.values(), *derived.part_holes.values()] for part in fit.occupants]
    wanted += [(pin.owner, part) for pin in derived.pins.values() for part in pin.parts]
    return {(owner, part): "feature" for owner, part in sorted(set(wanted))
            if not (owner in order and part in order and nx.has_path(order, owner, part))}
