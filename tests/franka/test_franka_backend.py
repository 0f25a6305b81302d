"""The franka backend against franky-sim, without Zenoh: a hand that closes on nothing (the
part elsewhere) fails the request; a cover and a head, which the arm has no skill for, are
manual steps that do not move it. (Experiments, their ``no_fit`` and the part carried back,
and plan steps checked in the simulated world: ``test_franka_learning.py``.)

Long-ish (the simulator steps at a fraction of real time on a shared 2-core machine: 10-30 s
each)."""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("franky")
pytest.importorskip("mujoco")

from bridge.assembly import DATA_DIR  # noqa: E402
from bridge.cell_settings import CellSettings, ServeSettings  # noqa: E402
from bridge.messages import InsertRequest, StepRequest  # noqa: E402
from executor import ExecutorError  # noqa: E402
from executor.backend_plugin import InvalidStep  # noqa: E402
from executor.franka.backend import FrankaBackend, franka_starter  # noqa: E402
from executor.franka.sim_server import SimRobot, sim_robot  # noqa: E402
from executor.world.geometry import CellGeometry, load_geometry  # noqa: E402
from tests.franka import SIM_DYNAMICS, franka_cell_description, parts_moved

# The tests drive the simulated arm: long, one arm on the machine at a time, on demand (-m franka_arm).
pytestmark = [pytest.mark.slow, pytest.mark.timeout(1200), pytest.mark.usefixtures("one_simulated_arm"),
              pytest.mark.franka_arm]


@contextmanager
def _arm(tmp_path: Path, product: str, moved: tuple[str, float] | None = None
         ) -> Iterator[tuple[SimRobot, FrankaBackend, CellGeometry]]:
    """franky-sim with a copy of the shipped ``product`` and a franka backend driving it;
    ``moved``: a part and how far [m] along x from its ``start`` the simulated world has it."""
    folder = Path(shutil.copytree(DATA_DIR / product, tmp_path / product, ignore=shutil.ignore_patterns("assets")))
    description = franka_cell_description(tmp_path)
    world = folder if moved is None else parts_moved(folder, tmp_path / "world", moved[1], {moved[0]})
    with sim_robot(world) as sim:
        settings = ServeSettings(backend="franka", assembly=str(folder),
                                 backend_options={"host": sim.host, "realtime": "ignore", "dynamics": SIM_DYNAMICS},
                                 cell=CellSettings(layer="pi_phase_stop", description=str(description)))
        backend = franka_starter(settings)()
        try:
            yield sim, backend, load_geometry(str(folder))
        finally:
            backend.close()


def test_a_hand_that_closes_on_nothing_says_so(tmp_path: Path) -> None:
    """p1 waits 50 mm from where the cell believes it: the hand comes down on its believed
    place and closes on nothing, and the request fails naming that (no outcome); the hand
    holds nothing and the part was not touched."""
    with _arm(tmp_path, "spare", moved=("p1", -0.05)) as (sim, backend, geometry):
        with pytest.raises(ExecutorError, match="closed on nothing at part p1's place"):
            backend.run(InsertRequest(id="a", part="p1", hole="r1"))
        world = sim.truth()
    assert not world.held, world.held
    waits = np.array([geometry.parts["p1"].start[0] - 0.05, geometry.parts["p1"].start[1], 0.0])
    assert np.linalg.norm(world.poses["p1"][0] - waits) < 1e-4, world.poses["p1"]


def test_covers_and_heads_are_left_to_an_operator_and_the_arm_stays(tmp_path: Path) -> None:
    """Cranfield's separator (a cover) and pendulum head: steps the arm has no skill for,
    answered manual without a motion, not among the placed parts' pose errors."""
    with _arm(tmp_path, "cranfield") as (_sim, backend, _geometry):
        backend.run_step(StepRequest(id="s1", assembly="run", step=1, part="bp"))
        tcp = backend.cell.robot.current_cartesian_state.pose.end_effector_pose.translation
        for number, part in ((2, "sp"), (3, "ph")):
            outcome, step, placed = backend.run_step(StepRequest(id=f"s{number}", assembly="run", step=number,
                                                                 part=part))
            assert (outcome, step.skill, step.attempts, set(placed)) == ("fit", "manual", 0, {"bp"}), step
        with pytest.raises(InvalidStep, match="already placed"):
            backend.run_step(StepRequest(id="s4", assembly="run", step=4, part="sp"))
        moved = backend.cell.robot.current_cartesian_state.pose.end_effector_pose.translation
        assert np.linalg.norm(np.array(moved) - np.array(tcp)) < 1e-4
