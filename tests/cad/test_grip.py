"""The fingers' grip: a peg is held over at most what stands out of the product at its goal
less the clearance, at least the minimum grip; a peg standing out less goes on the suction
cup or by hand with why; one standing out well is held the gripper's grasp depth; a part
with a bore onto a pin by the same rule, by hand where it stands out less
(docs/cell.md#the-fingers-grip)."""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

import numpy as np
import pytest
import shapely
import trimesh

from assembly_constraints.cli import main
from executor.assembly.product import load_product
from executor.assembly.step import Assembler
from executor.assembly.world import AssemblyWorld
from executor.cad.derive import Derived, derive
from executor.cad.operations import fingers
from executor.cad.operations.pins import onto_pin
from executor.cad.parts import CadPart
from executor.cad.write.geometry import _bore_grip_lines
from executor.cell_description import CellDescription, load_cell_description
from executor.trial import Cell
from executor.world.geometry import load_geometry
from tests.cad.conftest import teach
from tests.cad.test_covers import _solid
from tests.cad.test_mesh_import import _box
from tests.cad.test_pins import _prism, _round

X = 560.0
"""[mm] where the plate's centre stands: where the simulated arm reaches."""


def _plate_and_pegs(folder: Path, rib: bool = False) -> None:
    """A 120 x 80 x 20 mm plate (top at z 20) with three 13 mm square holes 15 mm deep, 35 mm
    apart along x; in them 12 mm square pegs standing on the bottoms: peg1 45 mm long (30 mm
    out), peg2 23 mm (8 mm out), peg3 a 19 mm body under a 1.5 mm pyramid (5.5 mm out, its
    top pointed); with ``rib``, the plate has a rib 4 x 20 mm and 80 mm high 6 mm beside peg1
    (its side along y): in the fingers' way closing along x, not along y."""
    folder.mkdir()
    holes = [_box((13, 13, 15.001), (X + dx, 0, 12.5)) for dx in (-35, 0, 35)]
    plate = _solid(_box((120, 80, 20), (X, 0, 10)), *holes)
    if rib:
        plate = trimesh.boolean.union([plate, _box((4, 20, 80), (X - 35 + 14, 0, 59.99))], engine="manifold")
    plate.export(folder / "plate.stl")
    _box((12, 12, 45), (X - 35, 0, 27.5)).export(folder / "peg1.stl")
    _box((12, 12, 23), (X, 0, 16.5)).export(folder / "peg2.stl")
    corners = [(X + 35 + sx * 6, sy * 6, z) for sx in (-1, 1) for sy in (-1, 1) for z in (5.0, 24.0)]
    trimesh.convex.convex_hull([*corners, (X + 35, 0.0, 25.5)]).export(folder / "peg3.stl")


@pytest.mark.slow  # imports the product and builds its assembling cell (about 10 s under load)
def test_a_peg_is_held_over_what_stands_out_of_the_product(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _plate_and_pegs(tmp_path / "cad", rib=True)
    assert main(["import", str(tmp_path / "cad"), "--out", str(tmp_path / "out")]) == 0
    printed = capsys.readouterr().out
    assert ("manual peg3: the cell has no operation for it, a plan's step places it by hand (part 'peg3' stands out "
            "of the product by 5.500 mm at its goal ('plate' where the fingers are), less than the 6 mm the "
            "fingers need, and its top is not flat for the suction cup)") in printed
    shapes = tomllib.loads((tmp_path / "out" / "geometry.toml").read_text())["part_shapes"]
    assert set(shapes) == {"peg1", "peg2"}
    # 30 mm out, the fingers closing along y clear of the rib: the fingers' 20
    assert "grasp_depth" not in shapes["peg1"] and "tool" not in shapes["peg1"]
    assert shapes["peg2"]["grasp_depth"] == pytest.approx(0.007, abs=1e-9)  # 8 mm out, 1 mm clear
    assert "assumes: " in printed and "the fingers hold a peg over its top 20 mm, less where it stands out" in printed
    geometry = load_geometry(str(tmp_path / "out"))
    gripper = geometry.gripper
    # The wrist clear of the rib's top (99.99 mm) with peg2 at its goal held 7 mm under its top
    # (28 mm): a flange of 99.99 - 21 + 10 mm, rounded up (held 20 mm deep it would be 102 mm).
    assert gripper.flange_length == pytest.approx(0.089)
    assert geometry.parts["peg1"].held_depth(gripper) == pytest.approx(0.02)
    assert geometry.parts["peg2"].held_depth(gripper) == pytest.approx(0.007)
    # The assembling cell holds each that deep: the tool at its grip point, that far under its top.
    world = AssemblyWorld(load_product(str(tmp_path / "out")), gains=load_cell_description(None).gains)
    try:
        for pid, held in (("peg1", 0.02), ("peg2", 0.007)):
            assert np.allclose(world.frames[pid].grip, [0.0, 0.0, geometry.parts[pid].length - held])
    finally:
        world.close()


@pytest.mark.slow  # imports the product (about 6 s under load)
def test_a_peg_standing_out_less_with_a_flat_top_goes_on_the_suction_cup(tmp_path: Path) -> None:
    # peg3 20.5 mm long with a flat top: 5.5 mm out, less than the fingers need; a 10 mm cup
    # lies on its 12 mm square top.
    _plate_and_pegs(tmp_path / "cad")
    _box((12, 12, 20.5), (X + 35, 0, 15.25)).export(tmp_path / "cad" / "peg3.stl")
    with pytest.MonkeyPatch.context() as patch:
        patch.setitem(fingers.GRIPPER, "cup_diameter", 0.01)
        assert main(["-q", "import", str(tmp_path / "cad"), "--out", str(tmp_path / "out")]) == 0
    shapes = tomllib.loads((tmp_path / "out" / "geometry.toml").read_text())["part_shapes"]
    assert shapes["peg3"]["tool"] == "suction" and "grasp_depth" not in shapes["peg3"]


def test_the_fingers_meet_a_neighbour_reaching_under_the_top_and_turn_away_from_it() -> None:
    # Pads 10 x 20 mm on either side of a 12 mm square: a 10 mm block whose side is 1 mm
    # into them (whole, and its walls only, cut at 10 mm), a wedge rising outwards from inside
    # them, a block 2 mm beyond them.
    pads = shapely.union_all([shapely.box(0.006, -0.01, 0.016, 0.01), shapely.box(-0.016, -0.01, -0.006, 0.01)])
    block = trimesh.creation.box((0.01, 0.01, 0.03))
    block.apply_translation((0.02, 0.0, 0.0))
    assert fingers._highest_in(block.vertices[block.faces], pads, -1.0) == pytest.approx(0.015)
    assert fingers._highest_in(block.vertices[block.faces], pads, 0.02) is None  # none above 20 mm
    wedge = trimesh.convex.convex_hull([(x, y, z) for x in (0.0, 0.03) for y in (-0.005, 0.005)
                                        for z in (0.0, 0.001 + x)])  # its top 1 mm at x 0, 31 mm at x 30
    wedge.apply_translation((0.013, 0.0, 0.0))  # from x 13, 4 mm high where the pad ends (x 16)
    assert fingers._highest_in(wedge.vertices[wedge.faces], pads, -1.0) == pytest.approx(0.004)
    walls = trimesh.intersections.slice_mesh_plane(block, (0.0, 0.0, -1.0), (0.0, 0.0, 0.01))  # open at 10 mm
    assert fingers._highest_in(walls.vertices[walls.faces], pads, -1.0) == pytest.approx(0.01)
    beyond = block.copy().apply_translation((0.003, 0.0, 0.0))
    assert fingers._highest_in(beyond.vertices[beyond.faces], pads, -1.0) is None


def _washer_on_a_pin(thick: float, wall: float) -> Derived:
    """A 60 x 60 x 10 mm base with a d 10 pin 30 mm above its top, and a washer (d 24, a
    d 10.5 bore, ``thick`` [mm]) on that top down the pin; where ``wall`` [mm] is positive,
    a ring wall of the base (d 34 to 50) that high around the washer, where the fingers
    are, slit through along a diagonal (a closed ring would make a pocket around the pin, its
    island); derived (lengths in metres)."""
    mm = 1e-3
    slit = shapely.affinity.rotate(shapely.box(-30 * mm, -1 * mm, 30 * mm, 1 * mm), 45.0, origin=(0.0, 0.0))
    around = shapely.Point(0.0, 0.0).buffer(25 * mm, quad_segs=16).difference(
        shapely.Point(0.0, 0.0).buffer(17 * mm, quad_segs=16)).difference(slit)
    base = trimesh.boolean.union([_prism(shapely.box(-30 * mm, -30 * mm, 30 * mm, 30 * mm), 0.0, 10 * mm),
                                  _round(0.0, 5 * mm, 5 * mm, 40 * mm),
                                  *[_prism(half, 5 * mm, (10 + wall) * mm) for half in around.geoms if wall > 0]],
                                 engine="manifold")
    washer = _prism(shapely.Point(0.0, 0.0).buffer(12 * mm, quad_segs=32).difference(
        shapely.Point(0.0, 0.0).buffer(5.25 * mm, quad_segs=32)), 10 * mm, (10 + thick) * mm)
    return derive([CadPart("base", "base", base, "test"), CadPart("washer", "washer", washer, "test")], "base", {})


@pytest.mark.parametrize(("thick", "wall", "reason", "held"), [
    (4.0, 0.0, "stands out of the product by 4.000 mm at its goal, less than the 6 mm the fingers need", None),
    (12.0, 8.0, "stands out of the product by 4.000 mm at its goal ('base' where the fingers are), less than the "
                "6 mm the fingers need", None),
    (8.0, 0.0, None, 4.0), (12.0, 4.0, None, 6.0), (20.0, 12.0, None, 7.0)])
def test_a_part_onto_a_pin_is_the_fingers_only_where_it_stands_out_of_the_product_enough_for_them(
        thick: float, wall: float, reason: str | None, held: float | None) -> None:
    # The fingers hold a washer on a pin by its outside, as they hold a peg: a 4 mm washer on
    # the base's top, or a 12 mm one within a wall 8 mm high, stands out 4 mm, less than
    # their 5 mm grip and 1 mm clear of the product: placed by hand (the cell put it on, held
    # 2 mm deep, where a real hand's fingers would meet the base). An 8 mm washer, or a
    # 12 mm one within a wall 4 mm high, stands out 8 mm: the cell puts it on, held half its
    # length deep at most (4 and 6 mm); a 20 mm one within a 12 mm wall no deeper than the
    # fingers' 7 mm, which geometry.toml states as its grasp_depth.
    derived = _washer_on_a_pin(thick, wall)
    pin = derived.pin_of("washer")
    why = onto_pin(derived, pin, "washer")
    assert why == (None if reason is None else f"goes onto a pin ({pin.id}), but part 'washer' {reason}"), why
    if held is not None:
        assert fingers.bore_grip(derived, "washer", pin) == pytest.approx(held * 1e-3)
        lines = _bore_grip_lines(derived, "washer", thick * 1e-3)  # none where half its length is less
        stated = f"grasp_depth = {held * 1e-3:g}  # held {held:g} mm deep by the fingers: it stands out of the product"
        assert (lines[0].startswith(stated) if held < thick / 2 else lines == []), lines


@pytest.mark.slow  # imports, teaches peg2's skill, one trial and one assembly step in physics (about 60 s under load)
@pytest.mark.timeout(900)
def test_a_peg_held_shallower_is_taught_inserted_and_assembled(tmp_path: Path) -> None:
    # peg2 stands 8 mm out of the plate: held 7 mm deep, its skill taught so held, one trial
    # into its hole fits and the assembling cell puts it within 2 mm of its goal.
    _plate_and_pegs(tmp_path / "cad")
    assert main(["-q", "import", str(tmp_path / "cad"), "--out", str(tmp_path / "out")]) == 0
    out = teach(tmp_path / "out", {"peg2"})
    geometry = load_geometry(str(out))
    assert geometry.parts["peg2"].held_depth(geometry.gripper) == pytest.approx(0.007)
    hole = geometry.parts["peg2"].demo_hole
    cell = Cell(str(out))
    try:
        assert cell.run_trial("peg2", hole, 0, max_attempts=1).outcome == "fit"
    finally:
        cell.close()
    assembler = Assembler(load_product(str(out)), description=CellDescription())
    try:
        placed = [assembler.run_step(pid, where, 0) for pid, where in (("plate", None), ("peg2", hole))]
    finally:
        assembler.close()
    assert (placed[1].skill, placed[1].outcome) == ("insert", "fit")
    assert placed[1].pose_error < 0.002, placed[1].pose_error


@pytest.mark.slow  # imports the product (about 6 s under load)
def test_a_peg_goes_in_before_a_plate_that_would_meet_the_fingers(tmp_path: Path,
                                                                 capsys: pytest.CaptureFixture[str]) -> None:
    """A 45 mm peg 30 mm out of the base plate, in the 20 mm opening of a 25 mm high frame
    lying on the plate: nothing in the geometry orders them, but with the frame in place the
    peg stands 5 mm out, too little for the fingers' 20 mm grip. The import writes the
    cell's order and every plan puts the peg in first."""
    folder = tmp_path / "cad"
    folder.mkdir()
    _solid(_box((120, 80, 20), (X, 0, 10)), _box((13, 13, 15.001), (X, 0, 12.5))).export(folder / "plate.stl")
    _box((12, 12, 45), (X, 0, 27.5)).export(folder / "peg.stl")
    _solid(_box((60, 60, 25), (X, 0, 32.5)), _box((20, 20, 25.002), (X, 0, 32.5))).export(folder / "frame.stl")
    out = tmp_path / "out"
    assert main(["import", str(folder), "--out", str(out)]) == 0
    assert "'peg' goes in before 'frame'" in capsys.readouterr().out
    assert "cell_before(peg,frame)." in (out / "cell_order.lp").read_text()
    assert "cell_before" not in (out / "geometric_precedence.lp").read_text()
    facts = [str(out / "sizes.lp"), str(out / "geometric_precedence.lp")]
    assert main(["plan", *facts, "--assembly", str(out), "-n", "0", "--json"]) == 0
    found = json.loads(capsys.readouterr().out)["plans"]
    assert found and all([s["part"] for s in p].index("peg") < [s["part"] for s in p].index("frame") for p in found)
    # The product's precedence alone admits the frame first: the cell's order is what keeps it out.
    assert main(["plan", *facts, "-n", "0", "--json"]) == 0
    alone = json.loads(capsys.readouterr().out)["plans"]
    assert any([s["part"] for s in p].index("frame") < [s["part"] for s in p].index("peg") for p in alone)
