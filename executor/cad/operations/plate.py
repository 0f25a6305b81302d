"""The plate the cell builds the base as: whether it does (:func:`builds_plate`: the base its
bounding box less holes entered from above) and the entry and depth most holes share
(:func:`plate_level`), from which a hole differing by more than :data:`LEVEL` states its own.
Lengths in metres."""

from __future__ import annotations

from executor.cad.convex import base_is_primitive
from executor.cad.derive import Derived

LEVEL = 1e-5
"""A hole whose entry or depth differs by more than this from the plate's [m] states its own."""
MAX_PLATE_DEPTH = 0.2
"""The largest ``tile_thickness`` and ``base_thickness`` of a ``[plate]`` [m]."""


def builds_plate(cell: Derived) -> bool:
    """Whether the simulated cell builds the base of the product as it inserts it
    (:func:`cell_view`) as ``[plate]`` primitives, its holes from their sections: it has
    holes, all entered from above, no pins, and is its bounding box less them
    (:func:`executor.cad.convex.base_is_primitive`); else the base is its own mesh."""
    return (bool(cell.holes) and not cell.pins and all(fit.axis == "+z" for fit in cell.holes.values())
            and base_is_primitive(cell))


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
