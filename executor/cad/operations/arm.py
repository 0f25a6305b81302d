"""The arm's wrist clear of the product and its reach along horizontal axes: the gripper's
flange long enough that the wrist (:data:`WRIST_RADIUS` about the tool's axis) stays
:data:`WRIST_CLEARANCE` above the product with each part inserted from above at its goal
(:func:`tool_length`); a hole entered sideways (:func:`sideways_refused`) or a pin along a
horizontal axis (:func:`sideways_pin_refused`) the cell takes only inside the boxes where its
arm was measured to reach them (:data:`SIDEWAYS_HOLE_REACH`, :data:`SIDEWAYS_PIN_REACH`) and
where that wrist would not meet the product; the pose of the product on the table that
makes the most of those reaches (:func:`best_pose`). Lengths in metres."""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass

import numpy as np
import trimesh

from executor.cad.convex import NEAR
from executor.cad.derive import Derived, HoleFit, PinFit
from executor.cad.operations.fingers import GRIPPER, bore_grip, finger_grip
from executor.cad.operations.frames import along_axis, entry_point, feature_turn, pin_entry, upright
from executor.cad.operations.precedence import maybe_in_place
from executor.cad.operations.tools import tool_of
from executor.cad.sweep import opposite

WRIST_RADIUS = 0.06
"""[m] the arm's wrist about the tool's axis: pybullet_data's ``kuka_iiwa`` ``lbr_iiwa_link_7``,
52.1 mm in radius, its face where the gripper's flange starts, widened for the part's tilt
in the grasp (a 1 deg tilt moves its rim 1 mm down)."""
WRIST_CLEARANCE = 0.01
"""[m] how far above the product near a part's axis the arm's wrist stays with the part at its goal."""
Region = tuple[tuple[float, float], tuple[float, float], tuple[float, float]]
"""A box of the cell [m]: the spans of x, y (the arm's base at the origin) and height above the floor."""
SIDEWAYS_PIN_REACH: dict[str, tuple[Region, ...]] = {
    "+x": (((0.45, 0.65), (0.0, 0.1), (0.03, 0.03)), ((0.55, 0.65), (0.0, 0.1), (0.03, 0.12))),
    "+y": (((0.45, 0.60), (-0.1, 0.0), (0.03, 0.12)),),
    "-y": (((0.40, 0.65), (0.0, 0.1), (0.03, 0.12)),),
}
"""Where the cell puts a part onto a pin of the base along a horizontal axis: the axes (the
part's motion) and, on each, the boxes in which the pin's free end was measured to be reached,
taught and assembled, at each of their 8 corners (``./run.sh bench reach --kind pin``: the block
and ring of ``tests/cad/test_horizontal_pins.py`` turned about z, raised, and placed with
the free end at each point; docs/cell.md lists every point and where the arm stopped
short). Inside a box the arm is taken to reach it as at its corners; elsewhere, or along
another axis, it is taken as out of reach."""
SIDEWAYS_HOLE_REACH: dict[str, tuple[Region, ...]] = {
    "+x": (((0.50, 0.65), (0.0, 0.1), (0.03, 0.03)), ((0.65, 0.65), (0.0, 0.1), (0.03, 0.12))),
    "+y": (((0.45, 0.60), (-0.1, 0.0), (0.03, 0.12)),),
    "-y": (((0.40, 0.60), (0.0, 0.1), (0.03, 0.12)),),
}
"""Where the cell inserts a peg into a hole of the base entered sideways: the axes (the
peg's motion) and, on each, the boxes in which the hole's entry centre was measured to be
reached, taught and assembled, at each of their 8 corners (``./run.sh bench reach --kind
hole``: ``agh_hex_horizontal`` of ``tests/cad/test_sideways.py`` turned about z, raised
and placed; docs/cell.md). The wrist is 185 mm beyond the entry, farther than on a pin:
the pins' boxes do not carry over. Inside a box the arm is taken to reach it as at its
corners; elsewhere, or along another axis, it is taken as out of reach."""


QUARTERS = (0, 90, 180, 270)
"""The turns about z [deg] a product may be given on the table: the only ones that keep
every axis-aligned feature axis-aligned."""
POSE_MARGIN = 1e-3
"""[m] how far inside a measured reach box :func:`best_pose` keeps each feature it brings
into reach (the boxes' corners are where the reach was measured)."""


@dataclass(frozen=True)
class Reach:
    """One reach the cell's decision about ``part`` rests on: its motion along the
    horizontal ``axis`` to the ``point`` [m] (a pin's free end where ``pin``, else a hole's
    entry) in the cell frame."""

    part: str
    axis: str
    point: tuple[float, float, float]
    pin: bool


_RECORDED: ContextVar[list[Reach] | None] = ContextVar("_RECORDED", default=None)


@contextmanager
def reaches_recorded() -> Iterator[list[Reach]]:
    """Within the block the arm is taken to reach every horizontal insertion, and each one
    asked for is appended to the list yielded (:func:`sideways_pin_refused`,
    :func:`sideways_refused`): what the product's pose decides."""
    found: list[Reach] = []
    token = _RECORDED.set(found)
    try:
        yield found
    finally:
        _RECORDED.reset(token)


def turned_axis(axis: str, turn: int) -> str:
    """The name of ``axis`` (``+x``, ``-y``, ...) turned by ``turn`` [deg, a multiple of 90] about z."""
    names = ["+x", "+y", "-x", "-y"]
    return names[(names.index(axis) + turn // 90) % 4] if axis in names else axis


def turned_xy(x: float, y: float, turn: int) -> tuple[float, float]:
    """The point (x, y) turned by ``turn`` [deg, a multiple of 90] about the origin,
    exactly (a permutation with signs)."""
    for _ in range(turn // 90 % 4):
        x, y = -y, x
    return x + 0.0, y + 0.0


def reached(reach: Reach, turn: int, centre: tuple[float, float], place: tuple[float, float]) -> bool:
    """Whether the arm reaches ``reach`` with the product turned by ``turn`` [deg] about
    the vertical line through ``centre`` [m] (its base's centre) and that centre moved to
    ``place`` [m] (the boxes of :data:`SIDEWAYS_PIN_REACH`, :data:`SIDEWAYS_HOLE_REACH`)."""
    x, y = turned_xy(reach.point[0] - centre[0], reach.point[1] - centre[1], turn)
    regions = SIDEWAYS_PIN_REACH if reach.pin else SIDEWAYS_HOLE_REACH
    return not _box_missed(turned_axis(reach.axis, turn), (x + place[0], y + place[1], reach.point[2]), regions)


def _box_missed(axis: str, point: tuple[float, float, float], regions: Mapping[str, tuple[Region, ...]]) -> bool:
    """Whether ``point`` [m] lies in none of the boxes of ``regions`` along ``axis``."""
    return not any(all(low - 1e-9 <= v <= high + 1e-9 for v, (low, high) in zip(point, box, strict=True))
                   for box in regions.get(axis, ()))


@dataclass(frozen=True)
class Pose:
    """A product's pose on the table: turned ``turn`` [deg] about z about its base's
    centre, that centre at ``place`` [m]; ``steps``: the parts the cell inserts so."""

    turn: int
    place: tuple[float, float]
    steps: int


def best_pose(reaches: list[Reach], inserted: set[str], centre: tuple[float, float],
              fixed: tuple[int | None, tuple[float, float] | None], allowed: Callable[[tuple[float, float]], bool]
              ) -> Pose:
    """The pose (:class:`Pose`) under which the cell inserts the most of the parts
    ``inserted`` (those it inserts where the arm reaches everything), each one counted
    where it reaches every one of its ``reaches`` (:func:`reached`), the base's centre
    now at ``centre`` [m]: a turn of :data:`QUARTERS` and a place where ``allowed`` (the
    user's place wherever it is); ties go to the product as it stands (turn 0, at
    ``centre``), then the fewest quarter turns, then the smallest move. ``fixed`` holds
    the turn and the place the user set (None: free). A place that brings a feature into
    a box keeps it :data:`POSE_MARGIN` inside, rounded to 0.1 mm."""
    turn_set, place_set = fixed
    by_part: dict[str, list[Reach]] = {}
    for reach in reaches:
        by_part.setdefault(reach.part, []).append(reach)

    def steps(turn: int, place: tuple[float, float]) -> int:
        return sum(all(reached(r, turn, centre, place) for r in by_part.get(pid, [])) for pid in inserted)

    poses = [Pose(turn_set or 0, place_set or centre, steps(turn_set or 0, place_set or centre))]
    for turn in QUARTERS if turn_set is None else (turn_set,):
        xs, ys = {centre[0]}, {centre[1]}
        for reach in reaches:
            x, y = turned_xy(reach.point[0] - centre[0], reach.point[1] - centre[1], turn)
            regions = SIDEWAYS_PIN_REACH if reach.pin else SIDEWAYS_HOLE_REACH
            for (x0, x1), (y0, y1), _ in regions.get(turned_axis(reach.axis, turn), ()):
                xs |= {x0 + POSE_MARGIN - x, x1 - POSE_MARGIN - x}
                ys |= {y0 + POSE_MARGIN - y, y1 - POSE_MARGIN - y}
        places = [place_set] if place_set is not None else [
            place for place in ((round(x, 4) + 0.0, round(y, 4) + 0.0) for x in sorted(xs) for y in sorted(ys))
            if allowed(place)]
        poses += [Pose(turn, place, steps(turn, place)) for place in places]
    return min(poses, key=lambda pose: (-pose.steps, min(pose.turn, 360 - pose.turn),
                                        math.dist(pose.place, place_set or centre), pose.turn, pose.place))


def _highest_near(mesh: trimesh.Trimesh, xy: tuple[float, float], radius: float, inner: float = 0.0) -> float | None:
    """The highest point [m] of ``mesh`` within ``radius`` [m] of the vertical line through
    ``xy`` [m] (within the 32-gon prism circumscribing that circle) and outside the 32-gon
    prism circumscribing the circle of radius ``inner`` [m] about it (0: none), None where it
    has none."""
    turns = np.arange(32) * 2 * math.pi / 32
    out = np.c_[np.cos(turns), np.sin(turns), np.zeros(32)]
    centre = np.array([xy[0], xy[1], 0.0])
    inside = trimesh.intersections.slice_mesh_plane(mesh, -out, out * radius / math.cos(math.pi / 32) + centre)
    if not len(inside.faces) or inner <= 0:
        return float(inside.bounds[1][2]) if len(inside.faces) else None
    # outside a convex prism: the union of the half-spaces beyond its sides
    beyond = [trimesh.intersections.slice_mesh_plane(inside, side, side * inner + centre) for side in out]
    return max((float(piece.bounds[1][2]) for piece in beyond if len(piece.faces)), default=None)


def tool_length(derived: Derived) -> tuple[float | None, str]:
    """The length [m] of the gripper's flange that keeps the arm's wrist (:data:`WRIST_RADIUS`
    about the tool's axis, at the flange's top) :data:`WRIST_CLEARANCE` above every part that
    may be in place (any but those the geometric precedence puts after it, and but a base with
    pins: :func:`executor.world.scene.wrist_clear_of`) within that radius
    of the axis of each part the cell inserts from above, held :data:`GRIPPER`'s grasp depth
    deep (a part with a bore: :func:`bore_grip`; a peg standing out less: :func:`finger_grip`;
    a part on the suction cup by its top: :func:`tool_of`) at its goal (a peg standing on its
    hole's bottom, a part with a bore where the CAD has it), rounded up to the millimetre;
    None where :data:`GRIPPER`'s keeps it clear, with why (the part, the part below the
    wrist and how high it stands) otherwise. A part the wrist meets stops short of its goal
    (a bolt beside a bracket's 80 mm wall stopped 4.1 mm above it)."""
    grips = {pid: (fit.position, fit.entry - fit.depth + float(upright(derived, fit).extents[2])
                   - (0.0 if tool_of(derived, fit)[0] == "suction" else finger_grip(derived, pid, fit)[0]))  # cup: top
             for pid, fit in derived.hole_of.items() if fit.axis == "+z" and fit.part == pid}
    for pin in derived.pins.values():
        for pid in (p for p in pin.parts if p in derived.bores and pin.axis == "+z"):
            grips[pid] = (pin.position, float(derived.parts[pid].mesh.bounds[1, 2]) - bore_grip(derived, pid, pin))
    need, why = GRIPPER["flange_length"], ""
    clear = {derived.base} if derived.pins else set()  # the cell's wrist does not collide with a base with pins
    for pid, (xy, grip) in sorted(grips.items()):
        for other in sorted(maybe_in_place(derived, pid) - clear):
            top = _highest_near(derived.parts[other].mesh, xy, WRIST_RADIUS)
            if top is not None and top - grip + WRIST_CLEARANCE > need + 1e-9:
                need = top - grip + WRIST_CLEARANCE
                why = (f"the gripper's flange {{flange:.3f}} m long, not {GRIPPER['flange_length']:g}: with '{pid}' at "
                       f"its goal the arm's wrist ({1e3 * WRIST_RADIUS:g} mm about the tool's axis) stays "
                       f"{1e3 * WRIST_CLEARANCE:g} mm above '{other}' (up to {1e3 * top:.3f} mm within "
                       f"{1e3 * WRIST_RADIUS:g} mm of that axis)")
    if not why:
        return None, ""
    flange = math.ceil(round(need * 1e3, 6)) / 1e3
    return flange, why.format(flange=flange)


def _unreached(axis: str, end: tuple[float, float, float], regions: Mapping[str, tuple[Region, ...]],
               what: str, part: str) -> str:
    """Why the cell's arm may not reach ``what`` (a horizontal pin, its free end at ``end``
    [m]; a hole entered sideways, its entry there) along the horizontal ``axis`` (the part's
    motion, ``part``'s): "" inside a box in which it was measured to (``regions``:
    :data:`SIDEWAYS_PIN_REACH`, :data:`SIDEWAYS_HOLE_REACH`), and anywhere while the
    reaches are recorded (:func:`reaches_recorded`)."""
    if (recorded := _RECORDED.get()) is not None:
        recorded.append(Reach(part, axis, end, what.endswith("pin")))
        return ""
    if axis not in regions:
        return f"the cell's arm was measured to reach {what} along {', '.join(regions)} only"
    if not _box_missed(axis, end, regions):
        return ""
    where = "its free end" if what.endswith("pin") else "its entry"
    at = ", ".join(f"{round(1e3 * v, 1) + 0.0:.1f}" for v in end)  # + 0.0: no "-0.0"
    boxes = "; ".join(" ".join(f"{name} {_span(low, high)}" for name, (low, high) in zip("xyz", box, strict=True))
                      for box in regions[axis])
    return f"{where} at ({at}) mm, out of the reach measured along {axis} ({boxes} mm)"


def _span(low: float, high: float) -> str:
    """A span [m] in mm: "450-650", or "30" where it is one value."""
    low_mm, high_mm = round(1e3 * low, 1) + 0.0, round(1e3 * high, 1) + 0.0
    return f"{low_mm:g}" if low_mm == high_mm else f"{low_mm:g}-{high_mm:g}"


def sideways_pin_refused(derived: Derived, pin: PinFit, pid: str) -> str:
    """Why the cell does not put part ``pid`` onto ``pin`` along a horizontal axis ("" where
    it does, or where the pin is along z): the arm not measured to reach its free end along
    its axis (:func:`_unreached`, :data:`SIDEWAYS_PIN_REACH`), or its wrist meeting the
    product with the part at its goal (:func:`_wrist_on_pin`)."""
    if pin.axis != "+z" and (why := _unreached(opposite(pin.axis), pin_entry(derived, pin), SIDEWAYS_PIN_REACH,
                                               "a horizontal pin", pid)):
        return f"goes onto a pin ({pin.id}) along {opposite(pin.axis)}: {why}"
    if pin.axis != "+z" and (why := _wrist_on_pin(derived, pin, pid)):
        return f"goes onto a pin ({pin.id}) along {opposite(pin.axis)}, but {why}"
    return ""


def _wrist_on_pin(derived: Derived, pin: PinFit, pid: str) -> str:
    """Why the arm's wrist would meet the product with part ``pid`` at its goal on ``pin``
    along a horizontal axis ("" where it would not): :func:`_wrist_meets` about the pin's
    axis, the base outside the pin itself (its section's half diagonal about the axis, the
    gripper's fingers beside it)."""
    centre = (float(pin.section.centre[0]), float(pin.section.centre[1]))
    return _wrist_meets(derived, pin, pid, centre, {pin.owner: math.hypot(pin.section.a, pin.section.b) / 2 + NEAR},
                        bore_grip(derived, pid, pin))


def _wrist_meets(derived: Derived, fit: HoleFit | PinFit, pid: str, centre: tuple[float, float],
                 inner: Mapping[str, float], held: float | None = None) -> str:
    """Why the arm's wrist would meet the product with part ``pid`` at its goal along the
    horizontal axis of ``fit`` (a pin, a hole entered sideways) ("" where it would not):
    :func:`tool_length`'s rule in its frame (:func:`feature_turn`: z out along the axis), the axis
    through ``centre`` [m] (x, y in that frame). The part is held ``held`` [m] deep from its
    outer end (None: :data:`GRIPPER`'s grasp depth, at most half its length), the wrist (:data:`WRIST_RADIUS`
    about the tool's axis) starts the default flange beyond, and every part that may be in
    place (any but those the geometric precedence puts after ``pid``) must end
    :data:`WRIST_CLEARANCE` short of it within that radius of the axis, a part in ``inner``
    only outside that radius [m] of it. Any longer flange the product gets keeps this: the
    wrist only moves farther out along the axis."""
    turn = feature_turn(fit)
    along = along_axis(derived.parts[pid].mesh, fit)[:, 2]
    low, high = float(along.min()), float(along.max())
    grip = high - (min(GRIPPER["grasp_depth"], (high - low) / 2) if held is None else held)
    for other in sorted(maybe_in_place(derived, pid)):
        mesh = derived.parts[other].mesh.copy().apply_transform(turn)
        top = _highest_near(mesh, centre, WRIST_RADIUS, inner.get(other, 0.0))
        if top is not None and top - grip + WRIST_CLEARANCE > GRIPPER["flange_length"] + 1e-9:
            return (f"the arm's wrist ({1e3 * WRIST_RADIUS:g} mm about the tool's axis, "
                    f"{1e3 * GRIPPER['flange_length']:g} mm out from the grip) would meet '{other}', "
                    f"{1e3 * (top - grip):.3f} mm out from the grip within {1e3 * WRIST_RADIUS:g} mm of the axis")
    return ""


def sideways_refused(derived: Derived, hid: str, fit: HoleFit) -> str:
    """Why the cell does not insert the peg of ``fit``, a hole entered sideways ("" where it
    does): the arm not measured to reach its entry along its axis (:func:`_unreached`), or
    its wrist meeting the product with the peg at its goal (:func:`_wrist_meets`, the base
    counted whole: nothing of it stands out of the entry)."""
    assert fit.part is not None
    axis = opposite(fit.axis)
    if why := _unreached(axis, entry_point(fit), SIDEWAYS_HOLE_REACH, "a hole entered sideways",
                          fit.part):
        return f"goes into hole {hid} along {axis}: {why}"
    centre = (float(fit.hole.centre[0]), float(fit.hole.centre[1]))
    if why := _wrist_meets(derived, fit, fit.part, centre, {}):
        return f"goes into hole {hid} along {axis}, but {why}"
    return ""
