"""The pairs the simulated cell cannot tell the outcome of, decided from the CAD (a feature's
``near_miss`` in ``geometry.toml``, no experiment of the PyBullet cell): a peg no-fit by
less than its collision shape lacks, or in a hole no deeper than the goal tolerance
(:func:`near_misses`), a part stopping on a pin's end near its goal (:func:`pin_near_misses`);
as ``import`` states them (:func:`near_miss_assumption`). Lengths in metres."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np
import shapely
import trimesh

from executor.cad.convex import peg_is_primitive
from executor.cad.derive import Derived, PinFit
from executor.cad.operations.frames import along_axis, bore_frame, pin_level, upright
from executor.cad.operations.plate import LEVEL
from executor.cad.operations.rooms import margins, section_pairs
from executor.cad.sections import section
from executor.cad.sweep import DIRECTIONS
from executor.cad.write.depths import down_depth, sideways_depth
from executor.control.detector import Thresholds
from executor.world.near_miss import mesh_near_miss, near_miss

RIM_PRESS = 2e-4
"""How far [m] a part blocked on a hole's rim may end below the rim, pressed into it by the
insertion (0.05-0.18 mm measured: docs/cell.md, "What the physics resolves")."""


def near_misses(derived: Derived, pieces: Mapping[str, Sequence[np.ndarray]] | None = None
                ) -> dict[tuple[str, str], str]:
    """(peg, hole of the base) -> why the simulated cell cannot tell the pair's outcome:
    every peg in a hole no deeper than the cell's goal tolerance plus :data:`RIM_PRESS` (a
    part blocked on its rim ends as near its goal as one inside it), and each no-fit it
    cannot resolve (:func:`near_miss_reason`, how deep [m] the cell's peg lacks its
    section, plus the cell's resolution): for a peg the
    cell builds from its section (a cylinder, a box, a polygon's prism),
    :func:`executor.world.near_miss.near_miss` (its section eroded by what its collision
    shape may lack passes the hole); for a peg simulated from its mesh, whose convex
    pieces (vertices in its part frame) are in ``pieces``,
    :func:`executor.world.near_miss.mesh_near_miss` (what its pieces cover over the
    stretch that enters the hole passes it). A hole's ``near_miss`` in ``geometry.toml``."""
    rooms, pairs, found, tried = margins(derived), section_pairs(derived), {}, []
    for pid, fit in sorted(derived.hole_of.items()):
        if fit.section is None:
            continue
        primitive = peg_is_primitive(fit, upright(derived, fit))
        if not primitive and (pieces is None or pid not in pieces):
            continue
        tried.append(pid)
        tip = float((derived.parts[pid].mesh.vertices @ np.array(DIRECTIONS[fit.axis])).min())
        for hid in derived.holes:
            peg, hole = pairs[pid][hid]
            part, cell_hole = section(f"part {pid}", peg), section(f"hole {hid}", hole)
            depth = (near_miss(part, cell_hole, rooms[pid][hid]) if primitive else
                     mesh_near_miss(part, (pieces or {})[pid], fit.entry - tip, cell_hole, rooms[pid][hid]))
            if depth is not None:
                found[(pid, hid)] = near_miss_reason(pid, hid, depth)
    tolerance = Thresholds().goal_tolerance
    for hid, fit in derived.holes.items():
        deep = down_depth(derived, fit) if fit.axis == "+z" else sideways_depth(derived, fit)
        if deep <= tolerance + RIM_PRESS:
            for pid in tried:
                found.setdefault((pid, hid), (
                    f"{pid} in {hid}: the hole is {1e3 * deep:.3f} mm deep, no deeper than the cell's goal tolerance "
                    f"({1e3 * tolerance:g} mm) plus {1e3 * RIM_PRESS:g} mm: a part blocked on its rim would end as "
                    "near its goal as one inside it, decided from the CAD"))
    return found


def pin_near_misses(derived: Derived) -> dict[tuple[str, str], str]:
    """(part with a bore, pin) -> why the simulated cell cannot tell the pair's outcome: the
    part does not pass the pin (its room below 0) and would stop on the pin's end no farther
    than the cell's goal tolerance plus :data:`RIM_PRESS` from its goal there (the cell
    compares the part's origin, the centre of its bore at its end nearest the pin's root,
    with the pin's written bottom, where the first of the pin's parts rests in the CAD:
    :func:`executor.world.geometry.seat`, nothing stacked on it), so a part blocked on it
    ends as near its goal as one on it: a pin's ``near_miss`` in ``geometry.toml``. Where it
    stops (:func:`_pin_stop`) is a lower bound: the pair is listed whenever it may be that close."""
    rooms, found = margins(derived), {}
    tolerance = Thresholds().goal_tolerance
    for pin_id, pin in derived.pins.items():
        if not pin.parts:  # an empty pin: the cell has no goal on it (geometry_text leaves it out)
            continue
        top, height = pin_level(derived, pin)
        for pid in sorted(derived.bores):
            if rooms[pid][pin_id] >= 0:
                continue
            travel = _pin_stop(derived, pid, pin) - (top - height)
            if travel <= tolerance + RIM_PRESS:
                found[(pid, pin_id)] = (
                    f"{pid} on {pin_id}: it does not pass the pin and would stop on its end {1e3 * travel:.3f} mm from "
                    f"its goal there, no farther than the cell's goal tolerance ({1e3 * tolerance:g} mm) plus "
                    f"{1e3 * RIM_PRESS:g} mm: a part blocked on it would end as near its goal as one on it, "
                    "decided from the CAD")
    return found


STOP_RINGS = (0.0, 0.3, 0.6, 0.8, 0.9, 0.97, 0.995)
"""The radii, as fractions of the circle a pin's section holds, of the rings of points at
which :func:`_pin_stop` finds a part's material over that circle (72 points a ring)."""


def _pin_stop(derived: Derived, pid: str, pin: PinFit) -> float:
    """The lowest level [m, along ``pin``'s axis, its frame] the end of part ``pid`` nearest
    the pin's root reaches going down the pin's axis, its bore centred on it: the pin's top
    (the highest vertex of its owner within its section's reach at least as far from its
    axis as the circle its section holds, assumed to hold that circle up to there) less the
    height above that end of the part's lowest material over that circle (its lowest vertex
    in it, or the lowest of its faces over the points of :data:`STOP_RINGS`: the part's
    material the pin cannot pass). The part may be stopped higher (on material between
    those points, on a wider step above), never lower, so the travel from here to its goal
    is at most the cell's; without material over the circle (the pin's corners stop it),
    -inf: a near miss whatever its goal."""
    outline = shapely.Polygon(pin.section.outline)
    inner = float(outline.exterior.distance(shapely.Point(0.0, 0.0)))
    reach = math.hypot(pin.section.a, pin.section.b) / 2
    owner = along_axis(derived.parts[pin.owner].mesh, pin)
    off = np.linalg.norm(owner[:, :2] - pin.section.centre, axis=1)
    wide = (off >= inner - LEVEL) & (off <= reach + LEVEL)
    mesh = derived.parts[pid].mesh
    frame = bore_frame(derived, pid)
    part = trimesh.transform_points(mesh.vertices, frame)
    inside = part[np.linalg.norm(part[:, :2], axis=1) < inner - LEVEL, 2]
    turns = np.linspace(0.0, 2 * math.pi, 72, endpoint=False)
    points = np.array([(r * inner * math.cos(t), r * inner * math.sin(t)) for r in STOP_RINGS for t in turns])
    over = _lowest_over(points, part[mesh.faces])
    low = min([*inside, over])
    if not wide.any() or not math.isfinite(low):
        return -math.inf
    return float(owner[wide, 2].max()) - low


def _lowest_over(points: np.ndarray, triangles: np.ndarray) -> float:
    """The lowest z [m] of the ``triangles`` (n, 3, 3) over any of ``points`` (k, 2) [m] (the
    first face a ray up from below each point meets), inf over none."""
    (ax, ay, az), (bx, by, bz), (cx, cy, cz) = (triangles[:, k, :].T for k in range(3))
    det = (by - cy) * (ax - cx) + (cx - bx) * (ay - cy)
    flat = np.abs(det) > 1e-18  # faces seen from below; walls along the axis hide nothing
    ax, ay, az, bx, by, bz, cx, cy, cz, det = (v[flat] for v in (ax, ay, az, bx, by, bz, cx, cy, cz, det))
    lowest = math.inf
    for chunk in np.array_split(points, max(1, len(points) // 32)):
        px, py = chunk[:, :1], chunk[:, 1:]
        u = ((by - cy) * (px - cx) + (cx - bx) * (py - cy)) / det
        v = ((cy - ay) * (px - cx) + (ax - cx) * (py - cy)) / det
        hit = (u >= 0) & (v >= 0) & (u + v <= 1)
        if hit.any():
            lowest = min(lowest, float(np.where(hit, u * az + v * bz + (1 - u - v) * cz, np.inf).min()))
    return lowest


def near_miss_reason(pid: str, hid: str, depth: float) -> str:
    """Why the pair is no experiment of the PyBullet cell (:func:`near_misses`)."""
    return (f"{pid} in {hid}: misses by less than the cell's peg lacks at its corners (rounded by its 1 mm hull "
            f"margin) plus what the cell resolves ({1e3 * depth:.3f} mm), decided from the CAD")


def near_miss_assumption(derived: Derived, pieces: Mapping[str, Sequence[np.ndarray]] | None = None) -> list[str]:
    """The near misses the PyBullet cell does not observe (:func:`near_misses`), as
    ``import`` prints them (none without one), saying which backends try them
    (:data:`bridge.assembly.NEAR_MISS_BACKENDS`)."""
    return [f"no experiment of the PyBullet cell (backend sim; the truth and franka backends try it): {reason}"
            for reason in (near_misses(derived, pieces) | pin_near_misses(derived)).values()]
