"""Teaching on the arm: ``executor teach --backend franka`` against franky-sim records the
skill of every part shape of a product that has none (the scripted demonstration, the
reference wrench from the harness's wrist sensor) and stores it as the PyBullet cell's
skills are; a franka cell then starts on those skills and inserts a peg with one of them.
The pegs wait 2 mm from where the cell believes them, so the hand holds each 2 mm off
(along its pads, which do not centre it): the teaching finds each hole with the hole
search before the descent (brought straight down, a part lands on the plate beside it).

Long (each shape is picked, guided down its hole, replayed and put back; then one
insertion): several minutes on the shared 2-core machine."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

pytest.importorskip("franky")
pytest.importorskip("mujoco")

from bridge.cell_settings import CellSettings, ServeSettings  # noqa: E402
from bridge.messages import InsertRequest  # noqa: E402
from executor import ExecutorError  # noqa: E402
from executor.franka.backend import franka_starter  # noqa: E402
from executor.franka.sim_server import sim_robot  # noqa: E402
from tests.franka import franka_cell_description, parts_moved

TRIO = Path(__file__).parent / "data" / "trio"
DEMOS = {"peg_d10": ("p1", "h1"), "peg_d11": ("p2", "h2"), "peg_d12": ("p3", "h3")}
"""Each shape's part and the hole it is taught in (``demo_hole``)."""
GRASP_ERROR = 0.002
"""[m] along x, where the fingers' pads do not centre a part: how far each peg waits from
its ``start`` in the simulated world."""


@pytest.mark.slow
@pytest.mark.timeout(1800)
@pytest.mark.usefixtures("one_simulated_arm")
@pytest.mark.franka_arm
def test_skills_taught_on_the_arm_are_stored_and_an_insertion_uses_them(run_executor, tmp_path: Path) -> None:
    folder = Path(shutil.copytree(TRIO, tmp_path / "trio", ignore=shutil.ignore_patterns("assets", "demonstrations")))
    description = franka_cell_description(tmp_path)
    with sim_robot(parts_moved(folder, tmp_path / "world", GRASP_ERROR)) as sim:
        options = {"host": sim.host, "realtime": "ignore", "dynamics": "0.5"}
        settings = ServeSettings(backend="franka", assembly=str(folder), backend_options=options,
                                 cell=CellSettings(description=str(description)))
        with pytest.raises(ExecutorError, match="peg_d10"):
            franka_starter(settings)  # no skills yet: the cell refuses to start
        done = run_executor("teach", "--assembly", str(folder), "--backend", "franka",
                            *(arg for key, value in options.items() for arg in ("--backend-option", f"{key}={value}")),
                            "--cell-description", str(description), timeout=1500)
        assert done.returncode == 0, done.stderr
        for shape, (part, hole) in DEMOS.items():
            path = folder / "demonstrations" / f"{shape}.json"
            assert f"wrote {path}" in done.stdout, done.stdout
            taught = json.loads(path.read_text(encoding="utf-8"))["taught"]
            assert (taught["part"], taught["hole"]) == (part, hole), taught
            assert taught["end_error"] < taught["goal_tolerance"], taught  # the demonstration reached its goal
        backend = franka_starter(settings)()
        try:
            result, evidence = backend.run(InsertRequest(id="a", part="p1", hole="h1"))
        finally:
            backend.close()
    assert result == "fit" and evidence is not None and evidence.attempts >= 1, evidence
