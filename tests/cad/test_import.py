"""``import``: the shipped products' meshes in the assembled pose give back their holes,
kinds, sizes and fit relation; Cranfield's geometric precedence against the edges the
physics bench found enforced; a STEP assembly made by build123d; bad CAD refused."""

from __future__ import annotations

import math
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import clingo
import numpy as np
import pybullet_data
import pytest
import trimesh

from asp.precedence.relation import load_relation
from assembly_constraints.cli import main
from bridge.assembly import load_assembly
from executor.cad.cli import run_import
from executor.cad.convex import base_is_primitive
from executor.cad.derive import Derived, derive
from executor.cad.operations.arm import WRIST_RADIUS
from executor.cad.operations.rooms import margins
from executor.cad.operations.tools import finger_orders
from executor.cad.parts import CadPart, load_meshes
from executor.world.geometry import load_geometry

SIZE_BOUND = 5e-5
"""Imported sizes within this of the nominal ones [m] (0.05 mm)."""
PRODUCTS = ["cranfield", "taskboard", "graded", "spare"]
ENFORCED = {("bp", p) for p in ("p1", "p2", "p3", "p4", "sh")} | {("pd", "fp"), ("sh", "pd"), ("sp", "fp")}
NOT_ENFORCED = {("p1", "fp"), ("p2", "fp"), ("p3", "sp"), ("p4", "sp"), ("ph", "pd")}
"""docs/results.md, bench precedence-physics: the Cranfield edges a violating sequence broke or completed."""


def _fits(path: Path) -> set[tuple[str, str]]:
    control = clingo.Control(["--warn=none"])
    control.load(str(path))
    control.ground([("base", [])])
    return {(str(s.arguments[0]), str(s.arguments[1])) for s in control.symbolic_atoms.by_signature("fits", 2)
            for s in [s.symbol]}


@pytest.mark.slow
@pytest.mark.parametrize("product", PRODUCTS)
def test_round_trip_gives_back_holes_sizes_and_fits(imported: Callable[[str], tuple[Derived, Path]],
                                                    product: str) -> None:
    derived, out = imported(product)
    geometry = load_geometry(product)
    renamed: dict[str, str] = {}
    assert len(derived.holes) == len(geometry.holes)
    for hid, fit in derived.holes.items():
        hole = min(geometry.holes.values(), key=lambda h: math.dist(h.position, fit.position))
        assert math.dist(hole.position, fit.position) < SIZE_BOUND, (hid, hole.id)
        assert fit.hole.kind == hole.kind, (hid, hole.id)
        assert fit.hole.a == pytest.approx(hole.sides[0], abs=SIZE_BOUND)
        assert fit.hole.b == pytest.approx(hole.sides[1], abs=SIZE_BOUND)
        if hole.kind != "round":
            turn = 90.0 if hole.kind == "square" else 180.0
            assert (fit.hole.yaw - math.degrees(hole.yaw) + turn / 2) % turn == pytest.approx(turn / 2, abs=0.01)
        renamed[hid] = hole.id
        if fit.part is not None:
            peg = geometry.parts[fit.part]
            assert fit.section is not None and fit.section.kind == peg.kind
            assert (fit.section.a, fit.section.b) == pytest.approx(peg.sides, abs=SIZE_BOUND)
    assert len(set(renamed.values())) == len(renamed)
    truth = _fits(Path("data") / product / "sizes.lp")
    imported = {(p, renamed[h]) for p, h in _fits(out / "sizes.lp")}
    assert imported == {(p, h) for p, h in truth if p in derived.hole_of}
    load_assembly(str(out))
    assert {part.id for part in load_geometry(str(out)).layout.parts} == set(derived.parts)  # the cell takes it


@pytest.mark.slow
def test_cranfield_geometric_precedence_against_the_physics(
        imported: Callable[[str], tuple[Derived, Path]]) -> None:
    derived, out = imported("cranfield")
    closure = set(load_relation([out / "geometric_precedence.lp"]).pairs())
    assert closure & (ENFORCED | NOT_ENFORCED) == ENFORCED
    assert derived.stages == [["fp", "p1", "p2", "p3", "p4", "sh"], ["pd", "ph", "sp"]]  # ph moves with pd
    # The front plate rests on the pendulum and the spacer: the support rule orders them.
    assert {pair for pair, reason in derived.reasons.items() if reason == "supports"} == {("pd", "fp"), ("sp", "fp")}
    # The pendulum's opening is the big hole plus 0.5 mm: the shaft passes it whatever the
    # order, so no blocking orders them; the locating rule does (only the shaft keeps the
    # pendulum from sliding along x). Without it the geometry lacks that one edge.
    assert {pair for pair, reason in derived.reasons.items() if reason == "locates"} == {("sh", "pd")}
    assert "% sh->pd: locates" in (out / "geometric_precedence.lp").read_text()
    # The pegs stand 25 mm out of the base plate, 5 mm out of the front plate (the square
    # ones less out of the spacer too): the fingers' 20 mm grip needs each to go in before
    # them, the cell's own orders (cell_order.lp), which the true precedence holds.
    assert [order[:2] for order in finger_orders(derived)] == [
        ("p1", "fp"), ("p2", "fp"), ("p3", "fp"), ("p3", "sp"), ("p4", "fp"), ("p4", "sp")]
    parts = load_meshes(out.parent / "meshes", "m")
    blocking = derive(parts, "bp", {"ph": "pd"}, reach=0.0).edges
    assert blocking == derived.edges - {("sh", "pd")}


@pytest.mark.slow
def test_a_step_assembly_made_by_build123d(tmp_path: Path) -> None:
    script = tmp_path / "make.py"
    script.write_text(
        "from build123d import *\n"
        "plate = Box(100, 60, 20) - Pos(-20, 0, 2.5) * Cylinder(6.65, 15)\n"
        "plate = plate - Pos(20, 0, 2.5) * Rot(0, 0, 30) * Box(12.3, 8.3, 15)\n"
        "plate = plate - Pos(0, 20, 2.5) * Box(9, 9, 15)\n"
        "plate.label = 'plate'\n"
        "peg = Pos(-20, 0, 10) * Cylinder(6.0, 30); peg.label = 'round peg'\n"
        "rect = Pos(20, 0, 10) * Rot(0, 0, 30) * Box(12, 8, 30); rect.label = 'rect peg'\n"
        "cap = Pos(20, 0, 27) * Box(20, 20, 4); cap.label = 'cap'\n"
        f"export_step(Compound(label='product', children=[plate, peg, rect, cap]), {str(tmp_path / 'p.step')!r})\n"
        f"export_step(Compound(label='pegs', children=[plate, peg, rect]), {str(tmp_path / 'pegs.step')!r})\n")
    subprocess.run([sys.executable, str(script)], check=True)
    derived = run_import(tmp_path / "p.step", tmp_path / "out", "mm", None).derived
    assert derived.base == "plate"
    round_fit, rect_fit = derived.hole_of["round_peg"], derived.hole_of["rect_peg"]
    assert round_fit.section is not None and rect_fit.section is not None
    assert (round_fit.hole.kind, round_fit.section.kind) == ("round", "round")
    # the B-rep's cylinders give the round sizes exactly (a 1 µm tessellation's inscribed circle is smaller)
    assert round_fit.hole.a == pytest.approx(0.0133, abs=1e-9)
    assert round_fit.section.a == pytest.approx(0.012, abs=1e-9)
    assert (rect_fit.hole.kind, rect_fit.section.kind) == ("rect", "rect")
    assert (rect_fit.hole.a, rect_fit.hole.b) == pytest.approx((0.0123, 0.0083), abs=SIZE_BOUND)
    assert rect_fit.hole.yaw == pytest.approx(30.0, abs=0.01)
    assert margins(derived)["rect_peg"]["h3"] == pytest.approx(3e-4, abs=SIZE_BOUND)
    assert derived.edges == {("plate", "round_peg"), ("plate", "rect_peg"), ("rect_peg", "cap")}
    empty = derived.holes["h2"]
    assert (empty.part, empty.hole.kind, empty.depth) == (None, "square", pytest.approx(0.015, abs=SIZE_BOUND))
    assert _fits(tmp_path / "out" / "sizes.lp") == {("round_peg", "h1"), ("rect_peg", "h3")}
    # Without the cap the product is one of primitives: the cell's loader takes its geometry,
    # and the nominal sections decide every pair the learner would otherwise try.
    assert main(["import", str(tmp_path / "pegs.step"), "--out", str(tmp_path / "pegs")]) == 0
    geometry = load_geometry(str(tmp_path / "pegs"))
    assert (geometry.holes["h3"].kind, math.degrees(geometry.holes["h3"].yaw)) == ("rect", pytest.approx(30.0))
    assert geometry.parts["rect_peg"].sides == pytest.approx((0.012, 0.008), abs=SIZE_BOUND)
    for prior in ([], ["--prior", "cad", "--tolerance", "0.0005"]):
        assert main(["sizes", "learn", "--assembly", str(tmp_path / "pegs"), *prior, "--out",
                     str(tmp_path / "learned.lp")]) == 0
        assert _fits(tmp_path / "learned.lp") == _fits(tmp_path / "pegs" / "sizes.lp")


def _box(extents: tuple[float, float, float], centre: tuple[float, float, float]) -> trimesh.Trimesh:
    mesh = trimesh.creation.box(extents)
    mesh.apply_translation(centre)
    return mesh


def _plate_with_peg(folder: Path, peg_centre: tuple[float, float, float] = (0, 0, 10)) -> None:
    """A 100 x 100 x 20 mm plate with a 10.5 mm square hole and a 10 mm square peg in it [mm]."""
    folder.mkdir()
    plate = trimesh.boolean.difference([_box((100, 100, 20), (0, 0, 0)), _box((10.5, 10.5, 30), (0, 0, 0))],
                                       engine="manifold")
    plate.export(folder / "plate.stl")
    _box((10, 10, 40), peg_centre).export(folder / "peg.stl")


def _error(capsys: pytest.CaptureFixture[str], argv: list[str]) -> str:
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    return err[0]


def test_a_peg_in_a_plate_from_meshes(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _plate_with_peg(tmp_path / "cad")
    assert main(["import", str(tmp_path / "cad"), "--out", str(tmp_path / "out")]) == 0
    printed = capsys.readouterr().out
    # Drawn around the CAD origin, out of the arm's reach: placed at the cell's work position, and said so.
    assert ("the base's centre placed at (560.000, 0.000) mm in the cell (the base's centre 0.000 mm from the arm's "
            "base is out of its reach (350.000 to 700.000 mm)") in printed
    assert "hole h1 at (560.000, 0.000) mm, entered along -z: square 10.500 x 10.500 mm, depth 20.000 mm" in printed
    assert "holds peg (square 10.000 x 10.000 mm, clearance 0.500 mm: 0.250 mm all round at yaw 0.000 deg)" in printed
    assert sorted(load_geometry(str(tmp_path / "out")).parts) == ["peg"]
    assert _fits(tmp_path / "out" / "sizes.lp") == {("peg", "h1")}


def test_bad_cad_is_one_line_naming_the_part(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _plate_with_peg(tmp_path / "overlap", peg_centre=(3, 0, 10))
    assert "parts 'peg' and 'plate' overlap" in _error(capsys, ["import", str(tmp_path / "overlap"), "--out",
                                                              str(tmp_path / "o1")])
    _plate_with_peg(tmp_path / "open")
    peg = trimesh.load(tmp_path / "open" / "peg.stl")
    trimesh.Trimesh(peg.vertices, peg.faces[1:]).export(tmp_path / "open" / "peg.stl")
    assert "part 'peg' is an open mesh" in _error(capsys, ["import", str(tmp_path / "open"), "--out",
                                                          str(tmp_path / "o2")])
    _plate_with_peg(tmp_path / "units")
    small = trimesh.load(tmp_path / "units" / "peg.stl")
    small.apply_scale(1e-3)
    small.export(tmp_path / "units" / "peg.stl")
    assert "part 'peg' is" in _error(capsys, ["import", str(tmp_path / "units"), "--out", str(tmp_path / "o3")])
    (tmp_path / "caged").mkdir()
    cage = trimesh.boolean.difference([_box((40, 40, 40), (0, 0, 0)), _box((20, 20, 20), (0, 0, 0))],
                                      engine="manifold")
    cage.export(tmp_path / "caged" / "cage.stl")
    _box((10, 10, 10), (0, 0, 0)).export(tmp_path / "caged" / "bird.stl")
    assert "part(s) bird never come out" in _error(capsys, ["import", str(tmp_path / "caged"), "--out",
                                                          str(tmp_path / "o4")])


def test_the_wrist_the_import_keeps_clear_of_the_product_holds_the_arm_s_last_link() -> None:
    # The import makes the gripper's flange long enough that a circle of WRIST_RADIUS about
    # the tool's axis clears the product; the simulated arm's last link must lie within it.
    link = trimesh.load(Path(pybullet_data.getDataPath()) / "kuka_iiwa" / "meshes" / "link_7.stl", force="mesh")
    radius = float(np.hypot(link.vertices[:, 0], link.vertices[:, 1]).max())
    assert 0.05 < radius < WRIST_RADIUS


def _plate_with(hole: trimesh.Trimesh) -> Derived:
    """A 40 x 40 x 10 mm plate less ``hole`` [m], derived alone (its holes sliced at its middle)."""
    plate = trimesh.creation.box((0.04, 0.04, 0.01))
    plate.apply_translation((0.0, 0.0, 0.005))
    return derive([CadPart("plate", "plate", trimesh.boolean.difference([plate, hole], engine="manifold"), "test")],
                  "plate", {})


@pytest.mark.slow  # two plates cut and derived (9 s at load 33)
@pytest.mark.parametrize(("taper", "plate"), [(0.0, True), (math.radians(2.5), False)])
def test_a_plate_with_a_tapered_rect_hole_is_no_plate_of_straight_holes(taper: float, plate: bool) -> None:
    # A rect hole 2.5° a side (asap_beam's mortises) has the volume of its mid-depth section
    # times its depth, as a straight hole has: the cell's plate would give it straight walls,
    # which stop a tapered tenon half way in.
    spread = 0.012 * math.tan(taper)  # [m] per side, over its 12 mm (through the 10 mm plate)
    corners = [(x * (0.003 + s), y * (0.005 + s), z) for z, s in ((-0.001, 0.0), (0.011, spread))
               for x in (-1, 1) for y in (-1, 1)]
    derived = _plate_with(trimesh.convex.convex_hull(np.array(corners)))
    assert [fit.hole.kind for fit in derived.holes.values()] == ["rect"]
    assert base_is_primitive(derived) == plate
