"""Products of real CAD drawn by others, imported as a user imports them and compared with
a truth derived independently of the import.

Each ``tests/cad/corpus/<name>/`` holds the product's meshes in the assembled pose
(``meshes/``), the import settings (``import.toml``), where they came from and what was
changed (``SOURCE.md``) and ``truth.toml``, derived by hand from the source's drawing
(its header says how): the features that receive parts (holes of the base, pins of the
base a part goes over) with their axes, which part fits which feature (closed world),
the insertion axes the geometry allows each part, and the precedence pairs it forces.

Where the import cannot do something yet, only that assertion is marked
``xfail(strict=True)`` with what is missing, so it fails (XPASS) as soon as it works and
the mark must go; the truths are never weakened to pass.
"""

from __future__ import annotations

import json
import math
import tomllib
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import clingo
import pytest

from bridge.cell_settings import ServeSettings
from bridge.messages import InsertRequest
from executor import ExecutorError
from executor.assembly.product import load_product
from executor.assembly.step import Assembler
from executor.cad.cli import run_import
from executor.cad.sweep import opposite
from executor.cell_description import CellDescription
from executor.serve.truth import TruthBackend
from executor.world.geometry import load_geometry
from tests.conftest import Runner

CORPUS = Path(__file__).parent / "corpus"
FEATURE_REACH_MM = 2.0
"""An imported hole is a truth feature when its position lies this close to the feature's axis [mm]."""


@dataclass(frozen=True)
class Imported:
    """A corpus product as ``import`` wrote it: its ``truth``, the ``out`` folder, each
    moving part's insertion ``axes`` (the reverse of the direction it leaves along), the
    ``offset`` (x, y) [m] the import moved it by from its CAD frame (its truth's) into the
    cell, each imported hole's or pin's ``occupants`` (the parts in it or onto it) and
    ``owners`` (the part it is a feature of)."""

    truth: dict[str, Any]
    out: Path
    axes: dict[str, str]
    offset: tuple[float, float]
    occupants: dict[str, set[str]]
    owners: dict[str, str]
    pins: frozenset[str] = frozenset()


def _atoms(path: Path) -> dict[str, set[tuple[str, ...]]]:
    """The atoms of a written ``.lp`` file (facts only), by predicate name."""
    control = clingo.Control(["--warn=none"])
    control.load(str(path))
    control.ground([("base", [])])
    found: dict[str, set[tuple[str, ...]]] = {}
    with control.solve(yield_=True) as handle:
        for model in handle:
            for symbol in model.symbols(atoms=True):
                found.setdefault(symbol.name, set()).add(tuple(str(a) for a in symbol.arguments))
    return found


@pytest.fixture(scope="module")
def imported(tmp_path_factory: pytest.TempPathFactory) -> Callable[[str], Imported]:
    """Each corpus product imported once (``import meshes/ --config import.toml``)."""
    done: dict[str, Imported] = {}

    def get(name: str) -> Imported:
        if name not in done:
            folder = CORPUS / name
            out = tmp_path_factory.mktemp(name) / "out"
            result = run_import(folder / "meshes", out, "mm", folder / "import.toml")
            truth = tomllib.loads((folder / "truth.toml").read_text())
            derived = result.derived
            holes = derived.holes | derived.part_holes
            occupants = {hid: {fit.part} for hid, fit in holes.items() if fit.part is not None}
            occupants |= {pid: set(pin.parts) for pid, pin in derived.pins.items()}
            owners = {hid: fit.owner or derived.base for hid, fit in holes.items()}
            owners |= {pid: pin.owner for pid, pin in derived.pins.items()}
            done[name] = Imported(truth, out, {pid: opposite(leaves) for pid, leaves in derived.axis.items()},
                                  result.offset, occupants, owners, frozenset(derived.pins))
        return done[name]

    return get


def _distance_to_axis(position: list[float], feature: dict[str, Any], offset: tuple[float, float]) -> float:
    """How far an imported hole's ``position`` [m] (x, y, or x, y, z, in the cell, moved by
    ``offset`` [m] from the CAD frame) lies from a truth feature's axis line [mm]; with x, y
    only, from the line's projection on the xy plane."""
    point = [1000.0 * (v - (offset[k] if k < 2 else 0.0)) for k, v in enumerate(position)]
    origin = feature["axis_point"][:len(point)]
    direction = {"x": 0, "y": 1, "z": 2}[feature["axis"][1]]
    across = [point[k] - origin[k] for k in range(len(point)) if k != direction]
    return math.hypot(*across)


def _feature_holes(done: Imported) -> dict[str, str]:
    """Each truth feature's imported hole id (absent: none found): the one of the
    feature's owner on its axis that is a pin where the feature is one (of a hollow
    shaft's bore and the shaft, the shaft); of several (the two ends of one rod), the one
    that is empty or holds a part the truth puts in that feature."""
    holes = tomllib.loads((done.out / "assembly.toml").read_text()).get("holes", {})
    found = {}
    for fid, feature in done.truth["features"].items():
        inside = {pid for pid, part in done.truth["parts"].items() if part.get("in") == fid}
        near = [hid for hid, hole in holes.items() if done.owners.get(hid) == feature["owner"]
                and _distance_to_axis(hole["position"], feature, done.offset) <= FEATURE_REACH_MM
                and (hid in done.pins) == (feature["kind"] == "pin")]
        if len(near) > 1:
            near = [hid for hid in near if not done.occupants.get(hid) or done.occupants[hid] & inside]
        if len(near) == 1:
            found[fid] = near[0]
    return found


def _xfail(reason: str) -> pytest.MarkDecorator:
    return pytest.mark.xfail(strict=True, reason=reason)


INSERTED = "fits of any part on any part: the cell has no operation for a part going"

PRODUCTS = sorted(p.name for p in CORPUS.iterdir() if (p / "truth.toml").is_file())

REFUSED: dict[str, str] = {}
"""The products the import refuses though they are sound, with why."""
IMPORTED = [p for p in PRODUCTS if p not in REFUSED]
"""Every product the import takes."""

PUMP_FEATURES = ("features: the housing's bore is taken for the shaft's hole (d 26.951, 4.975 mm all round) and no "
                 "hole is found in the bearing ring the shaft runs in (d 21), the ring in its d 27 bore in no feature; "
                 "of the three parts on the shaft's d 17 end only gland_3 is on a pin, with a bore of d 33.901 (its "
                 "recess, not its d 17 lips)")
PUMP_SUPPORT = ("precedence: the shaft rests in the bearing ring's bore and on nothing else (2 mm all round, the "
                "source's balls left out), but it touches nothing in the CAD and the locating rule counts the glands "
                "and the impeller on it among what keeps it from moving sideways: bearing_ring->shaft is not written")
PULLEY_PIN = ("features: the pin the pulley goes onto (the hub's boss) is not found: pins are looked for at the middle "
              "of the part's extent along its axis only, where the pulley's slice (y -27.124 mm, through its rim, "
              "behind the hub's disc) crosses nothing of the hub")

BEAM_RECT_NOMINAL = ("fits: sizes.lp has none: each upright's tenon is in its mortise as rect 9.606 x 5.796 mm in "
                     "rect 9.605 x 5.795 mm (the tapers sliced at mid-depth, where they meet), 0.3 um of overlap a "
                     "side, and the nominal zero-clearance rule takes only round or polygon sections")
BEAM_PINS = ("features: the uprights' upper tenons the feet go onto are not found as pins: each foot is taken for a "
             "cover (50.8 mm above the plate top); and " + BEAM_RECT_NOMINAL)
BEAM_CONVEX = ("no geometry.toml: the convex pieces of upright_a leave foot_a -3.979 mm of the 0.000 mm its mesh "
               "leaves it (CoACD, a tapered tenon in a tapered mortise at zero clearance)")


def _imported_but(name: str, mark: pytest.MarkDecorator) -> list[Any]:
    """Every imported product, ``name`` with ``mark``."""
    return [pytest.param(p, marks=mark) if p == name else p for p in IMPORTED]


@pytest.mark.slow  # the first test of a product imports it
@pytest.mark.parametrize("name", [
    "agh_hex_horizontal",
    "agh_prism_array",
    pytest.param("asap_beam", marks=_xfail(BEAM_PINS)),
    "factory_gears",
    "factory_rect_pegs",
    "ldraw_axles",
    "metaworld_assembly",
    "occt_as1",
    "robosuite_nuts",
    "vitac_shapes",
    pytest.param("occt_pump", marks=_xfail(PUMP_FEATURES)),
    pytest.param("occt_pulley", marks=_xfail(PULLEY_PIN)),
])
def test_the_fit_relation_is_the_truth(imported: Callable[[str], Imported], name: str) -> None:
    done = imported(name)
    sizes = _atoms(done.out / "sizes.lp")
    holes = _feature_holes(done)
    missing = sorted(set(done.truth["features"]) - set(holes))
    assert not missing, f"no imported hole on the axis of {missing}"
    parts = {row["part"] for row in done.truth["fits"]}
    assert {(p,) for p in parts} <= sizes.get("part", set()), "parts missing from sizes.lp"
    assert {(h,) for h in holes.values()} <= sizes.get("hole", set()), "holes missing from sizes.lp"
    fits = sizes.get("fits", set())
    wrong = [(row["part"], row["feature"]) for row in done.truth["fits"]
             if ((row["part"], holes[row["feature"]]) in fits) != row["fits"]]
    assert not wrong, f"fits differ from the truth on {wrong}"
    # The CAD prior's margins agree in sign (the room's measure may differ by convention),
    # room 0 a nominal zero-clearance fit as in the truth.
    margins = {(p, h): int(m) for p, h, m in _atoms(done.out / "nominal_sizes.lp").get("nominal_margin", set())}
    assert all((margins[row["part"], holes[row["feature"]]] >= 0) == row["fits"] for row in done.truth["fits"])


@pytest.mark.slow  # the first test of a product imports it
@pytest.mark.parametrize("name", ["agh_hex_horizontal", "agh_prism_array", "asap_beam", "factory_gears",
                                  "factory_rect_pegs",
                                  "metaworld_assembly", "robosuite_nuts", "occt_pulley",
                                  "vitac_shapes"])
def test_the_cad_prior_margin_is_twice_the_truths_room(imported: Callable[[str], Imported], name: str) -> None:
    # nominal_sizes.lp's margin is diametral: twice the room all round, within 2 um, on each
    # pair that fits of the features the import finds (a no-fit's negative measure is a
    # convention: the sign is checked above).
    done = imported(name)
    holes = _feature_holes(done)
    margins = {(p, h): int(m) for p, h, m in _atoms(done.out / "nominal_sizes.lp").get("nominal_margin", set())}
    rows = [row for row in done.truth["fits"] if row["feature"] in holes and row["fits"]]
    assert rows
    off = {(row["part"], row["feature"]): (margins[row["part"], holes[row["feature"]]], round(2000 * row["room_mm"]))
           for row in rows if abs(margins[row["part"], holes[row["feature"]]] - 2000 * row["room_mm"]) > 2}
    assert off == {}


@pytest.mark.slow  # the first test of a product imports it
@pytest.mark.parametrize("name", [
    "agh_hex_horizontal",
    "agh_prism_array",
    pytest.param("asap_beam", marks=_xfail(BEAM_RECT_NOMINAL)),
    "factory_gears",
    "factory_rect_pegs",
    "ldraw_axles",
    "metaworld_assembly",
    "occt_as1",
    "robosuite_nuts",
    "vitac_shapes",
    pytest.param("occt_pump", marks=_xfail(PUMP_FEATURES)),
    "occt_pulley",
])
def test_each_part_fits_the_feature_it_is_in(imported: Callable[[str], Imported], name: str) -> None:
    # On the features the import finds: the part the CAD has in each fits it.
    done = imported(name)
    fits = _atoms(done.out / "sizes.lp").get("fits", set())
    holes = _feature_holes(done)
    pairs = [(pid, holes[part["in"]]) for pid, part in done.truth["parts"].items() if part.get("in") in holes]
    assert pairs and [pair for pair in pairs if pair not in fits] == []


@pytest.mark.slow  # the first test of a product imports it
@pytest.mark.parametrize("name", IMPORTED)
def test_insertion_axes_are_ones_the_geometry_allows(imported: Callable[[str], Imported], name: str) -> None:
    done = imported(name)
    allowed = {pid: part["axes"] for pid, part in done.truth["parts"].items()}
    assert set(done.axes) == set(allowed)
    assert {pid: axis for pid, axis in done.axes.items() if axis not in allowed[pid]} == {}


@pytest.mark.slow  # the first test of a product imports it
@pytest.mark.parametrize("name", _imported_but("occt_pump", _xfail(PUMP_SUPPORT)))
def test_no_precedence_the_geometry_does_not_force(imported: Callable[[str], Imported], name: str) -> None:
    done = imported(name)
    base = done.truth["base"]
    written = _atoms(done.out / "geometric_precedence.lp").get("must_precede", set())
    forced = {tuple(pair) for pair in done.truth["precedence"]}
    closed = set(forced)
    while True:
        more = {(a, d) for a, b in closed for c, d in closed if b == c} - closed
        if not more:
            break
        closed |= more
    assert {pair for pair in written if base not in pair} == closed
    if done.truth["base_first"]:
        assert all(a == base for a, b in written if base in (a, b))


@pytest.mark.slow  # the first test of a product imports it
@pytest.mark.parametrize("name", _imported_but("occt_pump", _xfail(PUMP_SUPPORT)))
def test_the_owner_of_a_feature_precedes_the_part_in_it(imported: Callable[[str], Imported], name: str) -> None:
    # The cell inserts a part into its feature: the feature's owner is placed first, for a
    # reason of its own where nothing else orders them (agh_prism_array's pegs stand on the
    # floor through the box's holes, touching none of it).
    done = imported(name)
    text = (done.out / "geometric_precedence.lp").read_text()
    written = _atoms(done.out / "geometric_precedence.lp").get("must_precede", set())
    owners = {(done.truth["features"][part["in"]]["owner"], pid) for pid, part in done.truth["parts"].items()
              if "in" in part}
    assert owners <= written
    assert all(f"% {a}->{b}: blocks" not in text for a, b in owners - {tuple(p) for p in done.truth["precedence"]})


@pytest.mark.slow  # imports the product
@pytest.mark.parametrize("name", [pytest.param(p, marks=pytest.mark.xfail(strict=True, raises=ExecutorError,
                                                                         reason=why)) for p, why in REFUSED.items()])
def test_a_sound_product_is_imported(imported: Callable[[str], Imported], name: str) -> None:
    # Once it is, the product goes out of REFUSED and into every test of the imported ones.
    done = imported(name)
    allowed = {pid: part["axes"] for pid, part in done.truth["parts"].items()}
    assert {pid: axis for pid, axis in done.axes.items() if axis not in allowed[pid]} == {}


@pytest.mark.slow  # the first test of a product imports it
@pytest.mark.parametrize("name", _imported_but("asap_beam", _xfail(BEAM_CONVEX)))
def test_every_product_is_simulated(imported: Callable[[str], Imported], name: str) -> None:
    done = imported(name)
    geometry = load_geometry(str(done.out))  # written, and the cell's loader takes it
    tables = geometry.tables
    simulated = set(geometry.parts) | set(tables.covers) | set(tables.heads) | set(tables.manual)
    assert set(done.truth["parts"]) <= simulated
    assert all(manual.reason for manual in tables.manual.values())


@pytest.mark.slow  # the first test of a product imports it
@pytest.mark.parametrize("name", [
    "agh_hex_horizontal",
    "agh_prism_array",
    pytest.param("asap_beam", marks=_xfail(BEAM_CONVEX + "; and " + INSERTED + " onto a tenon of another part "
                                           "(each foot, taken for a cover 50.8 mm above the plate top)")),
    pytest.param("factory_gears", marks=_xfail(INSERTED + " onto a shaft with less room than the cell resolves "
                                               "(0.012 mm per side)")),
    "factory_rect_pegs",
    pytest.param("ldraw_axles", marks=_xfail(INSERTED + " onto a pin on top of another (the gear on the bush), "
                                              "or a cross axle whose arms (1.6 mm) are thinner than the cell's "
                                              "hull margin twice")),
    "metaworld_assembly",
    pytest.param("occt_as1", marks=_xfail(INSERTED + " onto a bolt's end from below, onto a horizontal rod, or a "
                                          "rod through two brackets")),
    "robosuite_nuts",
    pytest.param("occt_pump", marks=_xfail(INSERTED + " along y into no hole found (the ring, gland_2, the impeller: "
                                           "in no feature) or onto a pin of a part that is not the base (gland_3)")),
    pytest.param("occt_pulley", marks=_xfail(INSERTED + " along -y onto a pin that is not found (the pulley "
                                             "onto the hub's boss), or into a hole and shorter than the gripper's "
                                             "grasp depth (the bolts, 14 mm)")),
    "vitac_shapes",
])
def test_the_cell_inserts_every_part(imported: Callable[[str], Imported], name: str) -> None:
    manual = load_geometry(str(imported(name).out)).tables.manual
    assert manual == {}, {pid: table.reason for pid, table in manual.items()}


def _taught_and_learned_in_the_cell(done: Imported, run_executor: Runner, run_cli: Runner,
                                    run: Path) -> tuple[dict[str, Any], list[dict[str, Any]]]:
    """Teach the imported product, run a sim session with ``--assemble`` into ``run``; its
    result and its journal's entries."""
    taught = run_executor("teach", "--assembly", str(done.out), timeout=240)
    assert taught.returncode == 0, taught.stderr
    session = run_cli("session", "--assembly", str(done.out), "--out", str(run), "--assemble", "--json", timeout=400)
    assert session.returncode == 0, session.stderr
    journal = [json.loads(line) for line in (run / "journal.jsonl").read_text().splitlines()]
    return json.loads(session.stdout), journal


@pytest.mark.slow  # imports the product, teaches it, runs a sim session of 16 experiments and assembles (about 90 s)
@pytest.mark.timeout(600)  # 257 s while the machine ran other work
def test_a_product_drawn_at_the_origin_is_learned_in_the_cell_where_the_import_placed_it(
        imported: Callable[[str], Imported], run_executor: Runner, run_cli: Runner, tmp_path: Path) -> None:
    done = imported("agh_prism_array")  # drawn around x = 0, out of the arm's reach: placed
    assert done.offset == pytest.approx((0.56, 0.0), abs=1e-9)
    result, journal = _taught_and_learned_in_the_cell(done, run_executor, run_cli, tmp_path / "run")
    # Every peg, the hexagon, octagon and 12-gon prisms too, goes into every hole in
    # physics: each pair is an experiment whose outcome is the truth's (peg8 refused by
    # the hexagon, 0.343 mm short; peg12 into it with 0.167 mm to spare).
    holes = _feature_holes(done)
    truth = {(row["part"], holes[row["feature"]]): "fit" if row["fits"] else "no_fit" for row in done.truth["fits"]}
    assert {(e["part"], e["hole"]): e["result"] for e in journal if "result" in e} == truth
    assert sorted(map(tuple, result["fits"])) == sorted(pair for pair, outcome in truth.items() if outcome == "fit")
    # The plan places the box (the holes' owner) first and every peg ends within 2 mm.
    report = result["assembly"]
    assert report["final_plan"][0]["part"] == done.truth["base"]
    assert report["assembled"] and max(report["final_pose_error_mm"].values()) < 2.0, report["final_pose_error_mm"]


@pytest.mark.slow  # imports the product, teaches it and assembles it in physics (about 140 s under load)
def test_prisms_with_2_mm_of_room_all_round_are_assembled_within_2_mm(
        imported: Callable[[str], Imported], run_executor: Runner) -> None:
    done = imported("agh_prism_array")
    taught = run_executor("teach", "--assembly", str(done.out), timeout=240)
    assert taught.returncode == 0, taught.stderr
    holes = _feature_holes(done)
    assembler = Assembler(load_product(str(done.out)), description=CellDescription())
    try:
        assert assembler.run_step(done.truth["base"], None, 0).outcome == "fit"
        steps = [assembler.run_step(pid, holes[part["in"]], 0) for pid, part in sorted(done.truth["parts"].items())]
    finally:
        assembler.close()
    # Each prism has 1.8 to 2.4 mm of room all round: held where the hole search found the
    # hole, it would stand up to that far off its hole's centre; centred by contact, it is not.
    assert {s.part: s.outcome for s in steps} == dict.fromkeys(done.truth["parts"], "fit")
    assert max(s.pose_error for s in steps) < 0.002, {s.part: round(s.pose_error * 1000, 2) for s in steps}


@pytest.mark.slow  # imports the product, teaches its bolts and inserts two in physics (330 s under load)
@pytest.mark.timeout(900)  # the import alone took 155 s while the machine ran other work
def test_bolts_beside_a_bracket_s_wall_and_through_its_flange_are_inserted(
        imported: Callable[[str], Imported], run_executor: Runner) -> None:
    # occt_as1: bolt_a1's axis is 10 mm from bracket_a's wall, whose top stands 80 mm high.
    # With the default 60 mm flange the arm's wrist came down on the wall top and the bolt
    # stopped 4.1 mm above its goal (no_fit, blocked by bracket_a); the import makes the
    # flange long enough that the wrist stays above the wall. bolt_b2 goes through
    # bracket_b's 10 mm flange over the plate: with the search pressing at the plate's top,
    # 10 mm under the flange's, the bolt was pushed onto the flange with 14-15 N, dragged
    # behind the spiral, and missed the opening in both attempts (no_fit, blocked by bracket_b).
    done = imported("occt_as1")
    gripper = load_geometry(str(done.out)).tables.gripper
    assert gripper is not None and gripper.flange_length > 0.06
    taught = run_executor("teach", "--assembly", str(done.out), timeout=240)
    assert taught.returncode == 0, taught.stderr
    holes = _feature_holes(done)
    assembler = Assembler(load_product(str(done.out)), description=CellDescription())
    try:
        steps = [assembler.run_step(part, holes[done.truth["parts"][part]["in"]] if "bolt" in part else None, 0)
                 for part in ("plate", "bracket_a", "bolt_a1", "bracket_b", "bolt_b2")]
    finally:
        assembler.close()
    assert [(s.part, s.skill, s.outcome) for s in steps] == [
        ("plate", "fixture", "fit"), ("bracket_a", "manual", "fit"), ("bolt_a1", "insert", "fit"),
        ("bracket_b", "manual", "fit"), ("bolt_b2", "insert", "fit")]
    assert max(s.pose_error for s in steps) < 0.002, steps


def _learned_from_its_cad_alone(done: Imported, run_executor: Runner, run_cli: Runner, run: Path) -> dict[str, Any]:
    """Teach, run a sim session of ``done`` (every part placed by hand) and assemble its
    plan 1; checks that nothing is taught, no experiment run, every pair of ``sizes.lp``
    labelled not observed with the truth's fits, and the product assembled within 2 mm,
    every part placed by hand. The session's result."""
    taught = run_executor("teach", "--assembly", str(done.out), timeout=120)
    assert taught.returncode == 0 and "no skill to teach" in taught.stdout, taught.stderr
    session = run_cli("session", "--assembly", str(done.out), "--out", str(run), "--json", timeout=300)
    assert session.stdout, session.stderr
    result: dict[str, Any] = json.loads(session.stdout)
    holes = _feature_holes(done)
    truth = {(row["part"], holes[row["feature"]]) for row in done.truth["fits"] if row["feature"] in holes
             and row["fits"]}
    assert {tuple(pair) for pair in result["fits"]} == truth
    sizes = _atoms(done.out / "sizes.lp")
    pairs = {(part, hole) for (part,) in sizes["part"] for (hole,) in sizes["hole"]}
    assert {(p, h) for p, h, _ in result["not_observed"]} == pairs  # every pair labelled, none observed
    assert {(p, h) for p, h, outcome in result["not_observed"] if outcome == "fit"} == truth
    assert result["experiments"] == 0 and not (run / "journal.jsonl").read_text().strip()
    assert _atoms(run / "learned.lp")["not_observed"] == pairs
    assert result["nominal_fits"] is None  # no pair the cell builds with room
    assert session.returncode == 0, result.get("error")
    # the sim cell takes plan 1, each part placed by hand on the feature the plan names
    done_run = run_cli("assemble", "--run", str(run), "--json", timeout=300)
    report = json.loads(done_run.stdout)
    assert done_run.returncode == 0 and report["assembled"], done_run.stderr
    assert max(report["final_pose_error_mm"].values()) < 2.0
    assert set(report["manual"]) == set(done.truth["parts"]) - {done.truth["base"]}
    return result


@pytest.mark.slow  # imports the product, runs a sim session of no experiment and assembles it (90 s under load)
def test_a_product_whose_every_part_is_placed_by_hand_is_learned_by_a_sim_session_from_its_cad_not_observed(
        imported: Callable[[str], Imported], run_executor: Runner, run_cli: Runner, tmp_path: Path) -> None:
    # ldraw_axles: the axle, the bush and the gear are nominal zero-clearance fits the cell
    # has no operation for (each placed by hand): the sim session must not refuse the
    # product; it takes every pair from sizes.lp and says none was observed.
    result = _learned_from_its_cad_alone(imported("ldraw_axles"), run_executor, run_cli, tmp_path / "run")
    # the bush and the gear share the liftarm's pin (capacity 2 in assembly.toml): the bush first
    for plan in result["plans"]:
        order = [step["part"] for step in plan]
        assert {step["part"]: step["hole"] for step in plan if step["part"] in ("bush", "gear")} == {
            "bush": "liftarm_pin1", "gear": "liftarm_pin1"} and order.index("bush") < order.index("gear")


@pytest.mark.slow  # imports the product, runs a sim session of no experiment and assembles it (about 40 s)
def test_gears_with_less_room_on_their_shafts_than_the_cell_resolves_are_learned_from_the_cad_not_observed(
        imported: Callable[[str], Imported], run_executor: Runner, run_cli: Runner, tmp_path: Path) -> None:
    # factory_gears: each gear has 0.012 mm of room per side on its shaft, under the 0.025 mm
    # the cell resolves (it jammed 11.5 mm short when taught): no experiment, each placed by
    # hand with that reason, every pair taken from sizes.lp as not observed.
    done = imported("factory_gears")
    manual = load_geometry(str(done.out)).tables.manual
    assert set(manual) == {"gear_small", "gear_medium"}
    assert all("mm of room per side, less than the 0.025 mm the simulated cell resolves" in table.reason
               for table in manual.values()), {pid: table.reason for pid, table in manual.items()}
    _learned_from_its_cad_alone(done, run_executor, run_cli, tmp_path / "run")


@pytest.mark.parametrize("name", PRODUCTS)
def test_each_truth_is_a_closed_world(name: str) -> None:
    # Every part that goes into a feature against every feature of that kind (a hole, a
    # pin); a part in none (a bracket on the base) has no row. Room 0 is a nominal
    # zero-clearance fit: the CAD has the part in it.
    truth = tomllib.loads((CORPUS / name / "truth.toml").read_text())
    features = truth["features"]
    rows = [(row["part"], row["feature"]) for row in truth["fits"]]
    assert sorted(rows) == sorted((p, f) for p, part in truth["parts"].items() if "in" in part
                                  for f, feature in features.items() if feature["kind"] == features[part["in"]]["kind"])
    assert all(row["fits"] == (row["room_mm"] >= 0) for row in truth["fits"])
    assert (CORPUS / name / "SOURCE.md").is_file()


@pytest.mark.slow  # the first test of a product imports it
@pytest.mark.parametrize("name", IMPORTED)
def test_the_truth_backend_answers_every_pair_as_sizes_lp(imported: Callable[[str], Imported], name: str) -> None:
    # occt_as1: its bolts (10.000 mm) are a nominal zero-clearance fit in the plate's holes (9.981 mm, the
    # inscribed circle), which the cell's sections pass only as a stated room 0
    done = imported(name)
    backend = TruthBackend(ServeSettings(backend="truth", assembly=str(done.out)))
    sizes = _atoms(done.out / "sizes.lp")
    for (part,) in sorted(sizes["part"]):
        for (hole,) in sorted(sizes["hole"]):
            result, _ = backend.run(InsertRequest(id=f"t.{part}.{hole}", part=part, hole=hole))
            assert result == ("fit" if (part, hole) in sizes.get("fits", set()) else "no_fit"), (part, hole)


@pytest.mark.slow  # imports, teaches the ring, a sim session of 1 experiment and its assembly (291 s loaded)
@pytest.mark.timeout(600)
def test_a_ring_that_is_no_prism_is_learned_onto_its_pin_and_assembled_in_physics(
        imported: Callable[[str], Imported], run_executor: Runner, run_cli: Runner, tmp_path: Path) -> None:
    # Meta-World's ring is a torus with a handle: no stack of prisms, it collides as CoACD's
    # pieces, which keep its bore within its room on the peg; the cell grips it, carries it
    # over the peg and inserts it down onto it with the skill taught on that peg.
    done = imported("metaworld_assembly")
    assert "CoACD" in (done.out / "meshes" / "round_nut.convex.obj").read_text().splitlines()[2]
    result, journal = _taught_and_learned_in_the_cell(done, run_executor, run_cli, tmp_path / "run")
    holes = _feature_holes(done)
    assert {(e["part"], e["hole"]): e["result"] for e in journal if "result" in e} == {
        (row["part"], holes[row["feature"]]): "fit" if row["fits"] else "no_fit" for row in done.truth["fits"]}
    report = result["assembly"]
    steps = {step["part"]: step for step in report["steps"]}
    assert report["assembled"] and steps["round_nut"]["skill"] == "insert", report
    assert steps["round_nut"]["pose_error_mm"] < 2.0, report["final_pose_error_mm"]
