"""A learning session and the assembly of its plan through the franka backend against
franky-sim, as docs/franka.md shows them: ``./run.sh session --backend franka
--backend-option host=...`` learns the fits of a product of three graded pegs exactly, then
``./run.sh assemble --run RUN --backend franka`` (the same options) places every peg, each
``fit`` and within 2 mm of its goal in the simulated world (its truth, not the robot's own
reading), no step left to an operator.

One test, long: 6-7 min on the shared 2-core machine under load (docs/franka.md, "The
session acceptance"); the harness holds a grasped part with a weld, as the PyBullet cell's
grasp constraint does. One simulated arm serves both commands (the assembly starts where
the session's experiments left the pegs: each back where it waited)."""

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
@pytest.mark.timeout(2400)
@pytest.mark.usefixtures("one_simulated_arm")
@pytest.mark.franka_arm
def test_a_session_through_the_franka_backend_learns_the_fits_and_assemble_places_every_peg(
        run_cli, tmp_path: Path) -> None:
    folder = Path(shutil.copytree(TRIO, tmp_path / "trio"))
    description = franka_cell_description(tmp_path)
    _, _, truth = sizes_truth(folder / "sizes.lp")
    with sim_robot(folder) as sim:
        arm = ("--backend", "franka", "--backend-option", f"host={sim.host}", "--backend-option", "realtime=ignore",
               "--backend-option", "dynamics=0.5", "--cell-description", str(description))
        done = run_cli("session", "--assembly", str(folder), "--cells", "1", *arm, "--timeout", "1500", "--json",
                       "--out", str(tmp_path / "run"), timeout=1700)
        assert done.returncode == 0, (done.stderr, done.stdout)
        result = json.loads(done.stdout)
        assert sorted(map(tuple, result["fits"])) == sorted(truth) and result["matches_truth"] is True
        done = run_cli("assemble", "--run", str(tmp_path / "run"), *arm, "--timeout", "600", "--json", timeout=1400)
        assert done.returncode == 0, (done.stderr, done.stdout)  # stdout: the steps' goal errors, if it got there
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
