"""A part's bore round another part's outside on a common axis: a collar round a sleeve
that is on a shaft goes onto the sleeve (a pin of the sleeve, measured on its outside),
not onto the shaft inside both, whichever of them sorts first; a sleeve slit into halves
where the collar is and whole towards its free end is one pin (cubefactory_cutting_unit's
clamping flange round its coupling); two pins in one slot are none, nor two outlines of one
part one inside the other (a bearing's rings)."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
import trimesh

from executor.cad.derive import derive
from executor.cad.derive.loops import bore_around
from executor.cad.operations.rooms import margins
from executor.cad.parts import CadPart

MM = 1e-3


def _prism(outline: shapely.Geometry, low: float, high: float) -> trimesh.Trimesh:
    """``outline`` [mm] extruded from ``low`` to ``high`` [mm] along z, in metres."""
    solid = trimesh.creation.extrude_polygon(outline, high - low)
    solid.apply_translation((0.0, 0.0, low))
    solid.apply_scale(MM)
    return solid


def _disc(radius: float) -> shapely.Polygon:
    """A disc of ``radius`` [mm] about the origin."""
    return shapely.Point(0.0, 0.0).buffer(radius, quad_segs=16)


def _shaft_sleeve_collar(sleeve: str, slit: bool) -> dict[str, trimesh.Trimesh]:
    """A plate (z 0 to 10 mm) with a d 8 shaft standing 30 mm above it; a sleeve named
    ``sleeve`` (a d 20 flange 2 mm thick on the plate, a d 12 tube to z 40, its d 8.2 bore
    on the shaft), its tube cut into halves by a 2 mm slit from its flange to z 25 when
    ``slit``; a collar (d 24, its d 12.6 bore round the tube) on the flange, z 12 to 20."""
    plate = trimesh.boolean.union([_prism(shapely.box(-30, -30, 30, 30), 0, 10), _prism(_disc(4.0), 5, 40)],
                                  engine="manifold")
    tube = _disc(6.0)
    if slit:
        tube = tube.difference(shapely.box(-7, -1, 7, 1))
    parts = [_prism(_disc(10.0), 10, 12), _prism(_disc(6.0), 25, 40)]
    parts += [_prism(piece, 12, 25) for piece in shapely.get_parts(tube.difference(_disc(4.1)))]
    sleeve_mesh = trimesh.boolean.difference([trimesh.boolean.union(parts, engine="manifold"),
                                              _prism(_disc(4.1), 9, 41)], engine="manifold")
    collar = _prism(_disc(12.0).difference(_disc(6.3)), 12, 20)
    return {"base": plate, sleeve: sleeve_mesh, "collar": collar}


@pytest.mark.parametrize(("sleeve", "slit"), [("sleeve", False), ("adapter", False), ("sleeve", True)])
def test_a_collar_round_a_sleeve_on_a_shaft_goes_onto_the_sleeve(sleeve: str, slit: bool) -> None:
    # the shaft is the base's, so it is tried first ("base" before "sleeve"), or the sleeve
    # is ("adapter"): the collar's bore holds the shaft's outline too, inside the sleeve's
    derived = derive([CadPart(pid, pid, mesh, "test") for pid, mesh in
                      _shaft_sleeve_collar(sleeve, slit).items()], "base", {})
    assert {pin.id: (pin.owner, pin.parts) for pin in derived.pins.values()} == {
        "base_pin1": ("base", (sleeve,)), f"{sleeve}_pin1": (sleeve, ("collar",))}
    rooms = margins(derived)
    # diametral: 0.6 mm round the d 12 tube (a 16-gon's, within its sagitta), 4.6 round the d 8 shaft
    assert abs(rooms["collar"][f"{sleeve}_pin1"] - 0.6 * MM) < 0.15 * MM, rooms
    assert rooms[sleeve][f"{sleeve}_pin1"] < 0 < rooms["collar"]["base_pin1"], rooms


def test_two_pins_in_one_slot_are_no_pin() -> None:
    # a plate's slot holds two d 6 pins of the base, never joined along them: no one pin
    # (nor a pin each: the slot is one bore round both)
    base = trimesh.boolean.union([_prism(shapely.box(-30, -20, 30, 20), 0, 10)]
                                 + [_prism(shapely.Point(x, 0.0).buffer(3.0, quad_segs=16), 5, 25) for x in (-8, 8)],
                                 engine="manifold")
    slot = shapely.LineString([(-8, 0), (8, 0)]).buffer(3.3, quad_segs=16)
    plate = _prism(shapely.box(-20, -10, 20, 10).difference(slot), 10, 14)
    derived = derive([CadPart("base", "base", base, "test"), CadPart("plate", "plate", plate, "test")], "base", {})
    assert derived.pins == {}


def test_outlines_of_one_part_one_inside_another_are_no_pin() -> None:
    # a bearing-like part (an outer ring d 20, an inner ring d 12 inside it, joined by a cap
    # beyond): a collar's bore round both holds two outlines, one inside the other; which
    # of them it is on is not measured, so it is on no pin there
    rings = trimesh.boolean.union([_prism(_disc(10.0).difference(_disc(8.0)), 0, 10),
                                   _prism(_disc(6.0).difference(_disc(4.0)), 0, 10), _prism(_disc(10.0), 10, 12)],
                                  engine="manifold")
    collar = _prism(_disc(14.0).difference(_disc(10.3)), 2, 8)
    assert bore_around(collar, rings, np.array([0.0, 0.0, 1.0]), 5 * MM) is None
