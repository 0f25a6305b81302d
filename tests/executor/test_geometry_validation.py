"""``geometry.toml`` is checked as a whole before the cell builds anything: types, ranges,
kinds, references and overlaps, each refused in one line ``<file>: [<table>] <key>:
expected ..., got ...`` (bridge/product.py)."""

from __future__ import annotations

import shutil
import tomllib
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from bridge import BridgeError
from bridge.assembly import DATA_DIR
from bridge.errors import ToolError
from bridge.product import Gripper, Plate, product_from_tables
from executor.world.geometry import load_geometry, plate_obj_text

CRANFIELD = DATA_DIR / "cranfield"
GRIPPER_TABLE = """[gripper]
flange_mass = 1.0
flange_inertia = 0.004
flange_length = 0.06
grasp_depth = 0.02

"""
ORIGINAL = (CRANFIELD / "geometry.toml").read_text().replace("[base]", GRIPPER_TABLE + "[base]", 1)
"""Cranfield's geometry with its own [gripper] (a product may override the cell's)."""

ROUND_HOLE = 'kind = "round"\nsize = 0.0133'
TRIANGLE = "[[-0.005, -0.005], [0.005, -0.005], [-0.005, 0.005]]"
"""A polygon section's outline [m]."""

# (id, text of data/cranfield/geometry.toml, its replacement, the expected end of the message)
SIZE = "a number in (0, 0.1] m, or for a rect [a, b] with a >= b, each such a number"
"""What a cross-section's size must be."""

CASES = [
    ("sides-huge", "polygon_sides = 24", "polygon_sides = 8000000",
     "[plate] polygon_sides: expected an integer multiple of 8 in 8 .. 256, got 8000000"),
    ("sides-zero", "polygon_sides = 24", "polygon_sides = 0", "[plate] polygon_sides: expected"),
    ("sides-negative", "polygon_sides = 24", "polygon_sides = -8", "got -8"),
    ("sides-not-multiple-of-8", "polygon_sides = 24", "polygon_sides = 25", "got 25"),
    ("sides-float", "polygon_sides = 24", "polygon_sides = 24.0", "got 24.0"),
    ("sides-boolean", "polygon_sides = 24", "polygon_sides = true", "got True"),
    ("top-z-zero", "top_z = 0.10", "top_z = 0.0", "[plate] top_z: expected a number in (0, 1] m, got 0.0"),
    ("tile-negative", "tile_size = 0.04", "tile_size = -0.04", "[plate] tile_size: expected a number in"),
    ("chamfer-zero", "chamfer = 0.0008", "chamfer = 0", "[plate] chamfer: expected a number in (0, 0.01] m, got 0"),
    ("chamfer-deeper-than-the-hole", "tile_thickness = 0.025", "tile_thickness = 0.0005",
     "[plate] chamfer: expected less than tile_thickness (0.0005 m), got 0.0008"),
    ("base-size-zero", "base_size = [0.20, 0.24]", "base_size = [0.0, 0.24]", "[plate] base_size: expected [x, y]"),
    ("base-size-string", "base_size = [0.20, 0.24]", 'base_size = ["0.2", 0.24]', "got ['0.2', 0.24]"),
    ("grasp-depth-negative", "grasp_depth = 0.02", "grasp_depth = -0.02", "[gripper] grasp_depth: expected"),
    ("grasp-deeper-than-the-part", "grasp_depth = 0.02", "grasp_depth = 0.06",
     "[part_shapes.round_peg] length: expected longer than [gripper] grasp_depth (0.06 m), got 0.05"),
    ("own-grasp-depth-on-the-suction-cup", 'demo_hole = "r1"      # where', 'tool = "suction"\ngrasp_depth = 0.01\n'
     'demo_hole = "r1"      # where', "[part_shapes.round_peg] grasp_depth: expected none: a part on the suction "
     "cup is not held by the fingers' depth, got 0.01"),
    ("own-grasp-depth-zero", 'demo_hole = "r1"      # where', 'grasp_depth = 0.0\ndemo_hole = "r1"      # where',
     "[part_shapes.round_peg] grasp_depth: expected a number in (0, 0.2] m"),
    ("flange-mass-zero", "flange_mass = 1.0", "flange_mass = 0.0",
     "[gripper] flange_mass: expected a number in (0, 20] kg"),
    ("size-string", 'kind = "round"\nsize = 0.0133', 'kind = "round"\nsize = "13.3"',
     f"[hole_shapes.round_small] size: expected {SIZE}, got '13.3'"),
    ("size-boolean", 'kind = "square"\nsize = 0.0133', 'kind = "square"\nsize = true',
     f"[hole_shapes.square] size: expected {SIZE}, got True"),
    ("size-zero", "size = 0.0200", "size = 0.0", "[hole_shapes.round_big] size: expected"),
    ("hole-wider-than-its-boss", "size = 0.0200", "size = 0.04",
     "[hole_shapes.round_big] size: expected a hole and its chamfer inside the 0.04 m boss"),
    ("hole-wider-than-its-own-boss", "size = 0.0200", "size = 0.0200\ntile = 0.02",
     "[hole_shapes.round_big] size: expected a hole and its chamfer inside the 0.02 m boss"),
    ("own-bosses-overlap", "size = 0.0200", "size = 0.0200\ntile = 0.0801",
     "[plate] tile_size: expected bosses that do not overlap, got holes br at (0.59, 0) and r1 at (0.55, -0.06) m "
     "closer than their bosses' half sides together (0.06005 m)"),
    ("peg-half-a-metre", "size = 0.0187", "size = 0.5",
     f"[part_shapes.shaft] size: expected {SIZE}, got 0.5"),
    ("mass-negative", "mass = 0.06", "mass = -0.06", "[part_shapes.square_peg] mass: expected a number in (0, 10] kg"),
    ("length-zero", "length = 0.05           # [m]", "length = 0", "[part_shapes.round_peg] length: expected"),
    ("kind-unknown", 'kind = "round"\nsize = 0.0187', 'kind = "hexagon"\nsize = 0.0187',
     "[part_shapes.shaft] kind: expected one of polygon, rect, round, square, got 'hexagon'"),
    ("hole-top-z-text", 'holes = ["br"]', 'holes = ["br"]\ntop_z = "0.11"',
     "[hole_shapes.round_big] top_z: expected a number in (0, 1] m, got '0.11'"),
    ("hole-depth-zero", 'holes = ["br"]', 'holes = ["br"]\ndepth = 0.0',
     "[hole_shapes.round_big] depth: expected a number in (0, 0.2] m, got 0.0"),
    ("hole-depth-within-the-chamfer", 'holes = ["br"]', 'holes = ["br"]\ndepth = 0.0005',
     "[hole_shapes.round_big] depth: expected more than the [plate] chamfer (0.0008 m), got 0.0005"),
    ("pin-without-a-base-mesh", 'holes = ["br"]', 'holes = ["br"]\npin = true',
     "[hole_shapes.round_big] pin: a pin needs a [base] with its own mesh (the pin is part of it), got none"),
    ("owner-of-a-hole", 'holes = ["br"]', 'holes = ["br"]\nowner = "sh"',
     "[hole_shapes.round_big] owner: expected no owner: only a pin has one, got 'sh'"),
    ("bore-taught-in-a-hole", "mass = 0.06", "mass = 0.06\nbore = true",
     "[part_shapes.square_peg] demo_hole: expected a pin for parts with a bore, a hole for pegs (s1 is a hole), "
     "got 's1'"),
    ("zero-clearance-unknown-part", 'holes = ["br"]', 'holes = ["br"]\nzero_clearance = ["zz"]',
     "[hole_shapes.round_big] zero_clearance: expected parts with a bore of [part_shapes.*] for a pin, pegs of "
     "[part_shapes.*] for a hole, got 'zz'"),
    ("widened-unknown-part", 'holes = ["br"]', 'holes = ["br"]\nwidened = ["zz"]',
     "[hole_shapes.round_big] widened: expected parts with a round bore of [part_shapes.*] on a round pin, round "
     "pegs in a round hole of a [base] with its own mesh, got 'zz'"),
    ("widened-peg-in-a-plate", 'holes = ["br"]', 'holes = ["br"]\nwidened = ["p1"]',  # the plate widens its holes
     "[hole_shapes.round_big] widened: expected parts with a round bore of [part_shapes.*] on a round pin, round "
     "pegs in a round hole of a [base] with its own mesh, got 'p1'"),
    ("near-miss-unknown-part", 'holes = ["br"]', 'holes = ["br"]\nnear_miss = ["zz"]',
     "[hole_shapes.round_big] near_miss: expected parts with a bore of [part_shapes.*] for a pin, pegs of "
     "[part_shapes.*] for a hole, got 'zz'"),
    ("hole-bottom-under-the-floor", 'holes = ["br"]', 'holes = ["br"]\ndepth = 0.1',
     "[hole_shapes.round_big] depth: expected less than the entry height (0.1 m: the bottom above the floor), "
     "got 0.1"),
    ("hole-entry-under-the-plate-depth", 'holes = ["br"]', 'holes = ["br"]\ntop_z = 0.02',
     "[hole_shapes.round_big] top_z: expected more than the depth (0.025 m, the [plate] tile_thickness: the bottom "
     "above the floor), got 0.02"),
    ("kind-number", 'holes = ["br"]\nkind = "round"', 'holes = ["br"]\nkind = 1',
     "[hole_shapes.round_big] kind: expected one of polygon, rect, round, square, got 1"),
    ("demo-hole-unknown", 'demo_hole = "br"', 'demo_hole = "zz"',
     "[part_shapes.shaft] demo_hole: expected a hole of [hole_shapes.*] (br, r1, r2, s1, s2), got 'zz'"),
    ("hole-twice", 'holes = ["br"]', 'holes = ["br", "r1"]',
     "[hole_shapes.round_big] holes: expected ids not already in [hole_shapes.round_small], got 'r1'"),
    ("hole-unknown", 'holes = ["br"]', 'holes = ["br", "q9"]',
     "[hole_shapes.round_big] holes: expected holes of assembly.toml with a position (q9 is not a hole there)"),
    ("part-unknown", 'parts = ["sh"]', 'parts = ["sh", "zz"]',
     "[part_shapes.shaft] parts: expected parts of assembly.toml with a start, or of [extra_parts] (zz is neither)"),
    ("holes-not-a-list", 'holes = ["br"]', 'holes = "br"', "[hole_shapes.round_big] holes: expected a non-empty list"),
    ("size-missing", 'size = 0.0200           # diameter [m]', "", "[hole_shapes.round_big] size: expected a number"),
    ("extra-start-nan", "start = [0.25, 0.46]", "start = [nan, 0.46]", "[extra_parts.tp] start: expected [x, y]"),
    ("unknown-key", "[plate]\n", "[plate]\ncolour = 3\n", "[plate] colour: unknown key; expected one of top_z"),
    ("unknown-table", "[base]\n", "[fixture]\nx = 1\n\n[base]\n", "fixture: unknown table or key"),
    ("table-name-not-an-id", "[part_shapes.shaft]", "[part_shapes.Shaft]",
     "[part_shapes.Shaft]: expected a table name that is an id (a lower-case ASP constant"),
    ("cover-mass-zero", "mass = 0.05             # [kg]\ngrip", "mass = 0             # [kg]\ngrip",
     "[covers.sp] mass: expected a number in (0, 10] kg, got 0"),
    ("cover-mass-missing", "mass = 0.05             # [kg]\ngrip", "grip",
     "[covers.sp] mass: expected a number in (0, 10] kg, got nothing (a required key)"),
    ("cover-over-unknown", 'over = ["s1", "s2"]', 'over = ["s1", "zz"]', "[covers.sp] over: expected holes of "
     "[hole_shapes.*] (br, r1, r2, s1, s2), got 'zz'"),
    ("cover-outline-inverted", "outline = [-0.015, -0.08, 0.015, 0.08]", "outline = [0.015, -0.08, -0.015, 0.08]",
     "[covers.sp] outline: expected [xmin, ymin, xmax, ymax] with xmin < xmax"),
    ("cover-skill-unknown", 'skill = "square_peg"', 'skill = "zz"', "[covers.sp] skill: expected a part shape"),
    ("cover-not-a-part", "[covers.sp]", "[covers.zz]", "[covers.zz]: expected a part of assembly.toml, got 'zz'"),
    ("socket-deeper-than-cover", "socket = [-0.075, 0.0, 0.0115, 0.008]", "socket = [-0.075, 0.0, 0.0115, 0.02]",
     "[covers.pd] socket: expected [x, y, side, depth] with side > 0 and 0 < depth < thickness"),
    ("head-kind-unknown", 'into = "pd"\nkind = "round"', 'into = "pd"\nkind = "rect"',
     "[heads.ph] kind: expected one of round, square, got 'rect'"),
    ("head-into-no-socket", 'into = "pd"', 'into = "fp"', "[heads.ph] into: expected a cover with a socket (pd)"),
    ("head-size-zero", "size = 0.010 ", "size = 0.0 ", "[heads.ph] size: expected a number in (0, 0.1] m, got 0.0"),
    ("base-part-unknown", 'part = "bp"', 'part = "zz"', "[base] part: expected a part of assembly.toml"),
    ("base-mass-negative", "mass = 2.0 ", "mass = -2.0 ", "[base] mass: expected a number in (0, 50] kg, got -2.0"),
    ("part-with-two-geometries", 'parts = ["sh"]', 'parts = ["sh", "sp"]',
     "part sp of assembly.toml has more than one geometry ([part_shapes.*] and [covers.*])"),
    ("extra-part-of-assembly", "[extra_parts.tp]", "[extra_parts.p1]", "[extra_parts.p1] start: expected a part "
     "that is not in assembly.toml"),
    ("gripper-unknown-key", "grasp_depth = 0.02", "grasp_depth = 0.02\ngrasp_force = 5",
     "[gripper] grasp_force: unknown key"),
    ("polygon-without-outline", ROUND_HOLE, 'kind = "polygon"\nsize = [0.01, 0.01]',
     "[hole_shapes.round_small] outline: expected an outline [[x, y], ...] in m (a polygon's section), got None"),
    ("outline-of-a-round", ROUND_HOLE, ROUND_HOLE + f"\noutline = {TRIANGLE}",
     "[hole_shapes.round_small] outline: expected an outline [[x, y], ...] for a polygon, none for a round"),
    ("outline-crossing", ROUND_HOLE, 'kind = "polygon"\nsize = [0.01, 0.01]\n'
     "outline = [[0.0, 0.0], [0.01, 0.01], [0.01, 0.0], [0.0, 0.01]]",
     "[hole_shapes.round_small] outline: expected a simple polygon (no crossing edges, positive area), got "
     "'Self-intersection"),
    ("outline-extents", ROUND_HOLE, f'kind = "polygon"\nsize = [0.02, 0.01]\noutline = {TRIANGLE}',
     "[hole_shapes.round_small] size: expected the outline's extents [0.01, 0.01] m along x and y, got [0.02, 0.01]"),
    ("outline-two-points", ROUND_HOLE, 'kind = "polygon"\nsize = [0.01, 0.01]\noutline = [[0.0, 0.0], [0.01, 0.01]]',
     "[hole_shapes.round_small] outline: expected the points [[x, y], ...] in m of a simple polygon"),
    ("outline-far", ROUND_HOLE,
     'kind = "polygon"\nsize = [0.01, 0.01]\noutline = [[0.0, 0.0], [0.5, 0.0], [0.0, 0.01]]',
     "[hole_shapes.round_small] outline: expected"),
    ("corner-of-a-round", ROUND_HOLE, ROUND_HOLE + "\ncorner = 0.001",
     "[hole_shapes.round_small] corner: expected no corner radius for a round, got 0.001"),
    ("corner-too-big", 'kind = "square"\nsize = 0.0133', 'kind = "square"\nsize = 0.0133\ncorner = 0.007',
     "[hole_shapes.square] corner: expected a corner radius of a square or rect at most half its short side "
     "(0.00665 m), got 0.007"),
    ("corner-without-base-mesh", 'kind = "square"\nsize = 0.0133', 'kind = "square"\nsize = 0.0133\ncorner = 0.001',
     "[hole_shapes.square] corner: a hole with rounded corners needs a [base] with its own mesh"),
]


def _folder(tmp_path: Path, text: str) -> Path:
    skip = shutil.ignore_patterns("assets", "demonstrations")
    folder = Path(shutil.copytree(CRANFIELD, tmp_path / "asm", ignore=skip))
    (folder / "geometry.toml").write_text(text)
    return folder


@pytest.mark.parametrize(("old", "new", "message"), [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_a_bad_value_is_refused_naming_file_table_and_key(tmp_path: Path, old: str, new: str, message: str) -> None:
    assert ORIGINAL.count(old) >= 1, old
    folder = _folder(tmp_path, ORIGINAL.replace(old, new, 1))
    with pytest.raises(ToolError) as error:
        load_geometry(str(folder))
    text = str(error.value)
    assert text.startswith(f"{folder / 'geometry.toml'}: ") and message in text, text
    assert "\n" not in text and len(text) < 300


def test_two_holes_at_one_position_are_refused(tmp_path: Path) -> None:
    folder = _folder(tmp_path, ORIGINAL)
    layout = folder / "assembly.toml"
    layout.write_text(layout.read_text().replace("position = [0.63, -0.06]", "position = [0.55, -0.06]", 1))
    with pytest.raises(BridgeError, match=r"geometry.toml: \[plate\] tile_size: expected bosses that do not "
                                            r"overlap, got holes r1 at \(0.55, -0.06\) and s1 at \(0.55, -0.06\)"):
        load_geometry(str(folder))


def test_a_hole_s_own_boss_may_reach_its_neighbours(tmp_path: Path) -> None:
    """br's own 80 mm boss touches the plate's 40 mm ones 60 mm away (x and y) and is built that wide."""
    folder = _folder(tmp_path, ORIGINAL.replace("size = 0.0200", "size = 0.0200\ntile = 0.08", 1))
    geometry = load_geometry(str(folder))
    assert (geometry.holes["br"].tile, geometry.holes["r1"].tile) == (0.08, None)
    vertices = [(float(x), float(y)) for line in plate_obj_text(geometry).splitlines() if line.startswith("v ")
                for x, y in [line.split()[1:3]]]
    between = [abs(y) for x, y in vertices if 0.571 < x < 0.609]  # br's alone: the others' reach 0.57 and 0.61
    assert max(between) == pytest.approx(0.04, abs=2e-6)


@pytest.mark.parametrize("assembly", ["cranfield", "spare", "graded", "taskboard"])
def test_the_shipped_geometries_pass(assembly: str) -> None:
    assert load_geometry(assembly).parts


def test_the_product_gripper_wins_over_the_cell_one(tmp_path: Path) -> None:
    folder = _folder(tmp_path, ORIGINAL.replace("flange_length = 0.06", "flange_length = 0.08", 1))
    assert load_geometry(str(folder)).gripper.flange_length == 0.08
    assert load_geometry("cranfield").gripper.flange_length == 0.06  # the cell description's


NUMERIC_KEYS = [("plate", key) for key in Plate.__struct_fields__] + [
    ("gripper", key) for key in Gripper.__struct_fields__] + [("hole_shapes.round_big", "top_z"),
                                                              ("hole_shapes.round_big", "depth")]
VALUES = st.one_of(st.integers(-10**12, 10**12), st.floats(allow_nan=True, allow_infinity=True), st.booleans(),
                   st.text(max_size=5), st.lists(st.floats(-1, 1), max_size=3))


@settings(max_examples=60, deadline=None)
@given(key=st.sampled_from(NUMERIC_KEYS), value=VALUES)
def test_any_value_of_a_key_loads_or_is_refused_in_one_line(key: tuple[str, str], value: object) -> None:
    """Whatever a [plate] or [gripper] key or a hole's own level holds, the check passes or
    raises one BridgeError of one line naming the file and a table (the key itself, or the
    key a cross check relates it to: a smaller tile_size refuses the hole that no longer
    fits), never another exception."""
    geo = tomllib.loads(ORIGINAL)
    table = geo
    for name in key[0].split("."):
        table = table[name]
    table[key[1]] = value
    path = CRANFIELD / "geometry.toml"
    layout = tomllib.loads((CRANFIELD / "assembly.toml").read_text())
    try:
        product_from_tables(CRANFIELD, layout, geo)
    except BridgeError as exc:
        assert str(exc).startswith(f"{path}: [") and "\n" not in str(exc), str(exc)
