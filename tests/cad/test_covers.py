"""``import`` maps covers and heads onto the cell's tables: the Cranfield round trip's
covers and head equal the shipped ones (within 0.05 mm, table by table, skills by the
stated rule), and the imported product is learned and assembled in the simulated cell;
a cover with round openings and a flanged head are simulated from their own meshes
(convex pieces) and rest where they belong (a part the cell cannot place:
``test_manual``)."""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pybullet as pb
import pytest
import trimesh

from assembly_constraints.cli import main
from executor import ExecutorError
from executor.assembly.product import MAX_COVER_BOXES, load_product
from executor.assembly.world import AssemblyWorld
from executor.cad.covers import GRIP_MARGIN
from executor.cad.derive import Derived
from executor.cad.write.geometry import DENSITY
from executor.cell_description import load_cell_description
from executor.world.meshes import read_objects
from tests.cad.test_import import _fits
from tests.cad.test_mesh_import import _box
from tests.conftest import ROOT, Runner

SIZE_BOUND = 5e-5
"""Imported lengths within this of the shipped ones [m] (0.05 mm)."""
POSE_BOUND_MM = 2.0
"""An assembled part is within this of its goal [mm] (the bar of the assembling cell)."""
SECTIONS = 24
"""The sides of the own-mesh cover's openings and socket and of the head's cylinders (CoACD
cuts the cover at its first threshold, 0.05; a 48-gon's cover it cuts twice, 2.5 times the CPU)."""
STEP_KEYS = {"part", "hole", "skill", "outcome", "attempts", "duration_s", "max_force_dev"}
"""What ``assemble --json`` reports of each step."""
REST_BOUND = 5e-4
"""A cover of convex pieces let go at its goal rests within this of it [m] (the hull margin,
1 mm, is what an uneroded piece would add)."""


def _shipped_holes(derived: Derived, shipped: dict) -> dict[str, str]:
    """Imported hole id -> the shipped hole at its position."""
    return {hid: min(shipped, key=lambda h: math.dist(shipped[h].position, fit.position))
            for hid, fit in derived.holes.items()}


def _on_top(boxes: tuple, grip: tuple[float, float], margin: float) -> bool:
    """Whether a disc of radius ``margin`` around ``grip`` lies on the boxes' top faces."""
    ring = [(grip[0] + margin * math.cos(a), grip[1] + margin * math.sin(a)) for a in np.linspace(0, 2 * math.pi, 32)]
    return all(any(abs(x - b.centre[0]) <= b.half[0] + 1e-9 and abs(y - b.centre[1]) <= b.half[1] + 1e-9
                   for b in boxes) for x, y in [grip, *ring])


@pytest.mark.slow
def test_cranfield_covers_and_head_equal_the_shipped_ones(imported: Callable[[str], tuple[Derived, Path]]) -> None:
    derived, out = imported("cranfield")
    shipped, mine = load_product("cranfield"), load_product(str(out))
    renamed = _shipped_holes(derived, shipped.geometry.holes)
    skill_parts = {name: set(shape.parts) for name, shape in shipped.geometry.tables.part_shapes.items()}
    assert set(mine.covers) == set(shipped.covers) and set(mine.heads) == set(shipped.heads)
    for cid, want in shipped.geometry.tables.covers.items():
        got = mine.geometry.tables.covers[cid]
        assert {renamed[h] for h in got.over} == set(want.over), cid
        for key in ("outline", "thickness", "bottom", "clearance", "socket", "tray"):
            value = getattr(want, key)
            assert getattr(got, key) == (None if value is None else pytest.approx(value, abs=SIZE_BOUND)), (cid, key)
        assert got.mesh is None and mine.covers[cid].boxes  # the cell's cover of boxes
        assert got.skill in skill_parts[want.skill], cid  # the largest peg through it
        volume = trimesh.load(out.parent / "meshes" / f"{cid}.obj", force="mesh").volume
        assert got.mass == pytest.approx(volume * DENSITY, rel=1e-6)
        assert _on_top(mine.covers[cid].boxes, (got.grip[0], got.grip[1]), GRIP_MARGIN - 1e-6), cid
    assert mine.geometry.tables.covers["sp"].grip == pytest.approx([0.0, 0.0], abs=SIZE_BOUND)  # its centre of mass
    for hid, want_head in shipped.geometry.tables.heads.items():
        got_head = mine.geometry.tables.heads[hid]
        assert (got_head.into, got_head.kind, got_head.mesh) == (want_head.into, want_head.kind, None)
        assert (got_head.size, got_head.length) == pytest.approx((want_head.size, want_head.length), abs=SIZE_BOUND)
        assert got_head.skill in skill_parts[want_head.skill]  # the nearest peg section
        assert mine.heads[hid].start == pytest.approx(shipped.heads[hid].start, abs=SIZE_BOUND)


@pytest.mark.slow
def test_the_imported_cranfield_is_learned_and_assembled_in_the_cell(
        imported: Callable[[str], tuple[Derived, Path]], run_main: Runner, tmp_path: Path) -> None:
    derived, out = imported("cranfield")
    # Cranfield's demonstrations refine the geometric prior into its true precedence (the
    # prior alone admits pegs inserted under covers: docs/import.md, Limits). The truth
    # backend answers from the imported sections (the shipped Cranfield's experiments in
    # physics: tests/session/); the plan learned is assembled by the sim cell.
    run = tmp_path / "run"
    done = run_main("session", "--backend", "truth", "--assembly", str(out), "--demos",
                    str(ROOT / "data" / "cranfield" / "demos.txt"), "--json", "--out", str(run))
    assert done.returncode == 0, done.stderr
    result = json.loads(done.stdout)
    renamed = _shipped_holes(derived, load_product("cranfield").geometry.holes)
    assert {(p, renamed[h]) for p, h in result["fits"]} == _fits(ROOT / "data" / "cranfield" / "sizes.lp")
    done = run_main("executor", "teach", "--assembly", str(out))
    assert done.returncode == 0, done.stderr
    done = run_main("assemble", "--run", str(run), "--json")
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    assert report["assembled"] and set(report["final_pose_error_mm"]) == set(derived.parts)
    assert len(report["steps"]) == 10 and all(STEP_KEYS <= set(step) for step in report["steps"])
    assert [step["outcome"] for step in report["steps"]] == ["fit"] * 10
    assert "truth" not in {step["skill"] for step in report["steps"]}  # the sim cell's skills, not the truth's
    assert max(report["final_pose_error_mm"].values()) <= POSE_BOUND_MM, report["final_pose_error_mm"]


def _solid(mesh: trimesh.Trimesh, *cuts: trimesh.Trimesh) -> trimesh.Trimesh:
    return trimesh.boolean.difference([mesh, *cuts], engine="manifold") if cuts else mesh


def _cylinder(radius: float, height: float, centre: tuple[float, float, float]) -> trimesh.Trimesh:
    mesh = trimesh.creation.cylinder(radius=radius, height=height, sections=SECTIONS)
    mesh.apply_translation(centre)
    return mesh


def _pegs_and_plate(folder: Path, at: tuple[float, float]) -> None:
    """A 120 x 80 x 20 mm plate (top at z 20) with two 13 mm square holes 15 mm deep 50 mm
    apart along x around ``at`` [mm], a 12 mm square peg 30 mm long in each (15 mm out)."""
    folder.mkdir()
    x, y = at
    holes = [_box((13, 13, 15.001), (x + dx, y, 12.5)) for dx in (-25, 25)]
    _solid(_box((120, 80, 20), (x, y, 10)), *holes).export(folder / "plate.stl")
    for k, dx in enumerate((-25, 25)):
        _box((12, 12, 30), (x + dx, y, 20)).export(folder / f"peg{k + 1}.stl")


@pytest.mark.slow
def test_a_cover_and_a_head_of_their_own_meshes(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    x, y = 560.0, 0.0  # [mm]: where the simulated arm reaches
    _pegs_and_plate(tmp_path / "cad", (x, y))
    openings = [_cylinder(11, 20, (x + dx, y, 26)) for dx in (-25, 25)]  # round: no cell's cover
    socket = _cylinder(6, 4.001, (x, y, 30 - 2 + 0.0005))
    _solid(_box((90, 34, 10), (x, y, 25)), *openings, socket).export(tmp_path / "cad" / "bar.stl")
    head = trimesh.boolean.union([_cylinder(4, 4, (x, y, 28)), _cylinder(7, 3, (x, y, 31.5))], engine="manifold")
    head.export(tmp_path / "cad" / "knob.stl")  # a flanged head: no cylinder
    (tmp_path / "import.toml").write_text("[parts.bar]\ntray = [0.30, 0.28]\n[parts.knob]\ntray = [0.45, 0.28]\n")
    assert main(["import", str(tmp_path / "cad"), "--out", str(tmp_path / "out"), "--config",
                 str(tmp_path / "import.toml")]) == 0
    printed = capsys.readouterr().out
    assert "cover bar over h1 h2 on plate" in printed and "no cell's cover: its own mesh" in printed
    assert "head knob into bar: round d 8.000" in printed and "no cylinder or box: its own mesh" in printed
    product = load_product(str(tmp_path / "out"))
    cover, knob = product.geometry.tables.covers["bar"], product.geometry.tables.heads["knob"]
    assert cover.mesh is not None and cover.mesh.convex is not None and not product.covers["bar"].boxes
    assert len(read_objects(tmp_path / "out" / cover.mesh.convex)) >= 2  # a decomposition, not its hull
    assert knob.mesh is not None and knob.skill in ("peg1", "peg2")
    inscribed = 0.012 * math.cos(math.pi / SECTIONS)  # the polygon's inscribed diameter [m]
    assert cover.socket == pytest.approx([0.0, 0.0, inscribed, 0.004], abs=1e-6)
    own = trimesh.load(tmp_path / "out" / cover.mesh.file, force="mesh")
    assert own.bounds[0] == pytest.approx([-0.045, -0.017, 0.0], abs=1e-6)  # the cover's frame
    world = AssemblyWorld(product, gains=load_cell_description(None).gains)
    try:
        world.set_pose("plate", world.goals["plate"])  # into its fixture
        for part in ("bar", "knob"):  # let go just above their goals, they settle where the CAD has them
            goal = world.goals[part] if part == "bar" else world.goals["bar"] + world.socket_offset["knob"]
            world.set_pose(part, goal + np.array([0.0, 0.0, 2e-4]))
            for _ in range(300):
                pb.stepSimulation(physicsClientId=world.client)
            assert np.linalg.norm(world.position(part) - goal) < REST_BOUND, part
    finally:
        world.close()


def test_a_cover_of_more_boxes_than_the_cell_holds_is_refused(tmp_path: Path) -> None:
    folder = tmp_path / "graded"
    folder.mkdir()
    for name in ("assembly.toml", "geometry.toml"):
        (folder / name).write_text((ROOT / "data" / "graded" / name).read_text())
    text = (folder / "geometry.toml").read_text()  # the bar over all seven holes: 32 boxes
    text = text.replace('over = ["h5", "h6"]', f"over = {json.dumps([f'h{k}' for k in range(1, 8)])}")
    (folder / "geometry.toml").write_text(text.replace("outline = [-0.015, -0.055, 0.015, 0.055]",
                                                       "outline = [-0.09, -0.11, 0.09, 0.11]"))
    with pytest.raises(ExecutorError, match=rf"\[covers.bar\] over: expected a cover whose outline less its openings "
                                            rf"is at most {MAX_COVER_BOXES} boxes .*, got 32"):
        load_product(str(folder))
