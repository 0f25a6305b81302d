"""The holes of the base (:func:`holes`): the inner loops of its slices at the levels of
the parts in it, each part in the hole around its slice, measured; and which empty ones a
part goes into (:func:`receives`), the others pockets."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from executor.cad.derive.cavities import without_cavities
from executor.cad.derive.derived import HoleFit
from executor.cad.derive.loops import SAME_HOLE, bore_around, hole_around, in_loop, outer, touching_gap
from executor.cad.derive.measure_hole import measure
from executor.cad.derive.rays import roofed
from executor.cad.parts import CadPart
from executor.cad.sections import Loop, frame_of, slice_loops
from executor.cad.sweep import DIRECTIONS, forked_map, opposite, processes
from executor.world.polygon_fit import OutlineError, polygon, symmetry


def holes(base: CadPart, parts: list[CadPart], axes: dict[str, str], before: dict[str, list[CadPart]]
          ) -> list[HoleFit]:
    """Every inner loop of the base's slices (at the levels of the parts in it, or at its
    middle along +z), with the part in it where one is, in order of position; a loop no
    wider than faces that touch (:func:`executor.cad.derive.loops.touching_gap`: the crack
    two closed objects of one part keep where their faces meet not quite flat) is none. A
    loop keeps the base's outlines standing in it as its islands (:func:`_islands`: the
    hole's opening has a hole, a pocket around a standing core). A part is in
    none when, at its level, its bore holds an outline of the base or of one of the parts
    ``before`` it (a gland on a shaft: it goes onto a pin, :func:`executor.cad.derive.pins`),
    but for the base's islands of a hole its outline lies in (:func:`_sunk`: a ring sunk in
    the pocket around them goes into it), or when it lies
    in the bore of another part standing in the base along its axis (a shaft in a bearing
    ring that stands in a housing's bore: the ring's hole, :func:`executor.cad.derive.part_holes`), in along
    the same way or, that part ``before`` it, the other way (the shaft sent in from the
    ring's far end, through the housing's other opening: still in the ring, not in the
    housing's bore, where it would be a peg standing in a hole of the base, and the glands
    going in after it along its axis covers over it, on no pin)."""
    def sliced(part: CadPart) -> tuple[float, Loop] | None:
        axis = np.array(DIRECTIONS[axes[part.id]])
        found = _part_slice(part, base, axis)
        if found is not None and not any(bore_around(part.mesh, other.mesh, axis, found[0]) is not None
                                         for other in [*([] if _sunk(base, axis, *found) else [base]),
                                                       *before.get(part.id, [])]):
            return found
        return None

    workers = processes([base.mesh, *(part.mesh for part in parts)])
    cut = {part.id: found for part, found in zip(parts, forked_map(sliced, parts, workers,
                                                                   cost=lambda part: len(part.mesh.faces)))
           if found is not None}
    by_id = {part.id: part for part in parts}
    slices: dict[tuple[str, float], list[tuple[CadPart, Loop]]] = {}

    def in_another(pid: str) -> bool:
        axis = np.array(DIRECTIONS[axes[pid]])
        earlier = {part.id for part in before.get(pid, [])}
        return any(other != pid and (axes[other] == axes[pid] or (axes[other] == opposite(axes[pid])
                                                                   and other in earlier))
                   and hole_around(by_id[other], by_id[pid], axis) for other in cut)

    for (pid, (level, own)), inside in zip(cut.items(), forked_map(in_another, list(cut), workers)):
        if not inside:
            slices.setdefault((axes[pid], round(level, 7)), []).append((by_id[pid], own))
    if not slices:
        z = base.mesh.vertices[:, 2]
        slices[("+z", round(float(z.min() + z.max()) / 2, 7))] = []
    fits: list[tuple[HoleFit, np.ndarray, np.ndarray]] = []  # each with its centre at the level sliced, its axis
    for (name, level), members in sorted(slices.items()):
        axis = np.array(DIRECTIONS[name])
        loops = slice_loops(base.mesh, axis, level)
        for loop in loops:
            around = sorted((o for o in loops if o is not loop and o.area > loop.area and o.contains(loop.centre)),
                            key=lambda o: o.area)
            if len(around) % 2 == 0:
                continue  # an outline, not a hole
            loop = Loop(loop.points, _islands(loop, loops))
            if touching_gap(loop.area, loop.length):
                continue  # a crack between faces that touch: no part goes in
            frame = frame_of(axis)
            centre = frame.T @ loop.centre + axis * level
            occupant = next(((p, own) for p, own in members if loop.contains(own.centre)), None)
            # across the axis, by the loops' centres: a fit's ``centre`` keeps the cell's x, y and
            # the entry (a horizontal hole's height across its axis is not in it)
            same = [k for k, (f, c, _) in enumerate(fits) if f.axis == name and np.linalg.norm(
                c - centre - axis * np.dot(c - centre, axis)) < SAME_HOLE]
            if same and occupant is None:
                continue
            if same and fits[same[0]][0].part is not None:
                # a further part in the hole (a bearing, a spacer and another bearing in one
                # housing bore): levels come deepest first, the hole is measured for the deepest
                first, at, along = fits[same[0]]
                more = measure(base, name, loop, level, around[0] if around else None, occupant, workers)
                if more.section is not None:
                    fits[same[0]] = (replace(first, more=(*first.more, (str(more.part), more.section))), at, along)
                continue
            if occupant is None and roofed(base.mesh, centre, axis):
                continue  # empty and roofed along its axis: a cavity open the other way (a brick's underside)
            # a hole met empty at another part's level (a shallower one beside a deeper) is its occupant's
            fit = (measure(base, name, loop, level, around[0] if around else None, occupant, workers), centre, axis)
            if same:
                fits[same[0]] = fit
            else:
                fits.append(fit)
    found = without_cavities(base.mesh, fits)
    found.sort(key=lambda f: (round(f.centre[0], 6), round(f.centre[1], 6), round(f.centre[2], 6)))
    return found


def _islands(loop: Loop, loops: list[Loop]) -> tuple[np.ndarray, ...]:
    """The points (k, 2) [m] of each outline among ``loops`` (a slice's) that stands in the
    hole ``loop`` with no other loop between them: the base's islands in it (a pocket's
    standing core)."""
    inside = [o for o in loops if o is not loop and o.area < loop.area and loop.contains(o.centre)]
    return tuple(o.points for o in inside
                 if not any(other is not o and other.area > o.area and other.contains(o.centre) for other in inside))


def _sunk(base: CadPart, axis: np.ndarray, level: float, own: Loop) -> bool:
    """Whether the part's outline ``own`` at ``level`` [m] across ``axis`` lies in a hole of
    the base's slice there that has islands (:func:`_islands`): the part stands in that
    pocket around them, not on them as on pins (a ring sunk over a pocket's core)."""
    loops = slice_loops(base.mesh, axis, level)
    return any(not outer(loop, loops) and _islands(loop, loops) and in_loop(own, loop) for loop in loops)


def _part_slice(part: CadPart, base: CadPart, axis: np.ndarray) -> tuple[float, Loop] | None:
    """The level [m] (to 0.1 µm) in the middle of the part's depth inside the base along ``axis`` (the
    base's extent there taken over its vertices within the part's box across the axis, where
    at that level the base has an inner loop around the part: a switch's body in the slot of
    a hollow case's top, sliced in the top, not in the cavity under it; else over its
    vertices within that box grown by the box's larger side on each side: the walls of a
    hole with room around the part, while a pin of the base standing farther off is not
    around it) and the part's one outline there (a ring's, its bore inside); None when
    the part does not reach into the base or its slice there is not one outline. Where the
    base's slice at that level has no inner loop around the part (a boss of the base beside
    it stretches the base's extent: a bolt in a hub's disc next to its boss, sliced at the
    disc's face), the level of the base's hole around it that :func:`hole_around` finds,
    if any."""
    across = np.abs(axis) < 0.5
    lower, upper = part.mesh.bounds[0][across], part.mesh.bounds[1][across]
    tight = _level_within(part, base, axis, lower, upper)
    if tight is not None and _holds(base, axis, *tight):
        return tight
    grown = float(np.max(upper - lower))
    found = _level_within(part, base, axis, lower - grown, upper + grown)
    if found is None:
        return None
    level, own = found
    if not _holds(base, axis, level, own):
        hit = hole_around(base, part, axis)
        if hit is not None:
            return round(hit[0], 7), hit[3]
    return level, own


def _level_within(part: CadPart, base: CadPart, axis: np.ndarray, lower: np.ndarray, upper: np.ndarray
                  ) -> tuple[float, Loop] | None:
    """The level [m] (to 0.1 µm) in the middle of the part's depth inside the base along
    ``axis``, the base's extent taken over its vertices between ``lower`` and ``upper``
    across the axis [m], and the part's one outline there (of several, the one around the
    others: a bearing's outer race around its balls and inner race); None when no vertex of
    the base lies there, the part does not reach into that extent or its slice there is no
    outline around the others."""
    across = np.abs(axis) < 0.5
    inside = np.all((base.mesh.vertices[:, across] >= lower) & (base.mesh.vertices[:, across] <= upper), axis=1)
    if not np.any(inside):
        return None
    along, base_along = part.mesh.vertices @ axis, base.mesh.vertices[inside] @ axis
    low, high = max(along.min(), base_along.min()), min(along.max(), base_along.max())
    if high - low <= 1e-6:
        return None
    level = round(float(low + high) / 2, 7)
    cut = slice_loops(part.mesh, axis, level)
    own = [loop for loop in cut if outer(loop, cut)]
    around = [loop for loop in own if all(o is loop or loop.contains(o.centre) for o in own)]
    return (level, around[0]) if len(around) == 1 else None


def _holds(base: CadPart, axis: np.ndarray, level: float, own: Loop) -> bool:
    """Whether the base's slice at ``level`` [m] across ``axis`` has an inner loop around
    the centre of the part's outline ``own``."""
    loops = slice_loops(base.mesh, axis, level)
    return any(loop.contains(own.centre) and not outer(loop, loops) for loop in loops)


def receives(fit: HoleFit) -> bool:
    """Whether the empty hole ``fit`` is one a part goes into along its axis: its section is
    round, square or rect, or a simple polygon that turns onto itself about its centre by
    a fraction of a turn (:func:`executor.world.polygon_fit.symmetry` of order 2 or more:
    a hexagon, a spline, a cross, a 16-gon). A polygon with no such axis is a pocket: the
    open corner beside a turned boss, a relieved corner or a slot left around a pin of the
    base's own in its hole, the gap between two of its bodies; a sliver whose mean width
    (twice its area over its perimeter) is at most :data:`executor.cad.fits.faces.TOUCH` is a
    gap between faces that touch, whatever symmetry rounding lends it (one of a Technic
    pin's slits, 0.816 x 0.000 mm, was a hole with ``ldraw_axles`` turned 90 deg about z).
    An empty hole with islands is a pocket: no part is known to go in around them (a groove
    round a pin of the base's own)."""
    if fit.hole.kind != "polygon":
        return True
    if len(fit.hole.inner):  # around islands: no part is known to go in (a groove round a pin)
        return False
    try:
        shape = polygon(fit.hole.outline, "hole")
    except OutlineError:  # no simple polygon: a gap of no area between faces that touch
        return False
    return not touching_gap(shape.area, shape.length) and symmetry(shape) >= 2
