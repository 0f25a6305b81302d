"""Features beyond the base's holes and pins: the hole of a moving part a part passes (a
rod through a bracket's bore), a peg's far end a part goes onto (a nut under the plate on
a bolt put in from above), and the owner of every feature placed before the part in it,
even where the part touches nothing (a peg standing on the floor through a hole of the
base)."""

from __future__ import annotations

from pathlib import Path

import pytest
import trimesh

from executor.cad.derive import derive
from executor.cad.parts import load_meshes


def _cylinder(radius: float, low: float, high: float, at: tuple[float, float], along: str = "z") -> trimesh.Trimesh:
    """A round bar of ``radius`` [mm] from ``low`` to ``high`` [mm] along ``along`` (x or
    z), its axis through ``at`` (y, z for x; x, y for z) [mm]."""
    bar = trimesh.creation.cylinder(radius=radius, height=high - low, sections=64)
    if along == "x":
        bar.apply_transform(trimesh.transformations.rotation_matrix(1.5707963267948966, (0.0, 1.0, 0.0)))
        bar.apply_translation(((low + high) / 2, at[0], at[1]))
    else:
        bar.apply_translation((at[0], at[1], (low + high) / 2))
    return bar


def _box(lower: tuple[float, float, float], upper: tuple[float, float, float]) -> trimesh.Trimesh:
    box = trimesh.creation.box(extents=[b - a for a, b in zip(lower, upper, strict=True)])
    box.apply_translation([(a + b) / 2 for a, b in zip(lower, upper, strict=True)])
    return box


def _less(mesh: trimesh.Trimesh, *cuts: trimesh.Trimesh) -> trimesh.Trimesh:
    return trimesh.boolean.difference([mesh, *cuts], engine="manifold")


def _write(folder: Path) -> None:
    """A 120 x 60 x 10 mm plate with a 10.5 mm hole at x -30 holding a bolt (10 mm shank,
    its head on the plate, its end 6 mm under it) with a nut on that end 1 mm under the
    plate, a 10 mm hole at x 0 holding an 8 mm peg standing on the floor, 1 mm from the hole
    all round, and a bracket on the plate at x 20 to 40 with an 8.5 mm bore along x at z 30
    that an 8 mm rod passes (x 10 to 50)."""
    folder.mkdir()
    plate = _less(_box((-60, -30, 0), (60, 30, 10)), _cylinder(5.25, -1, 11, (-30, 0)), _cylinder(5, -1, 11, (0, 0)))
    parts = {
        "plate": plate,
        "bolt": trimesh.boolean.union([_cylinder(5, -6, 10.5, (-30, 0)), _cylinder(8, 10, 13, (-30, 0))],
                                      engine="manifold"),
        "nut": _less(_box((-38, -8, -5), (-22, 8, -1)), _cylinder(5.25, -6, 0, (-30, 0))),
        "peg": _cylinder(4, 0, 20, (0, 0)),
        "bracket": _less(_box((20, -15, 10), (40, 15, 40)), _cylinder(4.25, 19, 41, (0, 30), along="x")),
        "rod": _cylinder(4, 10, 50, (0, 30), along="x"),
    }
    for name, mesh in parts.items():
        assert mesh.is_watertight, name
        mesh.export(folder / f"{name}.stl")


@pytest.mark.slow  # six parts swept (about 3 s)
def test_a_bracket_s_bore_and_a_bolt_s_end_are_features(tmp_path: Path) -> None:
    _write(tmp_path / "meshes")
    derived = derive(load_meshes(tmp_path / "meshes", "mm"), "plate", {})
    (hole,) = derived.part_holes.values()
    # The rod is free both ways along x: it leaves along -x, so it goes in along +x, which the arm reaches
    # sideways (executor.cad.derive.LEAVING), not along -x, which it does not.
    assert (hole.id, hole.owner, hole.part, hole.axis, hole.hole.kind) == ("bracket_hole1", "bracket", "rod", "-x",
                                                                         "round")
    assert hole.hole.a == pytest.approx(0.0085, abs=2e-5) and hole.depth == pytest.approx(0.02, abs=1e-6)
    # The bolt passes the plate only: its hole is the plate's, no part's.
    assert {fit.part for fit in derived.holes.values()} == {"bolt", "peg"}
    # The nut goes onto the bolt's end from below; the peg, in along the bolt's axis, is no part over it.
    assert {(pin.id, pin.owner, pin.parts) for pin in derived.pins.values()} == {("bolt_pin1", "bolt", ("nut",))}
    assert derived.bores["nut"].a == pytest.approx(0.0105, abs=2e-5)
    # Each owner first: the rod and the nut by the locating rule, the bolt touching the
    # plate; the peg touches nothing, and goes in after the plate for its hole.
    assert {pair: derived.reasons[pair] for pair in [("bracket", "rod"), ("bolt", "nut"), ("plate", "bolt"),
                                                     ("plate", "peg")]} == {
        ("bracket", "rod"): "locates", ("bolt", "nut"): "locates", ("plate", "bolt"): "base",
        ("plate", "peg"): "feature"}
    assert "blocks" not in {derived.reasons[pair] for pair in [("plate", "peg"), ("bracket", "rod")]}


@pytest.mark.slow  # four parts swept (about 3 s)
def test_rings_on_a_pin_are_in_the_hole_of_a_holder_around_them(tmp_path: Path) -> None:
    # flynn_clutch's plates on its shaft, their splined outsides in the outer holder's hole,
    # as squares: two rings (20 mm square outside, a d 10.4 bore) stacked on a d 10 pin of
    # the plate, in the 20.6 mm square hole of a holder floating 0.1 mm above the plate.
    folder = tmp_path / "meshes"
    folder.mkdir()
    parts = {
        "plate": trimesh.boolean.union([_box((-40, -40, 0), (40, 40, 10)), _cylinder(5, 9, 20, (0, 0))],
                                       engine="manifold"),
        "ring_a": _less(_box((-10, -10, 10), (10, 10, 12)), _cylinder(5.2, 9, 13, (0, 0))),
        "ring_b": _less(_box((-10, -10, 12), (10, 10, 14)), _cylinder(5.2, 11, 15, (0, 0))),
        "holder": _less(_box((-20, -20, 10.1), (20, 20, 16)), _box((-10.3, -10.3, 9), (10.3, 10.3, 17))),
    }
    for name, mesh in parts.items():
        assert mesh.is_watertight, name
        mesh.export(folder / f"{name}.stl")
    derived = derive(load_meshes(folder, "mm"), "plate", {})
    (hole,) = derived.part_holes.values()
    assert (hole.id, hole.owner, list(hole.occupants), hole.hole.kind) == (
        "holder_hole1", "holder", ["ring_a", "ring_b"], "square")
    assert hole.hole.a == pytest.approx(0.0206, abs=2e-6)
    assert all(section.a == pytest.approx(0.02, abs=2e-6) for section in hole.occupants.values())
    # each ring onto the pin through its bore, and into the holder's hole: the holder first
    assert {pid for pin in derived.pins.values() for pid in pin.parts} >= {"ring_a", "ring_b"}
    assert {pair: derived.reasons.get(pair) for pair in [("holder", "ring_a"), ("holder", "ring_b")]} == {
        ("holder", "ring_a"): "feature", ("holder", "ring_b"): "feature"}


@pytest.mark.slow  # four parts swept (about 3 s)
def test_a_bolt_through_a_bracket_into_the_plate_is_in_the_bracket_s_hole_on_the_plate_hole_s_line(
        tmp_path: Path) -> None:
    # A plate with two d 10.2 holes at x -20 and 20, a bracket on it over the first with a
    # d 10.6 flange hole on its line, a bolt (a d 10 shank, its head on the bracket) through
    # both, and a bolt in the second hole alone: the flange hole is a feature holding the
    # first bolt (0.3 mm all round), on h1's line (the planner's one place with h1), after
    # the bracket; the second bolt passes no hole of a part.
    folder = tmp_path / "meshes"
    folder.mkdir()
    parts = {
        "plate": _less(_box((-40, -20, 0), (40, 20, 10)), _cylinder(5.1, -1, 11, (-20, 0)),
                       _cylinder(5.1, -1, 11, (20, 0))),
        "bracket": _less(_box((-35, -15, 10), (-5, 15, 20)), _cylinder(5.3, 9, 21, (-20, 0))),
        "bolt_a": trimesh.boolean.union([_cylinder(5, 0, 20.5, (-20, 0)), _cylinder(8, 20, 23, (-20, 0))],
                                        engine="manifold"),
        "bolt_b": trimesh.boolean.union([_cylinder(5, 0, 10.5, (20, 0)), _cylinder(8, 10, 13, (20, 0))],
                                        engine="manifold"),
    }
    for name, mesh in parts.items():
        assert mesh.is_watertight, name
        mesh.export(folder / f"{name}.stl")
    derived = derive(load_meshes(folder, "mm"), "plate", {})
    assert {pid: fit.id for pid, fit in derived.hole_of.items()} == {"bolt_a": "h1", "bolt_b": "h2"}
    (hole,) = derived.part_holes.values()
    assert (hole.id, hole.owner, list(hole.occupants), hole.line) == ("bracket_hole1", "bracket", ["bolt_a"], "h1")
    assert hole.hole.a - hole.occupants["bolt_a"].a == pytest.approx(0.0006, abs=2e-5)
    assert ("bracket", "bolt_a") in derived.reasons and derived.in_holes["bolt_a"].id == "h1"
