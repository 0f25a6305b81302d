"""Complete assembly plans: an order of all parts that respects ``must_precede``, each
part that needs a hole in a distinct hole it fits (``plan_step/3``), and the checker.

- :func:`plans`: up to ``n`` plans (``plans.lp``); with ``optimal=True`` the plans of
  least total tool travel [mm] (``plans_optimal.lp``), optimality proven by clingo.
- :func:`travel_facts`: the ``travel/3`` facts of the cost, from an assembly's geometry.
  The tool starts at ``home`` ([x, y] [m], default the cell origin where the arm
  stands), and for every step goes to the part's ``start``, carries it to its hole (or,
  for a part without a hole, to the assembly ``site``: the centre of the holes; with no
  hole, the base's centre in the cell, ``base_center`` of ``[plate]``) and,
  after the last step, returns home. Legs are straight lines, in whole millimetres.
- :func:`check_plan`, :func:`check_assignment`: the error atoms the checker
  (``check_plan.lp``) derives; an empty list means valid.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import clingo

from asp import PlannerError
from asp.plans.assign import LearnedFacts, UnsolvableAssembly, feasible_assignment
from asp.solve import fact, solve
from bridge.assembly import Assembly

HOME: tuple[float, float] = (0.0, 0.0)
"""Default tool home [m]: the cell origin."""

OPTIMAL_CONFIGURATION = "crafty"
"""clingo configuration for optimal plans: on Cranfield 0.24 s CPU to prove the optimum
and enumerate the optimal plans, against 0.31 s with clingo's default (auto)."""


@dataclass(frozen=True)
class PlanStep:
    """One step: ``part`` goes into ``hole`` (None for a part placed without a hole)."""

    part: str
    hole: str | None


@dataclass(frozen=True)
class Plan:
    """Steps in order; ``cost`` is the total tool travel [mm] of an optimal plan, else None."""

    steps: tuple[PlanStep, ...]
    cost: int | None = None

    def as_json(self) -> list[dict[str, str | None]]:
        """The plan as the JSON contract has it: ``[{"part": p, "hole": h|null}, ...]``."""
        return [{"part": step.part, "hole": step.hole} for step in self.steps]


def _plan_of(model: clingo.Model) -> Plan:
    steps = sorted(
        (atom.arguments[0].number, str(atom.arguments[1]), str(atom.arguments[2]))
        for atom in model.symbols(shown=True)
        if atom.match("plan_step", 3)
    )
    return Plan(tuple(PlanStep(part, None if hole == "none" else hole) for _, part, hole in steps))


def plans(
    facts: LearnedFacts,
    n: int = 1,
    optimal: bool = False,
    travel: Sequence[clingo.Symbol] = (),
    time_limit_s: float | None = None,
    prefix: Sequence[PlanStep] = (),
) -> list[Plan]:
    """Up to ``n`` complete plans (0 = all); optimal ones need the ``travel`` facts. With a
    ``prefix`` (steps already done) only plans that begin with it (``plans/prefix.lp``).

    With ``optimal=True`` every plan returned has the least cost and clingo has proven
    it; PlannerError when that takes longer than ``time_limit_s`` [s] (None: no limit).
    Every plan keeps the cell's own orders (``cell_before/2``, ``plans/cell_order.lp``).
    UnsolvableAssembly names the part without a hole, or the parts on a cycle of the
    cell's orders and the precedence; PlannerError when no order respects
    ``must_precede`` (a cycle).
    """
    if optimal and not travel:
        raise PlannerError("optimal plans need the travel/3 facts of an assembly's geometry")
    found: list[Plan] = []

    def keep(model: clingo.Model) -> None:
        if not optimal:
            found.append(_plan_of(model))
        elif model.optimality_proven:
            found.append(Plan(_plan_of(model).steps, cost=model.cost[0]))

    entry, arguments = "plans.lp", [f"--models={n}"]
    if optimal:
        entry = "plans_optimal.lp"
        arguments += ["--opt-mode=optN", f"--configuration={OPTIMAL_CONFIGURATION}"]
    done = [fact("done", t, step.part, step.hole or "none") for t, step in enumerate(prefix, start=1)]
    solve([entry, "plans/prefix.lp"] if prefix else [entry], [*facts.atoms, *travel, *done], arguments, keep,
          time_limit_s)
    if not found:
        feasible_assignment(facts)  # raises UnsolvableAssembly when no assignment exists
        crossed = _parts_on_cycles(facts.must_precede | facts.cell_before)
        if crossed and facts.cell_before:
            raise UnsolvableAssembly(crossed, "the assembly is not solvable: the cell's own orders (cell_before/2, "
                                     "the fingers' grip: cell_order.lp) and the precedence have a cycle through "
                                     + " ".join(crossed))
        raise PlannerError(
            "no plan: no order of the parts respects must_precede, it has a cycle through "
            + " ".join(_parts_on_cycles(facts.must_precede))
        )
    return found


def _parts_on_cycles(must_precede: frozenset[tuple[str, str]]) -> list[str]:
    """The parts that must precede themselves through a chain of must_precede."""
    after: dict[str, set[str]] = {}
    for first, then in must_precede:
        after.setdefault(first, set()).add(then)
    on_cycle: list[str] = []
    for part in sorted(after):
        reached: set[str] = set()
        todo = list(after[part])
        while todo and part not in reached:
            nxt = todo.pop()
            if nxt not in reached:
                reached.add(nxt)
                todo.extend(after.get(nxt, ()))
        if part in reached:
            on_cycle.append(part)
    return on_cycle


def _errors(facts: LearnedFacts, given: list[clingo.Symbol]) -> list[str]:
    errors: list[str] = []

    def keep(model: clingo.Model) -> None:
        errors.extend(str(atom.arguments[0]) for atom in model.symbols(shown=True))

    solve(["check_plan.lp"], [*facts.atoms, *given], [], keep)
    return sorted(errors)


def check_plan(facts: LearnedFacts, steps: Sequence[PlanStep]) -> list[str]:
    """Errors of a plan (steps in order, numbered from 1), e.g. ``wrong_order(bp,p1)``."""
    given = [
        clingo.Function(
            "plan_step",
            [clingo.Number(t), clingo.Function(step.part), clingo.Function(step.hole or "none")],
        )
        for t, step in enumerate(steps, start=1)
    ]
    return _errors(facts, given)


def check_assignment(facts: LearnedFacts, assignment: Mapping[str, str]) -> list[str]:
    """Errors of a hole assignment (part -> hole), e.g. ``over_capacity(br)``."""
    return _errors(facts, [fact("assigned", part, hole) for part, hole in assignment.items()])


def _locations(
    assembly: Assembly, facts: LearnedFacts, home: tuple[float, float]
) -> dict[clingo.Symbol, tuple[float, float]]:
    starts = {part.id: part.start for part in assembly.parts if part.start is not None}
    positions = {hole.id: hole.position for hole in assembly.holes if hole.position is not None}
    missing = [p for p in facts.parts if p not in starts] + [h for h in facts.holes if h not in positions]
    if positions:
        xs, ys = zip(*positions.values())
        site = (sum(xs) / len(xs), sum(ys) / len(ys))
    elif assembly.base_center is not None:  # no hole: the parts are placed on the base, held at its centre
        site = assembly.base_center
    else:
        missing = missing or ["all holes (with none: base_center of [plate] in geometry.toml)"]
    if missing:
        raise PlannerError(
            f"assembly '{assembly.name}': optimal plans need a start [x, y] for every part "
            f"and a position for every hole; missing for: {' '.join(missing)}"
        )
    locations = {clingo.Function("home"): home, clingo.Function("site"): site}
    for part in facts.parts:
        locations[clingo.Function("start", [clingo.Function(part)])] = starts[part]
    for hole in facts.holes:
        locations[clingo.Function(hole)] = positions[hole]
    return locations


def travel_facts(
    assembly: Assembly, facts: LearnedFacts, home: tuple[float, float] = HOME
) -> list[clingo.Symbol]:
    """``travel(From,To,D)``: straight-line leg lengths D [mm, rounded] between the
    locations of the cost (home [m], site, each part's start, each hole)."""
    locations = _locations(assembly, facts, home)
    return [
        clingo.Function(
            "travel", [a, b, clingo.Number(round(1000.0 * math.dist(locations[a], locations[b])))]
        )
        for a in locations
        for b in locations
        if a != b
    ]
