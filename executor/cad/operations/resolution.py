"""Fits whose room the cell does not resolve (:data:`executor.world.SIZE_RESOLUTION`,
:func:`unresolved`): the features on or in which a part is such a fit (:func:`fine_fits`), a
round bore the cell widens on its pin (:func:`widens_bore`), a round peg it narrows in a hole
of a base that is its own mesh (:func:`narrows_peg`), by
:data:`bridge.product.nominal.NOMINAL_FIT_ROOM` per side; and why a part the cell resolves
neither way goes by hand (:func:`unresolved_in_hole`, :func:`bore_unresolved`): it would
jam there. Lengths in metres."""

from __future__ import annotations

from collections.abc import Iterable, Mapping

from bridge.product.nominal import NOMINAL_FIT_ROOM
from executor.cad.derive import Derived
from executor.cad.operations.plate import builds_plate
from executor.cad.operations.rooms import margins, nominal_fits
from executor.world import SIZE_RESOLUTION


def unresolved(room: float) -> str:
    """Why the cell cannot tell a (diametral) ``room`` [m] from its sign: ``with ... mm of room
    per side, less than`` :data:`executor.world.SIZE_RESOLUTION`; "" where it can."""
    if abs(room) / 2 >= SIZE_RESOLUTION:
        return ""
    return f"with {room * 500:+.4f} mm of room per side, less than the {SIZE_RESOLUTION * 1e3:g} mm the simulated " \
           "cell resolves"


def unresolved_in_hole(derived: Derived, cell: Derived) -> dict[str, str]:
    """Each part in a hole of ``cell`` (``derived`` as the cell inserts it, so far) whose room
    in it (:func:`margins`) is under the cell's resolution (a nominal zero-clearance fit too)
    and that the cell resolves neither by widening the hole (a nominal zero-clearance fit
    in a base it builds of primitives, :func:`builds_plate`: ``occt_as1``'s bolts) nor by
    narrowing the peg (:func:`_peg_unresolved`), with why the cell places it by hand: it
    would jam there."""
    rooms, nominal, plate = margins(derived), nominal_fits(derived), builds_plate(cell)
    found: dict[str, str] = {}
    for hid, fit in cell.holes.items():
        if fit.part is None or not (why := unresolved(rooms[fit.part][hid])) or (plate and (fit.part, hid) in nominal):
            continue
        if plate or (why := _peg_unresolved(derived, cell, fit.part, hid)):
            found[fit.part] = f"goes into hole {hid} {why}"
    return found


def _peg_unresolved(derived: Derived, cell: Derived, pid: str, hid: str) -> str:
    """Why the cell cannot tell peg ``pid``'s room in hole ``hid`` of a base that is its own
    mesh (``cell``: the product as the cell inserts it, so far) from its sign
    (:func:`unresolved`; "" where it can): a peg that is a fit there whose room the cell
    does not resolve it tries narrowed (:func:`narrows_peg`), in every hole where it is
    such a fit; it cannot where it does not narrow the peg (``asap_beam``'s tapered rect
    tenons at room 0 in the top's mortises), or where the narrower peg would turn its
    no-fit in another hole into a fit or a room it cannot tell (:func:`_turned`)."""
    rooms, nominal = margins(derived)[pid], nominal_fits(derived)
    holes = [*derived.holes, *derived.part_holes]
    fine, why = fine_fits(derived, pid, holes, nominal), unresolved(rooms[hid])
    if hid not in fine:
        return why
    if not narrows_peg(cell, pid, nominal):
        return (why + ("; a zero-clearance fit" if (pid, hid) in nominal else "")
                + "; the cell narrows a peg in a base that is its own mesh only where it and its hole are round")
    turned = _turned(rooms, fine, holes, "section", "hole")
    return f"{why}; {turned}" if turned else ""


def fine_fits(derived: Derived, pid: str, features: Iterable[str],
              nominal: Mapping[tuple[str, str], float] | None = None) -> list[str]:
    """The ``features`` (pins for a part with a bore, holes for a peg), sorted, on or in
    which part ``pid`` is a fit in the CAD whose room the cell does not resolve: a nominal
    zero-clearance fit (:func:`nominal_fits`, room 0) or a positive room under
    :func:`unresolved`'s (Factory's gears' 0.012 mm per side on their shafts);
    ``nominal``: the product's :func:`nominal_fits`, where known."""
    nominal = nominal_fits(derived) if nominal is None else nominal
    rooms = margins(derived).get(pid, {})
    return sorted(fid for fid in features if fid in rooms and (
        (pid, fid) in nominal or (rooms[fid] > 0 and unresolved(rooms[fid]))))


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


def bore_unresolved(derived: Derived, pid: str, pin_id: str) -> str:
    """Why the cell cannot tell part ``pid``'s room on pin ``pin_id`` from its sign (:func:`unresolved`; ""
    where it can). A part whose bore is a fit on a pin with room the cell does not resolve
    (:func:`fine_fits`) the cell tries with its bore widened (:func:`widens_bore`), on every
    pin: it cannot where it does not widen that bore, or where the wider bore would turn the
    part's no-fit on another pin into a fit or a room it cannot tell (:func:`_turned`)."""
    rooms, nominal = margins(derived)[pid], nominal_fits(derived)
    fine, why = fine_fits(derived, pid, derived.pins, nominal), unresolved(rooms[pin_id])
    if (why and pin_id not in fine) or not fine:
        return why
    why = why or f"with its bore a fit on pin {fine[0]} " + (
        "at nominal zero clearance" if (pid, fine[0]) in nominal else unresolved(rooms[fine[0]]))
    if not widens_bore(derived, pid, nominal):
        return f"{why}; the cell widens a bore only for a part on one pin, its bore and every pin round"
    turned = _turned(rooms, fine, derived.pins, "bore", "pin")
    return f"{why}; {turned}" if turned else ""


def round_pins(derived: Derived, pid: str) -> bool:
    """Whether part ``pid``'s bores are round and every pin it may go onto too (its cell's
    bores may then be polygons about their inscribed circles:
    :func:`executor.world.rings.round_bores`)."""
    return all(derived.bore_on(pid, pin.id).kind == "round" for pin in derived.pins.values() if pid in pin.parts) \
        and all(pin.section.kind == "round" for pin in derived.pins.values())
