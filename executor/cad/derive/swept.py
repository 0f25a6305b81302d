"""The fits the sweep admits where the sections over the whole stretch do not pass
(:func:`swept_fits`: a taper in its own taper, a stepped peg in its stepped hole)."""

from __future__ import annotations

import math

import numpy as np

from executor.cad.derive.derived import Derived
from executor.cad.sections import Passage, Shape2D, Slicer, classify, frame_of, passage, passes, zero_clearance
from executor.cad.sweep import DIRECTIONS


def swept_fits(derived: Derived) -> dict[tuple[str, str], tuple[Shape2D, Shape2D, float]]:
    """The pairs the sweep admits (:func:`executor.cad.sections.passage`) though the peg's
    section over its whole stretch does not pass the hole's (a taper in its own taper, a
    stepped peg in its stepped hole): a part in a hole (of the base or of a moving part)
    in the pose the product has it, leaving along the hole's axis from its tip to the entry,
    and a pin in the bore of a part on it, the pin leaving the bore; each with the sections
    at the levels of least room and that room (diametral). A peg the sweep admits into its
    own feature is tried the same way in every other feature of its owner along that axis
    (moved onto that feature's centre line and as deep past its entry; a pin under the bore
    as far past its tip), where the sections do not pass. A pair is admitted when its room
    is positive or it is a nominal zero-clearance fit (:func:`executor.cad.sections.zero_clearance`).
    A screwed pair (a modelled thread, :meth:`Derived.screwed`) is not swept: its part fits
    its feature by screwing, written with the feature's section for both and room 0."""
    found: dict[tuple[str, str], tuple[Shape2D, Shape2D, float]] = {}
    slicers: dict[tuple[str, str], Slicer] = {}

    def slicer(pid: str, name: str, out: np.ndarray) -> Slicer:
        if (pid, name) not in slicers:
            slicers[(pid, name)] = Slicer(derived.parts[pid].mesh, out)
        return slicers[(pid, name)]

    def admitted(way: Passage | None) -> tuple[Shape2D, Shape2D, float] | None:
        if way is None:
            return None
        peg, hole = classify(way.peg, hole=False), classify(way.hole, hole=True)
        return (peg, hole, way.room) if way.room > 0 or zero_clearance(peg, hole, way.room) is not None else None

    def extent(pid: str, out: np.ndarray, line: np.ndarray, reach: float) -> tuple[float, float]:
        """The least and the greatest level [m] along ``out`` of ``pid``'s vertices within
        ``reach`` [m] of the point ``line`` across it."""
        along = derived.parts[pid].mesh.vertices
        near = along[np.linalg.norm(along @ frame_of(out).T - line, axis=1) <= reach] @ out
        return (float(near.min()), float(near.max())) if len(near) else (math.inf, -math.inf)

    holes = {**derived.holes, **derived.part_holes}
    for hid, fit in holes.items():
        if fit.part is None or fit.section is None or passes(fit.section, fit.hole):
            continue
        if derived.screwed(fit.part, fit.owner or derived.base):
            found[(fit.part, hid)] = (fit.hole, fit.hole, 0.0)
            continue
        out = np.array(DIRECTIONS[fit.axis])
        owner = fit.owner or derived.base
        peg, walls = slicer(fit.part, fit.axis, out), slicer(owner, fit.axis, out)
        tip = float((derived.parts[fit.part].mesh.vertices @ out).min())
        for other, there in [(hid, fit), *((k, h) for k, h in holes.items() if k != hid)]:
            if other != hid and (there.axis != fit.axis or (there.owner or derived.base) != owner
                                 or passes(fit.section, there.hole)):
                continue
            floor = extent(owner, out, there.hole.centre, max(there.hole.a, there.hole.b))[0]
            offset = frame_of(out).T @ (there.hole.centre - fit.hole.centre) + out * (there.entry - fit.entry)
            way = admitted(passage(peg, walls, there.hole.centre, max(tip + there.entry - fit.entry, floor),
                                   there.entry, offset))
            if way is None and other == hid:
                break
            if way is not None:
                found[(fit.part, other)] = way
    for pin_id, pin in derived.pins.items():
        out = -np.array(derived.directions[pin.axis])
        name = f"against {pin.axis}"  # the slicers across the pin's way out of the bore
        line = frame_of(out) @ np.array(pin.centre)
        reach = max(pin.section.a, pin.section.b)
        for pid in pin.parts:
            own = derived.bore_on(pid, pin_id)
            if passes(pin.section, own):
                continue
            if derived.screwed(pid, pin.owner):
                found[(pid, pin_id)] = (own, own, 0.0)
                continue
            bore = slicer(pid, name, out)
            low, entry = extent(pid, out, line, reach)
            tip = extent(pin.owner, out, line, reach)[0]
            for other_id, under in [(pin_id, pin), *((k, p) for k, p in derived.pins.items() if k != pin_id)]:
                if other_id != pin_id and (under.axis != pin.axis or passes(under.section, own)):
                    continue
                centre = frame_of(out) @ np.array(under.centre)
                offset = frame_of(out).T @ (line - centre) + out * (tip - extent(under.owner, out, centre, reach)[0])
                way = admitted(passage(slicer(under.owner, name, out), bore, line, max(low, tip), entry, offset))
                if way is None and other_id == pin_id:
                    break
                if way is not None:
                    found[(pid, other_id)] = way
    return found
