"""A hole measured, of the base or of a moving part (:func:`measure`): its section and its
occupant's over the stretch the part passes, entry, depth and entry chamfer."""

from __future__ import annotations

import numpy as np
import shapely
import trimesh

from executor import ExecutorError
from executor.cad.derive.derived import HoleFit
from executor.cad.derive.rays import first_hit
from executor.cad.parts import STEP_DEFLECTION, CadPart
from executor.cad.sections import Loop, classify, exact_round, faceted, frame_of, over_span, slice_loops
from executor.cad.sweep import DIRECTIONS, forked_map

_ENTRY_PROBE = 2e-5  # the chamfer is measured this far [m] below the entry


def measure(base: CadPart, name: str, loop: Loop, level: float, outer: Loop | None,
            occupant: tuple[CadPart, Loop] | None, workers: int = 1) -> HoleFit:
    """Section, entry, depth (to the first face of ``base``, the part the hole is in, down
    the hole's centre line; through it, to its lowest point around the hole, when there is
    none) and chamfer of the hole ``loop`` sliced at ``level`` [m], and the section of the
    ``occupant`` (its part, its loop there). The sections are over the stretch from the
    occupant's end (or the hole's lowest point around it, if higher) to the entry
    (:func:`executor.cad.sections.over_span`, made in ``workers`` processes:
    :func:`executor.cad.sweep.forked_map`; 1 in a forked one); without an occupant, from the
    floor (the first face of ``base`` down the centre line of the loop) or, with none, from
    the hole's lowest point around it: as deep as a part goes in. Where nothing of the hole
    is free down to that floor, it is no face across the axis (a drill point's cone) and the
    stretch starts at ``level``. ExecutorError when nothing of the hole is free all along the
    stretch."""
    axis = np.array(DIRECTIONS[name])
    frame = frame_of(axis)
    sliced = classify(loop, hole=True)
    radial = base.mesh.vertices @ frame.T - sliced.centre
    around = (base.mesh.vertices @ axis)[np.linalg.norm(radial, axis=1) <= max(sliced.a, sliced.b)]
    entry = float(around.max())
    line = _free_point(loop, sliced.centre)
    if occupant is None:  # as deep as a part can go in: to the floor down its centre line, or through
        floor = first_hit(base.mesh, frame.T @ line + axis * level, -axis)
        tip = float(around.min()) if floor is None else level - floor
    else:
        tip = float((occupant[0].mesh.vertices @ axis).min())
    low = max(tip, float(around.min()))
    spans: list[tuple[Loop, trimesh.Trimesh, float, bool]] = [(loop, base.mesh, low, True)]
    bores: list[Loop] = []
    if occupant is not None:
        spans.append((occupant[1], occupant[0].mesh, tip, False))
        if loop.inner:  # around islands: the occupant's bores over them, each free all along as a hole is
            bores = _bores(occupant[0].mesh, axis, level, occupant[1])
            spans += [(bore, occupant[0].mesh, tip, True) for bore in bores]
    narrowest, *occupied = forked_map(lambda span: over_span(span[0], span[1], axis, span[2], entry, hole=span[3]),
                                      spans, workers)
    if occupied[1:]:  # a bore with something of the part in it (at the level or along) is left solid
        kept = tuple(bore.points for bore in occupied[1:] if len(bore.points) >= 3 and not bore.inner)
        occupied = [Loop(occupied[0].points, kept)]
    if occupant is None and len(narrowest.points) < 3:  # a floor not across the axis (a drill point's cone)
        low = level
        narrowest = over_span(loop, base.mesh, axis, low, entry, hole=True)
    if len(narrowest.points) < 3:
        x, y, z = 1e3 * (frame.T @ sliced.centre + axis * level)
        raise ExecutorError(f"the hole of part {base.id} at ({x:.3f}, {y:.3f}, {z:.3f}) mm is closed between "
                            f"{1e3 * (entry - low):.3f} mm below its entry and its entry along {name[1:]} "
                            "(expected an opening all the way in)")
    hole = exact_round(classify(narrowest, hole=True), base.cylinders, axis, level, STEP_DEFLECTION)
    part, section = (None, None) if occupant is None else (
        occupant[0].id, exact_round(classify(occupied[0], hole=False), occupant[0].cylinders, axis, level,
                                    STEP_DEFLECTION))
    if section is not None:  # a tessellated round section against a section that is no round: its polygon
        hole = faceted(hole, narrowest, section, hole=True)
        section = faceted(section, occupied[0], hole, hole=False)
    centre = frame.T @ hole.centre + axis * level
    bottom = first_hit(base.mesh, frame.T @ _free_point(narrowest, hole.centre) + axis * level, -axis)
    depth = entry - (level - bottom if bottom is not None else float(around.min()))
    probe = [o for o in slice_loops(base.mesh, axis, entry - _ENTRY_PROBE) if o.contains(hole.centre)]
    chamfer = 0.0
    if probe:
        top = classify(min(probe, key=lambda o: o.area), hole=True)
        chamfer = max(0.0, (top.b - hole.b) / 2 + _ENTRY_PROBE) if top.b > hole.b + 1e-7 else 0.0
    return HoleFit("", name, hole, (float(centre[0]), float(centre[1]), float(entry)), entry, depth, chamfer,
                   None if outer is None else classify(outer, hole=False), part, section)


def _free_point(loop: Loop, centre: np.ndarray) -> np.ndarray:
    """Where (2,) [m] a ray down the hole ``loop`` finds its floor: its ``centre``, or where
    that lies on an island (:attr:`executor.cad.sections.Loop.inner`), a point of the
    opening around it."""
    if not loop.inner:
        return centre
    opening = shapely.Polygon(loop.points, loop.inner)
    if opening.is_valid and opening.contains(shapely.Point(centre)):
        return centre
    return np.asarray(shapely.point_on_surface(shapely.make_valid(opening)).coords[0])


def _bores(mesh: trimesh.Trimesh, axis: np.ndarray, level: float, own: Loop) -> list[Loop]:
    """The inner loops of the part ``mesh``'s slice at ``level`` [m] across ``axis`` that lie
    in its outline ``own`` with no other loop between them (its bores there), each with the
    part's outlines that stand in it as its inner rings (a bearing's balls and inner race in
    its outer race's bore: what the section must keep solid)."""
    loops = slice_loops(mesh, axis, level)
    inside = [o for o in loops if o.area < own.area and own.contains(o.centre)]

    def direct(loop: Loop, among: list[Loop]) -> bool:
        return not any(other is not loop and other.area > loop.area and other.contains(loop.centre)
                       for other in among)

    bores = [o for o in inside if direct(o, inside)]
    return [Loop(bore.points, tuple(o.points for o in inside if o is not bore and o.area < bore.area
                                    and bore.contains(o.centre)
                                    and direct(o, [i for i in inside if i is not bore and bore.contains(i.centre)])))
            for bore in bores]
