"""What ``assemble`` and ``bench assemble`` check before a cell starts: plans read from a
plan JSON file or a run's ``session.json``, and facts and plans held against the product.

- :func:`plan_of_json`: the steps of one plan in the JSON contract (``[{"part": P,
  "hole": H|null}, ...]``), every id checked against :data:`bridge.assembly.ID_PATTERN`;
  :func:`read_plan_json` reads plan K of a plan JSON file.
- :func:`check_facts_product`: the facts describe the product of ``assembly.toml``: the
  same parts, only its holes, and every peg (``role = "peg"``) with something known of
  the holes it fits (``fits/2``, ``no_fit/2`` or ``needs_hole/1``).
- :func:`check_plan_product`: a plan places every part of the product exactly once,
  each peg into a hole it fits, in an order the precedence admits (the plan checker
  ``check_plan.lp`` against facts that passed :func:`check_facts_product`).

Every problem is a PlannerError of one line naming the file, the step and what was
expected; nothing reaches a cell before these checks pass.
"""

from __future__ import annotations

import json
from pathlib import Path

from asp import PlannerError
from asp.plans.assign import LearnedFacts
from asp.plans.plans import Plan, PlanStep, check_plan
from bridge.assembly import Assembly, is_id
from bridge.inputs import duplicate_key, read_bytes, shorten

_STEP_KEYS = frozenset({"part", "hole"})


def plan_of_json(steps: object, source: str) -> Plan:
    """The plan of the JSON steps ``steps``; PlannerError naming ``source`` and the step
    when it is not a non-empty list of ``{"part": id, "hole": id|null}`` objects."""
    if not isinstance(steps, list) or not steps:
        raise PlannerError(f'{source}: expected a plan [{{"part": P, "hole": H|null}}, ...] with at least one step')
    plan: list[PlanStep] = []
    for k, step in enumerate(steps, start=1):
        if not isinstance(step, dict) or "part" not in step or not set(step) <= _STEP_KEYS:
            raise PlannerError(f'{source}: step {k}: expected {{"part": P, "hole": H|null}}, '
                               f"got {shorten(json.dumps(step, ensure_ascii=True), 60)}")
        part, hole = step["part"], step.get("hole")
        for key, value, expected in (("part", part, "p1"), ("hole", hole, "s1 or null")):
            if (value is not None or key == "part") and not is_id(value):
                raise PlannerError(f"{source}: step {k}: {key} {shorten(json.dumps(value, ensure_ascii=True))} "
                                   f"is not an id (expected an ASCII ASP constant such as {expected}: "
                                   "a lower-case letter first, not the keyword not)")
        plan.append(PlanStep(part, hole))
    return Plan(tuple(plan))


def read_plan_json(path: Path, k: int) -> Plan:
    """Plan ``k`` (1-based) of a plan JSON file: a plan, ``{"plan": plan}`` or the
    ``{"plans": [plan, ...]}`` of ``plan --json``; PlannerError naming the file (and the
    step) when it is not one of these, or holds fewer than ``k`` plans."""
    text = read_bytes(path, "plan file (JSON)", error=PlannerError)
    try:
        data, twice = json.loads(text), duplicate_key(text)
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise PlannerError(f"{path}: not valid JSON ({shorten(exc, 80)})") from None
    except RecursionError:
        raise PlannerError(f"{path}: nested too deeply; expected a plan JSON file") from None
    if twice is not None:
        raise PlannerError(f"{path}: the key {shorten(repr(twice))} appears twice in one object; expected each "
                           "key once")
    if isinstance(data, dict) and set(data) - {"cost"} in ({"plan"}, {"plans"}):
        many = data.get("plans")
        if many is not None:
            if not isinstance(many, list) or len(many) < k:
                count = len(many) if isinstance(many, list) else 0
                raise PlannerError(f"{path}: --plan {k}, but the file holds {count} plan(s)")
            return plan_of_json(many[k - 1], f"{path}: plans[{k}]")
        data = data["plan"]
    elif isinstance(data, dict):
        raise PlannerError(f'{path}: expected a plan [{{"part": P, "hole": H|null}}, ...], {{"plan": [...]}} '
                           'or {"plans": [[...], ...]}')
    if k != 1:
        raise PlannerError(f"{path}: --plan {k}, but the file holds one plan")
    return plan_of_json(data, str(path))


def check_facts_product(assembly: Assembly, facts: LearnedFacts, sources: str) -> None:
    """PlannerError naming ``sources`` when the facts are not of the product ``assembly``:
    other parts than those of its ``assembly.toml``, a hole it does not have, or a peg
    about whose holes the facts say nothing (it would be placed without a hole; a peg
    pressed in by hand is: ``plans/needs_hole.lp``)."""
    toml = assembly.file("assembly.toml")
    parts, known = set(facts.parts), set(assembly.part_ids)
    if parts != known:
        extra, missing = sorted(parts - known), sorted(known - parts)
        detail = (f"part({extra[0]}) is not a part of it" if extra
                  else f"part {missing[0]} of it has no part/1 fact")
        raise PlannerError(f"{sources}: the facts are not of the product in {toml}: {detail} "
                           f"(expected the parts {' '.join(assembly.part_ids)})")
    unknown = sorted(set(facts.holes) - set(assembly.hole_ids))
    if unknown:
        raise PlannerError(f"{sources}: hole({unknown[0]}) is not a hole of the product in {toml} "
                           f"(holes: {' '.join(assembly.hole_ids) or '-'})")
    for part in assembly.parts:
        if part.role == "peg" and part.id not in facts.needs_hole and part.id not in assembly.pressed:
            raise PlannerError(f"{sources}: peg {part.id} of {toml} has no fits/2, no_fit/2 or needs_hole/1 "
                               "fact; expected the holes it fits")


def check_plan_product(facts: LearnedFacts, plan: Plan, source: str) -> None:
    """PlannerError naming ``source`` and the first step in error when the plan is not
    valid for facts of the product (:func:`check_facts_product`): every part exactly
    once, each peg in a hole it fits with room for it, the precedence respected."""
    errors = check_plan(facts, plan.steps)
    if not errors:
        return
    step_of = {step.part: k for k, step in enumerate(plan.steps, start=1)}
    located = []
    for error in errors:
        named = [name for name in error.replace("(", ",").replace(")", ",").split(",")[1:] if name]
        k = min((step_of[name] for name in named if name in step_of), default=None)
        located.append((k if k is not None else len(plan.steps) + 1, error))
    k, first = min(located)
    where = f"step {k} ({_step_text(plan.steps[k - 1])})" if k <= len(plan.steps) else "the plan"
    more = f" and {len(errors) - 1} more" if len(errors) > 1 else ""
    raise PlannerError(f"{source}: {where}: {first}{more}; expected every part of the product once, "
                       "each peg in a hole it fits with room for it, in an order the precedence admits")


def _step_text(step: PlanStep) -> str:
    return step.part + (f"->{step.hole}" if step.hole else "")
