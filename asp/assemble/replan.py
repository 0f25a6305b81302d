"""Re-planning from the current state of an assembly being executed.

A step that failed in the cell (after the cell's own retry) is an observation
``no_fit(P,H)``: the part did not go into that hole, whatever the learned sizes said.
The new plan keeps what is done (the placed parts keep their steps and holes,
``plans/prefix.lp``) and puts the rest into the holes still possible.  When no
assignment is left, :class:`asp.plans.assign.UnsolvableAssembly` names the part that
gets no hole.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import clingo

from asp import PlannerError
from asp.plans.assign import LearnedFacts, UnsolvableAssembly, feasible_assignment
from asp.plans.plans import Plan, PlanStep, check_plan, plans
from asp.solve import fact


def with_no_fit(facts: LearnedFacts, part: str, hole: str) -> LearnedFacts:
    """The facts with ``no_fit(part, hole)`` observed (its ``fits`` fact withdrawn)."""
    gone = fact("fits", part, hole)
    atoms = tuple(a for a in facts.atoms if a != gone)
    no_fit = fact("no_fit", part, hole)
    if no_fit not in atoms:
        atoms = (*atoms, no_fit)
    return replace(facts, atoms=atoms, fits=facts.fits - {(part, hole)})


def _placed_facts(facts: LearnedFacts, done: Sequence[PlanStep]) -> LearnedFacts:
    """The facts in which every placed part fits only the hole it is in."""
    held = {step.part: step.hole for step in done if step.hole is not None}
    stale = {(p, h) for p, h in facts.fits if p in held and h != held[p]}
    stale_atoms = {fact("fits", p, h) for p, h in stale}
    atoms: tuple[clingo.Symbol, ...] = tuple(a for a in facts.atoms if a not in stale_atoms)
    return replace(facts, atoms=atoms, fits=facts.fits - stale)


def replan(facts: LearnedFacts, done: Sequence[PlanStep]) -> Plan:
    """A checked plan that begins with the ``done`` steps; UnsolvableAssembly naming the
    part left without a hole, PlannerError when no order continues the done steps."""
    current = _placed_facts(facts, done)
    feasible_assignment(current)  # raises UnsolvableAssembly naming the part
    try:
        found = plans(current, n=1, prefix=done)
    except UnsolvableAssembly:
        raise
    except PlannerError:
        raise PlannerError("no plan continues the placed parts " + " ".join(step.part for step in done)
                           + " (must_precede forbids every order after them)") from None
    errors = check_plan(current, found[0].steps)
    if errors:
        raise PlannerError(f"re-plan {found[0].as_json()} fails the checker: {errors}")
    return found[0]
