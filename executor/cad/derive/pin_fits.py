"""The pins moving parts go onto (:func:`pins`): each part's bores around outlines of the
base or of parts before it, the pins numbered by owner, and the base's empty pins that
some bore passes over."""

from __future__ import annotations

import math
from collections.abc import Iterable

import networkx as nx
import numpy as np
import shapely

from executor.cad.derive.bore_on_pin import pin_of
from executor.cad.derive.derived import Derived, PinFit
from executor.cad.derive.loops import SAME_HOLE, outer
from executor.cad.sections import Shape2D, classify, frame_of, passes, slice_loops
from executor.cad.sweep import forked_map, processes

_ON_PIN = 1e-6  # a vertex of the base this close [m] to a pin's outline is on it


def pins(derived: Derived) -> tuple[dict[str, PinFit], dict[str, Shape2D], dict[tuple[str, str], Shape2D]]:
    """The pins moving parts go onto and each such part's bore section (module docstring,
    :func:`pin_of`): a part with a bore around one outline of another part, that part the
    base or one the geometric precedence puts before it (a part that goes in after, into
    the bore, is no pin: a head in a cover's socket). A bore around no such outline is no
    fit; nor is one around a peg standing in a hole of the base that goes in along the
    part's own axis (that part is a cover, :mod:`executor.cad.covers`), unless the part
    rests on such pegs alone (:attr:`Derived.supports`: it goes onto their ends). Parts on one pin
    share its section, the one measured over the longest stretch of it (from the part
    farthest from its end). A part goes onto every pin of each such owner (in order of their
    names) that stands in a bore of its own around no pin it is on already: a plate onto
    both dowel pins of the base, asm4_disk_arm's arm onto the base's pivot pin through its
    bore and onto the disk's nipple through its slot; but not onto a further pin that
    another part is around (:func:`_within_another`: a washer over a sleeve over a pin).
    Its first bore is its section against every pin (:attr:`Derived.bores`), each
    further one against its own pin (:attr:`Derived.further_bores`): also the (part,
    pin) -> bore pairs returned third."""
    found: list[tuple[str, str, Shape2D, np.ndarray, str | None, float]] = []  # owner, axis, pin, centre, part, level
    further: dict[int, Shape2D] = {}  # index in found -> the part's bore there, on a pin other than its first
    order = nx.DiGraph(list(derived.edges))
    bores: dict[str, Shape2D] = {}
    levels: dict[str, float] = {}
    for pid in sorted(derived.axis):
        if pid not in derived.hole_of:
            along = derived.parts[pid].mesh.vertices @ np.array(derived.directions[derived.axis[pid]])
            levels[pid] = float(along.min() + along.max()) / 2
    onto = forked_map(lambda pid: _pins_of(derived, order, pid, levels[pid]), list(levels),
                      processes(p.mesh for p in derived.parts.values()),
                      cost=lambda pid: len(derived.parts[pid].mesh.faces))
    for pid, hits in zip(levels, onto):
        for k, (other, pin, centre, level, bore) in enumerate(hits):
            if k:
                further[len(found)] = bore
            else:
                bores[pid] = bore
            found.append((other, derived.axis[pid], pin, centre, pid, level))
    found += [(derived.base, derived.axis[pid], pin, centre, None, math.inf) for pid in sorted(bores)
              for pin, centre in _standing_pins(derived, derived.axis[pid], levels[pid], bores.values())]
    merged: list[tuple[str, str, Shape2D, np.ndarray, list[str], float]] = []
    held: list[list[tuple[Shape2D, Shape2D]]] = []  # index in merged -> each part's own pin section and bore
    into: list[int] = []  # index in found -> index in merged
    for k, (owner, name, pin, centre, on, level) in enumerate(found):
        axis = np.array(derived.directions[name])
        mine = [] if on is None else [(pin, further[k] if k in further else bores[on])]
        same = None
        for k_merged, m in enumerate(merged):
            # coaxial, and the section kept passes every bore on it that passes its own: a
            # pin's wider step farther from its end (a pot's thread under its shaft) is a pin
            # of its own, not the section of the knob on the shaft; a standing pin whose
            # outline holds the pin's centre is that pin (a D-shaft's centroid lies off its axis)
            across = float(np.linalg.norm((m[3] - centre) - axis * np.dot(m[3] - centre, axis)))
            kept = pin if level < m[5] else m[2]
            if m[:2] == (owner, name) and (
                    across < SAME_HOLE and all(passes(kept, bore) or not passes(own, bore)
                                               for own, bore in held[k_merged] + mine)
                    if on is not None else across < SAME_HOLE or shapely.Polygon(pin.outline + pin.centre)
                    .contains(shapely.Point(frame_of(axis) @ m[3]))):
                same = k_merged
                break
        into.append(len(merged) if same is None else same)
        if same is None:
            merged.append((owner, name, pin, centre, [] if on is None else [on], level))
            held.append(mine)
            continue
        held[same] += mine
        parts = merged[same][4] + ([] if on is None else [on])
        merged[same] = (owner, name, pin, centre, parts, level) if level < merged[same][5] else (
            *merged[same][:4], parts, merged[same][5])
    ids: dict[int, str] = {}
    counts: dict[str, int] = {}
    result: dict[str, PinFit] = {}
    for k in sorted(range(len(merged)), key=lambda k: (merged[k][0], *(round(float(v), 6) for v in merged[k][3]))):
        owner, name, pin, centre, parts, _ = merged[k]
        counts[owner] = counts.get(owner, 0) + 1
        ids[k] = pin_id = f"{owner}_pin{counts[owner]}"
        result[pin_id] = PinFit(pin_id, owner, name, pin, (float(centre[0]), float(centre[1]), float(centre[2])),
                                tuple(parts))
    return result, bores, {(str(found[k][4]), ids[into[k]]): bore for k, bore in further.items()}


def _pins_of(derived: Derived, order: nx.DiGraph, pid: str, middle: float
             ) -> list[tuple[str, Shape2D, np.ndarray, float, Shape2D]]:
    """The pins part ``pid`` goes onto (:func:`pins`), in order: each one's owner, section,
    centre [m], the level [m] it was measured at and the part's bore there; ``order`` the
    geometric precedence, ``middle`` [m] the middle of the part's extent along its removal
    direction."""
    name = derived.axis[pid]
    before = nx.ancestors(order, pid) if pid in order else set()
    covered = {peg for peg in derived.hole_of if derived.axis[peg] == name}  # over it: a cover
    resting = {y for y, x in derived.supports if x == pid}
    if resting and resting <= covered:  # on those pegs alone: onto their ends, as no cover rests
        covered -= resting
    taken: list[np.ndarray] = []  # the centres of the pins the part is on so far, across the axis
    hits = []
    owners = sorted(({derived.base} | before) - covered)
    for other in owners:
        while (hit := pin_of(derived, pid, name, other, taken, owners)) is not None:
            pin, bore, centre, level = hit
            if any(np.linalg.norm(pin.centre - point) < SAME_HOLE for point in taken):
                break  # its bore is around a pin the part is on already
            taken.append(pin.centre)
            if len(taken) > 1 and _within_another(derived, pid, other, name, pin.centre, middle):
                continue  # a washer over a sleeve over a pin: the pin is the sleeve's to go into
            hits.append((other, pin, centre, level, bore))
    return hits


def _within_another(derived: Derived, pid: str, owner: str, name: str, centre: np.ndarray, level: float) -> bool:
    """Whether a part other than ``pid`` and ``owner`` is around the point ``centre`` (2,) [m]
    across removal direction ``name`` (an outline of its slice at ``level`` [m] along it
    holds the point): a pin of ``owner`` there stands in that part's bore (or under it),
    so ``pid``'s bore around both goes over that part, not onto the pin."""
    axis = np.array(derived.directions[name])
    frame = frame_of(axis)
    for other in sorted(set(derived.parts) - {pid, owner}):
        mesh = derived.parts[other].mesh
        along, across = mesh.vertices @ axis, mesh.vertices @ frame.T
        if not (along.min() < level < along.max()) or not np.all(
                (across.min(axis=0) <= centre) & (centre <= across.max(axis=0))):
            continue  # it does not reach the level, or no outline of it can hold the point
        loops = slice_loops(mesh, axis, level)
        if any(outer(loop, loops) and loop.contains(centre) for loop in loops):
            return True
    return False


def _standing_pins(derived: Derived, name: str, level: float,
                   bores: Iterable[Shape2D]) -> list[tuple[Shape2D, np.ndarray]]:
    """The pins of the base that stand out along ``name`` through ``level`` [m] and that
    some of ``bores`` passes over, each with its centre [m] on that level: the outlines
    of the base's slice there with no outline inside them (a pin, solid or hollow) and
    nothing of the base beyond the level within their circumscribed circle but the pin
    itself (its free end: a part comes down onto it), whose section passes a bore
    (:func:`executor.cad.sections.passes`, as ``sizes.lp`` decides)."""
    axis = np.array(derived.directions[name])
    frame = frame_of(axis)
    vertices = derived.parts[derived.base].mesh.vertices
    beyond = vertices[vertices @ axis > level] @ frame.T
    loops = slice_loops(derived.parts[derived.base].mesh, axis, level)
    standing = []
    for loop in loops:
        if not outer(loop, loops) or any(o is not loop and outer(o, loops) and loop.contains(o.centre)
                                          for o in loops):
            continue
        reach = float(np.linalg.norm(loop.points - loop.centre, axis=1).max()) + SAME_HOLE
        over = beyond[np.linalg.norm(beyond - loop.centre, axis=1) <= reach]
        outline = shapely.Polygon(loop.points).buffer(_ON_PIN)
        if not shapely.contains_xy(outline, over[:, 0], over[:, 1]).all():
            continue
        pin = classify(loop, hole=False)
        if any(passes(pin, bore) for bore in bores):
            standing.append((pin, frame.T @ pin.centre + axis * level))
    return standing
