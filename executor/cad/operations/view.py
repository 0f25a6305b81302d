"""The product as the cell inserts it (:func:`cell_view`): the holes it inserts pegs into, the
pins it puts parts onto, the bores it keeps, and for every other moving part why it is placed
by hand (``[manual.<id>]``): a peg entered along another axis or from below, out of reach
sideways, a polygon peg no prism of its section, no tool to hold it, a fit the cell does
not resolve, a part onto a pin the cell refuses, a pin of a part the cell moves
(:func:`_owner_refused`). Lengths in metres."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace

import numpy as np
from scipy.spatial.transform import Rotation

from executor.cad.convex import peg_frame, peg_is_primitive
from executor.cad.covers import hole_specs, map_parts
from executor.cad.derive import Derived, HoleFit, PinFit
from executor.cad.operations.arm import Reach, reaches_recorded, sideways_refused
from executor.cad.operations.frames import upright
from executor.cad.operations.pins import STACK_TOLERANCE, onto_pin
from executor.cad.operations.plate import plate_top
from executor.cad.operations.resolution import unresolved_in_hole
from executor.cad.operations.screwed import screwed
from executor.cad.operations.tools import tool_of
from executor.cad.sections import section
from executor.cad.sweep import opposite
from executor.world.geometry import Section, seated_pose, thin_prism


def section_kind(fit: HoleFit | None) -> str | None:
    """The kind of the section of the peg in ``fit`` (None: no hole, or no peg in it)."""
    return None if fit is None or fit.section is None else fit.section.kind


def cell_view(derived: Derived, refused: Mapping[str, str] | None = None) -> tuple[Derived, dict[str, str]]:
    """The product as the cell inserts it: only the holes entered from above or sideways
    holding, if anything, a peg going in along the hole's axis that is no polygon section,
    or the prism of its polygon (the cell builds that from its outline, exactly), longer than the gripper's
    grasp depth (the cell holds it by that much), with room in it the cell resolves or a
    nominal zero-clearance fit the cell widens (:func:`unresolved_in_hole`); the pins of the base that
    parts go down onto, and the pins standing up on parts the cell places by hand
    (:func:`executor.cad.covers.map_parts`) or on pegs it inserts down into holes of the
    base (:func:`_owner_refused`) that parts go down onto, and of the parts with
    a bore those it puts onto them (:func:`onto_pin`); the pegs of the other holes and
    the other parts going onto pins, each with why the cell places it by hand (a polygon
    peg's room is often below what convex pieces of its mesh keep), those ``refused``
    (part -> why) too."""
    kept: dict[str, HoleFit] = {}
    screws = screwed(derived)
    by_hand: dict[str, str] = screws | dict(refused or {})
    for pin in sorted(derived.pins.values(), key=lambda p: p.owner == derived.base):  # the cheap reasons first
        for pid in pin.parts:
            if pid not in by_hand and (why := onto_pin(derived, pin, pid)) is not None:
                by_hand[pid] = why
    for hid, fit in derived.holes.items():
        for pid in dict(fit.more):  # the further parts of a stack: the hole is measured for the deepest
            by_hand.setdefault(pid, f"stands in hole {hid} with '{fit.part}' deeper in it: the cell inserts one "
                                    "part into a hole of the base")
        if fit.part in screws or fit.part in (refused or {}):
            continue
        if fit.part is not None and derived.axis[fit.part] != fit.axis:
            by_hand[fit.part] = (f"part '{fit.part}' goes in along {opposite(derived.axis[fit.part])}, its hole {hid} "
                                 f"is entered along {opposite(fit.axis)}")
        elif fit.axis == "-z":
            if fit.part is not None:
                by_hand[fit.part] = f"goes into hole {hid} along +z, from below"
        elif fit.part is not None and fit.axis != "+z" and (why := sideways_refused(derived, hid, fit)):
            by_hand[fit.part] = why
        elif fit.part is not None and section_kind(fit) == "polygon" and (why := _polygon_refused(fit, derived)):
            by_hand[fit.part] = why
        elif fit.part is not None and (tool := tool_of(derived, fit))[0] == "":
            by_hand[fit.part] = tool[1]
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
    while unresolved := unresolved_in_hole(derived, replace(derived, holes=kept, pins=pins)):
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


def reaches_asked(derived: Derived) -> tuple[set[str], list[Reach]]:
    """The moving parts the cell places where its arm reaches every horizontal insertion
    (:func:`cell_view` with :func:`executor.cad.operations.arm.reaches_recorded`, then
    :func:`executor.cad.covers.map_parts`), and the
    reaches its decisions rest on: what the product's pose on the table decides (none,
    and no view made, where no part goes into or onto a feature along a horizontal axis)."""
    sideways = [fit.part for fit in derived.holes.values() if fit.axis not in ("+z", "-z")]
    if not any(sideways) and not any(pin.parts for pin in derived.pins.values() if pin.axis not in ("+z", "-z")):
        return set(), []
    with reaches_recorded() as found:
        cell, by_hand = cell_view(derived)
        manual = map_parts(cell, plate_top(cell), by_hand).manual  # covers and heads the cell places too
    return set(derived.parts) - {derived.base} - set(manual), found


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
