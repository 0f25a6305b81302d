"""What the simulated cell does with each part of an imported product, and why it places a part by hand.

Input: a product derived from its CAD (:class:`executor.cad.derive.Derived`: parts, holes,
pins, bores, axes, geometric precedence). Output: :func:`cell_view`, the product as the cell
inserts it (the holes it inserts pegs into, the pins it puts parts onto, the bores it keeps)
and, for every other moving part, the reason it is placed by hand (``[manual.<id>]``); with
the rules it applies: the reach measured along horizontal axes (:data:`SIDEWAYS_PIN_REACH`,
:data:`SIDEWAYS_HOLE_REACH`), the arm's wrist clear of the product (:data:`WRIST_RADIUS`,
:data:`WRIST_CLEARANCE`, :func:`tool_length`), parts stacked on a pin
(:data:`STACK_TOLERANCE`), a bore's room the cell resolves (:data:`BORE_LOSS`), a round
bore whose room on a pin it does not resolve widened (:func:`widens_bore`), a round peg
whose room in a hole of a base that is its own mesh it does not resolve narrowed
(:func:`narrows_peg`), a polygon
peg's prism. Also the figures both this and the product's files need: each peg's room in
each hole and each bore's on each pin (:func:`margins`, nominal zero-clearance fits:
:func:`nominal_fits`), the frames of holes, pins and bores, the plate's level
(:func:`plate_level`) and the simulated gripper (:data:`GRIPPER`). Lengths in metres.
:mod:`executor.cad.write` writes the product's files from these (it imports this module, never the
other way).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import replace

import networkx as nx
import numpy as np
import shapely
import trimesh
from scipy.spatial.transform import Rotation

from bridge.product.nominal import NOMINAL_FIT_ROOM
from executor import ExecutorError
from executor.cad.convex import (
    NEAR,
    Pieces,
    as_written,
    base_is_primitive,
    peg_frame,
    peg_is_primitive,
    pin_pieces,
)
from executor.cad.covers import hole_specs, map_parts
from executor.cad.derive import Derived, HoleFit, PinFit
from executor.cad.fits.faces import Slide
from executor.cad.sections import Shape2D, section, section_room, zero_clearance
from executor.cad.sweep import opposite
from executor.world import SIZE_RESOLUTION
from executor.world.frames import hole_rotation
from executor.world.geometry import Section, seated_pose, thin_prism
from executor.world.meshes import MIN_THICKNESS
from executor.world.polygon_fit import OutlineError
from executor.world.rings import NoStack, ring_pieces

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
FLAT_TOLERANCE = 1e-5
"""[m] how far from the plane of a part's top (its highest point along its way out) a
face's vertices may lie, and still seal the cup (a face tilted by more than its size
entails misses it)."""
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


LEVEL = 1e-5
"""A hole whose entry or depth differs by more than this from the plate's [m] states its own."""
MAX_PLATE_DEPTH = 0.2
"""The largest ``tile_thickness`` and ``base_thickness`` of a ``[plate]`` [m]."""


def section_kind(fit: HoleFit | None) -> str | None:
    return None if fit is None or fit.section is None else fit.section.kind


def feature_turn(fit: HoleFit | PinFit) -> np.ndarray:
    """The 4 × 4 rotation from the cell frame to the frame of ``fit``'s hole or pin (z out
    of it, x and y its slice axes: :func:`executor.world.frames.hole_rotation`); the
    identity along z (a hole entered from above or below, a pin parts go down or up onto:
    the slice's axes are the cell's x and y)."""
    turn = np.eye(4)
    if fit.axis in ("+z", "-z"):
        return turn
    turn[:3, :3] = hole_rotation(opposite(fit.axis)).T
    return turn


def upright(derived: Derived, fit: HoleFit) -> trimesh.Trimesh:
    """The mesh of the peg in ``fit`` in its hole's frame (:func:`feature_turn`): its axis along z."""
    assert fit.part is not None
    mesh = derived.parts[fit.part].mesh
    return mesh if fit.axis == "+z" else mesh.copy().apply_transform(feature_turn(fit))


def entry_point(fit: HoleFit) -> tuple[float, float, float]:
    """The centre of a hole's entry in the cell frame [m] (x, y its position, z its ``top_z``;
    ``entry`` is measured along the removal direction: a hole entered from below, removal
    -z, has its entry at z = -``entry``)."""
    if fit.axis in ("+z", "-z"):  # the slice's axes are the cell's x and y (sections.frame_of)
        return fit.centre[0], fit.centre[1], fit.entry if fit.axis == "+z" else -fit.entry
    x, y, z = hole_rotation(opposite(fit.axis)) @ np.array([*fit.hole.centre, fit.entry])
    return float(x), float(y), float(z)


def section_pairs(derived: Derived) -> dict[str, dict[str, tuple[Shape2D, Shape2D]]]:
    """Peg (a part in a hole of the base or of a moving part) -> hole -> the measured
    sections of the peg and the hole, and part with a bore -> pin -> those of the pin and
    the bore (the pin goes into the bore); for a pair the sweep admits, those at its levels
    of least room (:func:`executor.cad.derive.swept_fits`)."""
    holes = {**derived.holes, **derived.part_holes}
    pairs = {pid: {hid: (fit.occupants[pid], hole.hole) for hid, hole in holes.items()}
             for pid, fit in sorted(derived.in_holes.items()) if pid in fit.occupants}
    for pid in sorted(derived.bores):
        pairs.setdefault(pid, {}).update({pin_id: (pin.section, derived.bore_on(pid, pin_id))
                                          for pin_id, pin in derived.pins.items()})
    for (pid, hid), (peg, hole, _) in derived.swept.items():
        if hid in pairs.get(pid, {}):  # the cell's view leaves out the parts it places by hand
            pairs[pid][hid] = (peg, hole)
    return pairs


def nominal_fits(derived: Derived) -> dict[tuple[str, str], float]:
    """(peg, hole) -> how far apart [m] the vertex circles' radii of each nominal
    zero-clearance fit are (:func:`executor.cad.sections.zero_clearance`: a round peg at
    least as wide as a round hole's inscribed circle, their vertex circles' radii within
    10 µm); a part with a bore and a pin too; a screwed pair (:func:`screwed_fits`) at 0."""
    rooms = _rooms(derived)
    found = {(pid, hid): zero_clearance(peg, hole, rooms[pid][hid])
             for pid, holes in section_pairs(derived).items() for hid, (peg, hole) in holes.items()}
    found |= {(pid, hid): 0.0 for pid, hid in screwed_fits(derived) if (pid, hid) in found}
    return {pair: apart for pair, apart in found.items() if apart is not None}


def screwed_fits(derived: Derived) -> dict[tuple[str, str], Slide]:
    """(part, feature) -> the screwed pair (:meth:`Derived.screwed`) of each part in a hole
    or on a pin of the part it is screwed with (a thread): a fit at room 0, by screwing."""
    owners = {hid: fit.owner or derived.base for hid, fit in {**derived.holes, **derived.part_holes}.items()}
    owners |= {pin_id: pin.owner for pin_id, pin in derived.pins.items()}
    found = {(pid, hid): derived.screwed(pid, owners[hid]) for pid, hid in derived.swept if hid in owners}
    return {pair: slide for pair, slide in found.items() if slide is not None}


def margins(derived: Derived) -> dict[str, dict[str, float]]:
    """Peg -> hole -> the room [m] of the peg's nominal section in the hole's, and part
    with a bore -> pin -> the room of the pin's section in the bore's
    (:func:`executor.cad.sections.section_room`: the outlines' room for straight-sided
    pairs, the polygon relation for polygon sections; negative: it does not pass; 0 for a nominal zero-clearance fit,
    :func:`nominal_fits`); ExecutorError naming the part, hole, pin or bore whose polygon
    section is no simple outline."""
    nominal = nominal_fits(derived)
    return {pid: {hid: 0.0 if (pid, hid) in nominal else room for hid, room in holes.items()}
            for pid, holes in _rooms(derived).items()}


def _rooms(derived: Derived) -> dict[str, dict[str, float]]:
    """Peg -> hole -> the room [m] of its measured section in the hole's, and part with a
    bore -> pin -> that of the pin in the bore (:func:`executor.cad.sections.section_room`;
    negative: it does not pass), or the least room of the sweep where it admits the pair
    (:func:`executor.cad.derive.swept_fits`); ExecutorError naming the part, hole, pin or
    bore whose polygon section is no simple outline. Each measured section is made the
    cell's section once (a polygon's outline of 1500 corners, rounded, against every hole)."""
    made: dict[tuple[int, str], Section] = {}

    def cell(name: str, shape: Shape2D) -> Section:
        if (id(shape), name) not in made:
            made[(id(shape), name)] = section(name, shape)
        return made[(id(shape), name)]

    try:
        return {pid: {hid: derived.swept[(pid, hid)][2] if (pid, hid) in derived.swept else
                      section_room(peg, hole, f"pin {hid}" if hid in derived.pins else f"part {pid}",
                                   f"bore of {pid}" if hid in derived.pins else f"hole {hid}",
                                   make=cell).margin
                      for hid, (peg, hole) in holes.items()}
                for pid, holes in section_pairs(derived).items()}
    except OutlineError as exc:  # a slice of a mesh that crosses itself
        raise ExecutorError(f"{exc} (the mesh's slice at the hole's mid-depth)") from None


def order(derived: Derived) -> nx.DiGraph:
    """The geometric precedence as a graph: every part a node, each derived pair an edge."""
    graph = nx.DiGraph()
    graph.add_nodes_from(derived.parts)
    graph.add_edges_from(derived.edges)
    return graph


def _maybe_in_place(derived: Derived, pid: str) -> set[str]:
    """The parts that may be in place when part ``pid`` goes to its goal: all but ``pid``
    and those the geometric precedence puts after it."""
    return set(derived.parts) - nx.descendants(order(derived), pid) - {pid}


def _leaving_first(derived: Derived) -> dict[str, Slide]:
    """Part -> the screwed pair (a thread, :func:`executor.cad.fits.threads.screwed_pairs`) or
    press fit (:func:`executor.cad.fits.faces.press_fits`) of which it is the part that
    leaves first in the disassembly (both where they leave at one stage; never the base)."""
    stage = {pid: k for k, parts in enumerate(derived.stages) for pid in parts}
    found: dict[str, Slide] = {}
    for slide in (s for s in derived.slides if s.pitch or s.interference):
        pair = [pid for pid in (slide.shaft, slide.bore) if pid in stage]
        first = min((stage[pid] for pid in pair), default=None)
        for pid in (pid for pid in pair if stage[pid] == first):
            found.setdefault(pid, slide)
    return found


def screwed(derived: Derived) -> dict[str, str]:
    """Part -> why it is placed by hand, for the parts of screwed pairs and press fits that
    leave first (:func:`_leaving_first`): the cell has no screwing operation, nor a pressing one."""
    found: dict[str, str] = {}
    for pid, slide in _leaving_first(derived).items():
        other = slide.bore if pid == slide.shaft else slide.shaft
        way = f"{'into' if pid == slide.shaft else 'onto'} '{other}' along {opposite(derived.axis[pid])}"
        found[pid] = (f"part '{pid}' is pressed {way} (a press fit, {1000 * slide.interference:.3f} mm per side): "
                      "the cell has no pressing operation" if slide.interference else
                      f"part '{pid}' is screwed {way} ({slide.thread}, pitch {1000 * slide.pitch:.3f} mm): "
                      "the cell has no screwing operation")
    return found


def pressed(derived: Derived) -> set[str]:
    """The parts placed by hand for a press fit (:func:`screwed`): pressed in, no fit as the cell slides parts."""
    return {pid for pid, slide in _leaving_first(derived).items() if slide.interference}


def cell_view(derived: Derived, refused: Mapping[str, str] | None = None) -> tuple[Derived, dict[str, str]]:
    """The product as the cell inserts it: only the holes entered from above or sideways
    holding, if anything, a peg going in along the hole's axis that is no polygon section,
    or the prism of its polygon (the cell builds that from its outline, exactly), longer than the gripper's
    grasp depth (the cell holds it by that much), with room in it the cell resolves or a
    nominal zero-clearance fit the cell widens (:func:`_unresolved_in_hole`); the pins of the base that
    parts go down onto, and the pins standing up on parts the cell places by hand
    (:func:`executor.cad.covers.map_parts`) or on pegs it inserts down into holes of the
    base (:func:`_owner_refused`) that parts go down onto, and of the parts with
    a bore those it puts onto them (:func:`_onto_pin`); the pegs of the other holes and
    the other parts going onto pins, each with why the cell places it by hand (a polygon
    peg's room is often below what convex pieces of its mesh keep), those ``refused``
    (part -> why) too."""
    kept: dict[str, HoleFit] = {}
    screws = screwed(derived)
    by_hand: dict[str, str] = screws | dict(refused or {})
    for pin in sorted(derived.pins.values(), key=lambda p: p.owner == derived.base):  # the cheap reasons first
        for pid in pin.parts:
            if pid not in by_hand and (why := _onto_pin(derived, pin, pid)) is not None:
                by_hand[pid] = why
    for hid, fit in derived.holes.items():
        if fit.part in screws or fit.part in (refused or {}):
            continue
        if fit.part is not None and derived.axis[fit.part] != fit.axis:
            by_hand[fit.part] = (f"part '{fit.part}' goes in along {opposite(derived.axis[fit.part])}, its hole {hid} "
                                 f"is entered along {opposite(fit.axis)}")
        elif fit.axis == "-z":
            if fit.part is not None:
                by_hand[fit.part] = f"goes into hole {hid} along +z, from below"
        elif fit.part is not None and fit.axis != "+z" and (why := _sideways_refused(derived, hid, fit)):
            by_hand[fit.part] = why
        elif fit.part is not None and section_kind(fit) == "polygon" and _polygon_refused(fit, derived):
            by_hand[fit.part] = _polygon_refused(fit, derived)
        elif fit.part is not None and tool_of(derived, fit)[0] == "":
            by_hand[fit.part] = tool_of(derived, fit)[1]
        else:
            kept[hid] = fit
    # The pins the cell puts parts onto: none empty (no goal on it), the base's unless
    # entered from below, another part's standing up; a further pin of a part the cell puts
    # onto its first pin goes with that part.
    pins = {pin_id: pin for pin_id, pin in derived.pins.items()
            if pin.parts and (pin.axis != "-z" if pin.owner == derived.base else pin.axis == "+z")
            and not any((pid, pin_id) in derived.further_bores and pid not in by_hand for pid in pin.parts)}
    # A hole whose part goes by hand leaves the cell, which may make the base its own mesh,
    # where the cell widens no zero-clearance fit: until no more parts go.
    while unresolved := _unresolved_in_hole(derived, replace(derived, holes=kept, pins=pins)):
        by_hand |= unresolved
        kept = {hid: fit for hid, fit in kept.items() if fit.part not in unresolved}
    view = replace(derived, holes=kept, pins=pins,
                   bores={pid: bore for pid, bore in derived.bores.items() if pid not in by_hand})
    owned = [pin for pin in pins.values() if pin.owner != derived.base]
    several = {pid: [derived.pins[pin_id] for part, pin_id in sorted(derived.further_bores) if part == pid]
               for pid in view.bores}
    several = {pid: [derived.pin_of(pid), *further] for pid, further in several.items() if further}
    if not owned and not any(pin.owner != derived.base for on in several.values() for pin in on):
        return view, by_hand
    placed = map_parts(view, plate_top(view), by_hand).manual  # the owners the cell leaves where they are
    inserted = {fit.part: fit for fit in kept.values() if fit.part is not None and fit.axis == "+z"}
    moved = {pid: f"goes onto a pin of '{pin.owner}' ({pin.id}), {why}" for pin in owned if pin.owner not in placed
             if (why := _owner_refused(derived, pin, inserted.get(pin.owner))) for pid in pin.parts
             if pid not in by_hand}
    moved |= {pid: (f"goes onto {len(on)} pins ({', '.join(pin.id for pin in on)}), of '{pin.owner}', which the "
                    "cell moves: it puts a part onto several pins of the base and of parts placed by hand only")
              for pid, on in several.items() for pin in on if pin.owner not in (derived.base, *placed)}
    if moved:
        return cell_view(derived, by_hand | moved)
    return replace(view, pins={pin_id: pin for pin_id, pin in pins.items()
                               if pin.owner in (derived.base, *placed, *inserted)}), by_hand


def _owner_refused(derived: Derived, pin: PinFit, fit: HoleFit | None) -> str:
    """Why the cell does not put parts onto ``pin`` (standing up) of a part it moves ("" where
    it does): its owner must be a peg it inserts down into a hole of the base (``fit``),
    of no polygon section, so that the cell takes the pin's place from where that peg ends
    (:meth:`executor.assembly.world.AssemblyWorld.on_owner`: its pose with the peg at its
    goal, :func:`executor.world.geometry.seated_pose`, is the CAD's within
    :data:`STACK_TOLERANCE`, the peg drawn on its hole's bottom, centred, turned as the cell
    inserts it)."""
    if fit is None:
        return ("which the cell moves: it puts parts onto pins of the base, of parts placed by hand and of pegs it "
                "inserts down into holes of the base only")
    assert fit.section is not None  # a hole's part has its section
    if "polygon" in (fit.section.kind, fit.hole.kind):
        return (f"a peg the cell inserts into hole {fit.id}, of a polygon section: the cell takes the place of a pin "
                "on a peg of a round, square or rect section only")
    seated, turn = seated_pose(Section(pin.owner, fit.section.kind, fit.section.a), hole_specs(derived)[fit.id])
    at_goal = np.eye(4)
    at_goal[:3, :3], at_goal[:3, 3] = Rotation.from_quat(turn).as_matrix(), seated
    mesh = derived.parts[pin.owner].mesh
    off = at_goal @ peg_frame(fit.section, mesh) @ np.array([*pin.centre, 1.0]) - np.array([*pin.centre, 1.0])
    if (apart := float(np.linalg.norm(off[:3]))) > STACK_TOLERANCE:
        return (f"a peg the cell inserts into hole {fit.id}: at its goal there (centred, on the bottom) its pin is "
                f"{1e3 * apart:.3f} mm from the CAD's (at most {1e3 * STACK_TOLERANCE:g} mm)")
    return ""


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
        grip, why = finger_grip(derived, fit)
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


def finger_assumption() -> str:
    """The finger model, as the import states it among its assumptions."""
    return (f"the fingers hold a peg over its top {1e3 * GRIPPER['grasp_depth']:g} mm, less where it stands out of "
            f"the product less at its goal (its top above the base and every part the geometric precedence puts "
            f"before it, where the fingers are: "
            f"two {1e3 * FINGER_THICKNESS:g} x {1e3 * FINGER_WIDTH:g} mm beside its outline, turned about its axis "
            f"where it stands out most) less {1e3 * GRIP_CLEARANCE:g} mm, over "
            f"{1e3 * MIN_GRIP:g} mm at least; a peg standing out less goes on the suction cup or by hand")


def finger_grip(derived: Derived, fit: HoleFit) -> tuple[float, str]:
    """How deep [m] the fingers hold the peg of ``fit`` (longer than :data:`GRIPPER`'s
    grasp depth) and why where not that deep: the grasp depth, or what the peg stands out
    at its goal of the parts in place whenever it goes there (:func:`standing_out`, the
    base and those the geometric precedence puts before it; others the precedence admits
    before it: :func:`finger_orders`) less :data:`GRIP_CLEARANCE` where
    that is less, rounded down to 0.1 mm; 0 where that is under :data:`MIN_GRIP` (the
    fingers would meet the product before the peg reaches its goal)."""
    assert fit.part is not None
    return _grip(*standing_out(derived, fit.part, fit, _in_place_before(derived, fit.part)))


def _grip(out: float, under: str) -> tuple[float, str]:
    """:func:`finger_grip`'s rule for a part standing ``out`` [m] of ``under`` ("": of nothing)."""
    depth, need = GRIPPER["grasp_depth"], MIN_GRIP + GRIP_CLEARANCE
    if out - GRIP_CLEARANCE >= depth:
        return depth, ""
    where = f"stands out of the product by {1e3 * out:.3f} mm at its goal" + (
        f" ('{under}' where the fingers are)" if under else "")
    if out < need - 1e-9:
        return 0.0, f"{where}, less than the {1e3 * need:g} mm the fingers need"
    return math.floor(round((out - GRIP_CLEARANCE) * 1e4, 6)) / 1e4, f": it {where}, less {1e3 * GRIP_CLEARANCE:g} mm"


def _in_place_before(derived: Derived, pid: str) -> set[str]:
    """The parts in place whenever part ``pid`` goes to its goal: the base and those the
    geometric precedence puts before it."""
    return (nx.ancestors(order(derived), pid) | {derived.base}) - {pid}


def finger_orders(cell: Derived) -> list[tuple[str, str, float, float]]:
    """The orders the fingers' grip (:func:`finger_grip`) needs, as (peg, part, grip [m],
    out [m]): each peg the cell inserts with the fingers goes in before each part the
    geometric precedence merely lets be in place before it (:func:`_maybe_in_place`, not
    the base nor those it puts before it) that would leave it standing out ``out``, too
    little for its ``grip`` (Cranfield's pegs: 5 mm out of the front plate, 25 mm out of
    the base plate). The parts are taken in id order, each one left free to be in place
    only while the peg, with it and those left free before it, keeps its grip; so every
    part left free, all together in place, leaves the grip as it is. The plans honour
    these orders (``cell_order.lp``, :func:`executor.cad.write.cell_order_text`)."""
    found = []
    for pid, fit in sorted(cell.hole_of.items()):
        if fit.axis == "-z" or tool_of(cell, fit)[0] != "fingers":
            continue
        grip = finger_grip(cell, fit)[0]
        free = _in_place_before(cell, pid)
        if _grip(*standing_out(cell, pid, fit, _maybe_in_place(cell, pid)))[0] >= grip:
            continue
        for other in sorted(_maybe_in_place(cell, pid) - free):
            out, _ = standing_out(cell, pid, fit, free | {other})
            if _grip(out, other)[0] < grip:
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
        fingers = shapely.union_all(pads).buffer(-FINGER_TOUCH)  # a face they touch is not in their way
        under, other_top = "", low
        for other, corners in triangles.items():
            top = _highest_in(corners, fingers, other_top)
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


def builds_plate(cell: Derived) -> bool:
    """Whether the simulated cell builds the base of the product as it inserts it
    (:func:`cell_view`) as ``[plate]`` primitives, its holes from their sections: it has
    holes, all entered from above, no pins, and is its bounding box less them
    (:func:`executor.cad.convex.base_is_primitive`); else the base is its own mesh."""
    return (bool(cell.holes) and not cell.pins and all(fit.axis == "+z" for fit in cell.holes.values())
            and base_is_primitive(cell))


def _unresolved(room: float) -> str:
    """Why the cell cannot tell a (diametral) ``room`` [m] from its sign: ``with ... mm of room
    per side, less than`` :data:`executor.world.SIZE_RESOLUTION`; "" where it can."""
    if abs(room) / 2 >= SIZE_RESOLUTION:
        return ""
    return f"with {room * 500:+.4f} mm of room per side, less than the {SIZE_RESOLUTION * 1e3:g} mm the simulated " \
           "cell resolves"


def _unresolved_in_hole(derived: Derived, cell: Derived) -> dict[str, str]:
    """Each part in a hole of ``cell`` (``derived`` as the cell inserts it, so far) whose room
    in it (:func:`margins`) is under the cell's resolution (a nominal zero-clearance fit too)
    and that the cell resolves neither by widening the hole (a nominal zero-clearance fit
    in a base it builds of primitives, :func:`builds_plate`: ``occt_as1``'s bolts) nor by
    narrowing the peg (:func:`_peg_unresolved`), with why the cell places it by hand: it
    would jam there."""
    rooms, nominal, plate = margins(derived), nominal_fits(derived), builds_plate(cell)
    found: dict[str, str] = {}
    for hid, fit in cell.holes.items():
        if fit.part is None or not (why := _unresolved(rooms[fit.part][hid])) or (plate and (fit.part, hid) in nominal):
            continue
        if plate or (why := _peg_unresolved(derived, cell, fit.part, hid)):
            found[fit.part] = f"goes into hole {hid} {why}"
    return found


def _peg_unresolved(derived: Derived, cell: Derived, pid: str, hid: str) -> str:
    """Why the cell cannot tell peg ``pid``'s room in hole ``hid`` of a base that is its own
    mesh (``cell``: the product as the cell inserts it, so far) from its sign
    (:func:`_unresolved`; "" where it can): a peg that is a fit there whose room the cell
    does not resolve it tries narrowed (:func:`narrows_peg`), in every hole where it is
    such a fit; it cannot where it does not narrow the peg (``asap_beam``'s tapered rect
    tenons at room 0 in the top's mortises), or where the narrower peg would turn its
    no-fit in another hole into a fit or a room it cannot tell (:func:`_turned`)."""
    rooms, nominal = margins(derived)[pid], nominal_fits(derived)
    holes = [*derived.holes, *derived.part_holes]
    fine, why = fine_fits(derived, pid, holes, nominal), _unresolved(rooms[hid])
    if hid not in fine:
        return why
    if not narrows_peg(cell, pid, nominal):
        return (why + ("; a zero-clearance fit" if (pid, hid) in nominal else "")
                + "; the cell narrows a peg in a base that is its own mesh only where it and its hole are round")
    turned = _turned(rooms, fine, holes, "section", "hole")
    return f"{why}; {turned}" if turned else ""


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
    deep (a part with a bore: at most half its length; a peg standing out less: :func:`finger_grip`;
    a part on the suction cup by its top: :func:`tool_of`) at its goal (a peg standing on its
    hole's bottom, a part with a bore where the CAD has it), rounded up to the millimetre;
    None where :data:`GRIPPER`'s keeps it clear, with why (the part, the part below the
    wrist and how high it stands) otherwise. A part the wrist meets stops short of its goal
    (a bolt beside a bracket's 80 mm wall stopped 4.1 mm above it)."""
    depth = GRIPPER["grasp_depth"]
    grips = {pid: (fit.position, fit.entry - fit.depth + float(upright(derived, fit).extents[2])
                   - (0.0 if tool_of(derived, fit)[0] == "suction" else finger_grip(derived, fit)[0]))  # cup: top
             for pid, fit in derived.hole_of.items() if fit.axis == "+z"}
    for pin in derived.pins.values():
        for pid in (p for p in pin.parts if p in derived.bores and pin.axis == "+z"):
            low, high = (float(v) for v in derived.parts[pid].mesh.bounds[:, 2])
            grips[pid] = (pin.position, high - min(depth, (high - low) / 2))
    need, why = GRIPPER["flange_length"], ""
    clear = {derived.base} if derived.pins else set()  # the cell's wrist does not collide with a base with pins
    for pid, (xy, grip) in sorted(grips.items()):
        for other in sorted(_maybe_in_place(derived, pid) - clear):
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


def _onto_pin(derived: Derived, pin: PinFit, pid: str) -> str | None:
    """Why the cell does not put part ``pid`` onto ``pin`` (None: it does, onto a pin of
    the base or down one of another part, the part colliding as its exact pieces:
    :func:`executor.world.rings.ring_pieces`; whether that part is placed by hand is
    :func:`cell_view`'s, and a part after another on the pin is :func:`_stack_refused`'s);
    a part on more than one pin (a plate over two dowel pins) goes onto them all at once
    where :func:`_onto_pins` allows;
    a part that stands out of the product at its goal less than the fingers need
    (:func:`_grip`) is placed by hand; a part whose room on it per side (:func:`margins`) is under
    :data:`executor.world.scene.SIZE_RESOLUTION` (a nominal zero-clearance fit too) is no
    experiment of the cell: it would jam there, and its pairs are taken from ``sizes.lp``."""
    if pin.owner != derived.base and pin.axis != "+z":
        return (f"goes onto a pin of '{pin.owner}' ({pin.id}) along {opposite(pin.axis)}: the cell puts parts onto "
                "pins of other parts than the base down (-z) only")
    if pin.axis == "-z":
        return f"goes onto its pin ({pin.id}) along +z, from below"
    if len(on := [p for p in derived.pins.values() if pid in p.parts]) > 1:
        return _onto_pins(derived, on, pid)
    if (why := _stack_refused(derived, pin, pid)) is not None:
        return why
    if why := _bore_unresolved(derived, pid, pin.id):
        return f"goes onto a pin ({pin.id}) {why}"
    if pin.axis != "+z" and (why := _unreached(opposite(pin.axis), pin_entry(derived, pin), SIDEWAYS_PIN_REACH,
                                               "a horizontal pin")):
        return f"goes onto a pin ({pin.id}) along {opposite(pin.axis)}: {why}"
    if pin.axis != "+z" and (why := _wrist_on_pin(derived, pin, pid)):
        return f"goes onto a pin ({pin.id}) along {opposite(pin.axis)}, but {why}"
    mesh = derived.parts[pid].mesh.copy().apply_transform(bore_frame(derived, pid))
    found = bore_pieces(derived, pid)(pid, as_written(mesh))
    if isinstance(found, str):
        return f"goes onto a pin ({pin.id}), but {found}"
    grip, why = _grip(*standing_out(derived, pid, pin, _in_place_before(derived, pid)))
    if grip == 0.0:  # sunk at its goal (a ring over an island of a pocket, flush with its top)
        return f"goes onto a pin ({pin.id}), but part '{pid}' {why}"
    return None


def _onto_pins(derived: Derived, on: list[PinFit], pid: str) -> str | None:
    """Why the cell does not put part ``pid`` onto the several pins ``on`` it is on (None: it
    does, down its first pin, :meth:`executor.cad.derive.Derived.pin_of`, held as the CAD
    turns it, so each further bore comes down over its own pin). :func:`_onto_pin` has
    checked its first pin (not entered from below); the pins must share the part's axis,
    which must be +z (pins standing up; those of other parts than the base must be of parts
    the cell places by hand: :func:`cell_view`'s), the part must be the lowest on each, with
    room on each that the cell resolves, and a stack of prisms with one bore per pin
    (:func:`bore_pieces`). Pins with less room than the cell resolves are all named, with
    the least room."""
    names = ", ".join(pin.id for pin in on)
    if on[0].axis != "+z":  # a part's pins share its axis (executor.cad.derive.pins)
        return (f"goes onto {len(on)} pins ({names}) along {opposite(on[0].axis)}: the cell puts a part onto several "
                "pins only down onto pins standing up (+z)")
    for pin in on:
        lowest = min(pin.parts, key=lambda p: (float(along_axis(derived.parts[p].mesh, pin)[:, 2].min()), p))
        if pid != lowest:
            return (f"goes onto a pin ({pin.id}) on top of '{lowest}': the cell puts a part onto several pins only "
                    "as the first on each")
    rooms = margins(derived)[pid]
    if tight := sorted(pin.id for pin in on if _bore_unresolved(derived, pid, pin.id)):  # all named: no pin first
        tight = [pin_id for pin_id in tight if _unresolved(rooms[pin_id])] or tight  # those of the room, if any
        least = min(tight, key=lambda pin_id: (rooms[pin_id], pin_id))
        return (f"goes onto {'a pin' if len(tight) == 1 else 'pins'} ({', '.join(tight)}) "
                f"{_bore_unresolved(derived, pid, least)}")
    mesh = derived.parts[pid].mesh.copy().apply_transform(bore_frame(derived, pid))
    found = bore_pieces(derived, pid)(pid, as_written(mesh))
    return f"goes onto {len(on)} pins ({names}), but {found}" if isinstance(found, str) else None


STACK_TOLERANCE = 1e-4
"""[m] a part on top of another on a pin goes onto it in the cell when its end nearest the
pin's root is within this of the other's far end in the CAD: the cell stacks them end to
end (:meth:`executor.assembly.step.Assembler.stacked`), so its goal is the CAD's within this."""


def _stack_refused(derived: Derived, pin: PinFit, pid: str) -> str | None:
    """Why the cell does not put part ``pid`` onto ``pin`` after the part below it there
    (nearer the pin's root; None: it is the part nearest the root, or the cell stacks it):
    the cell stacks each part end to end on the one below (:data:`STACK_TOLERANCE`), the
    one below put onto the pin by the cell too."""
    def span(part: str) -> tuple[float, float]:
        along = along_axis(derived.parts[part].mesh, pin)[:, 2]
        return float(along.min()), float(along.max())

    low = span(pid)[0]
    below = [part for part in pin.parts if part != pid and span(part)[0] < low - LEVEL]
    if not below:
        return None
    under = max(below, key=lambda part: (span(part)[1], part))
    end = "top" if pin.axis == "+z" else "outer end"
    if abs(gap := low - span(under)[1]) > STACK_TOLERANCE:
        return (f"goes onto a pin ({pin.id}) {1e3 * gap:+.3f} mm from the {end} of '{under}': the cell stacks the "
                f"parts on a pin end to end (within {1e3 * STACK_TOLERANCE:g} mm)")
    if _onto_pin(derived, pin, under) is not None:
        return (f"goes onto a pin ({pin.id}) {'on top of' if pin.axis == '+z' else 'after'} '{under}', which the "
                "cell does not put onto it")
    return None


def _unreached(axis: str, end: tuple[float, float, float], regions: Mapping[str, tuple[Region, ...]],
               what: str) -> str:
    """Why the cell's arm may not reach ``what`` (a horizontal pin, its free end at ``end``
    [m]; a hole entered sideways, its entry there) along the horizontal ``axis`` (the part's
    motion): "" inside a box in which it was measured to (``regions``:
    :data:`SIDEWAYS_PIN_REACH`, :data:`SIDEWAYS_HOLE_REACH`)."""
    if axis not in regions:
        return f"the cell's arm was measured to reach {what} along {', '.join(regions)} only"
    if any(all(low - 1e-9 <= v <= high + 1e-9 for v, (low, high) in zip(end, box, strict=True))
           for box in regions[axis]):
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


def _wrist_on_pin(derived: Derived, pin: PinFit, pid: str) -> str:
    """Why the arm's wrist would meet the product with part ``pid`` at its goal on ``pin``
    along a horizontal axis ("" where it would not): :func:`_wrist_meets` about the pin's
    axis, the base outside the pin itself (its section's half diagonal about the axis, the
    gripper's fingers beside it)."""
    centre = (float(pin.section.centre[0]), float(pin.section.centre[1]))
    return _wrist_meets(derived, pin, pid, centre, {pin.owner: math.hypot(pin.section.a, pin.section.b) / 2 + NEAR})


def _wrist_meets(derived: Derived, fit: HoleFit | PinFit, pid: str, centre: tuple[float, float],
                 inner: Mapping[str, float]) -> str:
    """Why the arm's wrist would meet the product with part ``pid`` at its goal along the
    horizontal axis of ``fit`` (a pin, a hole entered sideways) ("" where it would not):
    :func:`tool_length`'s rule in its frame (:func:`feature_turn`: z out along the axis), the axis
    through ``centre`` [m] (x, y in that frame). The part is held :data:`GRIPPER`'s grasp
    depth deep (at most half its length) from its outer end, the wrist (:data:`WRIST_RADIUS`
    about the tool's axis) starts the default flange beyond, and every part that may be in
    place (any but those the geometric precedence puts after ``pid``) must end
    :data:`WRIST_CLEARANCE` short of it within that radius of the axis, a part in ``inner``
    only outside that radius [m] of it. Any longer flange the product gets keeps this: the
    wrist only moves farther out along the axis."""
    turn = feature_turn(fit)
    along = along_axis(derived.parts[pid].mesh, fit)[:, 2]
    low, high = float(along.min()), float(along.max())
    grip = high - min(GRIPPER["grasp_depth"], (high - low) / 2)
    for other in sorted(_maybe_in_place(derived, pid)):
        mesh = derived.parts[other].mesh.copy().apply_transform(turn)
        top = _highest_near(mesh, centre, WRIST_RADIUS, inner.get(other, 0.0))
        if top is not None and top - grip + WRIST_CLEARANCE > GRIPPER["flange_length"] + 1e-9:
            return (f"the arm's wrist ({1e3 * WRIST_RADIUS:g} mm about the tool's axis, "
                    f"{1e3 * GRIPPER['flange_length']:g} mm out from the grip) would meet '{other}', "
                    f"{1e3 * (top - grip):.3f} mm out from the grip within {1e3 * WRIST_RADIUS:g} mm of the axis")
    return ""


def _sideways_refused(derived: Derived, hid: str, fit: HoleFit) -> str:
    """Why the cell does not insert the peg of ``fit``, a hole entered sideways ("" where it
    does): the arm not measured to reach its entry along its axis (:func:`_unreached`), or
    its wrist meeting the product with the peg at its goal (:func:`_wrist_meets`, the base
    counted whole: nothing of it stands out of the entry)."""
    assert fit.part is not None
    axis = opposite(fit.axis)
    if why := _unreached(axis, entry_point(fit), SIDEWAYS_HOLE_REACH, "a hole entered sideways"):
        return f"goes into hole {hid} along {axis}: {why}"
    centre = (float(fit.hole.centre[0]), float(fit.hole.centre[1]))
    if why := _wrist_meets(derived, fit, fit.part, centre, {}):
        return f"goes into hole {hid} along {axis}, but {why}"
    return ""


def bore_pieces(derived: Derived, pid: str) -> Pieces:
    """How the pieces of part ``pid`` with a bore are made from its mesh in its part frame:
    a stack of prisms of its sections (:func:`executor.world.rings.ring_pieces`, with the
    sections of the pins along its pin's axis placed on that axis, which a bore made of its
    round part and flats must leave the room the bore does), or, for
    a part that is no such stack, CoACD's pieces that keep its bore within :func:`bore_loss`
    of its pin's room (the part has room on its pin: :func:`_onto_pin`)
    (:func:`executor.cad.convex.pin_pieces`)."""
    pin = derived.pin_of(pid)
    allowed, along = bore_loss(derived, pid), along_axis(derived.parts[pid].mesh, pin)[:, 2]
    low, high = float(along.min()), float(along.max())
    solid = trimesh.creation.extrude_polygon(shapely.Polygon(pin.section.outline + pin.section.centre),
                                             high - low + 2 * NEAR)
    solid.apply_translation((0.0, 0.0, low - NEAR))  # the pin in its frame, turned into the part frame
    solid.apply_transform(bore_frame(derived, pid) @ feature_turn(pin).T)
    bores = 1 + sum(part == pid for part, _ in derived.further_bores)  # one per pin it is on
    widen = NOMINAL_FIT_ROOM if widens_bore(derived, pid) else 0.0
    frame = bore_frame(derived, pid) @ feature_turn(pin).T
    parallel = [pin, *(other for _, other in sorted(derived.pins.items())
                       if other is not pin and other.axis == pin.axis)]
    pins = tuple(shapely.Polygon(trimesh.transform_points(np.column_stack([
        other.section.outline + pin.section.centre, np.zeros(len(other.section.outline))]), frame)[:, :2])
        for other in parallel)  # each pin's section with its axis on the part's pin's, in the part frame

    def pieces(name: str, part: trimesh.Trimesh) -> tuple[list[tuple[trimesh.Trimesh, float]], str] | str:
        found = ring_pieces(name, part, allowed, round_pins(derived, pid), bores, widen, pins)
        if not isinstance(found, NoStack) or bores > 1 or widen:  # CoACD's pieces: about one pin, not widened
            return found
        other = pin_pieces(name, part, solid, allowed)
        return other if not isinstance(other, str) else f"{found}; nor do CoACD's pieces fit: {other}"
    return pieces


def fine_fits(derived: Derived, pid: str, features: Iterable[str],
              nominal: Mapping[tuple[str, str], float] | None = None) -> list[str]:
    """The ``features`` (pins for a part with a bore, holes for a peg), sorted, on or in
    which part ``pid`` is a fit in the CAD whose room the cell does not resolve: a nominal
    zero-clearance fit (:func:`nominal_fits`, room 0) or a positive room under
    :func:`_unresolved`'s (Factory's gears' 0.012 mm per side on their shafts);
    ``nominal``: the product's :func:`nominal_fits`, where known."""
    nominal = nominal_fits(derived) if nominal is None else nominal
    rooms = margins(derived).get(pid, {})
    return sorted(fid for fid in features if fid in rooms and (
        (pid, fid) in nominal or (rooms[fid] > 0 and _unresolved(rooms[fid]))))


def widens_bore(derived: Derived, pid: str, nominal: Mapping[tuple[str, str], float] | None = None) -> bool:
    """Whether the cell widens part ``pid``'s bore by
    :data:`bridge.product.nominal.NOMINAL_FIT_ROOM` per side: it is a fit on some pin whose
    room the cell does not resolve (:func:`fine_fits`), the part goes onto one pin (the
    cell's view of a part on several keeps its first pin only), and its bore and every pin
    are round (:func:`round_pins`: its pieces' bore is a regular polygon about its
    inscribed circle, grown by that room, :func:`executor.world.rings.round_bores`). The
    fit's answer is the CAD's; the cell observes it with that room, not the CAD's."""
    return (round_pins(derived, pid) and not any(part == pid for part, _ in derived.further_bores)
            and bool(fine_fits(derived, pid, derived.pins, nominal)))


def narrows_peg(cell: Derived, pid: str, nominal: Mapping[tuple[str, str], float] | None = None) -> bool:
    """Whether the cell narrows peg ``pid`` by :data:`bridge.product.nominal.NOMINAL_FIT_ROOM`
    per side, the counterpart of :func:`widens_bore` for a hole it cannot widen: the peg's
    room in its hole of ``cell`` (the product as the cell inserts it, :func:`cell_view`) is
    a fit the cell does not resolve (:func:`fine_fits`), the base is its own mesh (a base of
    primitives has the hole widened instead, :func:`builds_plate`), and the peg and its hole
    are round (its pieces are narrowed about its axis: :func:`executor.world.meshes.narrowed`).
    The fit's answer is the CAD's; the cell observes it with that room, not the CAD's."""
    fit = cell.hole_of.get(pid)
    return (fit is not None and fit.id in cell.holes and not builds_plate(cell)
            and fit.section is not None and fit.section.kind == "round" and fit.hole.kind == "round"
            and bool(fine_fits(cell, pid, [fit.id], nominal)))


def _turned(rooms: Mapping[str, float], fine: list[str], features: Iterable[str], what: str, noun: str) -> str:
    """Where giving a part :data:`bridge.product.nominal.NOMINAL_FIT_ROOM` more room per side
    (``what``: its bore, wider on a pin, or its section, narrower in a hole) would turn its
    no-fit in another of ``features`` (not in ``fine``; ``noun``: pin or hole; ``rooms``:
    its room in each [m])
    into a fit or a room the cell cannot tell (a room of at most 0, less than twice that
    room and :data:`executor.world.SIZE_RESOLUTION` below it): why, naming the first; ""
    where none."""
    reach = 2 * (NOMINAL_FIT_ROOM + SIZE_RESOLUTION)
    turned = sorted(other for other in features if other in rooms and other not in fine and -reach < rooms[other] <= 0)
    return (f"its {what} {1e3 * NOMINAL_FIT_ROOM:g} mm {'wider' if noun == 'pin' else 'narrower'} per side would "
            f"pass {noun} {turned[0]} ({rooms[turned[0]] * 500:+.4f} mm per side)" if turned else "")


def _bore_unresolved(derived: Derived, pid: str, pin_id: str) -> str:
    """Why the cell cannot tell part ``pid``'s room on pin ``pin_id`` from its sign (:func:`_unresolved`; ""
    where it can). A part whose bore is a fit on a pin with room the cell does not resolve
    (:func:`fine_fits`) the cell tries with its bore widened (:func:`widens_bore`), on every
    pin: it cannot where it does not widen that bore, or where the wider bore would turn the
    part's no-fit on another pin into a fit or a room it cannot tell (:func:`_turned`)."""
    rooms, nominal = margins(derived)[pid], nominal_fits(derived)
    fine, why = fine_fits(derived, pid, derived.pins, nominal), _unresolved(rooms[pin_id])
    if (why and pin_id not in fine) or not fine:
        return why
    why = why or f"with its bore a fit on pin {fine[0]} " + (
        "at nominal zero clearance" if (pid, fine[0]) in nominal else _unresolved(rooms[fine[0]]))
    if not widens_bore(derived, pid, nominal):
        return f"{why}; the cell widens a bore only for a part on one pin, its bore and every pin round"
    turned = _turned(rooms, fine, derived.pins, "bore", "pin")
    return f"{why}; {turned}" if turned else ""


BORE_LOSS = 0.25
"""The cell's bore of a part may be smaller than its mesh's by this fraction of the least
positive (diametral) room the part has on a pin [m/m] (half its room all round), so the
cell's physics keeps every fit and no-fit of the nominal sections
(:func:`executor.world.rings.coarser_bores`)."""


def bore_loss(derived: Derived, pid: str) -> float:
    """How much smaller [m] the cell's bore of part ``pid`` may be (:data:`BORE_LOSS`; 0 when
    it goes onto no pin with room: a smaller bore keeps a no-fit)."""
    rooms = [room for hole, room in margins(derived).get(pid, {}).items() if hole in derived.pins and room > 0]
    return BORE_LOSS * min(rooms) if rooms else 0.0


def round_pins(derived: Derived, pid: str) -> bool:
    """Whether part ``pid``'s bores are round and every pin it may go onto too (its cell's
    bores may then be polygons about their inscribed circles:
    :func:`executor.world.rings.round_bores`)."""
    return all(derived.bore_on(pid, pin.id).kind == "round" for pin in derived.pins.values() if pid in pin.parts) \
        and all(pin.section.kind == "round" for pin in derived.pins.values())


def along_axis(mesh: trimesh.Trimesh, pin: HoleFit | PinFit) -> np.ndarray:
    """The vertices (n, 3) [m] of ``mesh`` in the frame of ``pin`` (:func:`feature_turn`): z along
    its removal direction."""
    return mesh.vertices @ feature_turn(pin)[:3, :3].T


def _pin_top(derived: Derived, pin: PinFit) -> float:
    """A pin's top [m] in its frame (:func:`feature_turn`): its owner's farthest point along the
    pin's removal direction within its section around its axis (a pin parts go down onto:
    its highest)."""
    vertices = along_axis(derived.parts[pin.owner].mesh, pin)
    reach = math.hypot(pin.section.a, pin.section.b) / 2
    near = np.linalg.norm(vertices[:, :2] - pin.section.centre, axis=1) <= reach + 1e-9
    return float(vertices[near, 2].max())


def pin_level(derived: Derived, pin: PinFit) -> tuple[float, float]:
    """A pin's top (:func:`_pin_top`) and its height [m] above the nearest end of the parts
    going onto it (where the first rests, or, on a pin along a horizontal axis, where the
    CAD has it), in the pin's frame."""
    top = _pin_top(derived, pin)
    return top, top - min(float(along_axis(derived.parts[pid].mesh, pin)[:, 2].min()) for pid in pin.parts)


def pin_entry(derived: Derived, pin: PinFit) -> tuple[float, float, float]:
    """The centre of a pin's free end in the cell frame [m] (:func:`_pin_top`): its
    ``position`` (x, y) and, on a pin along a horizontal axis, its ``top_z``."""
    x, y, z = feature_turn(pin)[:3, :3].T @ np.array([*pin.section.centre, _pin_top(derived, pin)])
    return float(x), float(y), float(z)


def bore_frame(derived: Derived, pid: str) -> np.ndarray:
    """The 4 × 4 transform from the cell frame to the part frame of part ``pid`` with a bore:
    turned into its pin's frame (:func:`feature_turn`), its origin the centre of the bore at the
    part's end nearest the pin's root (:func:`executor.cad.convex.peg_frame`)."""
    turn = feature_turn(derived.pin_of(pid))
    return peg_frame(derived.bores[pid], derived.parts[pid].mesh.copy().apply_transform(turn)) @ turn


def _polygon_refused(fit: HoleFit, derived: Derived) -> str:
    """Why the cell cannot insert the polygon peg of ``fit`` ("" when it can): it is no
    prism of its section (convex pieces of its mesh would not keep its room), or its
    outline's prism has a piece the cell's hull margin would widen."""
    assert fit.part is not None and fit.section is not None
    mesh = upright(derived, fit)
    if not peg_is_primitive(fit, mesh):
        return (f"part '{fit.part}' has a polygon section but is no prism of it: convex pieces of its mesh would not "
                "keep its room")
    thin = thin_prism(section(fit.part, fit.section), float(mesh.extents[2]))
    return "" if thin is None else f"part '{fit.part}': {thin}"


def plate_top(derived: Derived) -> float:
    """The plate's ``top_z`` [m] (:func:`plate_level`)."""
    return plate_level(derived)[0]


def plate_level(derived: Derived) -> tuple[float, float]:
    """The plate's ``top_z`` and ``tile_thickness`` [m]: the entry and depth most holes
    share (the first hole's among equally many), so that only the others state their own;
    without holes the base's top and half its height (at most the largest depth a plate
    states; the base is then its own mesh, these only place what lies on it)."""
    fits = [fit for fit in derived.holes.values() if fit.axis == "+z"]  # a sideways hole states its own
    if not fits:
        (_, _, low), (_, _, high) = derived.parts[derived.base].mesh.bounds
        return float(high), min(float(high - low) / 2, MAX_PLATE_DEPTH)
    levels = [(f.entry, f.depth) for f in fits]

    def sharing(level: tuple[float, float]) -> int:
        return sum(abs(e - level[0]) <= LEVEL and abs(d - level[1]) <= LEVEL for e, d in levels)

    return max(levels, key=sharing)
