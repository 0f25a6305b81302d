"""A precedence relation over the parts of an assembly, and its ASP forms.

:class:`Relation` holds a boolean matrix (``matrix[i, j]``: part ``parts[i]`` must be
placed before ``parts[j]``, paper Fig. 2). Transitive closure and reduction are
computed by the ASP encodings ``precedence_closure.lp`` and
``precedence_reduction.lp``; the relation is written as ``part/1``,
``must_precede/2`` (closure) and ``precedence_edge/2`` (reduction) facts.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from graphlib import CycleError, TopologicalSorter
from pathlib import Path

import clingo
import numpy as np

from asp import MAX_IDS, PlannerError
from asp.solve import (
    atoms_by_name,
    check_facts,
    fact,
    load_atoms,
    pairs_by_name,
    read_ground_facts,
)
from bridge.assembly import Assembly

Pair = tuple[str, str]


@dataclass(frozen=True, eq=False)
class Relation:
    """A precedence relation: ``matrix[i, j]`` is True when ``parts[i]`` precedes ``parts[j]``."""

    parts: tuple[str, ...]
    matrix: np.ndarray

    @classmethod
    def from_pairs(cls, parts: Sequence[str], pairs: Iterable[Pair]) -> Relation:
        """Relation over ``parts`` holding exactly ``pairs``; PlannerError on an unknown id."""
        index = {p: i for i, p in enumerate(parts)}
        matrix = np.zeros((len(parts), len(parts)), dtype=bool)
        for a, b in pairs:
            for x in (a, b):
                if x not in index:
                    raise PlannerError(f"must_precede({a},{b}): '{x}' is not a part ({', '.join(parts)})")
            matrix[index[a], index[b]] = True
        return cls(tuple(parts), matrix)

    def pairs(self) -> list[Pair]:
        """The ordered pairs (a, b) with a before b, in part order."""
        rows, cols = np.nonzero(self.matrix)
        return [(self.parts[i], self.parts[j]) for i, j in zip(rows.tolist(), cols.tolist())]

    def key(self) -> tuple[tuple[str, ...], bytes]:
        """A hashable identity of the relation (for memoising counts)."""
        return self.parts, np.packbits(self.matrix).tobytes()

    def same_as(self, other: Relation) -> bool:
        return self.parts == other.parts and bool(np.array_equal(self.matrix, other.matrix))

    def admits(self, sequence: Sequence[str]) -> bool:
        """Whether the sequence (all parts, each once) respects every pair."""
        position = {p: i for i, p in enumerate(sequence)}
        order = np.array([position[p] for p in self.parts])
        return not bool(np.any(self.matrix & (order[:, None] > order[None, :])))

    def matrix_text(self) -> str:
        """The relation as a 0/1 matrix with row and column labels (paper Fig. 2)."""
        width = max(len(p) for p in self.parts)
        lines = [" " * width + " " + " ".join(f"{p:>{width}}" for p in self.parts)]
        for name, row in zip(self.parts, self.matrix):
            lines.append(f"{name:>{width}} " + " ".join(f"{int(v):>{width}}" for v in row))
        return "\n".join(lines)


def _relation_facts(relation: Relation, name: str) -> list[clingo.Symbol]:
    return [fact("part", p) for p in relation.parts] + [fact(name, a, b) for a, b in relation.pairs()]


def close(relation: Relation, source: str = "precedence constraints") -> Relation:
    """Transitive closure by ``precedence_closure.lp``; PlannerError naming a cycle."""
    atoms = load_atoms([], encodings=["precedence_closure.lp"], extra=_relation_facts(relation, "must_precede"))
    cycle = atoms_by_name(atoms, "cycle", 1)
    if cycle:
        raise PlannerError(
            f"{source}: the constraints contain a cycle through {', '.join(c[0] for c in cycle)}; "
            "expected an acyclic precedence relation"
        )
    return Relation.from_pairs(relation.parts, pairs_by_name(atoms, "must_precede"))


def reduction(relation: Relation) -> list[Pair]:
    """Transitive reduction (``precedence_edge`` pairs) of a closed acyclic relation."""
    atoms = load_atoms([], encodings=["precedence_reduction.lp"], extra=_relation_facts(relation, "must_precede"))
    return pairs_by_name(atoms, "precedence_edge")


def precedence_facts(relation: Relation) -> list[clingo.Symbol]:
    """``part/1``, ``must_precede/2`` (closure) and ``precedence_edge/2`` (reduction) facts."""
    closed = close(relation)
    return _relation_facts(closed, "must_precede") + [
        fact("precedence_edge", a, b) for a, b in reduction(closed)
    ]


MAX_PRIOR_FACTS = MAX_IDS + 2 * MAX_IDS * MAX_IDS
"""The most facts a precedence prior holds: every part, and every pair in both forms."""


def load_relation(paths: Sequence[Path | str], *, data: bool = False) -> Relation:
    """Read ``part/1`` with ``must_precede/2`` and/or ``precedence_edge/2`` facts; closed.
    With ``data`` (a prior such as the ``geometric_precedence.lp`` import writes) the files
    are read as ground facts only (:func:`asp.solve.read_ground_facts`,
    at most :data:`MAX_PRIOR_FACTS`), never grounded as a program.

    PlannerError when the files hold no ``part/1``, name an unknown part or hold a cycle.
    """
    names = ", ".join(str(p) for p in paths)
    if data:
        expected = "part/1, must_precede/2 and precedence_edge/2 facts"
        facts = [atom for path in paths
                 for _, atom in read_ground_facts(Path(path), expected, max_facts=MAX_PRIOR_FACTS)]
        atoms = load_atoms([], encodings=["precedence_closure.lp"], extra=facts, shown_only=False)
    else:
        atoms = load_atoms(paths, encodings=["precedence_closure.lp"], shown_only=False)
    check_facts(atoms, {"part": 1, "must_precede": 2, "precedence_edge": 2}, names)
    parts = [p for (p,) in atoms_by_name(atoms, "part", 1)]
    if not parts:
        raise PlannerError(f"{names}: expected part/1 facts naming the parts of the assembly")
    pairs = pairs_by_name(atoms, "must_precede")
    unknown = sorted({x for pair in pairs for x in pair} - set(parts))
    if unknown:
        raise PlannerError(f"{names}: must_precede/precedence_edge name '{unknown[0]}', which is not a part/1")
    relation = Relation.from_pairs(parts, pairs)
    cycle = atoms_by_name(atoms, "cycle", 1)
    if cycle:
        raise PlannerError(f"{names}: the constraints contain a cycle through {', '.join(c[0] for c in cycle)}")
    return relation


def closed_precedence(atoms: Sequence[clingo.Symbol], source: str) -> frozenset[Pair]:
    """The precedence of checked facts atoms (:func:`asp.solve.check_facts`) in both forms,
    ``must_precede/2`` and ``precedence_edge/2`` (a reduction, as every shipped
    ``precedence.lp`` has it), transitively closed.

    PlannerError naming ``source`` and the atom when a pair names an id that is not a
    ``part/1``, or naming the cycle (``a < b < a``) when the pairs have one.
    """
    parts = [p for (p,) in atoms_by_name(atoms, "part", 1)]
    pairs: list[Pair] = []
    for name in ("must_precede", "precedence_edge"):
        for first, then in pairs_by_name(atoms, name):
            unknown = next((x for x in (first, then) if x not in parts), None)
            if unknown is not None:
                raise PlannerError(f"{source}: {name}({first},{then}): {unknown} is not a part/1 "
                                   f"(parts: {' '.join(parts)})")
            pairs.append((first, then))
    successors: dict[str, set[str]] = {}
    for first, then in pairs:
        successors.setdefault(first, set()).add(then)
    try:
        TopologicalSorter(successors).prepare()
    except CycleError as exc:
        ring = list(reversed(exc.args[1]))[:-1]  # graphlib names each node's predecessor next
        start = ring.index(min(ring))
        cycle = " < ".join([*ring[start:], *ring[:start], ring[start]])
        raise PlannerError(f"{source}: must_precede has a cycle {cycle}; expected an acyclic precedence "
                           "relation") from None
    return frozenset(close(Relation.from_pairs(parts, pairs), source).pairs())


def true_relation(assembly: Assembly) -> Relation:
    """The assembly's true constraints (``precedence.lp``), closed, in assembly part order."""
    relation = load_relation([assembly.file("precedence.lp")])
    if set(relation.parts) != set(assembly.part_ids):
        raise PlannerError(
            f"{assembly.file('precedence.lp')}: part/1 facts {sorted(relation.parts)} differ from "
            f"the parts of assembly.toml {sorted(assembly.part_ids)}"
        )
    return Relation.from_pairs(assembly.part_ids, relation.pairs())
