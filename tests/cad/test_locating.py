"""The locating rule of ``import`` (executor/cad/locating.py) on small products of boxes:
a washer on a plate that only a peg through it locates goes after the peg; one located
by two pegs gets no pair; a pair the blocking contradicts (a bolt's head over the washer)
is dropped; reach 0 turns the rule off."""

from __future__ import annotations

import math

import pytest
import trimesh

from executor.cad.derive import derive
from executor.cad.parts import CadPart

MM = 1e-3


def _box(extents: tuple[float, float, float], centre: tuple[float, float, float]) -> trimesh.Trimesh:
    """A box [m] from extents and centre [mm]."""
    mesh = trimesh.creation.box([MM * e for e in extents])
    mesh.apply_translation([MM * c for c in centre])
    return mesh


def _part(pid: str, mesh: trimesh.Trimesh) -> CadPart:
    return CadPart(pid, pid, mesh, f"{pid}.stl")


def _product(pegs: list[float], head: bool = False) -> list[CadPart]:
    """A 100 x 100 x 20 mm plate (top at z 10 mm) with a 10.5 mm square hole 15 mm deep at
    each x of ``pegs`` [mm], a 10 mm square peg standing 25 mm out of each (with ``head``: a 20 mm
    square head on top, a bolt), and a 4 mm washer lying on the plate over all of them,
    its openings 12 mm square (1 mm of play a side)."""
    plate = trimesh.boolean.difference([_box((100, 100, 20), (0, 0, 0)),
                                        *(_box((10.5, 10.5, 16), (x, 0, 3)) for x in pegs)], engine="manifold")
    parts = [_part("plate", plate)]
    for k, x in enumerate(pegs):
        peg = _box((10, 10, 40), (x, 0, 15))
        if head:
            peg = trimesh.boolean.union([peg, _box((20, 20, 4), (x, 0, 37))], engine="manifold")
        parts.append(_part(f"peg{k}", peg))
    washer = trimesh.boolean.difference([_box((90, 30, 4), (0, 0, 12)),
                                         *(_box((12, 12, 10), (x, 0, 12)) for x in pegs)], engine="manifold")
    return [*parts, _part("washer", washer)]


def test_a_part_only_a_peg_locates_goes_after_the_peg() -> None:
    derived = derive(_product([0.0]), "plate", {})
    assert derived.reasons == {("plate", "peg0"): "base", ("plate", "washer"): "base", ("peg0", "washer"): "locates"}
    assert derived.located["washer"] == {"+z": set(), "-z": {"plate"}, "+x": {"peg0"}, "-x": {"peg0"},
                                         "+y": {"peg0"}, "-y": {"peg0"}}
    assert not derived.dropped
    assert derive(_product([0.0]), "plate", {}, reach=0.0).reasons == {
        ("plate", "peg0"): "base", ("plate", "washer"): "base"}
    # Moved 0.5 mm the washer meets nothing: its 1 mm of play is beyond that reach.
    assert ("peg0", "washer") not in derive(_product([0.0]), "plate", {}, reach=0.5 * MM).edges


def test_a_part_two_pegs_locate_gets_no_pair() -> None:
    derived = derive(_product([-20.0, 20.0]), "plate", {})
    assert derived.located["washer"]["+x"] == {"peg0", "peg1"}
    assert {pair for pair, reason in derived.reasons.items() if reason == "locates"} == set()


@pytest.mark.parametrize("reach", [1.5 * MM, 3 * MM])
def test_a_locating_pair_the_blocking_contradicts_is_dropped(reach: float) -> None:
    derived = derive(_product([0.0], head=True), "plate", {}, reach)
    assert derived.reasons[("washer", "peg0")] == "blocks"  # the bolt's head lies over the washer
    assert derived.dropped == {("peg0", "washer")} and ("peg0", "washer") not in derived.edges


def _ring(pid: str, inner: float, outer: float, start: float, end: float, sections: int) -> CadPart:
    """A ring along x from ``start`` to ``end`` [mm] at 30 mm height, bore ``inner``, outside ``outer`` [mm]."""
    ring = trimesh.creation.annulus(r_min=inner * MM, r_max=outer * MM, height=(end - start) * MM, sections=sections)
    ring.apply_transform(trimesh.transformations.rotation_matrix(math.pi / 2, (0, 1, 0)))
    ring.apply_translation(((start + end) / 2 * MM, 0, 30 * MM))
    return _part(pid, ring)


def test_a_ring_that_slides_on_along_its_shaft_is_located_by_the_shaft_alone() -> None:
    """A housing bored along x (r 16 mm), a bearing in it, a horizontal shaft through the
    bearing, then a spacer and a pulley on the shaft outside the housing, all at zero
    clearance. Lowered from above (once the shaft is out) the spacer is located along x by
    the bearing and the pulley alone; slid on along the shaft from outside it stops on the
    bearing, and from inside (through the bore) on the pulley: only the shaft locates it
    whichever way it goes in. The pulley, lowered or slid on, stops on the spacer."""
    bore = trimesh.creation.cylinder(radius=16 * MM, height=62 * MM, sections=64)
    bore.apply_transform(trimesh.transformations.rotation_matrix(math.pi / 2, (0, 1, 0)))
    bore.apply_translation((0, 0, 30 * MM))
    housing = trimesh.boolean.difference([trimesh.boolean.union(
        [_box((80, 50, 5), (0, 0, -2.5)), _box((60, 50, 60), (0, 0, 30))], engine="manifold"), bore],
        engine="manifold")
    shaft = trimesh.creation.cylinder(radius=8 * MM, height=130 * MM, sections=43)
    shaft.apply_transform(trimesh.transformations.rotation_matrix(math.pi / 2, (0, 1, 0)))
    shaft.apply_translation((0, 0, 30 * MM))
    parts = [_part("housing", housing), _part("shaft", shaft), _ring("bearing", 8, 16, -30, -18, 45),
             _ring("spacer", 8, 12, -40, -30, 47), _ring("pulley", 8, 25, -55, -40, 49)]
    derived = derive(parts, "housing", {})
    assert derived.located["spacer"]["+x"] == {"bearing"} and derived.located["spacer"]["-x"] == {"pulley"}
    assert {pair for pair, reason in derived.reasons.items() if reason == "locates"} == {
        ("shaft", "spacer"), ("shaft", "pulley"), ("spacer", "pulley")}


def test_a_part_is_located_by_what_it_meets_first_not_by_what_lies_beyond() -> None:
    # A 10 mm square peg in the plate (0.25 mm of play a side), a sleeve on it at zero
    # clearance (13 mm square) and a flange round the sleeve with 0.5 mm of play a side,
    # both lying on the plate. Moved 3 mm sideways the sleeve meets the peg at once and the
    # flange after 0.5 mm; the flange meets the sleeve after 0.5 mm and the peg 2 mm on,
    # through the sleeve. Each is located by the one it meets first (cubefactory_cutting_unit's
    # coupling on the shaft's end and its clamping flange).
    plate = trimesh.boolean.difference([_box((100, 100, 20), (0, 0, 0)), _box((10.5, 10.5, 16), (0, 0, 3))],
                                       engine="manifold")
    sleeve = trimesh.boolean.difference([_box((13, 13, 10), (0, 0, 15)), _box((10, 10, 12), (0, 0, 15))],
                                        engine="manifold")
    flange = trimesh.boolean.difference([_box((30, 30, 4), (0, 0, 12)), _box((14, 14, 6), (0, 0, 12))],
                                        engine="manifold")
    parts = [_part("plate", plate), _part("peg", _box((10, 10, 40), (0, 0, 15))), _part("sleeve", sleeve),
             _part("flange", flange)]
    derived = derive(parts, "plate", {})
    assert derived.located["sleeve"]["+x"] == {"peg", "flange"} and derived.located["flange"]["+x"] == {"sleeve", "peg"}
    assert derived.nearer["sleeve"]["+x"][0] == {"peg"} and derived.nearer["flange"]["+x"][0] == {"sleeve"}
    assert {pair: why for pair, why in derived.reasons.items() if why == "locates"} == {
        ("peg", "sleeve"): "locates", ("sleeve", "flange"): "locates"}
