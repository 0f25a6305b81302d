"""The nominal zero-clearance fits a product states and how the simulated cell models them.

A ``[hole_shapes.*]`` table's ``zero_clearance`` names the parts the CAD has in that hole (or
on that pin) at one nominal section, room 0. Room 0 is below what the simulated cell's
physics resolves (``executor.world.scene.SIZE_RESOLUTION``, 0.025 mm per side): a part
built at room 0 jams, and the cell's trials refuse such a pair. A nominal zero-clearance
fit is a sliding fit in practice, so the simulated cell builds it with
:data:`NOMINAL_FIT_ROOM` per side where it builds the hole itself from its section (a base
of ``[plate]`` primitives: the hole is widened by that room all round, and the cell's loader
refuses the product when that changes the answer of any other pair). Where the hole is
part of the base's own mesh (a ``[base]`` with ``mesh``: holes entered sideways) the
cell cannot widen it: those pairs are no experiment, the planner takes them from the CAD
(``sizes.lp``), not observed, unless the cell narrows the peg (below). On a pin (always in
the base's own mesh) it widens the part instead, for such a fit and for a positive room
under what it resolves alike: a part a pin names in ``widened`` has its round bore wider by
:data:`NOMINAL_FIT_ROOM` per side (its ``[part_shapes.*]`` section as the cell reads it,
and the convex pieces the import writes for it: regular polygons about its bore's
inscribed circle grown by that room), and the cell's loader refuses the product when that
changes the part's answer on any other pin. In a round hole of a base with its own mesh it
narrows the round peg the hole names in ``widened`` by that room per side alike (its
section as read, its pieces as written: narrowed about its axis), and the loader refuses
the product when that changes the peg's answer in any other hole (:func:`widened_fits`).
Both sides read the rule here, so they agree on which pairs the cell tries
(docs/decisions.md, "Nominal zero-clearance fits in the simulated cell").
"""

from __future__ import annotations

from bridge.product.tables import GeometryFile

NOMINAL_FIT_ROOM = 150e-6
"""[m] per side: the room the simulated cell builds a stated nominal zero-clearance fit with,
six times the 0.025 mm per side its physics resolves (looser than a real sliding fit: ISO
286's loose running fit 10 H11/c11 has 0.04 to 0.13 mm per side). The least of those
measured on ``occt_as1``'s six d 10 mm bolts in their 20 mm deep holes (``executor
teach``): at 0.05 mm per side bolt_a1 stopped 4.4 mm short of the bottom, at 0.10 mm
bolt_a2 3.2 mm short (the cell's goal tolerance is 3 mm), at 0.15 mm all six were taught
(docs/cell.md#nominal-zero-clearance-fits)."""


def models_nominal_fits(geometry: GeometryFile) -> bool:
    """Whether the simulated cell builds ``geometry``'s holes from their sections (a base of
    ``[plate]`` primitives), so that it can widen a hole by :data:`NOMINAL_FIT_ROOM` for the
    parts it states a nominal zero-clearance fit with; False for a base with its own mesh."""
    return geometry.base is None or geometry.base.mesh is None


def widened_fits(geometry: GeometryFile) -> dict[tuple[str, str], float]:
    """The (part, feature) pairs, sorted, whose room the simulated cell builds
    :data:`NOMINAL_FIT_ROOM` wider per side (a feature's ``widened``: the room, room 0 or
    positive, is under what the cell resolves): on a pin with the part's round bore that
    much wider, in a hole of a base that is its own mesh with the round peg that much
    narrower; each with the room per side [m] its sections state (the CAD's; both round,
    diameters)."""
    sizes = {pid: shape.size for shape in geometry.part_shapes.values() for pid in shape.parts}
    found: dict[tuple[str, str], float] = {}
    for shape in geometry.hole_shapes.values():
        for pid in shape.widened or ():
            part, feature = sizes[pid], shape.size
            assert not isinstance(part, list) and not isinstance(feature, list)  # round: checked as the file is read
            found |= {(pid, hid): (part - feature if shape.pin else feature - part) / 2 for hid in shape.holes}
    return dict(sorted(found.items()))


def stated_nominal_fits(geometry: GeometryFile) -> list[tuple[str, str]]:
    """The (part, hole) pairs ``geometry`` states as nominal zero-clearance fits, sorted."""
    return sorted((pid, hid) for shape in geometry.hole_shapes.values() for hid in shape.holes
                  for pid in shape.zero_clearance or ())
