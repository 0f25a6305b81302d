"""``./run.sh assemble --backend franka --backend-option host=...`` against franky-sim: plan 1
of the test product's true facts, executed by a franka cell, places every peg within 2 mm of
its goal in the simulated world (its truth, not the robot's own reading).

Long (three pegs picked and inserted, 30-80 s each on the shared 2-core machine)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("franky")
pytest.importorskip("mujoco")

from executor.franka.sim_server import sim_robot  # noqa: E402
from executor.world.geometry import load_geometry  # noqa: E402
from tests.franka import franka_cell_description

TRIO = Path(__file__).parent / "data" / "trio"
PLACED = 0.002  # [m] a placed peg's distance from its goal, at most


@pytest.mark.slow
@pytest.mark.timeout(1500)
@pytest.mark.usefixtures("one_simulated_arm")
@pytest.mark.franka_arm
def test_assemble_on_the_franka_places_every_peg(run_cli, tmp_path: Path) -> None:
    folder = Path(shutil.copytree(TRIO, tmp_path / "trio"))
    description = franka_cell_description(tmp_path)
    with sim_robot(folder) as sim:
        done = run_cli("assemble", "--assembly", str(folder), "--backend", "franka",
                       "--backend-option", f"host={sim.host}", "--backend-option", "realtime=ignore",
                       "--backend-option", "dynamics=0.5", "--cell-description", str(description),
                       "--timeout", "600", "--json", timeout=1400)
        assert done.returncode == 0, done.stderr
        report = json.loads(done.stdout)
        world = sim.truth()
    assert report["assembled"] and report["manual"] == [], report
    geometry = load_geometry(str(folder))
    inserted = [step for step in report["steps"] if step["hole"] is not None]
    assert len(inserted) == 3 and all(step["outcome"] == "fit" for step in inserted), report["steps"]
    for step in inserted:
        hole = geometry.holes[step["hole"]]
        goal = np.array([*hole.position, hole.bottom_z])  # the peg's body frame: its bottom face's centre
        error = float(np.linalg.norm(world.poses[step["part"]][0] - goal))
        assert error <= PLACED, (step, world.poses[step["part"]][0], goal)
