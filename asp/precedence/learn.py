"""Learning the must-precede relation from demonstrations (paper Algorithm 1).

Each feasible sequence s gives its maximal relation C_s (s_i before s_j for i < j);
the learned relation is the intersection of all C_s (paper eq. 1). It is computed on
numpy boolean matrices, vectorised over demonstrations (and over trials in the
evaluation). By paper eq. 10 it contains the true relation when every demonstration
is feasible.

Demonstrations can be wrong. :func:`pair_evidence` counts, per pair, the
demonstrations that support and contradict it; :func:`suspects` flags a demonstration
that alone removes constraints all the others support; ``min_support=K`` in
:func:`learn_must_precede` drops a constraint only when at least K demonstrations
contradict it.

A product imported from its CAD carries its geometric precedence
(``geometric_precedence.lp``): :func:`learn_for_assembly` uses it as the prior the
demonstrations refine, or alone where the product has none.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from asp import PlannerError
from asp.precedence.demos import Demonstrations, load_demos
from asp.precedence.relation import Pair, Relation, close, load_relation
from bridge.assembly import Assembly

GEOMETRIC_PRIOR = "geometric_precedence.lp"
"""The file of an assembly folder holding the precedence its geometry forces (``import``)."""


def positions(sequences: Sequence[Sequence[str]], parts: Sequence[str]) -> np.ndarray:
    """``pos[d, i]``: the step (0-based) at which demonstration d places ``parts[i]``."""
    index = {p: i for i, p in enumerate(parts)}
    pos = np.empty((len(sequences), len(parts)), dtype=np.int16)
    steps = np.arange(len(parts), dtype=np.int16)
    for d, sequence in enumerate(sequences):
        pos[d, [index[p] for p in sequence]] = steps
    return pos


def intersect_orders(pos: np.ndarray) -> np.ndarray:
    """Algorithm 1 on positions ``pos[..., d, i]``: ``C[..., i, j]`` = i before j in every d.

    Leading axes are batch axes (e.g. evaluation trials); with no demonstration the
    result is all ones, as in the paper.
    """
    return np.all(pos[..., :, :, None] < pos[..., :, None, :], axis=-3)


def precedence_support(pos: np.ndarray) -> np.ndarray:
    """``support[i, j]``: how many demonstrations place i before j (int, shape (n, n)).

    The number contradicting (i, j) is ``support[j, i]``.
    """
    return np.sum(pos[:, :, None] < pos[:, None, :], axis=0)


def learn_must_precede(demos: Demonstrations, min_support: int = 1) -> Relation:
    """The learned must-precede relation (transitively closed).

    ``min_support=1`` is Algorithm 1 (intersection). With K > 1 a pair is kept while
    fewer than K demonstrations contradict it and more support it than contradict it;
    the kept pairs are then closed (ASP). PlannerError when they form a cycle.
    """
    if min_support < 1:
        raise PlannerError(f"--min-support {min_support}: expected an integer >= 1")
    pos = positions(demos.sequences, demos.parts)
    if min_support == 1:
        return Relation(demos.parts, intersect_orders(pos))
    support = precedence_support(pos)
    contradict = support.T
    kept = (contradict < min_support) & (support > contradict)
    return close(Relation(demos.parts, kept), source=f"demonstrations with --min-support {min_support}")


@dataclass(frozen=True)
class Suspect:
    """A demonstration that alone removes constraints every other one supports."""

    demo: int  # index into demos.sequences
    origin: str  # file:line
    removes: tuple[Pair, ...]


def suspects(demos: Demonstrations, min_others: int = 2) -> list[Suspect]:
    """Demonstrations that are the only ones contradicting some pair supported by all others.

    Only reported when at least ``min_others`` other demonstrations agree (with one
    other, every new demonstration would look suspicious).
    """
    count = len(demos.sequences)
    if count - 1 < min_others:
        return []
    pos = positions(demos.sequences, demos.parts)
    support = precedence_support(pos)
    lone = support == count - 1  # all but one demonstration place i before j
    found = []
    for d in range(count):
        reversed_here = pos[d][:, None] > pos[d][None, :]
        rows, cols = np.nonzero(lone & reversed_here)
        if rows.size:
            pairs = tuple((demos.parts[i], demos.parts[j]) for i, j in zip(rows.tolist(), cols.tolist()))
            found.append(Suspect(d, demos.origins[d], pairs))
    return found


def pair_evidence(demos: Demonstrations) -> list[dict[str, object]]:
    """Per ordered pair seen both ways or one way: ``{"pair", "support", "contradict"}``."""
    support = precedence_support(positions(demos.sequences, demos.parts))
    n = len(demos.parts)
    return [
        {"pair": [demos.parts[i], demos.parts[j]], "support": int(support[i, j]), "contradict": int(support[j, i])}
        for i in range(n)
        for j in range(n)
        if i != j and support[i, j] > 0
    ]


def check_prior(demos: Demonstrations, prior: Relation, source: str) -> None:
    """Every demonstration respects every pair of ``prior`` (the geometric precedence of
    ``import``: what the CAD decides); PlannerError naming the first demonstration that
    breaks one (file:line) and the pairs it breaks, and when the prior's parts are not the
    demonstrations'."""
    if set(prior.parts) != set(demos.parts):
        raise PlannerError(f"{source}: the prior's parts ({', '.join(sorted(prior.parts))}) are not the "
                           f"demonstrations' ({', '.join(sorted(demos.parts))})")
    index = {p: i for i, p in enumerate(prior.parts)}
    rows, cols = np.nonzero(prior.matrix)
    for sequence, origin in zip(demos.sequences, demos.origins):
        step = np.empty(len(prior.parts), dtype=np.int64)
        step[[index[p] for p in sequence]] = np.arange(len(sequence))
        broken = [(prior.parts[i], prior.parts[j]) for i, j in zip(rows.tolist(), cols.tolist()) if step[i] > step[j]]
        if broken:
            pairs = " ".join(f"{a}<{b}" for a, b in broken)
            raise PlannerError(f"{origin}: a wrong demonstration: it breaks the geometric precedence {pairs} "
                               f"of {source} (the CAD admits no such order)")


def learn_with_prior(demos: Demonstrations, prior: Relation, source: str, min_support: int = 1) -> Relation:
    """Algorithm 1 with the geometric ``prior``: the demonstrations are checked against it
    (:func:`check_prior`); the learned relation is theirs joined with the prior (closed),
    so it contains every geometric pair, and it is the prior alone without demonstrations."""
    check_prior(demos, prior, source)
    order = [prior.parts.index(p) for p in demos.parts]
    aligned = Relation(demos.parts, prior.matrix[np.ix_(order, order)])
    if not demos.sequences:
        return aligned
    learned = learn_must_precede(demos, min_support)
    return close(Relation(demos.parts, learned.matrix | aligned.matrix), source=f"demonstrations and {source}")


def learn_for_assembly(assembly: Assembly,
                       demos_file: Path | None = None) -> tuple[Demonstrations, Relation, Path | None]:
    """The demonstrations of ``assembly`` (``demos_file``, else its ``demos.txt``), the
    must-precede relation learned from them and the geometric prior used, if any: with a
    :data:`GEOMETRIC_PRIOR` file in the folder the demonstrations refine it
    (:func:`learn_with_prior`; one that breaks it is an error naming its line), and
    without demonstrations it alone is the relation."""
    prior_file = assembly.file(GEOMETRIC_PRIOR) if assembly.has_file(GEOMETRIC_PRIOR) else None
    if prior_file is None:
        demos = load_demos(demos_file or assembly.file("demos.txt"), assembly.part_ids, assembly.hole_ids)
        return demos, learn_must_precede(demos), None
    if demos_file is None and not assembly.has_file("demos.txt"):
        demos = Demonstrations(tuple(assembly.part_ids), (), ())
    else:
        demos = load_demos(demos_file or assembly.file("demos.txt"), assembly.part_ids, assembly.hole_ids)
    return demos, learn_with_prior(demos, load_relation([prior_file], data=True), str(prior_file)), prior_file
