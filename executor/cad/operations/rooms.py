"""Each peg's room in each hole and each bore's on each pin (:func:`margins`), from the sections
measured (or the sweep's level of least room, :func:`executor.cad.derive.swept_fits`), the
nominal zero-clearance fits at room 0 (:func:`nominal_fits`). Lengths in metres."""

from __future__ import annotations

from executor import ExecutorError
from executor.cad.derive import Derived
from executor.cad.operations.screwed import screwed_fits
from executor.cad.sections import Shape2D, section, section_room, zero_clearance
from executor.world.geometry import Section
from executor.world.polygon_fit import OutlineError


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
