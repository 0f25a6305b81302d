"""Hole assignment (paper 2.2, end): the paper's greedy assignment and all feasible ones.

Input are learned facts files in the project's vocabulary (docs/plans.md): ``part/1``, ``hole/1``,
``fits/2`` (and ``no_fit/2``, ``needs_hole/1``, ``must_precede/2``...). A part *needs a
hole* when it has a ``fits/2`` or ``no_fit/2`` fact or a ``needs_hole/1`` fact
(``asp/encodings/plans/needs_hole.lp``); every other part (Cranfield: bp sp pd ph fp) is
placed without a hole.

- :func:`greedy_assignment`: the paper's greedy: the biggest unassigned part gets a free
  hole big enough for it. Sizes come from the learned relation: a part is the bigger
  the fewer holes it fits, a hole the bigger the more parts fit it. The part takes the
  smallest free hole it fits (ties: lower id), which keeps the big holes for the big
  parts. When the sizes are a biorder (what the size learner assumes, paper 2.2) this
  finds an assignment whenever one exists.
- :func:`all_assignments`: every feasible assignment, by ASP (``assignments.lp``).
- :func:`feasible_assignment`: the greedy one, or ASP's first when greedy gets stuck on
  sizes that are not a biorder although an assignment exists (``assign`` prints this).

An assembly without an assignment raises :class:`UnsolvableAssembly` naming a set of
parts that fit fewer holes than they are (Hall's condition; :func:`hall_violation`),
found from a maximum matching; "not solvable" is never said while a matching of every
part exists.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import clingo

from asp import PlannerError
from asp.precedence.relation import closed_precedence
from asp.solve import atoms_by_name, check_facts, fact, load_atoms, pairs_by_name, solve

Assignment = dict[str, str]
"""Part id -> hole id, for the parts that need a hole."""


class UnsolvableAssembly(PlannerError):
    """No feasible hole assignment. ``parts`` are parts that together fit fewer holes
    than they are (Hall's condition fails for them; the witness a maximum matching
    gives); ``part`` is the first of them."""

    def __init__(self, parts: Sequence[str], message: str) -> None:
        super().__init__(message)
        self.parts = tuple(parts)
        self.part = self.parts[0]


@dataclass(frozen=True)
class LearnedFacts:
    """What the planner knows, read from learned facts files.

    ``atoms`` are all atoms of the files plus ``needs_hole/1``; the other fields are the
    same knowledge as Python values (ids as strings, sorted).
    """

    atoms: tuple[clingo.Symbol, ...]
    parts: tuple[str, ...]
    holes: tuple[str, ...]
    fits: frozenset[tuple[str, str]]
    needs_hole: tuple[str, ...]
    must_precede: frozenset[tuple[str, str]]

    def holes_of(self, part: str) -> list[str]:
        """The holes ``part`` fits, sorted."""
        return [hole for hole in self.holes if (part, hole) in self.fits]


LEARNED_SIGNATURES = {"part": 1, "hole": 1, "fits": 2, "no_fit": 2, "needs_hole": 1,
                      "must_precede": 2, "precedence_edge": 2}
"""The predicates of learned facts the planner reads, with their arities (ids only)."""

RESERVED_IDS = frozenset({"none", "home", "site"})
"""Constants of plan_step/3 (``none``) and of the travel cost (``home``, ``site``)."""


def _check_ids(facts: LearnedFacts, sources: str) -> None:
    known_parts, known_holes = set(facts.parts), set(facts.holes)
    reserved = sorted(known_holes & RESERVED_IDS)
    if reserved:
        raise PlannerError(
            f"{sources}: hole({reserved[0]}): the ids {', '.join(sorted(RESERVED_IDS))} are "
            "reserved for plans (no hole, tool home, assembly site); rename the hole"
        )
    for name in ("fits", "no_fit"):
        for part, hole in atoms_by_name(facts.atoms, name, 2):
            if part not in known_parts or hole not in known_holes:
                raise PlannerError(
                    f"{sources}: {name}({part},{hole}): expected a part/1 and a hole/1 "
                    f"(parts: {' '.join(facts.parts)}; holes: {' '.join(facts.holes) or '-'})"
                )
    both = sorted(facts.fits & set(pairs_by_name(facts.atoms, "no_fit")))
    if both:
        part, hole = both[0]
        raise PlannerError(f"{sources}: both fits({part},{hole}) and no_fit({part},{hole}); "
                           "expected one result per part and hole")


def load_learned_facts(paths: Sequence[Path | str]) -> LearnedFacts:
    """Read learned facts files; PlannerError on a file that does not parse, a predicate of
    the wrong arity or with non-id arguments (:data:`LEARNED_SIGNATURES`), unknown ids,
    a pair both fitting and not fitting, or a precedence cycle.

    Precedence is read in both forms, ``must_precede/2`` and ``precedence_edge/2``, and
    closed (:func:`asp.precedence.relation.closed_precedence`): ``must_precede`` and the
    ``must_precede/2`` atoms hold the closure."""
    sources = ", ".join(str(p) for p in paths)
    atoms = load_atoms(paths, encodings=["plans/needs_hole.lp"])
    check_facts(atoms, LEARNED_SIGNATURES, sources)
    if not atoms_by_name(atoms, "part", 1):
        raise PlannerError(f"{sources}: expected part/1 facts (the assembly's parts), found none")
    must_precede = closed_precedence(atoms, sources)
    atoms = [atom for atom in atoms if not atom.match("must_precede", 2)]
    atoms += [fact("must_precede", first, then) for first, then in sorted(must_precede)]
    facts = LearnedFacts(
        atoms=tuple(atoms),
        parts=tuple(p for (p,) in atoms_by_name(atoms, "part", 1)),
        holes=tuple(h for (h,) in atoms_by_name(atoms, "hole", 1)),
        fits=frozenset(pairs_by_name(atoms, "fits")),
        needs_hole=tuple(p for (p,) in atoms_by_name(atoms, "needs_hole", 1)),
        must_precede=must_precede,
    )
    _check_ids(facts, sources)
    return facts


def greedy_assignment(facts: LearnedFacts) -> Assignment:
    """The paper's greedy assignment; UnsolvableAssembly naming the part left without a hole."""
    holes_of = {part: facts.holes_of(part) for part in facts.needs_hole}
    parts_in = {hole: sum(hole in holes for holes in holes_of.values()) for hole in facts.holes}
    biggest_first = sorted(facts.needs_hole, key=lambda part: (len(holes_of[part]), part))
    assignment: Assignment = {}
    taken_by: dict[str, str] = {}
    for part in biggest_first:
        free = [hole for hole in holes_of[part] if hole not in taken_by]
        if not free:
            raise UnsolvableAssembly([part], _no_hole_message(part, holes_of[part], taken_by))
        hole = min(free, key=lambda h: (parts_in[h], h))
        assignment[part] = hole
        taken_by[hole] = part
    return assignment


def _no_hole_message(part: str, fitting: list[str], taken_by: dict[str, str]) -> str:
    if not fitting:
        return f"the assembly is not solvable: part {part} fits no hole"
    taken = ", ".join(f"{hole} by {taken_by[hole]}" for hole in fitting)
    return (
        f"the assembly is not solvable: part {part} gets no hole; the holes it fits are "
        f"taken by parts at least as big ({taken})"
    )


def maximum_matching(facts: LearnedFacts) -> Assignment:
    """A largest set of parts with distinct holes they fit (augmenting paths, Kuhn's
    algorithm; parts in id order, holes in the facts' order)."""
    holes_of = {part: facts.holes_of(part) for part in sorted(facts.needs_hole)}
    owner: dict[str, str] = {}

    def augment(part: str, seen: set[str]) -> bool:
        for hole in holes_of[part]:
            if hole not in seen:
                seen.add(hole)
                if hole not in owner or augment(owner[hole], seen):
                    owner[hole] = part
                    return True
        return False

    for part in holes_of:
        augment(part, set())
    return {part: hole for hole, part in owner.items()}


def hall_violation(facts: LearnedFacts, matching: Assignment) -> tuple[list[str], list[str]]:
    """For a maximum ``matching`` that leaves a part out: parts S and the holes N(S) they
    fit, with |N(S)| < |S| (König: the parts reachable from an unmatched part along
    alternating paths; every hole they reach is matched, to another part of S)."""
    unmatched = sorted(p for p in facts.needs_hole if p not in matching)
    owner = {hole: part for part, hole in matching.items()}
    parts, holes, frontier = {unmatched[0]}, set(), [unmatched[0]]
    while frontier:
        for hole in facts.holes_of(frontier.pop()):
            if hole not in holes:
                holes.add(hole)
                if owner[hole] not in parts:
                    parts.add(owner[hole])
                    frontier.append(owner[hole])
    return sorted(parts), [h for h in facts.holes if h in holes]


def _unsolvable(facts: LearnedFacts, matching: Assignment) -> UnsolvableAssembly:
    """The error for facts whose maximum ``matching`` leaves a part without a hole."""
    parts, holes = hall_violation(facts, matching)
    if not holes:
        return UnsolvableAssembly(parts, f"the assembly is not solvable: part {parts[0]} fits no hole")
    return UnsolvableAssembly(parts, f"the assembly is not solvable: parts {' '.join(parts)} fit only "
                                     f"{len(holes)} hole(s) between them ({' '.join(holes)}): fewer holes "
                                     "than parts")


def _solve_assignments(facts: LearnedFacts, limit: int) -> list[Assignment]:
    """Up to ``limit`` (0 = all) assignments of ``assignments.lp``, in clingo's order."""
    found: list[Assignment] = []

    def keep(model: clingo.Model) -> None:
        found.append(dict(pairs_by_name(model.symbols(shown=True), "assigned")))

    solve(["assignments.lp"], facts.atoms, [f"--models={limit}"], keep)
    return found


def _require_complete_matching(facts: LearnedFacts) -> None:
    """UnsolvableAssembly naming a Hall violator when no complete assignment exists."""
    matching = maximum_matching(facts)
    if len(matching) < len(facts.needs_hole):
        raise _unsolvable(facts, matching)


def all_assignments(facts: LearnedFacts, limit: int = 0) -> list[Assignment]:
    """Every feasible assignment (at most ``limit``, 0 = all), sorted.

    UnsolvableAssembly naming parts with fewer holes than parts when there is none.
    """
    _require_complete_matching(facts)
    return sorted(_solve_assignments(facts, limit), key=lambda a: sorted(a.items()))


def feasible_assignment(facts: LearnedFacts) -> Assignment:
    """The paper's greedy assignment; when greedy gets stuck although an assignment
    exists (the relation is not one biorder: parts of several cross-sections, a
    hand-written fits/2 table), the first one ASP finds.

    UnsolvableAssembly naming parts with fewer holes than parts only when none exists.
    """
    try:
        return greedy_assignment(facts)
    except UnsolvableAssembly:
        _require_complete_matching(facts)
        return _solve_assignments(facts, 1)[0]
