"""The covers and heads of an imported product: the parts the cell places over the pins
standing in the base's holes or into a cover's socket (``[covers.*]``, ``[heads.*]`` of
``geometry.toml``, docs/geometry.md), recognised and measured in the assembled pose.

Every part that is neither the base nor a peg in a hole of the base must leave along +z
(the cell places it from above). Taken lowest bottom first, each is

- a **cover** when pins pass through it: a peg standing in a base hole passes through a
  part when, at the middle of their common height, the centre of the peg's section lies
  within the convex hull of the part's section (an opening, or a fork open at one side);
  ``over`` are those pegs' holes. A part with no pins that rests on covers is a cover too,
  over the holes of the covers it rests on. A cover rests on the base or on covers (their
  faces meet where its bottom face is, :data:`PROBE` below and above it); one that rests
  on neither (only on pins, say) is one the cell cannot place;
- a **head** when it has no pins and stands on the floor of a blind opening of a cover
  (the cover's material right under its bottom, its bottom below the cover's top): the
  cover's ``socket``; one head per cover.

Any other part is named as one the cell has no model for. Measured, relative to a cover's
origin (the centre of its holes at its bottom face): the ``outline`` (its bounding box),
``thickness``, ``bottom`` (above the holes' entry), ``clearance`` (the least room of its
openings over its holes: twice the distance from a hole's centre to the cover's section
at mid-height, less the hole's size), ``socket`` (its head's opening: centre, its
inscribed size, depth to its floor). Chosen by rule: the **grip**, the point of the top
face nearest above the cover's centre of mass that lies :data:`GRIP_MARGIN` or more from
every edge of that face (its outline, openings and socket; to 1 mm); the **skill**, a
cover's that of the largest peg (by section area, ties by id) in its holes, a head's that
of the peg whose section is nearest its own (same kind first, then size, then id).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace

import numpy as np
import trimesh
from matplotlib.path import Path as PolygonPath
from scipy.spatial import ConvexHull, QhullError

from bridge.product import Cover
from executor.assembly.product import MAX_COVER_BOXES, cover_spec
from executor.cad.convex import cover_is_primitive, head_is_primitive, section_area
from executor.cad.derive import Derived, first_hit
from executor.cad.parts import STEP_DEFLECTION
from executor.cad.sections import Loop, Shape2D, classify, edge_distance, exact_round, slice_loops
from executor.cad.sweep import opposite
from executor.world.geometry import HoleSpec

PROBE = 1e-5
"""How far [m] from a face a slice or ray looks for what touches it (10 µm)."""
GRIP_MARGIN = 0.005
"""The grip point lies at least this far [m] from every edge of the cover's top face."""
GRIP_GRID = 0.001
"""The grid [m] the grip is looked for on when the centre of mass is no grip point."""
SAME_AREA = 1e-8
"""Section areas within this [m²] (0.01 mm²) are one size when a skill is chosen."""
_UP = np.array([0.0, 0.0, 1.0])


@dataclass(frozen=True)
class CoverFit:
    """A cover as measured (module docstring), lengths [m]: ``origin`` in the cell frame,
    ``outline`` [xmin, ymin, xmax, ymax], ``socket`` [x, y, side, depth] or None, ``grip``
    [x, y], all but the origin relative to it; ``on`` the parts it rests on; ``primitive``
    whether it is the cell's cover of boxes."""

    id: str
    over: tuple[str, ...]
    origin: tuple[float, float, float]
    outline: tuple[float, float, float, float]
    thickness: float
    bottom: float
    clearance: float
    socket: tuple[float, float, float, float] | None
    grip: tuple[float, float]
    skill: str
    on: tuple[str, ...]
    primitive: bool


@dataclass(frozen=True)
class HeadFit:
    """A head in the socket of cover ``into``: its ``section`` in the socket, ``origin``
    (the section's centre at its bottom, cell frame [m]), ``length`` [m], ``skill``;
    ``primitive`` whether it is the cell's cylinder or box."""

    id: str
    into: str
    section: Shape2D
    origin: tuple[float, float, float]
    length: float
    skill: str
    primitive: bool


@dataclass(frozen=True)
class Mapped:
    """The covers and heads of a product, the parts the cell places by hand (``manual``:
    why it has no operation for each), or ``why`` the cell builds none of it; ``flange``
    the length [m] of its gripper's flange where the default's would not keep the arm's
    wrist clear of the product (:func:`executor.cad.operations.arm.tool_length`; None: the default),
    and why (``tool``)."""

    covers: dict[str, CoverFit]
    heads: dict[str, HeadFit]
    why: str | None = None
    manual: dict[str, str] = field(default_factory=dict)
    flange: float | None = None
    tool: str = ""


def hole_specs(derived: Derived) -> dict[str, HoleSpec]:
    """The base's holes as the cell's plate has them (position [m], size, yaw [rad], entry
    height and depth [m])."""
    return {hid: HoleSpec(hid, fit.hole.kind, fit.hole.a, fit.position, yaw=float(np.radians(fit.hole.yaw)),
                          width=fit.hole.b if fit.hole.kind == "rect" else 0.0, top_z=fit.entry, depth=fit.depth)
            for hid, fit in derived.holes.items()}


def _in_solid(loops: list[Loop], points: np.ndarray) -> np.ndarray:
    """Which ``points`` (n, 2) [m] lie inside the section made of ``loops`` (inside an odd
    number of them: the outline less its openings)."""
    count = np.zeros(len(points), dtype=int)
    for loop in loops:
        count += PolygonPath(loop.points).contains_points(points)
    return count % 2 == 1


def _clear(loops: list[Loop], points: np.ndarray) -> np.ndarray:
    """The distance [m] of each of ``points`` (n, 2) to the nearest edge of ``loops``."""
    best = np.full(len(points), np.inf)
    for loop in loops:
        start = loop.points
        edge = np.roll(start, -1, axis=0) - start
        for begin, along in zip(start, edge):
            length = float(along @ along)
            t = np.clip((points - begin) @ along / length, 0.0, 1.0) if length > 0 else np.zeros(len(points))
            best = np.minimum(best, np.linalg.norm(points - (begin + t[:, None] * along), axis=1))
    return best


def _in_hull(loops: list[Loop], point: np.ndarray) -> bool:
    """Whether ``point`` (2,) [m] lies within the convex hull of the section ``loops``."""
    points = np.vstack([loop.points for loop in loops])
    try:
        hull = points[ConvexHull(points).vertices]
    except QhullError:
        return False
    return bool(PolygonPath(hull).contains_point((float(point[0]), float(point[1]))))


def _centre(mesh: trimesh.Trimesh, level: float) -> np.ndarray | None:
    """The centre (2,) [m] of the largest loop of ``mesh`` at height ``level`` [m]."""
    loops = slice_loops(mesh, _UP, level)
    return max(loops, key=lambda loop: loop.area).centre if loops else None


def _pins(derived: Derived, pid: str) -> list[str]:
    """The holes whose pegs pass through part ``pid`` (module docstring)."""
    mesh = derived.parts[pid].mesh
    low, high = float(mesh.bounds[0][2]), float(mesh.bounds[1][2])
    holes = []
    for peg, fit in sorted(derived.hole_of.items()):
        bottom, top = (float(z) for z in derived.parts[peg].mesh.bounds[:, 2])
        if min(top, high) - max(bottom, low) <= PROBE:
            continue
        level = (min(top, high) + max(bottom, low)) / 2
        centre = _centre(derived.parts[peg].mesh, level)
        loops = slice_loops(mesh, _UP, level)
        if centre is not None and loops and _in_hull(loops, centre):
            holes.append(fit.id)
    return holes


def _touching(lower: trimesh.Trimesh, upper: trimesh.Trimesh, level: float) -> bool:
    """Whether ``upper``'s bottom face at height ``level`` [m] meets ``lower``'s material
    just under it (on a :data:`GRIP_GRID` grid over ``upper``'s section there)."""
    above, below = slice_loops(upper, _UP, level + PROBE), slice_loops(lower, _UP, level - PROBE)
    if not above or not below:
        return False
    (x0, y0), (x1, y1) = upper.bounds[0][:2], upper.bounds[1][:2]
    xs, ys = np.arange(x0, x1, GRIP_GRID / 2), np.arange(y0, y1, GRIP_GRID / 2)
    points = np.stack(np.meshgrid(xs, ys), axis=-1).reshape(-1, 2)
    return bool(np.any(_in_solid(above, points) & _in_solid(below, points)))


def _grip(mesh: trimesh.Trimesh, origin: np.ndarray) -> tuple[float, float] | None:
    """The grip point (module docstring) relative to ``origin`` [m], None when the top face
    has no point :data:`GRIP_MARGIN` from its edges."""
    loops = slice_loops(mesh, _UP, float(mesh.bounds[1][2]) - PROBE)
    com = np.asarray(mesh.center_mass)[:2]
    if loops and _in_solid(loops, com[None])[0] and _clear(loops, com[None])[0] >= GRIP_MARGIN:
        return float(com[0] - origin[0]), float(com[1] - origin[1])
    (x0, y0), (x1, y1) = mesh.bounds[0][:2] - origin[:2], mesh.bounds[1][:2] - origin[:2]
    xs = np.arange(np.ceil(x0 / GRIP_GRID), np.floor(x1 / GRIP_GRID) + 1) * GRIP_GRID
    ys = np.arange(np.ceil(y0 / GRIP_GRID), np.floor(y1 / GRIP_GRID) + 1) * GRIP_GRID
    points = np.stack(np.meshgrid(xs, ys), axis=-1).reshape(-1, 2) + origin[:2]
    points = points[_in_solid(loops, points)] if loops else points[:0]
    points = points[_clear(loops, points) >= GRIP_MARGIN] if len(points) else points
    if not len(points):
        return None
    best = points[int(np.argmin(np.linalg.norm(points - com, axis=1)))]
    return float(best[0] - origin[0]), float(best[1] - origin[1])


def _largest_peg(derived: Derived, holes: tuple[str, ...]) -> str:
    """The peg of largest section area in ``holes`` (to :data:`SAME_AREA`; ties: the smallest id)."""
    pegs = [(fit.part, fit.section) for fit in derived.holes.values()
            if fit.id in holes and fit.part is not None and fit.section is not None]
    return min(pegs, key=lambda item: (-round(section_area(item[1].kind, item[1].a, item[1].b) / SAME_AREA),
                                       item[0]))[0]


def _nearest_peg(derived: Derived, section: Shape2D) -> str:
    """The peg whose section is nearest ``section`` (same kind first, then size, then id)."""
    pegs = [(pid, fit.occupants[pid]) for pid, fit in derived.hole_of.items() if pid in fit.occupants]
    return min(pegs, key=lambda item: (item[1].kind != section.kind, abs(item[1].a - section.a), item[0]))[0]


def map_parts(derived: Derived, top: float, by_hand: Mapping[str, str]) -> Mapped:
    """The covers and heads of ``derived`` (module docstring), ``top`` [m] the holes'
    entry (the plate top); the parts ``by_hand`` (id -> why) and each other part that is
    neither, and goes onto no pin of ``derived.pins``, are ones the cell places by hand."""
    covers: dict[str, CoverFit] = {}
    heads: dict[str, HeadFit] = {}
    manual = dict(by_hand)
    others = [pid for pid in derived.parts if pid != derived.base and pid not in derived.hole_of
              and pid not in by_hand and pid not in derived.bores]
    for pid in sorted(others, key=lambda p: (float(derived.parts[p].mesh.bounds[0][2]), p)):
        if derived.axis[pid] != "+z":
            manual[pid] = f"part '{pid}' goes in along {opposite(derived.axis[pid])}, not from above"
            continue
        pins = _pins(derived, pid)
        head = None if pins else _head(derived, pid, covers)
        if isinstance(head, str):
            manual[pid] = head
        elif head is not None and any(h.into == head.into for h in heads.values()):
            manual[pid] = f"cover '{head.into}' holds two heads (the cell's covers have one socket)"
        elif head is not None:
            heads[pid] = head
        else:
            cover = _cover(derived, pid, pins, covers, top)
            if isinstance(cover, str):
                manual[pid] = cover
            else:
                covers[pid] = cover
    for hid, head in sorted(heads.items()):  # the sockets are measured with their heads
        found = _socket(derived, covers[head.into], derived.parts[hid].mesh)
        if isinstance(found, str):
            manual[hid] = found
        else:
            covers[head.into] = found
    return Mapped(covers, {hid: head for hid, head in heads.items() if hid not in manual}, manual=manual)



def _head(derived: Derived, pid: str, covers: dict[str, CoverFit]) -> HeadFit | str | None:
    """Part ``pid`` as a head in a blind opening of one of ``covers``, None when it stands
    in none, or why it cannot be the cell's head."""
    mesh = derived.parts[pid].mesh
    bottom, top = (float(z) for z in mesh.bounds[:, 2])
    centre = _centre(mesh, bottom + PROBE)
    if centre is None:
        return None
    for cid in sorted(covers):
        cover = derived.parts[cid].mesh
        low, high = (float(z) for z in cover.bounds[:, 2])
        if not low < bottom < high - PROBE:
            continue
        floor = first_hit(cover, np.array([*centre, bottom + PROBE]), -_UP)
        if floor is None or floor > 2 * PROBE:
            continue
        level = (bottom + min(top, high)) / 2
        own = slice_loops(mesh, _UP, level)
        if len(own) != 1:
            return f"head '{pid}' has {len(own)} loops in the socket of cover '{cid}' (expected one section)"
        section = exact_round(classify(own[0], hole=False), derived.parts[pid].cylinders, _UP, level,
                              STEP_DEFLECTION)
        if section.kind not in ("round", "square"):
            return f"head '{pid}' has a {section.kind} section (the cell's heads are round or square)"
        origin = (float(section.centre[0]), float(section.centre[1]), bottom)
        return HeadFit(pid, cid, section, origin, top - bottom, _nearest_peg(derived, section),
                       head_is_primitive(section, mesh))
    return None


def _cover(derived: Derived, pid: str, pins: list[str], covers: dict[str, CoverFit], top: float) -> CoverFit | str:
    """Part ``pid`` as a cover over ``pins`` (or over the holes of the ``covers`` it rests
    on), measured, or why the cell cannot place it."""
    mesh = derived.parts[pid].mesh
    (x0, y0, low), (x1, y1, high) = (tuple(float(v) for v in corner) for corner in mesh.bounds)
    on = tuple(other for other in [derived.base, *sorted(covers)]
               if _touching(derived.parts[other].mesh, mesh, low))
    if not pins:
        pins = sorted({h for other in on if other in covers for h in covers[other].over})
        if not pins:
            return (f"part '{pid}' is no peg in a hole of the base, no cover (no pin passes through it and it rests "
                    "on no cover) and no head (it stands in no cover's blind opening)")
    if low < top - PROBE:
        return f"cover '{pid}' reaches {1000 * (top - low):.3f} mm below the plate top (the cell's covers lie on it)"
    if not on:
        return (f"cover '{pid}' lies {1000 * (low - top):.3f} mm above the plate top on neither the base nor a cover "
                "(the cell's covers rest on one of them)")
    holes = hole_specs(derived)
    centre = np.mean([holes[h].position for h in pins], axis=0)
    origin = np.array([centre[0], centre[1], low])
    mid = slice_loops(mesh, _UP, (low + high) / 2)
    rooms = [2 * min(edge_distance(loop.points, np.asarray(holes[h].position)) for loop in mid) - holes[h].size
             for h in pins]
    grip = _grip(mesh, origin)
    if grip is None:
        return f"cover '{pid}' has no point {1000 * GRIP_MARGIN:g} mm from the edges of its top face to grip"
    fit = CoverFit(pid, tuple(sorted(pins)), (float(origin[0]), float(origin[1]), low),
                   (x0 - origin[0], y0 - origin[1], x1 - origin[0], y1 - origin[1]), high - low, low - top,
                   min(max(0.0, min(rooms)), 0.02), None, grip, _largest_peg(derived, tuple(pins)), on, False)
    return _with_primitive(derived, fit)


def _socket(derived: Derived, cover: CoverFit, head: trimesh.Trimesh) -> CoverFit | str:
    """``cover`` with the socket its ``head`` stands in (module docstring), or why not."""
    mesh = derived.parts[cover.id].mesh
    bottom, high = float(head.bounds[0][2]), float(mesh.bounds[1][2])
    centre = _centre(head, bottom + PROBE)
    assert centre is not None  # found so when the head was
    around = [loop for loop in slice_loops(mesh, _UP, (bottom + high) / 2) if loop.contains(centre)]
    if not around:  # the head stands in a notch of the outline
        return f"the opening of cover '{cover.id}' a head stands in is open at its side (the cell's socket is a hole)"
    inner = min(around, key=lambda loop: loop.area)
    x, y = inner.centre
    floor = first_hit(mesh, np.array([x, y, high + PROBE]), -_UP)
    assert floor is not None  # the head stands on it
    depth = floor - PROBE
    if abs(high - depth - bottom) > 2 * PROBE:
        return (f"a head stands {1000 * (bottom - high + depth):.3f} mm above the floor of its socket in cover "
                f"'{cover.id}' (the cell puts a head on its socket's floor)")
    socket = (float(x - cover.origin[0]), float(y - cover.origin[1]), 2 * edge_distance(inner.points, inner.centre),
              float(depth))
    return _with_primitive(derived, replace(cover, socket=socket))


def _with_primitive(derived: Derived, fit: CoverFit) -> CoverFit:
    """``fit`` with ``primitive`` decided against the cell's cover of its measures."""
    table = Cover(over=list(fit.over), outline=list(fit.outline), thickness=fit.thickness, mass=1.0, grip=[0.0, 0.0],
                  tray=[0.0, 0.0], skill=fit.skill, clearance=fit.clearance,
                  socket=None if fit.socket is None else list(fit.socket))
    mesh = derived.parts[fit.id].mesh.copy()
    mesh.apply_translation(-np.asarray(fit.origin))
    boxes = cover_spec(fit.id, table, hole_specs(derived)).boxes
    return replace(fit, primitive=len(boxes) <= MAX_COVER_BOXES and cover_is_primitive(mesh, boxes))
