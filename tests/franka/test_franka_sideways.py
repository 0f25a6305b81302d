"""Holes entered sideways on the Franka backend against franky-sim: ``tests/franka/data/side``
(pegs d 10 mm; a hole d 10.8 mm along +x, one d 9.6 mm along -y, in a block whose bosses
the MuJoCo scene builds in each hole's frame), the skill taught in the PyBullet cell and
shipped with the product (``demonstrations/``, ``./run.sh executor teach``): the test is
the arm's, not the teaching's. A peg stops at the entry of the narrow -y hole, eq. (6) on
the force along its axis, backs out and goes into the +x hole to its depth, the tool
turned along each axis in turn."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("franky")
pytest.importorskip("mujoco")

from executor.cell_description import load_cell_description  # noqa: E402
from executor.world.arm import quat_to_matrix  # noqa: E402
from executor.world.geometry import load_geometry  # noqa: E402
from tests.franka import franka_cell_description, franka_on_sim

pytestmark = [pytest.mark.slow, pytest.mark.timeout(1200), pytest.mark.usefixtures("one_simulated_arm"),
              pytest.mark.franka_arm]

PRODUCT = Path(__file__).parent / "data" / "side"
SEARCH_RADIUS = 0.0015
"""[m] the hole search's radius in the test's cell (its ``[search]`` table): franky-sim puts
the product where the cell believes it, and the peg's tip came down within 0.2 mm of
the hole's axis, so the grasp's error and half a pitch (0.6 mm) in place of the
default's 4.6 mm for a calibrated plate: the too-narrow hole's search, which runs its
whole spiral, takes 0.7 s of robot time in place of about 7 s."""


def test_a_peg_stops_at_a_too_narrow_hole_entered_sideways_and_goes_into_one_that_fits(tmp_path: Path) -> None:
    folder = Path(shutil.copytree(PRODUCT, tmp_path / "side"))
    description = load_cell_description(franka_cell_description(tmp_path, SEARCH_RADIUS))
    geometry = load_geometry(str(folder), description)
    seen = {}
    with franka_on_sim(folder, geometry, description) as (cell, sim):
        cell.pick("p1")
        for hole in ("h3", "h2"):  # -y, then +x
            result, detector, _found = cell.insert("p1", hole, np.random.default_rng(0))
            frame = geometry.holes[hole].frame
            assert frame is not None
            tip, quat = sim.truth().poses["p1"]  # the peg's bottom face: its tip; w x y z
            along = quat_to_matrix(np.array([*quat[1:], quat[0]]))[:, 2] @ frame.rotation[:, 2]
            seen[hole] = (result.reached, geometry.holes[hole].top_z - frame.points_in(tip)[2], along,
                          detector.max_force_dev)
            if not result.reached:
                cell.lift()  # out along the axis, up
    reached, depth, _along, force = seen["h3"]
    assert not reached and abs(depth) < 0.001 and force >= description.thresholds.f_stop, seen  # in the entry's chamfer
    reached, depth, along, _force = seen["h2"]
    tolerance = description.thresholds.goal_tolerance
    assert reached and abs(depth - geometry.holes["h2"].depth) < tolerance and along > 0.999, seen  # in along +x
