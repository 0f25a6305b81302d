"""franky-sim with a product in its MuJoCo scene (executor.franka.sim_scene, sim_server):
the holes are where and as large as geometry.toml says, and a Franka driven through franky
grasps a peg (welded to the hand while held), inserts it where it fits, stops on force where
it does not, and reports the contact force that MuJoCo applies."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")
franky = pytest.importorskip("franky")

from executor.franka.sim_scene import product_model, to_base  # noqa: E402
from executor.franka.sim_server import sim_robot  # noqa: E402
from executor.world.geometry import load_geometry  # noqa: E402
from tests.executor.test_polygon_cell import HOLES, _product, hexagon  # noqa: E402
from tests.franka import SIM_DYNAMICS  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]


def _drop(model: object, data: object, x: float, y: float) -> float:
    """Height [m] where a ray down from 1 m at (x, y) first hits the plate (-1: nothing)."""
    geom = np.zeros(1, dtype=np.int32)
    start = to_base(np.array([x, y, 1.0]))
    distance = mujoco.mj_ray(model, data, start, np.array([0.0, 0.0, -1.0]), None, 1, -1, geom)
    return -1.0 if distance < 0 else float(start[2] - distance)


@pytest.mark.parametrize("assembly", ["spare", "taskboard", "cranfield"])
def test_holes_are_open_to_their_size_and_the_boss_stands_around_them(assembly: str) -> None:
    geometry = load_geometry(assembly)
    model, data, _bodies = product_model(geometry)
    base = geometry.base_top
    for hid, hole in geometry.holes.items():
        cx, cy = hole.position
        c, s = np.cos(hole.yaw), np.sin(hole.yaw)
        a, b = hole.sides
        inset = 1e-4 + (hole.size / 2 * (1 / np.cos(np.pi / geometry.plate.polygon_sides) - 1)
                        if hole.kind == "round" else 0.0)
        # Inside the hole, 0.1 mm from its wall, along its x and y axes: down to its bottom.
        for u, v in ((a / 2 - 1e-4, 0.0), (0.0, b / 2 - 1e-4), (-(a / 2 - 1e-4), 0.0)):
            assert _drop(model, data, cx + c * u - s * v, cy + s * u + c * v) == pytest.approx(
                max(hole.bottom_z, base), abs=2e-6), (hid, u, v)
        # Beyond the chamfer (0.1 mm past it): the boss's top at the entry.
        out = a / 2 + geometry.plate.chamfer + 1e-4 + inset
        assert _drop(model, data, cx + c * out, cy + s * out) == pytest.approx(hole.top_z, abs=2e-6), hid
        # On the chamfer, halfway: halfway down it (45°).
        mid = a / 2 + geometry.plate.chamfer / 2
        if hole.kind != "round":
            assert _drop(model, data, cx + c * mid, cy + s * mid) == pytest.approx(
                hole.top_z - geometry.plate.chamfer / 2, abs=2e-6), hid


def test_holes_entered_sideways_are_open_along_their_axis_and_the_boss_stands_around_them() -> None:
    """A base mesh's holes entered sideways (the MuJoCo scene builds their bosses in each
    hole's frame): a ray along the axis from 10 cm out passes through the hole 0.1 mm from
    its wall, across either side, and meets the boss's face at the entry past the chamfer."""
    geometry = load_geometry(str(ROOT / "tests" / "franka" / "data" / "side"))
    model, data, _bodies = product_model(geometry)
    geom = np.zeros(1, dtype=np.int32)
    for hid, hole in geometry.holes.items():
        frame = hole.frame
        assert frame is not None
        into, across = -frame.rotation[:, 2], frame.rotation[:, :2].T
        start = to_base(np.array([*hole.position, hole.top_z])) - 0.1 * into
        inset = hole.size / 2 * (1 / np.cos(np.pi / geometry.plate.polygon_sides) - 1)
        for side in (*across, *-across):
            inside = mujoco.mj_ray(model, data, start + side * (hole.size / 2 - 1e-4), into, None, 1, -1, geom)
            assert inside < 0, (hid, side, inside)  # through: nothing along the axis
            out = hole.size / 2 + geometry.plate.chamfer + 1e-4 + inset
            face = mujoco.mj_ray(model, data, start + side * out, into, None, 1, -1, geom)
            assert face == pytest.approx(0.1, abs=2e-6), (hid, side, face)


def test_pins_along_a_horizontal_axis_stand_to_their_size_from_their_foot() -> None:
    """A base mesh's pins along a horizontal axis (the MuJoCo scene builds each pin and the
    tile at its foot in the pin's frame): a ray along the axis from 10 cm out meets the
    pin's free end on its axis and, 0.1 mm beyond its radius on either side, passes the
    pin to meet the tile at its foot."""
    geometry = load_geometry(str(ROOT / "tests" / "franka" / "data" / "pins"))
    model, data, _bodies = product_model(geometry)
    geom = np.zeros(1, dtype=np.int32)
    for hid, pin in geometry.holes.items():
        frame = pin.frame
        assert frame is not None and pin.pin
        into, across = -frame.rotation[:, 2], frame.rotation[:, :2].T
        start = to_base(np.array([*pin.position, pin.top_z])) - 0.1 * into
        assert mujoco.mj_ray(model, data, start, into, None, 1, -1, geom) == pytest.approx(0.1, abs=2e-6), hid
        for side in (*across, *-across):
            foot = mujoco.mj_ray(model, data, start + side * (pin.size / 2 + 1e-4), into, None, 1, -1, geom)
            assert foot == pytest.approx(0.1 + pin.depth, abs=2e-6), (hid, side, foot)


def test_polygon_holes_are_open_to_their_outline_and_the_boss_stands_around_them(tmp_path: Path) -> None:
    """The hexagon holes of tests/executor/test_polygon_cell.py (one turned 30° in its
    outline) in the MuJoCo plate: at the middle of every edge of each outline, 0.1 mm
    inside down to the plate, halfway across the chamfer halfway down it, 0.1 mm past the
    chamfer the entry."""
    geometry = load_geometry(str(_product(tmp_path / "hex")))
    model, data, _bodies = product_model(geometry)
    chamfer = geometry.plate.chamfer
    for hid, (inradius, turn) in HOLES.items():
        hole = geometry.holes[hid]
        outline = np.array(hexagon(inradius, turn)) + hole.position  # yaw 0
        for k in range(6):
            middle = (outline[k] + outline[(k + 1) % 6]) / 2
            out = (middle - hole.position) / np.linalg.norm(middle - hole.position)  # the edge's normal
            for distance, height in ((-1e-4, geometry.base_top), (chamfer / 2, hole.top_z - chamfer / 2),
                                     (chamfer + 1e-4, hole.top_z)):
                x, y = middle + distance * out
                assert _drop(model, data, x, y) == pytest.approx(height, abs=2e-6), (hid, k, distance)


def _spare_with_peg_at(tmp_path: Path, part: str, start: tuple[float, float]) -> Path:
    """data/spare with ``part`` waiting at ``start`` [m] (on the line of the holes: a straight transfer)."""
    folder = tmp_path / "spare"
    shutil.copytree(ROOT / "data" / "spare", folder, ignore=shutil.ignore_patterns("assets", "demonstrations"))
    toml = folder / "assembly.toml"
    text = toml.read_text()
    block = text.index(f"[parts.{part}]")
    line = text.index("start = ", block)
    end = text.index("\n", line)
    toml.write_text(text[:line] + f"start = [{start[0]}, {start[1]}]" + text[end:])
    return folder


class _Arm:
    """The franky client of the test: moves the TCP, tool pointing down, at the tests'
    dynamics factor (:data:`tests.franka.SIM_DYNAMICS`), and waits until the measured pose
    is there (franky's move returns when the commanded path ends)."""

    def __init__(self, host: str) -> None:
        self.robot = franky.Robot(host, realtime_config=franky.RealtimeConfig.Ignore)
        self.robot.relative_dynamics_factor = franky.RelativeDynamicsFactor(float(SIM_DYNAMICS))
        self.gripper = franky.Gripper(host)
        self.quat = self.robot.current_cartesian_state.pose.end_effector_pose.quaternion

    def tcp(self) -> np.ndarray:
        return np.array(self.robot.current_cartesian_state.pose.end_effector_pose.translation)

    def go(self, target: np.ndarray, timeout: float = 20.0) -> None:
        self.robot.move(franky.CartesianMotion(franky.Affine(list(to_base(target)), self.quat)))
        deadline = time.monotonic() + timeout
        while np.linalg.norm(self.tcp() - to_base(target)) > 1e-3:
            assert time.monotonic() < deadline, f"the arm did not reach {target}: at {self.tcp()}"
            time.sleep(0.02)

    def press_down(self, distance: float, force: float) -> bool:
        """Move the tool ``distance`` [m] down, stopping when the wrench's z exceeds ``force``
        [N]; whether the force stopped it."""
        fired: list[float] = []
        reaction = franky.Reaction(franky.Measure.FORCE_Z > force, franky.CartesianStopMotion())
        reaction.register_callback(lambda _state, _rel, abs_time: fired.append(abs_time.to_sec()))
        motion = franky.CartesianMotion(franky.Affine([0.0, 0.0, distance]), franky.ReferenceType.Relative,
                                        franky.RelativeDynamicsFactor(0.1))
        motion.add_reaction(reaction)
        self.robot.move(motion)
        return bool(fired)


@pytest.mark.slow
@pytest.mark.timeout(1200)  # the wait for the arm lock included
@pytest.mark.usefixtures("one_simulated_arm")
def test_franka_inserts_a_peg_where_it_fits_and_stops_on_force_where_not(tmp_path: Path) -> None:
    folder = _spare_with_peg_at(tmp_path, "p3", (0.42, -0.06))
    geometry = load_geometry(str(folder))
    peg, fits, too_small = geometry.parts["p3"], geometry.holes["s1"], geometry.holes["r1"]
    held = 0.015  # the fingers hold the peg's top 15 mm; its bottom is this far below the TCP:
    below = peg.length - held
    with sim_robot(folder) as sim:
        arm = _Arm(sim.host)
        arm.go(np.array([*peg.start, peg.length + 0.03]))
        arm.go(np.array([*peg.start, peg.length - held]))
        before = sim.truth().poses["p3"][0]
        assert arm.gripper.grasp(0.0, 0.05, 60.0, epsilon_inner=0.005, epsilon_outer=0.03)
        grasped = sim.truth()
        assert grasped.held == {"p3"}  # welded to the hand where the fingers closed on it: no jump
        assert np.allclose(grasped.poses["p3"][0], before, atol=1e-3)
        arm.robot.set_load(peg.mass, [0.0, 0.0, 0.1034 - held + peg.length / 2], [0.0] * 9)

        arm.go(np.array([*peg.start, too_small.top_z + below + 0.01]))  # up, then across at that height
        arm.go(np.array([*too_small.position, too_small.top_z + below + 0.01]))
        assert arm.press_down(0.028, 8.0), "no force stop on a hole too small for the peg"
        time.sleep(0.3)
        truth = sim.truth()
        assert too_small.top_z - truth.poses["p3"][0][2] < 0.005  # on the entry, not in
        assert truth.wrench is not None
        plate = truth.plate_force["p3"][2]
        assert plate > 8.0
        assert truth.wrench.force[2] == pytest.approx(plate, rel=0.05)  # the sensor reads the contact

        arm.go(np.array([*too_small.position, too_small.top_z + below + 0.01]))
        arm.go(np.array([*fits.position, fits.top_z + below + 0.01]))
        assert not arm.press_down(0.028, 8.0), "a force stop in a hole the peg fits"
        time.sleep(0.3)
        depth = fits.top_z - sim.truth().poses["p3"][0][2]
        assert depth > 0.010  # in the hole (18 mm commanded below the entry; the no-fit stays within 5 mm)
        assert arm.gripper.move(0.04, 0.05)
        assert sim.truth().held == frozenset()  # let go as the fingers opened


@pytest.mark.slow
@pytest.mark.timeout(1200)  # the wait for the arm lock included
@pytest.mark.usefixtures("one_simulated_arm")
def test_the_server_process_prints_its_address_and_writes_the_poses_when_stopped(tmp_path: Path) -> None:
    poses = tmp_path / "poses.json"
    process = subprocess.Popen([sys.executable, "-m", "executor.franka.sim_server", "--assembly", "spare",
                                "--poses-out", str(poses)], cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               text=True, env={**os.environ, "PYTHONPATH": str(ROOT)})
    try:
        assert process.stdout is not None
        line = process.stdout.readline()
        assert line.startswith("franky-sim serving ") and " at 127." in line, line
        host = line.rsplit(" ", 1)[1].strip()
        robot = franky.Robot(host, realtime_config=franky.RealtimeConfig.Ignore)  # the address serves the arm
        assert len(robot.state.q) == 7
    finally:
        process.send_signal(signal.SIGTERM)
        _out, err = process.communicate(timeout=60)
    assert process.returncode == 143 and "Traceback" not in err, err
    parts = json.loads(poses.read_text())["parts"]
    geometry = load_geometry("spare")
    assert parts.keys() == geometry.parts.keys()
    for pid, part in geometry.parts.items():  # waiting on the tray, upright
        assert np.allclose(parts[pid]["position"], [*part.start, 0.0], atol=1e-3), pid
        assert parts[pid]["quat_wxyz"][0] == pytest.approx(1.0, abs=1e-3)
