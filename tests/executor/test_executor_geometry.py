"""Cell geometry: sizes make paper Fig. 5 true, every shipped product's geometry gives its
sizes.lp, the graded-peg board is graded, generated assets are reproducible."""

from __future__ import annotations

import itertools
import math
import re

import pytest

from asp.sizes.truth_oracle import TruthOracle
from bridge.assembly import DATA_DIR
from executor.world.geometry import (
    PartSpec,
    Section,
    load_geometry,
    part_urdf_text,
    passes,
    plate_obj_text,
)
from tests._tolerances import assert_same_asset

WITH_GEOMETRY = sorted(p.parent.name for p in DATA_DIR.glob("*/geometry.toml"))


def test_sizes_make_fig5_true(root):
    """The truth backend of the cell answers from these cross-sections: they must give sizes.lp."""
    geometry = load_geometry("cranfield")
    truth = set(re.findall(r"fits\((\w+),(\w+)\)", (root / "data/cranfield/sizes.lp").read_text()))
    for pid in ("p1", "p2", "p3", "p4", "sh"):
        for hid, hole in geometry.holes.items():
            assert passes(geometry.parts[pid], hole) == ((pid, hid) in truth), (pid, hid)


def test_clearances():
    geometry = load_geometry("cranfield")
    holes, parts = geometry.holes, geometry.parts
    assert math.isclose(holes["r1"].size - parts["p1"].size, 0.0013, abs_tol=1e-9)
    assert math.isclose(holes["s1"].size - parts["p3"].size, 0.0013, abs_tol=1e-9)
    assert math.isclose(holes["br"].size - parts["sh"].size, 0.0013, abs_tol=1e-9)
    assert math.isclose(holes["r2"].size - parts["tp"].size, 0.0001, abs_tol=1e-9)


def test_every_shipped_product_with_geometry_is_listed() -> None:
    assert {"cranfield", "spare", "graded"} <= set(WITH_GEOMETRY)


@pytest.mark.parametrize("assembly", WITH_GEOMETRY)
def test_the_geometry_rule_gives_sizes_lp(assembly: str) -> None:
    """The truth cells answer from the cross-sections, the session checks against sizes.lp."""
    geometry = load_geometry(assembly)
    truth = TruthOracle.from_assembly(assembly)
    assert set(truth.holes) == set(geometry.holes)
    assert {(p, h) for p in truth.parts for h in truth.holes
            if passes(geometry.parts[p], geometry.holes[h])} == truth.fits


def _complete_assignments(truth: TruthOracle, holes: list[str] | tuple[str, ...]) -> int:
    """How many ways every part gets its own hole that it fits (brute force)."""
    return sum(all((p, h) in truth.fits for p, h in zip(truth.parts, chosen))
               for chosen in itertools.permutations(holes, len(truth.parts)))


def test_the_graded_board_is_a_staircase_with_one_spare_hole() -> None:
    """Six pegs of distinct sizes, seven holes: nested fit sets of six different sizes (not
    all-fit, not one-to-one); without the spare h7 one complete assignment (peg i, hole i),
    with it the three thinnest pegs have a choice."""
    truth = TruthOracle.from_assembly("graded")
    rows = {p: frozenset(h for h in truth.holes if (p, h) in truth.fits) for p in truth.parts}
    assert len(rows) == 6 and len(truth.holes) == 7
    chain = sorted(rows.values(), key=len)
    assert all(a < b for a, b in zip(chain, chain[1:])), "fit sets not strictly nested"
    assert 0 < len(truth.fits) < 6 * 7 and any(len(r) > 1 for r in rows.values())
    assert rows["p6"] == {"h6"} and rows["p1"] == set(truth.holes)
    assert {p for p, r in rows.items() if "h7" in r} == {"p1", "p2", "p3"}
    assert _complete_assignments(truth, truth.holes) == 8
    assert _complete_assignments(truth, [h for h in truth.holes if h != "h7"]) == 1
    sizes = load_geometry("graded")
    assert sizes.holes["h7"].size == sizes.holes["h3"].size
    # The largest clearance of any complete assignment: p1 in a hole of h3's size.
    assert math.isclose(sizes.holes["h3"].size - sizes.parts["p1"].size, 0.0028, abs_tol=1e-9)


@pytest.mark.parametrize("assembly", WITH_GEOMETRY)
def test_committed_assets_are_what_the_generator_makes(assembly: str) -> None:
    geometry = load_geometry(assembly)
    assert_same_asset((geometry.assets / "plate.obj").read_text(), plate_obj_text(geometry))
    for part in geometry.parts.values():
        assert_same_asset((geometry.assets / f"part_{part.shape}.urdf").read_text(), part_urdf_text(part))


def test_a_square_peg_passes_a_round_hole_only_by_its_diagonal() -> None:
    square = PartSpec("q", "square", 0.010, shape="q", length=0.05, mass=0.05, start=(0.0, 0.0), demo_hole="h")
    assert passes(square, Section("h", "round", 0.0142))  # diagonal 14.14 mm
    assert not passes(square, Section("h", "round", 0.0141))
    assert passes(square, Section("h", "square", 0.0101))
