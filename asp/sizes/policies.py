"""Experiment-selection policies of the size learner: the plug-in registry.

A policy tells the learner which unknown part-hole pair to try next. It is either

- an **encoding** under ``asp/encodings/`` that the learner adds, once, to its one
  long-lived ``clingo.Control`` beside ``sizes_closure.lp``; it reads ``unknown/2``,
  ``smaller/2``, ``fits/2``, ``no_fit/2``, ``part_index/2``, ``hole_index/2`` (1-based
  order) and whatever ``session_facts`` adds, and shows exactly one ``select(P,H)``
  while some pair is unknown (in the last model, if it optimises); or
- a Python callable ``choose(knowledge, rng) -> (part, hole)`` over the current
  :class:`asp.sizes.knowledge.Knowledge` (it must return an unknown pair).

Registry entries are :class:`SelectionPolicy` objects or ``"module:attribute"`` strings
naming one, imported on first use (so ``best`` lives in its own module).
"""

from __future__ import annotations

import importlib
import random
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import clingo

from asp import PlannerError
from asp.sizes.knowledge import Knowledge, Pair
from asp.solve import fact

Chooser = Callable[[Knowledge, random.Random], Pair]
BatchRank = Callable[[Knowledge, Sequence[Pair]], list[Pair]]
SessionFacts = Callable[[Sequence[str], Sequence[str], int], list[clingo.Symbol]]


@dataclass(frozen=True)
class SelectionPolicy:
    """One way to pick the next experiment (see the module docstring).

    ``deterministic``: the chosen experiments depend only on the truth matrix in index
    order (not on names or the seed), so an evaluation may memoise per matrix.
    ``solver_options``: clingo options of the learner's Control (e.g. an optimisation
    strategy for an encoding that optimises; its last model is taken).
    ``batch_rank(knowledge, pending)``: the unknown pairs not pending, best first to run
    in parallel beside the pending ones (without it a batch takes the policy's choice,
    then index order).
    ``prepare(m, n)``: one-time set-up for sessions of m parts × n holes (tables a
    chooser needs), run when the learner is built, like the grounding of an encoding.
    """

    name: str
    summary: str
    encoding: str | None = None
    choose: Chooser | None = None
    session_facts: SessionFacts | None = None
    deterministic: bool = True
    solver_options: tuple[str, ...] = ()
    batch_rank: BatchRank | None = None
    prepare: Callable[[int, int], None] | None = None

    def __post_init__(self) -> None:
        if (self.encoding is None) == (self.choose is None):
            raise ValueError(f"policy {self.name}: give exactly one of encoding or choose")


def random_priorities(parts: Sequence[str], holes: Sequence[str], seed: int) -> list[clingo.Symbol]:
    """``priority(P,H,K)``: a uniformly random permutation of all pairs, from ``seed``."""
    pairs = [(p, h) for p in parts for h in holes]
    ranks = list(range(len(pairs)))
    random.Random(seed).shuffle(ranks)
    return [fact("priority", p, h, k) for (p, h), k in zip(pairs, ranks)]


POLICIES: dict[str, SelectionPolicy | str] = {
    "systematic": SelectionPolicy(
        "systematic",
        "lowest part index, then lowest hole index, among unknown pairs",
        encoding="select_systematic.lp",
    ),
    "random": SelectionPolicy(
        "random",
        "uniformly among unknown pairs (seeded)",
        encoding="select_random.lp",
        session_facts=random_priorities,
        deterministic=False,
    ),
    "heuristic": SelectionPolicy(
        "heuristic",
        "the paper's template count with its tie-breaks (paper 2.2)",
        encoding="select_heuristic.lp",
    ),
    "best": "asp.sizes.best:POLICY",
}


def policy_names() -> list[str]:
    """Names of all registered policies."""
    return list(POLICIES)


def get_policy(name: str) -> SelectionPolicy:
    """The registered policy ``name``; PlannerError for an unknown or unavailable one."""
    entry = POLICIES.get(name)
    if entry is None:
        raise PlannerError(f"policy '{name}': expected one of {', '.join(POLICIES)}")
    if isinstance(entry, SelectionPolicy):
        return entry
    module_name, _, attribute = entry.partition(":")
    try:
        policy = getattr(importlib.import_module(module_name), attribute)
    except (ImportError, AttributeError) as exc:
        raise PlannerError(f"policy '{name}' is not available ({entry}: {exc})") from None
    if not isinstance(policy, SelectionPolicy):
        raise PlannerError(f"policy '{name}': {entry} is not a SelectionPolicy")
    POLICIES[name] = policy
    return policy
