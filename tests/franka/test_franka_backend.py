"""The franka backend against franky-sim, without Zenoh: an experiment whose part cannot
pass (the square peg, diagonal 17 mm, onto a round hole of 13.3 mm) stops on eq. (6) and
answers no_fit with the part back on the table; a plan step puts a round peg into a round
hole, and the simulated world (not the robot's reading) has it within 2 mm of its goal.

Long (the simulator steps at about a tenth of real time on a shared 2-core machine: about
5 min); in one xdist group (with ``--dist loadgroup``) with the other franky loop."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("franky")
pytest.importorskip("mujoco")

from bridge.assembly import DATA_DIR  # noqa: E402
from bridge.cell_settings import CellSettings, ServeSettings  # noqa: E402
from bridge.messages import InsertRequest, StepRequest  # noqa: E402
from executor.franka.backend import franka_starter  # noqa: E402
from executor.franka.sim_server import sim_robot  # noqa: E402
from executor.world.geometry import load_geometry  # noqa: E402

GRASP_DEPTH = 0.012  # [m] the Franka Hand's pads reach 8.5 mm below its TCP: they clear the plate so
PLACED = 0.002  # [m] a placed peg's distance from its goal, at most
BACK = 0.015
"""[m] a part carried back lies this close to where it waited, at most: franky-sim's hand lets
the peg slide along its pads under the insertion's forces (13 mm measured, docs/franka.md)."""


@pytest.mark.slow
@pytest.mark.timeout(1800)
@pytest.mark.xdist_group("franka")
def test_the_franka_backend_refuses_a_part_too_big_and_places_one_that_fits(tmp_path: Path) -> None:
    folder = Path(shutil.copytree(DATA_DIR / "spare", tmp_path / "spare", ignore=shutil.ignore_patterns("assets")))
    description = tmp_path / "franka-cell.toml"
    description.write_text("[gripper]\nflange_mass = 1.0\nflange_inertia = 0.004\nflange_length = 0.06\n"
                           f"grasp_depth = {GRASP_DEPTH}\n")
    geometry = load_geometry(str(folder))
    with sim_robot(folder) as sim:
        settings = ServeSettings(backend="franka", assembly=str(folder),
                                 backend_options={"host": sim.host, "realtime": "ignore", "dynamics": "0.5"},
                                 cell=CellSettings(layer="pi_phase_stop", description=str(description)))
        backend = franka_starter(settings)()
        try:
            result, evidence = backend.run(InsertRequest(id="a", part="p3", hole="r1"))
            assert result == "no_fit" and evidence is not None and evidence.max_force_dev >= 30.0, evidence
            back, quat = sim.truth().poses["p3"]
            assert np.linalg.norm(back[:2] - np.array(geometry.parts["p3"].start)) < BACK, back
            assert abs(back[2]) < 0.001 and abs(quat[0]) > np.cos(np.radians(5) / 2), (back, quat)  # standing

            assert backend.run_step(StepRequest(id="s1", assembly="run", step=1, part="bp"))[0] == "fit"
            outcome, step, placed = backend.run_step(StepRequest(id="s2", assembly="run", step=2, part="p1",
                                                                 hole="r1"))
            assert outcome == "fit" and set(placed) == {"bp", "p1"}, step
        finally:
            backend.close()
        world = sim.truth()
    hole = geometry.holes["r1"]
    goal = np.array([*hole.position, hole.bottom_z])  # the peg's body frame: its bottom face's centre
    assert np.linalg.norm(world.poses["p1"][0] - goal) <= PLACED, (world.poses["p1"][0], goal)
