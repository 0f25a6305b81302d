"""The simulated gripper (:data:`GRIPPER`) and the fingers' grip of a peg or of a part with a
bore going onto its pin: how deep the fingers hold it (:func:`finger_grip`, :func:`bore_grip`),
from how far it stands out at its goal of the parts in place where the fingers are
(:func:`standing_out`, the finger model :data:`FINGER_THICKNESS`, :data:`FINGER_WIDTH`), at
least :data:`MIN_GRIP`; the model as the import states it (:func:`finger_assumption`).
Lengths in metres (docs/cell.md#the-fingers-grip)."""

from __future__ import annotations

import math

import numpy as np
import shapely
import trimesh

from executor.cad.derive import Derived, HoleFit, PinFit
from executor.cad.operations.frames import along_axis, feature_turn
from executor.cad.operations.precedence import in_place_before

GRIPPER = {"flange_mass": 1.0, "flange_inertia": 0.004, "flange_length": 0.06, "grasp_depth": 0.02,
           "cup_diameter": 0.03, "cup_force": 20.0}
"""The simulated gripper of every imported product (Cranfield's, with the cell's suction
cup: ``cup_diameter`` [m], ``cup_force`` [N]), its flange longer where the arm's wrist
would meet the product (:func:`tool_length`)."""
FINGER_THICKNESS = 0.01
"""[m] the finger model: a parallel gripper's two fingers, each this thick along the way they
close and :data:`FINGER_WIDTH` across it, centred on the part's axis, beside the part's
footprint (its outline seen along its axis) from its top down as deep as they hold it; the
gripper turned about that axis where the part stands out most (every
:data:`FINGER_YAW_STEP`). An assumption of about a parallel gripper's fingertips
(docs/cell.md#the-fingers-grip)."""
FINGER_WIDTH = 0.02
"""[m] each finger across the way the fingers close (:data:`FINGER_THICKNESS`)."""
FINGER_TOUCH = 1e-6
"""[m] how far into the fingers a part must reach to be in their way (less: it touches them)."""
FINGER_YAW_STEP = 15.0
"""[deg] the turns about the part's axis the fingers are tried at, over half a turn."""
GRIP_CLEARANCE = 0.001
"""[m] how far above everything else of the product where the fingers are the fingertips
stay with the part at its goal."""
MIN_GRIP = 0.005
"""[m] the least length of a part the fingers hold it over (docs/cell.md#the-fingers-grip):
below it the pads' give tilts the part beyond the cell's grasp error model (≤ 1 deg)."""


def finger_assumption() -> str:
    """The finger model, as the import states it among its assumptions."""
    return (f"the fingers hold a peg over its top {1e3 * GRIPPER['grasp_depth']:g} mm, less where it stands out of "
            f"the product less at its goal (its top above the base and every part the geometric precedence puts "
            f"before it, where the fingers are: "
            f"two {1e3 * FINGER_THICKNESS:g} x {1e3 * FINGER_WIDTH:g} mm beside its outline, turned about its axis "
            f"where it stands out most) less {1e3 * GRIP_CLEARANCE:g} mm, over "
            f"{1e3 * MIN_GRIP:g} mm at least, and a part with a bore so by its outside (at most half its length); "
            f"a peg standing out less goes on the suction cup or by hand, a part with a bore by hand")


def finger_grip(derived: Derived, pid: str, fit: HoleFit | PinFit) -> tuple[float, str]:
    """How deep [m] the fingers hold part ``pid``, the peg of hole ``fit`` (longer than
    :data:`GRIPPER`'s grasp depth) or a part with a bore on pin ``fit`` (the cell holds it
    at most half its length deep besides: :func:`bore_grip`), by its outside, and why where
    not that deep: the grasp depth, or what the part stands out at its goal of the parts in
    place whenever it goes there (:func:`standing_out`, the base, the pin's owner and those
    the geometric precedence puts before it; others the precedence admits before it:
    :func:`executor.cad.operations.tools.finger_orders`) less :data:`GRIP_CLEARANCE` where
    that is less, rounded down to 0.1 mm; 0 where that is under :data:`MIN_GRIP` (the
    fingers would meet the product before the part reaches its goal: placed by hand, or
    a peg on the suction cup)."""
    return grip_for(*standing_out(derived, pid, fit, in_place_before(derived, pid)))


def bore_grip(derived: Derived, pid: str, pin: PinFit) -> float:
    """How deep [m] the cell holds part ``pid`` with a bore on ``pin``: by its top, at most
    half its length along the pin (:meth:`executor.world.geometry.PartSpec.held_depth`) and
    no deeper than the fingers' grip (:func:`finger_grip`)."""
    along = along_axis(derived.parts[pid].mesh, pin)[:, 2]
    return min(finger_grip(derived, pid, pin)[0], float(np.ptp(along)) / 2)


def grip_for(out: float, under: str) -> tuple[float, str]:
    """:func:`finger_grip`'s rule for a part standing ``out`` [m] of ``under`` ("": of nothing)."""
    depth, need = GRIPPER["grasp_depth"], MIN_GRIP + GRIP_CLEARANCE
    if out - GRIP_CLEARANCE >= depth:
        return depth, ""
    where = f"stands out of the product by {1e3 * out:.3f} mm at its goal" + (
        f" ('{under}' where the fingers are)" if under else "")
    if out < need - 1e-9:
        return 0.0, f"{where}, less than the {1e3 * need:g} mm the fingers need"
    return math.floor(round((out - GRIP_CLEARANCE) * 1e4, 6)) / 1e4, f": it {where}, less {1e3 * GRIP_CLEARANCE:g} mm"


def standing_out(derived: Derived, pid: str, fit: HoleFit | PinFit, others: set[str]) -> tuple[float, str]:
    """How far [m] part ``pid``'s top stands out, at its goal (where the CAD has it) along
    the removal direction of ``fit`` (its hole or pin), of the ``others`` (in place then)
    where the fingers are (:data:`FINGER_THICKNESS`,
    turned about the axis where it stands out most), below its top (what overhangs the top
    is the wrist's: :func:`tool_length`); and the part it stands out of there ("" where none
    reaches the fingers above the part's bottom: its length)."""
    turn = feature_turn(fit)[:3, :3].T
    own = derived.parts[pid].mesh.vertices @ turn
    low, high = float(own[:, 2].min()), float(own[:, 2].max())
    triangles = {}  # of the others, below the part's top (above it: the wrist's, tool_length)
    for other in sorted(others):
        below = trimesh.Trimesh(derived.parts[other].mesh.vertices @ turn, derived.parts[other].mesh.faces,
                                process=False)
        below = trimesh.intersections.slice_mesh_plane(below, (0.0, 0.0, -1.0), (0.0, 0.0, high))
        if len(below.faces):
            triangles[other] = below.vertices[below.faces]
    centre = np.asarray(shapely.MultiPoint(own[:, :2]).convex_hull.centroid.coords[0])
    best = (-math.inf, "")
    for yaw in np.radians(np.arange(0.0, 180.0, FINGER_YAW_STEP)):
        across, along = np.array([math.cos(yaw), math.sin(yaw)]), np.array([-math.sin(yaw), math.cos(yaw)])
        reach = (own[:, :2] - centre) @ across
        pads = [shapely.Polygon([centre + s * across + w * along
                                 for s, w in ((start, -FINGER_WIDTH / 2), (start + FINGER_THICKNESS, -FINGER_WIDTH / 2),
                                              (start + FINGER_THICKNESS, FINGER_WIDTH / 2),
                                              (start, FINGER_WIDTH / 2))])
                for start in (float(reach.max()), float(reach.min()) - FINGER_THICKNESS)]
        under, other_top = "", low
        for other, corners in triangles.items():
            for pad in pads:  # one at a time: each one's bounds keep the triangles near it alone
                top = _highest_in(corners, pad.buffer(-FINGER_TOUCH), other_top)  # a face it touches: not in its way
                if top is not None:
                    under, other_top = other, top
        if high - other_top > best[0]:
            best = (high - other_top, under)
    return best


def _highest_in(triangles: np.ndarray, region: shapely.Geometry, above: float) -> float | None:
    """The highest point [m] of the ``triangles`` (n, 3, 3) [m] within the vertical prism
    over ``region`` (x, y [m]), where above ``above`` [m]; None where none is. A triangle's
    height is linear over it: its highest over the region is at a corner of their
    intersection; a vertical one's on its edges."""
    x0, y0, x1, y1 = region.bounds
    xy = triangles[:, :, :2]
    near = ((xy[:, :, 0].max(axis=1) >= x0) & (xy[:, :, 0].min(axis=1) <= x1)
            & (xy[:, :, 1].max(axis=1) >= y0) & (xy[:, :, 1].min(axis=1) <= y1)
            & (triangles[:, :, 2].max(axis=1) > above))
    triangles = triangles[near]
    normals = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    best = above
    for k in np.argsort(-triangles[:, :, 2].max(axis=1)):
        corner, normal = triangles[k], normals[k]
        if float(corner[:, 2].max()) <= best:
            break
        if abs(normal[2]) > 1e-12:
            points = shapely.get_coordinates(shapely.Polygon(corner[:, :2]).intersection(region))
            heights = corner[0, 2] - ((points - corner[0, :2]) @ normal[:2]) / normal[2]
        else:  # vertical: along its edges
            heights = np.array([_edge_height(corner[j], corner[(j + 1) % 3], region) for j in range(3)])
        if len(heights) and (top := float(min(np.nanmax(heights, initial=-np.inf), corner[:, 2].max()))) > best:
            best = top
    return None if best == above else best


def _edge_height(start: np.ndarray, end: np.ndarray, region: shapely.Geometry) -> float:
    """The highest point [m] of the segment from ``start`` to ``end`` (x, y, z [m]) over
    ``region``; NaN where it does not pass over it."""
    run = float(np.hypot(*(end[:2] - start[:2])))
    if run < 1e-12:  # upright: its top where it stands in the region
        return float(max(start[2], end[2])) if region.intersects(shapely.Point(start[:2])) else math.nan
    points = shapely.get_coordinates(shapely.LineString([start[:2], end[:2]]).intersection(region))
    if not len(points):
        return math.nan
    along = np.hypot(*(points - start[:2]).T) / run
    return float((start[2] + along * (end[2] - start[2])).max())
