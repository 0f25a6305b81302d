"""Fits the cell builds with other room than the CAD's sections: a hole's or bore's section
at its nominal diameter with its nominal zero-clearance fits (:func:`nominal_section`,
:func:`zero_clearance_parts`), and the fits under the cell's resolution it builds
:data:`bridge.product.nominal.NOMINAL_FIT_ROOM` wider per side (:func:`widened_fits`), as
``import`` states them (:func:`widened_fits_assumption`). Lengths in metres."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import replace

from bridge.product.nominal import NOMINAL_FIT_ROOM
from executor.cad.derive import Derived
from executor.cad.operations.resolution import fine_fits, narrows_peg, widens_bore
from executor.cad.operations.rooms import margins, nominal_fits
from executor.cad.sections import Shape2D
from executor.world import SIZE_RESOLUTION


def widened_fits(cell: Derived) -> dict[tuple[str, str], float]:
    """The fits of the product as the cell inserts it (``cell``:
    :func:`executor.cad.operations.view.cell_view`) whose room the simulated cell builds
    :data:`bridge.product.nominal.NOMINAL_FIT_ROOM` wider per side, sorted: on a pin with
    the part's round bore wider (:func:`executor.cad.operations.resolution.widens_bore`), in a hole of
    a base that is its own mesh with the round peg narrower
    (:func:`executor.cad.operations.resolution.narrows_peg`); (part, feature) to the CAD's room per
    side [m] (0.0 for a nominal zero-clearance fit); a feature's ``widened`` in ``geometry.toml``."""
    rooms, nominal = margins(cell), nominal_fits(cell)
    resized: list[tuple[str, list[str]]] = [
        *((pid, list(cell.pins)) for pid in cell.bores if widens_bore(cell, pid, nominal)),
        *((pid, list(cell.holes)) for pid in cell.hole_of if narrows_peg(cell, pid, nominal))]
    found = {(pid, fid): 0.0 if (pid, fid) in nominal else rooms[pid][fid] / 2
             for pid, features in resized for fid in fine_fits(cell, pid, features, nominal)}
    return dict(sorted(found.items()))


def widened_fits_assumption(cell: Derived) -> list[str]:
    """What the simulated cell assumes of the fits whose room it does not resolve
    (:func:`widened_fits`), as ``import`` prints it; none without one."""
    pairs = widened_fits(cell)
    return [f"fits with room under the {1e3 * SIZE_RESOLUTION:g} mm per side the simulated cell resolves: it builds "
            f"each with {1e3 * NOMINAL_FIT_ROOM:g} mm more room per side, on a pin with the part's round bore that "
            "much wider (its pieces' bores regular polygons about the bore's inscribed circle grown by that), in a "
            "hole of a base that is its own mesh with the round peg that much narrower (its pieces narrowed about its "
            "axis), so they are observed in that model, not at the CAD's room: "
            + " ".join(f"{pid}->{fid} ({'room 0' if not room else f'{1e3 * room:+.4f} mm'})"
                       for (pid, fid), room in pairs.items())] if pairs else []


def zero_clearance_parts(derived: Derived) -> dict[str, list[str]]:
    """Feature (a hole or a pin) -> the parts that are a nominal zero-clearance fit in or on
    it (:func:`executor.cad.operations.rooms.nominal_fits`), sorted: a hole's ``zero_clearance``
    in ``geometry.toml``."""
    found: dict[str, list[str]] = {}
    for pid, hid in sorted(nominal_fits(derived)):
        found.setdefault(hid, []).append(pid)
    return found


def nominal_section(inward: Shape2D, outward: Iterable[Shape2D]) -> Shape2D:
    """A hole's or bore's section (``inward``) at its nominal diameter when it is a nominal
    zero-clearance fit with the round ``outward`` sections (the pegs in it, the pins in the
    bore): its vertex circle's diameter, or the widest of theirs where that is wider, so
    that the cell simulates every such fit at room 0 or more, never an interference;
    ``inward`` unchanged with none."""
    widths = [shape.a for shape in outward]
    if not widths:
        return inward
    size = max(inward.a + 2 * inward.deflection, *widths)
    return replace(inward, a=size, b=size, deflection=0.0)
