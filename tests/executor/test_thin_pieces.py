"""A moving part's convex piece thinner than twice the hull margin across a face (a 2 mm
plate): the cell erodes it across that face to near its middle only, so PyBullet, adding
its 1 mm margin back, collides as the piece with each face at most THIN_EXCESS farther out
(executor/world/meshes.py); a thinner piece is refused."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pybullet as p
import pytest
import shapely

from executor import ExecutorError
from executor.world.meshes import MIN_THICKNESS, THIN_EXCESS, URDF_HULL_MARGIN, eroded, eroded_text
from tests.executor import load_piece


def plate(thickness: float) -> np.ndarray:
    """The vertices [m] of a rounded-rect plate 40 x 24 mm, corner radius 5 (arcs of 8
    segments), ``thickness`` [m] thick, its bottom on z = 0."""
    outline = shapely.box(-0.015, -0.007, 0.015, 0.007).buffer(0.005, quad_segs=8)
    ring = np.asarray(outline.exterior.coords)[:-1]
    return np.vstack([np.column_stack([ring, np.full(len(ring), z)]) for z in (0.0, thickness)])


def _reach(body: int, start: np.ndarray, direction: np.ndarray) -> float:
    """How far [m] from ``start`` along ``direction`` PyBullet's collision shape of ``body``
    reaches: where a probe sphere of 0.1 mm coming from 20 mm out first touches it
    (bisected to 0.1 µm)."""
    radius = 1e-4
    probe = p.createMultiBody(0, p.createCollisionShape(p.GEOM_SPHERE, radius=radius))
    unit = direction / np.linalg.norm(direction)
    low, high = 0.0, 0.03
    while high - low > 1e-7:
        mid = (low + high) / 2
        p.resetBasePositionAndOrientation(probe, start + unit * (mid + radius), (0, 0, 0, 1))
        touching = p.getClosestPoints(body, probe, 0.0)
        low, high = (mid, high) if touching and min(contact[8] for contact in touching) <= 0 else (low, mid)
    p.removeBody(probe)
    return (low + high) / 2


def test_a_2_mm_plate_collides_in_pybullet_as_its_cad_within_what_the_cell_resolves(tmp_path: Path) -> None:
    # The plate as the cell writes a mesh part's collision asset and loads it (a URDF
    # link): at mid-height its sides and rounded corners where the CAD has them, its top
    # and bottom faces at most THIN_EXCESS beyond the CAD's.
    client = p.connect(p.DIRECT)
    try:
        body = load_piece(tmp_path, plate(0.002), "plate", 0.02)
        middle = np.array([0.0, 0.0, 0.001])
        side, end = _reach(body, middle, np.array([0.0, 1.0, 0.0])), _reach(body, middle, np.array([1.0, 0.0, 0.0]))
        corner = _reach(body, np.array([0.015, 0.007, 0.001]), np.array([1.0, 1.0, 0.0]))
        top = _reach(body, middle, np.array([0.0, 0.0, 1.0]))
        bottom = _reach(body, middle, np.array([0.0, 0.0, -1.0]))
    finally:
        p.disconnect(client)
    assert side == pytest.approx(0.012, abs=2e-6) and end == pytest.approx(0.020, abs=2e-6)
    assert 0.005 - 2e-5 < corner <= 0.005 + 1e-6  # the arc's chords lie inside it (8 segments: 19 µm)
    assert 0.001 <= top <= 0.001 + THIN_EXCESS and 0.001 <= bottom <= 0.001 + THIN_EXCESS


def test_a_piece_thinner_than_the_margin_twice_less_what_the_cell_resolves_is_refused() -> None:
    assert eroded(plate(MIN_THICKNESS + 1e-6), URDF_HULL_MARGIN) is not None
    assert eroded(plate(MIN_THICKNESS - 1e-6), URDF_HULL_MARGIN) is None
    with pytest.raises(ExecutorError, match=r"plate.convex.obj: convex piece 1 of plate is thinner than 1.952 mm"):
        eroded_text([plate(0.0012)], "plate", "plate.convex.obj")
