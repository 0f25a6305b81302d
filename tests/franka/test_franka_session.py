"""A learning session and the assembly through the franka backend against franky-sim:
``./run.sh session --backend franka --backend-option host=...`` learns the fits of a product
of three graded pegs exactly, and ``--assemble`` places every peg within 2 mm of its goal
in the simulated world (its truth, not the robot's own reading).

One test, long: 6 min 40 s on the shared 2-core machine under load (docs/franka.md, "The
session acceptance"); the harness holds a grasped part with a weld, as the PyBullet cell's
grasp constraint does."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("franky")
pytest.importorskip("mujoco")

from executor.franka.sim_server import sim_robot  # noqa: E402
from executor.serve.truth import sizes_truth  # noqa: E402
from executor.world.geometry import load_geometry  # noqa: E402
from tests.franka import franka_cell_description

TRIO = Path(__file__).parent / "data" / "trio"
PLACED = 0.002  # [m] a placed peg's distance from its goal, at most


@pytest.mark.slow
@pytest.mark.timeout(1800)
@pytest.mark.usefixtures("one_simulated_arm")
@pytest.mark.franka_arm
def test_a_session_through_the_franka_backend_learns_the_fits_and_assembles(run_cli, tmp_path: Path) -> None:
    folder = Path(shutil.copytree(TRIO, tmp_path / "trio"))
    description = franka_cell_description(tmp_path)
    _, _, truth = sizes_truth(folder / "sizes.lp")
    with sim_robot(folder) as sim:
        done = run_cli("session", "--assembly", str(folder), "--cells", "1", "--backend", "franka",
                       "--backend-option", f"host={sim.host}", "--backend-option", "realtime=ignore",
                       "--backend-option", "dynamics=0.5",
                       "--cell-description", str(description), "--timeout", "1500", "--assemble", "--json",
                       "--out", str(tmp_path / "run"), timeout=1700)
        assert done.returncode == 0, (done.stderr, done.stdout)  # stdout: the steps' goal errors, if it got there
        result = json.loads(done.stdout)
        assert sorted(map(tuple, result["fits"])) == sorted(truth) and result["matches_truth"] is True
        assert result["assembly"]["assembled"], result["assembly"]
        world = sim.truth()
    geometry = load_geometry(str(folder))
    for step in result["assembly"]["steps"]:
        if step["hole"] is None:
            continue
        hole = geometry.holes[step["hole"]]
        goal = np.array([*hole.position, hole.bottom_z])  # the peg's body frame: its bottom face's centre
        error = float(np.linalg.norm(world.poses[step["part"]][0] - goal))
        assert error <= PLACED, (step, world.poses[step["part"]][0], goal)
