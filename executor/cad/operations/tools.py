"""What holds each peg the cell inserts (:func:`tool_of`): the fingers where they grip it deep
enough (:mod:`executor.cad.operations.fingers`), else the suction cup on its flat top
(:func:`flat_top`), else nothing (placed by hand); and the orders the fingers' grip needs
among the parts (:func:`finger_orders`, ``cell_order.lp``). Lengths in metres."""

from __future__ import annotations

import numpy as np
import shapely
import trimesh

from executor.cad.derive import Derived, HoleFit, PinFit
from executor.cad.operations.fingers import GRIPPER, bore_grip, finger_grip, grip_for, standing_out
from executor.cad.operations.frames import upright
from executor.cad.operations.precedence import in_place_before, maybe_in_place
from executor.world.meshes import MIN_THICKNESS

FLAT_TOLERANCE = 1e-5
"""[m] how far from the plane of a part's top (its highest point along its way out) a
face's vertices may lie, and still seal the cup (a face tilted by more than its size
entails misses it)."""


def tool_of(derived: Derived, fit: HoleFit) -> tuple[str, str]:
    """What holds the peg of ``fit`` and why: ``fingers`` for a part longer than
    :data:`GRIPPER`'s grasp depth that stands out of the product at its goal far enough
    for them (:func:`finger_grip`), else ``suction`` where it is at least
    :data:`executor.world.meshes.MIN_THICKNESS` thick and the cup (``cup_diameter``) lies
    whole on its flat top (:func:`flat_top`: the face opposite its way in, around its
    axis), else "" (placed by hand) with why."""
    assert fit.part is not None and fit.section is not None
    mesh = upright(derived, fit)
    length, depth = float(mesh.extents[2]), GRIPPER["grasp_depth"]
    if length > depth:
        grip, why = finger_grip(derived, fit.part, fit)
        if grip > 0:
            return "fingers", f"{1e3 * length:.3f} mm long, held {1e3 * grip:g} mm deep by the fingers{why}"
        short = f"part '{fit.part}' {why}"
    else:
        short = (f"part '{fit.part}' is {1e3 * length:.3f} mm long, no longer than the gripper's grasp depth "
                 f"({1e3 * depth:g} mm)")
    if length < MIN_THICKNESS:  # a physics limit: no convex piece of it keeps its shape
        return "", (f"{short}, and thinner than the cell's hull margin twice less what it resolves "
                    f"({1e3 * MIN_THICKNESS:g} mm): it has no convex pieces the cell can collide as")
    top = flat_top(mesh)
    cup = shapely.Point(*fit.section.centre).buffer(GRIPPER["cup_diameter"] / 2, 64)
    if top.is_empty:
        return "", f"{short}, and its top is not flat for the suction cup"
    if not top.buffer(1e-9).contains(cup):
        inside = top.buffer(1e-9).intersection(cup).area / cup.area
        return "", (f"{short}, and the suction cup ({1e3 * GRIPPER['cup_diameter']:g} mm) does not lie whole on its "
                    f"flat top ({100 * inside:.1f}% of the cup on it)")
    return "suction", (f"{short}: its flat top ({1e6 * top.area:.1f} mm^2) holds the suction cup "
                       f"({1e3 * GRIPPER['cup_diameter']:g} mm) about its axis")


def finger_orders(cell: Derived) -> list[tuple[str, str, float, float]]:
    """The orders the fingers' grip (:func:`finger_grip`) needs, as (peg, part, grip [m],
    out [m]): each peg the cell inserts with the fingers, and each part with a bore it puts
    onto its pin (held :func:`bore_grip` deep), goes in before each part the
    geometric precedence merely lets be in place before it (:func:`maybe_in_place`, not
    the base nor those it puts before it) that would leave it standing out ``out``, too
    little for its ``grip`` (Cranfield's pegs: 5 mm out of the front plate, 25 mm out of
    the base plate). The parts are taken in id order, each one left free to be in place
    only while the peg, with it and those left free before it, keeps its grip; so every
    part left free, all together in place, leaves the grip as it is. The plans honour
    these orders (``cell_order.lp``, :func:`executor.cad.write.facts.cell_order_text`)."""
    held: list[tuple[str, HoleFit | PinFit, float]] = [
        (pid, fit, finger_grip(cell, pid, fit)[0]) for pid, fit in sorted(cell.hole_of.items())
        if fit.axis != "-z" and tool_of(cell, fit)[0] == "fingers"]
    held += [(pid, cell.pin_of(pid), bore_grip(cell, pid, cell.pin_of(pid))) for pid in sorted(cell.bores)]
    found = []
    for pid, fit, grip in held:
        free = in_place_before(cell, pid)
        if grip_for(*standing_out(cell, pid, fit, maybe_in_place(cell, pid)))[0] >= grip:
            continue
        for other in sorted(maybe_in_place(cell, pid) - free):
            out, _ = standing_out(cell, pid, fit, free | {other})
            if grip_for(out, other)[0] < grip:
                found.append((pid, other, grip, out))
            else:
                free.add(other)
    return found


def finger_order_text(order: tuple[str, str, float, float]) -> str:
    """One order of :func:`finger_orders` as the import states it."""
    pid, other, grip, out = order
    return (f"'{pid}' goes in before '{other}' (the fingers hold it {1e3 * grip:g} mm deep; with "
            f"'{other}' in place it would stand out {1e3 * out:.3f} mm): the cell's own order, "
            "every plan honours it (cell_order.lp)")


def flat_top(mesh: trimesh.Trimesh) -> shapely.Geometry:
    """The flat face of ``mesh`` (axis along z) at its highest: the union, seen along z, of
    its faces facing up whose vertices all lie within :data:`FLAT_TOLERANCE` of its top [m];
    empty where none does."""
    high = float(mesh.vertices[:, 2].max())
    level = np.all(mesh.vertices[mesh.faces][:, :, 2] >= high - FLAT_TOLERANCE, axis=1) & (mesh.face_normals[:, 2] > 0)
    if not level.any():
        return shapely.Polygon()
    triangles = shapely.polygons(mesh.vertices[mesh.faces[level]][:, :, :2])
    return shapely.union_all(triangles[shapely.area(triangles) > 0]).buffer(0)
