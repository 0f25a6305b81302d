"""Parts put onto pins: why the cell does not put a part onto its pin (:func:`onto_pin`), onto
several pins at once, or after the part below it on the pin (:data:`STACK_TOLERANCE`); and
the pieces the cell collides a part with a bore as (:func:`bore_pieces`), its bore at most
:func:`bore_loss` smaller than the mesh's (:data:`BORE_LOSS`). Lengths in metres."""

from __future__ import annotations

import numpy as np
import shapely
import trimesh

from bridge.product.nominal import NOMINAL_FIT_ROOM
from executor.cad.convex import NEAR, Pieces, as_written, pin_pieces
from executor.cad.derive import Derived, PinFit
from executor.cad.operations.arm import sideways_pin_refused
from executor.cad.operations.fingers import finger_grip
from executor.cad.operations.frames import along_axis, bore_frame, feature_turn
from executor.cad.operations.plate import LEVEL
from executor.cad.operations.resolution import bore_unresolved, round_pins, unresolved, widens_bore
from executor.cad.operations.rooms import margins
from executor.cad.sweep import opposite
from executor.world.rings import NoStack, ring_pieces


def onto_pin(derived: Derived, pin: PinFit, pid: str) -> str | None:
    """Why the cell does not put part ``pid`` onto ``pin`` (None: it does, onto a pin of
    the base or down one of another part, the part colliding as its exact pieces:
    :func:`executor.world.rings.ring_pieces`; whether that part is placed by hand is
    :func:`cell_view`'s, and a part after another on the pin is :func:`_stack_refused`'s);
    a part on more than one pin (a plate over two dowel pins) goes onto them all at once
    where :func:`_onto_pins` allows;
    a part the fingers do not hold at its goal, gripping its outside
    (:func:`executor.cad.operations.fingers.finger_grip`: it stands out of the product there
    less than they need), is placed by hand; a part whose room on it per side (:func:`margins`) is under
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
    if why := bore_unresolved(derived, pid, pin.id):
        return f"goes onto a pin ({pin.id}) {why}"
    if why := sideways_pin_refused(derived, pin, pid):
        return why
    if why := _no_pieces(derived, pid):
        return f"goes onto a pin ({pin.id}), but {why}"
    if not (grip := finger_grip(derived, pid, pin))[0]:  # a washer on a plate, a ring sunk flush over a pin
        return f"goes onto a pin ({pin.id}), but part '{pid}' {grip[1]}"
    return None


def _onto_pins(derived: Derived, on: list[PinFit], pid: str) -> str | None:
    """Why the cell does not put part ``pid`` onto the several pins ``on`` it is on (None: it
    does, down its first pin, :meth:`executor.cad.derive.Derived.pin_of`, held as the CAD
    turns it, so each further bore comes down over its own pin). :func:`onto_pin` has
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
    if tight := sorted(pin.id for pin in on if bore_unresolved(derived, pid, pin.id)):  # all named: no pin first
        tight = [pin_id for pin_id in tight if unresolved(rooms[pin_id])] or tight  # those of the room, if any
        least = min(tight, key=lambda pin_id: (rooms[pin_id], pin_id))
        return (f"goes onto {'a pin' if len(tight) == 1 else 'pins'} ({', '.join(tight)}) "
                f"{bore_unresolved(derived, pid, least)}")
    return f"goes onto {len(on)} pins ({names}), but {why}" if (why := _no_pieces(derived, pid)) else None


def _no_pieces(derived: Derived, pid: str) -> str:
    """Why part ``pid`` with a bore has no pieces the cell collides it as
    (:func:`bore_pieces` of its mesh in its part frame); "" where it has."""
    mesh = derived.parts[pid].mesh.copy().apply_transform(bore_frame(derived, pid))
    found = bore_pieces(derived, pid)(pid, as_written(mesh))
    return found if isinstance(found, str) else ""


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
    if onto_pin(derived, pin, under) is not None:
        return (f"goes onto a pin ({pin.id}) {'on top of' if pin.axis == '+z' else 'after'} '{under}', which the "
                "cell does not put onto it")
    return None


def bore_pieces(derived: Derived, pid: str) -> Pieces:
    """How the pieces of part ``pid`` with a bore are made from its mesh in its part frame:
    a stack of prisms of its sections (:func:`executor.world.rings.ring_pieces`, with the
    sections of the pins along its pin's axis placed on that axis, which a bore made of its
    round part and flats must leave the room the bore does), or, for
    a part that is no such stack, CoACD's pieces that keep its bore within :func:`bore_loss`
    of its pin's room (the part has room on its pin: :func:`onto_pin`)
    (:func:`executor.cad.convex.pin_pieces`)."""
    pin = derived.pin_of(pid)
    allowed, along = bore_loss(derived, pid), along_axis(derived.parts[pid].mesh, pin)[:, 2]
    low, high = float(along.min()), float(along.max())
    solid = trimesh.creation.extrude_polygon(shapely.Polygon(pin.section.outline + pin.section.centre),
                                             high - low + 2 * NEAR)
    frame = bore_frame(derived, pid) @ feature_turn(pin).T
    solid.apply_translation((0.0, 0.0, low - NEAR))  # the pin in its frame, turned into the part frame
    solid.apply_transform(frame)
    bores = 1 + sum(part == pid for part, _ in derived.further_bores)  # one per pin it is on
    widen = NOMINAL_FIT_ROOM if widens_bore(derived, pid) else 0.0
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
