"""Parts that go onto pins: a washer and a gear whose bores go over the pins of a plate are
fits of each part onto a pin (the pin's section inside the bore's), written like pegs in
holes, and the cell places them by hand."""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

import clingo
import pytest
import shapely
import shapely.affinity
import trimesh

from assembly_constraints.cli import main
from tests.cad.test_mesh_import import _box
from tests.conftest import Runner

X_MM = 560.0
"""Where the product stands along x [mm]: within the simulated arm's reach."""


def _pin(radius: float, x: float) -> trimesh.Trimesh:
    """A round pin of ``radius`` [mm] at ``x`` [mm], from inside the plate to 40 mm up."""
    pin = trimesh.creation.cylinder(radius=radius, height=35.0, sections=64)
    pin.apply_translation((x, 0.0, 22.5))
    return pin


def _with_bore(outline: shapely.Polygon, bore: float, x: float) -> trimesh.Trimesh:
    """``outline`` [mm] less a round bore of diameter ``bore`` [mm], 4 mm thick, on the plate
    top (z 10) at ``x`` [mm]."""
    ring = outline.difference(shapely.Point(0.0, 0.0).buffer(bore / 2, quad_segs=32))
    part = trimesh.creation.extrude_polygon(ring, 4.0)
    part.apply_translation((x, 0.0, 10.0))
    return part


def _gear_outline(teeth: int, root: float, tip: float) -> shapely.Polygon:
    """A gear's outline: ``teeth`` square teeth between radii ``root`` and ``tip`` [mm]."""
    ring = shapely.Point(0.0, 0.0).buffer(root, quad_segs=32)
    tooth = shapely.box(root - 1.0, -1.0, tip, 1.0)
    teeth_turned = [shapely.affinity.rotate(tooth, 360.0 * k / teeth, origin=(0, 0)) for k in range(teeth)]
    return shapely.unary_union([ring, *teeth_turned])


def _atoms(path: Path, name: str) -> set[tuple[str, ...]]:
    control = clingo.Control(["--warn=none"])
    control.load(str(path))
    control.ground([("base", [])])
    with control.solve(yield_=True) as handle:
        model = next(iter(handle))
        return {tuple(str(a) for a in s.arguments) for s in model.symbols(atoms=True) if s.name == name}


def _import(tmp_path: Path) -> Path:
    """The plate with a round pin of 10 mm (at x - 25 mm) and one of 8 mm (at x + 25 mm), a
    washer with a 10.5 mm bore on the first and a 12-tooth gear with an 8.6 mm bore on the
    second, imported; the folder written."""
    cad = tmp_path / "cad"
    cad.mkdir()
    plate = trimesh.boolean.union([_box((100, 60, 10), (X_MM, 0, 5)), _pin(5.0, X_MM - 25), _pin(4.0, X_MM + 25)],
                                  engine="manifold")
    plate.export(cad / "plate.stl")
    _with_bore(shapely.Point(0.0, 0.0).buffer(12.0, quad_segs=32), 10.5, X_MM - 25).export(cad / "washer.stl")
    _with_bore(_gear_outline(12, 9.0, 12.0), 8.6, X_MM + 25).export(cad / "gear.stl")
    (tmp_path / "import.toml").write_text('base = "plate"\n[parts.washer]\ntray = [0.30, 0.28]\n'
                                          '[parts.gear]\ntray = [0.40, 0.28]\n')
    out = tmp_path / "out"
    assert main(["-q", "import", str(cad), "--out", str(out), "--config", str(tmp_path / "import.toml")]) == 0
    return out


FITS = {("washer", "plate_pin1"), ("washer", "plate_pin2"), ("gear", "plate_pin2")}
"""The washer's 10.5 mm bore passes both pins (10 and 8 mm), the gear's 8.6 mm only the 8 mm one."""


def test_a_washer_and_a_gear_go_onto_the_pins_of_a_plate(tmp_path: Path) -> None:
    out = _import(tmp_path)
    holes = tomllib.loads((out / "assembly.toml").read_text())["holes"]
    assert {hid: (hole["shape"], round(1000 * hole["position"][0])) for hid, hole in holes.items()} == {
        "plate_pin1": ("round", X_MM - 25), "plate_pin2": ("round", X_MM + 25)}
    assert _atoms(out / "sizes.lp", "fits") == FITS
    rooms = {(p, h): int(m) for p, h, m in _atoms(out / "nominal_sizes.lp", "nominal_margin")}
    assert rooms[("gear", "plate_pin1")] < 0 < rooms[("gear", "plate_pin2")] < rooms[("washer", "plate_pin2")]
    manual = tomllib.loads((out / "geometry.toml").read_text())["manual"]
    assert {pid: entry["reason"] for pid, entry in manual.items()} == {
        "washer": "goes onto a pin (plate_pin1): the cell has no operation for it",
        "gear": "goes onto a pin (plate_pin2): the cell has no operation for it"}


@pytest.mark.slow
def test_a_truth_session_learns_which_part_goes_onto_which_pin(run_cli: Runner, tmp_path: Path) -> None:
    out = _import(tmp_path)
    done = run_cli("session", "--backend", "truth", "--json", "--assemble", "--assembly", str(out), "--out",
                   str(tmp_path / "truth"), timeout=240)
    assert done.returncode == 0, done.stderr
    result = json.loads(done.stdout)
    assert {tuple(pair) for pair in result["fits"]} == FITS
    steps = {step["part"]: step for step in result["assembly"]["steps"]}
    assert result["assembly"]["assembled"] and {steps[p]["skill"] for p in ("washer", "gear")} == {"manual"}
