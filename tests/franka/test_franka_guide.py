"""Teaching by hand-guiding (executor.franka.guide): the recorder's triggers and resampling
on recordings made up here, the command's refusal without an arm, and, slow, a person's hand
in franky-sim's MuJoCo world (an external force on the held part, executor.franka.sim_hand)
guiding a peg from above its hole into it while the arm is compliant: the skill taught from
that demonstration is the hand's (its duration and its end), reaches its goal in the replay
and is stored and read back as the scripted teaching's skills are (long: `-m franka_arm`)."""

from __future__ import annotations

import logging
import shutil
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("franky")
pytest.importorskip("mujoco")

from executor import ExecutorError  # noqa: E402
from executor.franka.guide import REST_SPEED, Recording, demonstration_span, resample  # noqa: E402
from executor.world.scene import TIME_STEP  # noqa: E402
from tests.franka import SIM_DYNAMICS, franka_cell_description

TRIO = Path(__file__).parent / "data" / "trio"
DUO = Path(__file__).parent / "data" / "duo"  # its pegs stand in front of their holes: short carrying moves
LOG = logging.getLogger(__name__)  # the figures of the run (pytest --log-cli-level=INFO shows them)


def _recording(z: np.ndarray, dt: float = TIME_STEP) -> Recording:
    n = len(z)
    times = 10.0 + dt * np.arange(n)
    positions = np.column_stack([np.full(n, 0.5), np.zeros(n), z])
    speeds = np.abs(np.gradient(z, dt))
    quats = np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
    return Recording(times, positions, quats, speeds, np.zeros((n, 6)))


def test_the_demonstration_is_the_span_from_the_entrance_to_the_rest() -> None:
    """Down to 1 mm above the start depth, a pause, down through it to the bottom in 0.5 s,
    then at rest: the span starts at the last sample at the start depth or above (after the
    pause) and ends where the rest begins."""
    start_z = 0.098
    z = np.concatenate([np.linspace(0.12, 0.099, 400), np.full(300, 0.099),
                        np.linspace(0.099, 0.0755, 500), np.full(1200, 0.0755)])
    rec = _recording(z)
    first, last = demonstration_span(rec, start_z)
    assert z[first] >= start_z > z[first + 1]
    assert rec.speeds[last] < REST_SPEED <= rec.speeds[last - 1]
    assert last == 1200  # the first sample at rest on the bottom
    assert 0.4 < rec.times[last] - rec.times[first] < 0.5


def test_a_part_never_below_the_entrance_or_too_short_a_motion_is_refused() -> None:
    with pytest.raises(ExecutorError, match="not guided below"):
        demonstration_span(_recording(np.linspace(0.12, 0.099, 500)), 0.098)
    with pytest.raises(ExecutorError, match="expected at least"):
        demonstration_span(_recording(np.concatenate([np.linspace(0.0985, 0.0975, 20), np.full(900, 0.0975)])),
                           0.098)


def test_missed_cycles_are_filled_in_on_the_1_ms_grid() -> None:
    times = np.array([5.0, 5.001, 5.004, 5.005])  # two cycles missed
    positions = np.array([[0.0, 0.0, 0.1], [0.0, 0.0, 0.099], [0.0, 0.0, 0.096], [0.0, 0.0, 0.095]])
    quats = np.array([[1.0, 0.0, 0.0, 0.0], [-1.0, 0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]])
    grid, pos, q = resample(times, positions, quats)
    assert np.allclose(grid, TIME_STEP * np.arange(6))
    assert np.allclose(pos[:, 2], 0.1 - 0.001 * np.arange(6))
    assert np.allclose(np.abs(q[:, 0]), 1.0) and np.all(q[:, 0] * q[0, 0] > 0)  # the sign flip undone


def test_hand_guiding_needs_the_franka_backend(run_main) -> None:
    done = run_main("executor", "teach", "--assembly", str(TRIO), "--demonstration", "hand")
    assert done.returncode == 2 and "--backend franka" in done.stderr and "Traceback" not in done.stderr, done.stderr


def test_teaching_on_the_arm_refuses_an_offset_it_would_not_apply(run_main) -> None:
    done = run_main("executor", "teach", "--assembly", str(TRIO), "--backend", "franka",
                    "--backend-option", "host=127.0.0.9", "--backend-option", "offset=0.01,0,0")
    assert done.returncode == 2 and "offset=0,0,0" in done.stderr and "Traceback" not in done.stderr, done.stderr


def test_teaching_refuses_a_shape_the_product_has_not_before_it_reaches_the_arm(run_main) -> None:
    """``--shapes`` names a shape of the product and one it has not: one line naming the
    unknown one and geometry.toml, exit 2, before a connection to the (absent) arm."""
    done = run_main("executor", "teach", "--assembly", str(TRIO), "--backend", "franka",
                    "--backend-option", "host=127.0.0.9", "--shapes", "peg_d10,peg_d9")
    lines = [line for line in done.stderr.splitlines() if line.strip()]
    assert done.returncode == 2 and len(lines) == 1, done.stderr
    assert "peg_d9" in lines[0] and "geometry.toml" in lines[0] and "127.0.0.9" not in lines[0], lines


@pytest.mark.slow
@pytest.mark.timeout(1200)
@pytest.mark.usefixtures("one_simulated_arm")
@pytest.mark.franka_arm
def test_a_peg_guided_into_its_hole_by_a_hand_is_taught(tmp_path: Path) -> None:
    from executor.cell_description import load_cell_description
    from executor.control.ilc import layer_named
    from executor.franka.backend import franka_options
    from executor.franka.cell import FrankaCell
    from executor.franka.guide import HandGuiding
    from executor.franka.sim_hand import Waypoint
    from executor.franka.sim_server import sim_robot
    from executor.franka.teach import FrankaTeacher
    from executor.skills.dmp import load_skill, save_skill
    from executor.skills.teach import DEMO_START_HEIGHT, teach_shape
    from executor.world.geometry import load_geometry

    folder = Path(shutil.copytree(DUO, tmp_path / "duo", ignore=shutil.ignore_patterns("assets", "demonstrations")))
    description_file = franka_cell_description(tmp_path)
    description = load_cell_description(str(description_file))
    geometry = load_geometry(str(folder), description)
    hole = geometry.holes["h1"]
    descent = 3.0  # [s] of the hand's path from 5 mm above the entrance to the bottom
    path = [Waypoint((hole.position[0], hole.position[1], hole.top_z + 0.005), 1.0),
            Waypoint((hole.position[0], hole.position[1], hole.bottom_z - 0.001), descent)]
    lines: list[str] = []
    with sim_robot(folder) as sim:
        def prompt(line: str) -> None:
            LOG.info("%s", line)
            lines.append(line)
            if line.startswith("guide"):
                hands.append(sim.guide("p1", path, hold=2.0))

        hands: list = []
        options = franka_options({"host": sim.host, "realtime": "ignore", "dynamics": SIM_DYNAMICS})
        cell = FrankaCell(geometry, description, layer_named("full"), options)
        try:
            skill = teach_shape(FrankaTeacher(cell), "peg_d10", HandGuiding(prompt, timeout=30.0))
        finally:
            cell.stop()
    LOG.info("skill: %.3f s, start %s, goal %s, taught %s; the hand's largest pull %.1f N", skill.execution_time,
             np.round(skill.demo_start, 5).tolist(), np.round(skill.demo_goal, 5).tolist(), skill.taught,
             hands[0].peak if hands else 0.0)
    assert len(lines) == 2 and lines[1].startswith("recorded"), lines
    assert hands and hands[0].done and hands[0].peak > 1.0, hands
    # The hand's: it crosses the start depth 7 mm into its 3 s descent of 31 mm (minimum jerk,
    # at 1.0 s) and the part stops on the bottom (30 mm, at 2.6 s); the scripted one lasts 0.8 s.
    assert 1.2 < skill.execution_time < descent, skill.execution_time
    assert abs(skill.demo_start[2] - DEMO_START_HEIGHT) < 0.001, skill.demo_start
    assert abs(skill.demo_goal[2] + hole.depth) < 0.001, skill.demo_goal  # at the hole's bottom
    assert skill.taught is not None and skill.taught.reached, skill.taught
    path_written = save_skill(folder, skill)
    again = load_skill(folder, "peg_d10")
    assert path_written.name == "peg_d10.json" and again.execution_time == pytest.approx(skill.execution_time)
