"""Hole assignment (paper 2.2, end): the paper's greedy assignment and all feasible ones.

Input are learned facts files in the project's vocabulary (docs/plans.md): ``part/1``, ``hole/1``,
``fits/2`` (and ``no_fit/2``, ``needs_hole/1``, ``must_precede/2``...). A part *needs a
hole* when it has a ``fits/2`` or ``no_fit/2`` fact or a ``needs_hole/1`` fact
(``asp/encodings/plans/needs_hole.lp``); every other part (Cranfield: bp sp pd ph fp) is
placed without a hole.

A hole takes one part, or ``capacity(H,C)`` parts (a pin the product stacks parts
onto, one above the other: the import writes it); parts that share a hole must be
ordered by ``must_precede/2`` (the lower first), else their order along it is unknown.
A part is never given a hole the cell cannot put it in (``out_of_reach(P,H)``: a hole of
a part placed by hand; :func:`product_facts`). A part held where the CAD has it
(``cad_hole(P,H)``: a part placed by hand, and a part the cell places that carries its
hole or pin) gets only one of those holes, and they go to no other part
(``asp/encodings/plans/cad_hole.lp``).

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

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import clingo

from asp import MAX_IDS, PlannerError
from asp.precedence.relation import Pair, closed_precedence
from asp.solve import atoms_by_name, check_facts, fact, load_atoms, pairs_by_name, solve
from bridge.assembly import Assembly
from bridge.inputs import shorten

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
    capacity: Mapping[str, int] = field(default_factory=dict)
    """Hole -> the number of parts it takes, for the holes of a ``capacity/2`` fact (others: 1)."""
    out_of_reach: frozenset[tuple[str, str]] = frozenset()
    """(part, hole) pairs the cell cannot put in or the CAD holds elsewhere (``out_of_reach/2``)."""
    cad_holes: frozenset[tuple[str, str]] = frozenset()
    """(part, hole) pairs of a part held where the CAD has it (``cad_hole/2``)."""
    cell_before: frozenset[tuple[str, str]] = frozenset()
    """(peg, part) pairs the cell's fingers need in this order (``cell_before/2``, not precedence)."""
    on_line: frozenset[tuple[str, str, str]] = frozenset()
    """(G, H, O): hole G of part O lies on hole H's line (``on_line/3``): a part goes through G
    into H, never into G alone, and only if it fits both (``asp/encodings/plans/on_line.lp``)."""

    @property
    def plan_order(self) -> frozenset[tuple[str, str]]:
        """The orders every plan keeps: the precedence and the cell's own orders."""
        return self.must_precede | self.cell_before

    def holes_of(self, part: str) -> list[str]:
        """The holes ``part`` fits and the cell can put it in, sorted: places (on no other
        hole's line) whose every hole on their line it fits too (:attr:`on_line`)."""
        passed = {g for g, _, _ in self.on_line}
        return [hole for hole in self.holes if (part, hole) in self.fits and (part, hole) not in self.out_of_reach
                and hole not in passed and all((part, g) in self.fits for g, h, _ in self.on_line if h == hole)]

    def room(self, hole: str) -> int:
        """How many parts ``hole`` takes."""
        return self.capacity.get(hole, 1)

    def ordered(self, first: str, then: str) -> bool:
        """Whether precedence orders the two parts (either way), so they can share a hole."""
        return (first, then) in self.must_precede or (then, first) in self.must_precede


LEARNED_SIGNATURES = {"part": 1, "hole": 1, "fits": 2, "no_fit": 2, "needs_hole": 1,
                      "must_precede": 2, "precedence_edge": 2, "out_of_reach": 2, "cad_hole": 2,
                      "cell_before": 2, "pressed": 1, "on_line": 3}
"""The predicates of learned facts the planner reads, with their arities (ids only)."""

CELL_ORDER = "cell_order.lp"
"""The product's file of the cell's own orders (``cell_before/2``, written by ``./run.sh import``)."""

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
    for name in ("fits", "no_fit", "cad_hole", "out_of_reach"):  # cad_hole first: out_of_reach follows from it
        for part, hole in atoms_by_name(facts.atoms, name, 2):
            if part not in known_parts or hole not in known_holes:
                raise PlannerError(
                    f"{sources}: {name}({part},{hole}): expected a part/1 and a hole/1 "
                    f"(parts: {' '.join(facts.parts)}; holes: {' '.join(facts.holes) or '-'})"
                )
    for passed, hole, owner in sorted(facts.on_line):
        if passed not in known_holes or hole not in known_holes or owner not in known_parts or passed == hole:
            raise PlannerError(f"{sources}: on_line({passed},{hole},{owner}): expected two holes/1 and a part/1 "
                               f"(parts: {' '.join(facts.parts)}; holes: {' '.join(facts.holes) or '-'})")
    for first, then in sorted(facts.cell_before):
        if first not in known_parts or then not in known_parts:
            raise PlannerError(f"{sources}: cell_before({first},{then}): expected two part/1 "
                               f"(parts: {' '.join(facts.parts)})")
    both = sorted(facts.fits & set(pairs_by_name(facts.atoms, "no_fit")))
    if both:
        part, hole = both[0]
        raise PlannerError(f"{sources}: both fits({part},{hole}) and no_fit({part},{hole}); "
                           "expected one result per part and hole")


def _capacities(atoms: Sequence[clingo.Symbol], holes: set[str], sources: str) -> dict[str, int]:
    """Hole -> capacity from the ``capacity(H,C)`` atoms; PlannerError naming the atom
    unless H is a hole/1 and C an integer in 1 .. MAX_IDS, one per hole."""
    capacity: dict[str, int] = {}
    for atom in atoms:
        if atom.type != clingo.SymbolType.Function or atom.name != "capacity":
            continue
        args = atom.arguments
        if (len(args) != 2 or args[0].type != clingo.SymbolType.Function or str(args[0]) not in holes
                or args[1].type != clingo.SymbolType.Number or not 1 <= args[1].number <= MAX_IDS
                or str(args[0]) in capacity):
            raise PlannerError(f"{sources}: {shorten(atom, 60)}: expected capacity(H,C), H a hole/1 and C the "
                               f"number of parts it takes (an integer in 1 .. {MAX_IDS}), one per hole")
        capacity[str(args[0])] = args[1].number
    return capacity


def cell_orders(assembly: Assembly) -> tuple[Pair, ...]:
    """The cell's own orders ``cell_before(P,Q)`` of the product's :data:`CELL_ORDER` (the
    fingers' grip of peg P needs it in before part Q), sorted; () without the file.
    PlannerError naming the file for an order of an id that is no part of the assembly."""
    if not assembly.has_file(CELL_ORDER):
        return ()
    path = assembly.file(CELL_ORDER)
    orders = pairs_by_name(load_atoms([path]), "cell_before")
    parts = set(assembly.part_ids)
    for first, then in orders:
        if first not in parts or then not in parts:
            raise PlannerError(f"{path}: cell_before({first},{then}): expected two parts of the assembly "
                               f"({' '.join(assembly.part_ids)})")
    return tuple(orders)


def product_facts(assembly: Assembly) -> list[clingo.Symbol]:
    """What the product says about its holes beyond sizes: ``capacity(H,C)`` for a hole
    taking C > 1 parts, ``out_of_reach(P,H)`` for a part the cell inserts (not the base,
    not placed by hand) and a hole the cell cannot put it in (:meth:`bridge.assembly.Assembly.cell_cannot_insert`),
    ``pressed(P)`` for a part pressed in by hand (:attr:`bridge.assembly.Assembly.pressed`: it needs no hole),
    ``cad_hole(P,H)`` for a part held where the CAD has it (:attr:`bridge.assembly.Assembly.cad_holes`),
    ``on_line(G,H,O)`` for a hole G of part O on hole H's line (:attr:`bridge.assembly.Hole.line`),
    and the cell's own orders ``cell_before(P,Q)`` of the product's ``cell_order.lp``
    (:data:`CELL_ORDER`: the fingers' grip of peg P needs it in before part Q)."""
    atoms = [fact("capacity", hole.id, hole.capacity) for hole in assembly.holes if hole.capacity > 1]
    atoms += [fact("pressed", part) for part in sorted(assembly.pressed)]
    atoms += [fact("cad_hole", part, hole) for part, holes in sorted(assembly.cad_holes.items())
              for hole in sorted(holes)]
    atoms += [fact("cell_before", first, then) for first, then in cell_orders(assembly)]
    atoms += [fact("on_line", hole.id, *hole.line) for hole in assembly.holes if hole.line is not None]
    inserted = [part.id for part in assembly.parts if part.role != "base" and part.id not in assembly.manual]
    return atoms + [fact("out_of_reach", part, hole) for part in inserted
                    for hole in assembly.hole_ids if assembly.cell_cannot_insert(part, hole)]


def load_learned_facts(paths: Sequence[Path | str], product: Sequence[clingo.Symbol] = ()) -> LearnedFacts:
    """Read learned facts files (and the ``product`` facts, :func:`product_facts`);
    PlannerError on a file that does not parse, a predicate of the wrong arity or with
    non-id arguments (:data:`LEARNED_SIGNATURES`), unknown ids, a bad ``capacity/2``,
    a pair both fitting and not fitting, or a precedence cycle. ``out_of_reach`` holds
    too the pairs ``cad_hole/2`` rules out (``plans/cad_hole.lp``).

    Precedence is read in both forms, ``must_precede/2`` and ``precedence_edge/2``, and
    closed (:func:`asp.precedence.relation.closed_precedence`): ``must_precede`` and the
    ``must_precede/2`` atoms hold the closure."""
    sources = ", ".join(str(p) for p in paths)
    atoms = list(dict.fromkeys(load_atoms(paths, encodings=["plans/needs_hole.lp", "plans/cad_hole.lp"],
                                          extra=product)))
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
        capacity=_capacities(atoms, {h for (h,) in atoms_by_name(atoms, "hole", 1)}, sources),
        out_of_reach=frozenset(pairs_by_name(atoms, "out_of_reach")),
        cad_holes=frozenset(pairs_by_name(atoms, "cad_hole")),
        cell_before=frozenset(pairs_by_name(atoms, "cell_before")),
        on_line=frozenset((g, h, o) for g, h, o in atoms_by_name(atoms, "on_line", 3)),
    )
    _check_ids(facts, sources)
    return facts


def greedy_assignment(facts: LearnedFacts) -> Assignment:
    """The paper's greedy assignment; UnsolvableAssembly naming the part left without a
    hole. A hole that takes several parts is free for a part while it has room and the
    part is ordered with each part already in it."""
    holes_of = {part: facts.holes_of(part) for part in facts.needs_hole}
    parts_in = {hole: sum(hole in holes for holes in holes_of.values()) for hole in facts.holes}
    biggest_first = sorted(facts.needs_hole, key=lambda part: (len(holes_of[part]), part))
    assignment: Assignment = {}
    taken_by: dict[str, list[str]] = {hole: [] for hole in facts.holes}
    for part in biggest_first:
        free = [hole for hole in holes_of[part] if len(taken_by[hole]) < facts.room(hole)
                and all(facts.ordered(part, other) for other in taken_by[hole])]
        if not free:
            raise UnsolvableAssembly([part], _no_hole_message(facts, part, holes_of[part], taken_by))
        hole = min(free, key=lambda h: (parts_in[h], h))
        assignment[part] = hole
        taken_by[hole].append(part)
    return assignment


def _no_hole_message(facts: LearnedFacts, part: str, fitting: list[str], taken_by: dict[str, list[str]]) -> str:
    if not fitting:
        return f"the assembly is not solvable: part {part} fits no hole{_reach_note(facts, [part])}"
    taken = ", ".join(f"{hole} by {' '.join(taken_by[hole])}" for hole in fitting)
    return (
        f"the assembly is not solvable: part {part} gets no hole; the holes it fits are "
        f"taken by parts at least as big ({taken})"
    )


def _reach_note(facts: LearnedFacts, parts: Sequence[str]) -> str:
    """`` the cell can use`` when the cell cannot reach a hole one of ``parts`` fits,
    `` the CAD leaves it`` when the CAD holds one of them or such a hole elsewhere, else
    `` (with every hole on its line ...)`` when a hole one of them fits is no place for it
    (on another's line, or a hole on its line it does not fit: :attr:`LearnedFacts.on_line`)."""
    ruled_out = [pair for pair in facts.out_of_reach & facts.fits if pair[0] in parts]
    held = {part for part, _ in facts.cad_holes} | {hole for _, hole in facts.cad_holes}
    if any(part in held or hole in held for part, hole in ruled_out):
        return " the CAD leaves it (cad_hole/2)"
    if ruled_out:
        return " the cell can use"
    off_line = [(part, hole) for part, hole in facts.fits if part in parts and hole not in facts.holes_of(part)]
    return " (with every hole on its line: on_line/3)" if off_line else ""


def maximum_matching(facts: LearnedFacts) -> Assignment:
    """A largest set of parts with holes they fit, each hole holding at most its
    :meth:`LearnedFacts.room` (augmenting paths, Kuhn's algorithm over the holes' places;
    parts in id order, holes in the facts' order). Precedence between parts sharing a
    hole is not looked at."""
    holes_of = {part: facts.holes_of(part) for part in sorted(facts.needs_hole)}
    owners: dict[str, list[str]] = {hole: [] for hole in facts.holes}

    def augment(part: str, seen: set[str]) -> bool:
        for hole in holes_of[part]:
            if hole not in seen:
                seen.add(hole)
                if len(owners[hole]) < facts.room(hole):
                    owners[hole].append(part)
                    return True
                for k, other in enumerate(owners[hole]):
                    if augment(other, seen):
                        owners[hole][k] = part
                        return True
        return False

    for part in holes_of:
        augment(part, set())
    return {part: hole for hole, parts in owners.items() for part in parts}


def hall_violation(facts: LearnedFacts, matching: Assignment) -> tuple[list[str], list[str]]:
    """For a maximum ``matching`` that leaves a part out: parts S and the holes N(S) they
    fit, with room for fewer than |S| parts (König: the parts reachable from an unmatched
    part along alternating paths; every hole they reach is full, of other parts of S)."""
    unmatched = sorted(p for p in facts.needs_hole if p not in matching)
    owners: dict[str, list[str]] = {}
    for part, hole in matching.items():
        owners.setdefault(hole, []).append(part)
    parts, holes, frontier = {unmatched[0]}, set(), [unmatched[0]]
    while frontier:
        for hole in facts.holes_of(frontier.pop()):
            if hole not in holes:
                holes.add(hole)
                for owner in owners[hole]:
                    if owner not in parts:
                        parts.add(owner)
                        frontier.append(owner)
    return sorted(parts), [h for h in facts.holes if h in holes]


def _unsolvable(facts: LearnedFacts, matching: Assignment) -> UnsolvableAssembly:
    """The error for facts whose maximum ``matching`` leaves a part without a hole."""
    parts, holes = hall_violation(facts, matching)
    reach = _reach_note(facts, parts)
    if not holes:
        return UnsolvableAssembly(parts, f"the assembly is not solvable: part {parts[0]} fits no hole{reach}")
    room = sum(facts.room(hole) for hole in holes)
    fewer = "fewer holes than parts" if room == len(holes) else f"room for {room} part(s), fewer than parts"
    return UnsolvableAssembly(parts, f"the assembly is not solvable: parts {' '.join(parts)} fit only "
                                     f"{len(holes)} hole(s){reach} between them "
                                     f"({' '.join(holes)}): {fewer}")


def _unordered_stack(facts: LearnedFacts, matching: Assignment) -> UnsolvableAssembly:
    """The error for facts with a complete matching but no assignment: every one stacks
    parts on a hole that precedence does not order (their order along it is unknown);
    names two such parts of ``matching``."""
    pairs = sorted((a, b, hole) for a, hole in matching.items() for b, other in matching.items()
                   if other == hole and a < b and not facts.ordered(a, b))
    a, b, hole = pairs[0]
    return UnsolvableAssembly([a, b], f"the assembly is not solvable: every hole assignment puts parts that no "
                                      f"precedence orders onto one hole (e.g. {a} {b} on {hole}), so their order "
                                      "along it is unknown")


def _solve_assignments(facts: LearnedFacts, limit: int) -> list[Assignment]:
    """Up to ``limit`` (0 = all) assignments of ``assignments.lp``, in clingo's order."""
    found: list[Assignment] = []

    def keep(model: clingo.Model) -> None:
        found.append(dict(pairs_by_name(model.symbols(shown=True), "assigned")))

    solve(["assignments.lp"], facts.atoms, [f"--models={limit}"], keep)
    return found


def _require_complete_matching(facts: LearnedFacts) -> None:
    """UnsolvableAssembly naming a Hall violator when no complete assignment exists (or
    two parts no precedence orders when the holes' room suffices but every assignment
    stacks such parts)."""
    matching = maximum_matching(facts)
    if len(matching) < len(facts.needs_hole):
        raise _unsolvable(facts, matching)
    if any(facts.room(hole) > 1 for hole in facts.holes) and not _solve_assignments(facts, 1):
        raise _unordered_stack(facts, matching)


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
