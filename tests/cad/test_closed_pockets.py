"""A base's empty cavity that opens on its far side (a pocket cut up from its underside, a
Lego brick's inside) is no hole along the axis it is sliced on: the import goes on without
it, and measures the base's other empty holes as before."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import shapely
import trimesh

from executor.cad.cli import report, run_import
from executor.cad.sections import Loop, classify


def _write(folder: Path, *, through: bool = True) -> None:
    """A 60 x 60 x 20 mm block with a d 10 pocket 12 mm up from its underside (closed
    above) and a d 8 hole through it (``through``), and a 20 x 20 x 5 mm plate lying on
    its top, as STL [mm]."""
    folder.mkdir()
    block = trimesh.creation.box((60.0, 60.0, 20.0))
    block.apply_translation((0.0, 0.0, 10.0))
    pocket = trimesh.creation.extrude_polygon(shapely.Point(-15.0, 0.0).buffer(5.0, quad_segs=16), 12.0)
    pocket.apply_translation((0.0, 0.0, -1.0))
    hole = trimesh.creation.extrude_polygon(shapely.Point(15.0, 0.0).buffer(4.0, quad_segs=16), 22.0)
    hole.apply_translation((0.0, 0.0, -1.0))
    cuts = [pocket, hole] if through else [pocket]
    trimesh.boolean.difference([block, *cuts], engine="manifold").export(folder / "block.stl")
    plate = trimesh.creation.box((20.0, 20.0, 5.0))
    plate.apply_translation((0.0, 20.0, 22.5))
    plate.export(folder / "plate.stl")


def test_pocket_open_on_the_far_side_is_no_hole(tmp_path: Path) -> None:
    # Sliced at the block's middle along +z, the pocket's loop has nothing free up to the
    # block's top: the import stopped on it ("the hole of part block ... is closed").
    _write(tmp_path / "meshes")
    derived = run_import(tmp_path / "meshes", tmp_path / "out", "mm", None).derived
    assert derived.base == "block"
    holes = list(derived.holes.values())
    assert len(holes) == 1 and holes[0].part is None
    assert holes[0].hole.kind == "round" and abs(holes[0].hole.a - 0.008) < 1e-4
    assert derived.axis["plate"] == "+z"
    assert not [line for line in report(derived) if line.startswith("no hole and no pin")]


def test_a_product_with_no_hole_and_no_pin_is_named(tmp_path: Path) -> None:
    # The plate on the block with its pocket alone: sizes.lp names nothing, nothing to learn
    # (tests/cad/test_stacked_boxes.py plans, learns and assembles such a product); the import says so.
    _write(tmp_path / "meshes", through=False)
    derived = run_import(tmp_path / "meshes", tmp_path / "out", "mm", None).derived
    assert not derived.holes and not derived.pins
    assert [line for line in report(derived) if line.startswith(
        "no hole and no pin found: sizes.lp names no part and no hole, nothing to learn")]


def test_a_sliver_of_no_area_is_a_polygon() -> None:
    # The narrowest section of a Lego brick's underside cavity over its stretch came out
    # as three points on one line (two faces meeting): classify() divided by its zero
    # width (ZeroDivisionError). It is a polygon, so the empty loop is a pocket, no hole.
    sliver = Loop(np.array([[0.5537604, -0.0035801], [0.554799, -0.0044975], [0.5537604, -0.0035801]]))
    shape = classify(sliver, hole=True)
    assert shape.kind == "polygon" and shape.b == 0.0 and shape.a > 0
