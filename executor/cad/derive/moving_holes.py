"""The holes of moving parts (:func:`part_holes`): a part in no hole of the base going
through another part's bore (a rod through a bracket, a clutch plate's outside in the
outer holder's hole), and a part in a hole of the base passing a hole on that hole's line
(a bolt through a bracket's flange into the plate: :attr:`HoleFit.line`), each hole with
its occupants."""

from __future__ import annotations

from dataclasses import replace

import networkx as nx
import numpy as np
import trimesh

from executor.cad.derive.derived import Derived, HoleFit
from executor.cad.derive.loops import SAME_HOLE, hole_around
from executor.cad.derive.measure_hole import measure
from executor.cad.sections import frame_of
from executor.cad.sweep import DIRECTIONS, forked_map, processes


def part_holes(derived: Derived) -> dict[str, HoleFit]:
    """The holes of moving parts (``<owner>_hole1``, ... by position) and the parts in
    each (module docstring): a moving part in no hole of the base and onto no pin, whose
    outline across its insertion axis (one of the six) lies in an inner loop of a part the
    geometric precedence puts before it (not the base, not of its own body) at a level both
    reach: a rod through a bracket's bore, a shaft into a bearing placed before it; and a
    part onto a pin whose outline (its outside) lies so in an inner loop of a part the
    precedence does not put after it: a clutch plate on its shaft, its splined outside in
    the outer holder's splined hole; and a part standing in a hole of the base, in the
    hole of a part the precedence puts before it (its box across the axis around the
    part's) that lies on that hole's line (:func:`_on_line`): a bolt through a bracket's
    flange into the plate, a hinge's pin through the female leaf's knuckles into the male
    leaf's, such a hole no place of its own (:attr:`HoleFit.line`; a hole off the line
    is dropped). The parts in one hole (within :data:`SAME_HOLE` of each other across its
    axis) are its occupants, the deepest first (the hole measured over its stretch); it is
    on a line when every occupant's is that one."""
    order = nx.DiGraph(list(derived.edges))
    pairs = []  # (part, owner): each part's, owners in order of their names
    for pid in sorted(derived.axis):
        if derived.axis[pid] not in DIRECTIONS or pid not in order:
            continue
        body = next(members for members in derived.bodies.values() if pid in members)
        if pid in derived.hole_of:  # in a hole of the base: the holes it passes on its way, kept on the line
            owners = {owner for owner in nx.ancestors(order, pid) - {derived.base}
                      if _around(derived.parts[owner].mesh, derived.parts[pid].mesh, derived.axis[pid])}
        elif pid in derived.bores:  # onto a pin: owners around it (their box across the axis holds its box)
            owners = {other for other in set(derived.parts) - nx.descendants(order, pid)
                      if _around(derived.parts[other].mesh, derived.parts[pid].mesh, derived.axis[pid])}
        else:
            owners = nx.ancestors(order, pid)
        pairs += [(pid, owner) for owner in sorted(owners - {derived.base} - body)]
    found = [fit for fit in forked_map(lambda pair: _hole_of(derived, *pair), pairs,
                                       processes(p.mesh for p in derived.parts.values()),
                                       cost=lambda pair: len(derived.parts[pair[1]].mesh.faces)) if fit is not None]
    found = [fit for fit in map(lambda f: _on_line(derived, f), found) if fit.line or fit.part not in derived.hole_of]
    found.sort(key=lambda f: (f.owner or "", round(f.centre[0], 6), round(f.centre[1], 6), round(f.centre[2], 6)))
    holes: list[list[HoleFit]] = []
    for fit in found:
        same = next((hole for hole in holes if hole[0].owner == fit.owner and hole[0].axis == fit.axis
                     and np.linalg.norm(hole[0].hole.centre - fit.hole.centre) < SAME_HOLE), None)
        if same is None:
            holes.append([fit])
        else:
            same.append(fit)
    counts: dict[str, int] = {}
    result: dict[str, HoleFit] = {}
    for group in holes:
        deepest, *rest = sorted(group, key=lambda f: (_tip(derived, str(f.part), f.axis), str(f.part)))
        owner = deepest.owner or ""
        counts[owner] = counts.get(owner, 0) + 1
        hid = f"{owner}_hole{counts[owner]}"
        lines = {f.line for f in group}  # a place unless every part in it stands in the one hole of the base
        result[hid] = replace(deepest, id=hid, more=tuple((str(f.part), f.section) for f in rest
                                                          if f.section is not None),
                              line=lines.pop() if len(lines) == 1 else None)
    return result


def _around(owner: trimesh.Trimesh, part: trimesh.Trimesh, name: str) -> bool:
    """Whether ``owner`` may have a hole around ``part`` across removal direction ``name``:
    its bounding box across the direction holds the part's, and along it the two overlap by
    more than 1 µm (as :func:`hole_around` needs), a test of their vertices' extents alone."""
    axis = np.array(DIRECTIONS[name])
    frame = np.vstack([frame_of(axis), axis])
    low, high = (owner.vertices @ frame.T).min(axis=0), (owner.vertices @ frame.T).max(axis=0)
    inner_low, inner_high = (part.vertices @ frame.T).min(axis=0), (part.vertices @ frame.T).max(axis=0)
    return bool(np.all(low[:2] <= inner_low[:2]) and np.all(inner_high[:2] <= high[:2])
                and min(high[2], inner_high[2]) - max(low[2], inner_low[2]) > 1e-6)


def _on_line(derived: Derived, fit: HoleFit) -> HoleFit:
    """``fit`` with its :attr:`HoleFit.line`: the hole of the base its part stands in, where
    the two go along one axis and their sections' centres (on the slice across it) lie within
    :data:`SAME_HOLE` of each other (one line: the part passes this hole on its way into
    that one); else as it is."""
    base = derived.hole_of.get(str(fit.part))
    if base is None or base.axis != fit.axis or np.linalg.norm(base.hole.centre - fit.hole.centre) >= SAME_HOLE:
        return fit
    return replace(fit, line=base.id)


def _tip(derived: Derived, pid: str, name: str) -> float:
    """How far [m] part ``pid`` reaches against removal direction ``name``: its lowest
    level along it (the deepest part in a hole has the least)."""
    return float((derived.parts[pid].mesh.vertices @ np.array(DIRECTIONS[name])).min())


def _hole_of(derived: Derived, pid: str, owner: str) -> HoleFit | None:
    """The hole of part ``owner`` that part ``pid`` goes through along its insertion axis
    (:func:`part_holes`), with its owner; None: none."""
    name = derived.axis[pid]
    hit = hole_around(derived.parts[owner], derived.parts[pid], np.array(DIRECTIONS[name]))
    if hit is None:
        return None
    level, loop, outer, own = hit
    return replace(measure(derived.parts[owner], name, loop, level, outer, (derived.parts[pid], own)), owner=owner)
