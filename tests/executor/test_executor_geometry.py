"""Cell geometry: sizes make paper Fig. 5 true, generated assets are reproducible."""

from __future__ import annotations

import math
import re

from executor.world.geometry import HoleSpec, PartSpec, load_geometry, part_urdf_text, passes, plate_obj_text


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


def test_committed_assets_are_what_the_generator_makes():
    geometry = load_geometry("cranfield")
    assert (geometry.assets / "plate.obj").read_text() == plate_obj_text(geometry)
    for part in geometry.parts.values():
        assert (geometry.assets / f"part_{part.shape}.urdf").read_text() == part_urdf_text(part)


def test_a_square_peg_passes_a_round_hole_only_by_its_diagonal() -> None:
    square = PartSpec("q", "square", 0.010, shape="q", length=0.05, mass=0.05, start=(0.0, 0.0), demo_hole="h")
    assert passes(square, HoleSpec("h", "round", 0.0142, (0.0, 0.0)))  # diagonal 14.14 mm
    assert not passes(square, HoleSpec("h", "round", 0.0141, (0.0, 0.0)))
    assert passes(square, HoleSpec("h", "square", 0.0101, (0.0, 0.0)))
