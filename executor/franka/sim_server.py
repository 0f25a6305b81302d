"""franky-sim serving one simulated FR3 with a product in its MuJoCo scene, for the tests
and benchmarks of the Franka backend: in-process (:class:`SimRobot`, :func:`sim_robot`) or
as a process that a cell connects to by address::

    python -m executor.franka.sim_server --assembly spare [--hostname 127.0.0.5] [--poses-out FILE]

It prints ``franky-sim serving <folder> at <hostname>`` once the arm is up, then serves
until SIGTERM or Ctrl-C, and then writes the parts' poses to ``--poses-out``. libfranka's
ports are fixed (1337 the arm, 1338 the gripper), so servers on one machine differ by
their loopback address: the first free one of 127.0.0.1, 127.0.0.2, … unless given.

franky-sim 1.0.4 needs four things for a peg insertion, all done here at run time (no
file of it is changed; figures in docs/franka.md, "Testing against franky-sim"):

1. a wrench: franky-sim reports none (``O_F_ext_hat_K`` zero). A MuJoCo force/torque
   sensor at the flange (the hand body's origin) gives it, as a wrist F/T sensor would:
   the hand's and the load's gravity removed, moved to the TCP (:class:`FlangeSensor`);
2. the measured pose: franky-sim reports the commanded pose as ``O_T_EE`` (its forward
   kinematics returns a view that the next call overwrites); it is recomputed from q;
3. joint 7's damping: :data:`JOINT_KV` (franky-sim's 200 chatters at the 1 ms step);
4. the fingers: :data:`FINGER_GAIN` and :data:`FINGER_DAMPING` (franky-sim's squeeze ~6 N,
   and its damping is unstable at the 1 ms step); and MuJoCo's contact options against slip
   in a grasp (:data:`executor.franka.sim_scene.CONTACT_OPTIONS`). Even so, two point
   contacts let a peg pivot and slide under insertion forces (3-31 mm), so a grasped part
   is held as the PyBullet cell holds it (:mod:`executor.assembly.grasp`): welded to the
   hand while the fingers close on it (:class:`GraspWelds`, :class:`WeldingGripperServer`).

And one thing a client needs to see its own lateness: franky-sim's loop advances 1 ms per
tick whether a command came or not (the last one is applied again), and reports a
``control_command_success_rate`` of 1 always; here it is libfranka's figure, the share of
the last 100 ticks of a motion on which a new command arrived (:class:`CommandRate`).
"""

from __future__ import annotations

import json
import socket
import threading
import xml.etree.ElementTree as ET
from collections import deque
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np
from franky_sim import SimulationServer
from franky_sim.franka_gripper_server import FrankaGripperServer, _MotionState
from franky_sim.franka_robot_server import FrankaRobotServer
from franky_sim.franka_robot_state import FrankaRobotState
from franky_sim.mujoco_simulator import FrankaMujocoRobot, MujocoSimulator

from bridge.cli_types import ArgumentParser, add_assembly_argument, run_command
from bridge.errors import ToolError
from bridge.files import write_atomic
from executor import ExecutorError
from executor.franka.sim_hand import GuidingHand, Waypoint
from executor.franka.sim_scene import (
    add_grasp_welds,
    add_product,
    contact_force,
    from_base,
    set_contact_options,
    weld_name,
)
from executor.world.geometry import CellGeometry, load_geometry

JOINT_KV = (450.0, 450.0, 350.0, 350.0, 200.0, 200.0, 60.0)
"""Joint damping gains [N m s/rad] of franky-sim's joint controller: its own but joint 7's
(200 chatters ±12 N m at the 1 ms step, a false ±1.1 N at the sensor at rest)."""

FINGER_GAIN = 5000.0
"""Stiffness [N/m] of each simulated finger toward its target width (franky-sim's 1000
squeezes ~6 N per finger; 5000 gives ~26 N at a 60 N grasp)."""

FINGER_DAMPING = 10.0
"""Damping [N s/m] of each simulated finger: franky-sim applies its finger PD as a force
outside MuJoCo's implicit integrator, so at the 1 ms step a finger of 15 g is stable only
for kv dt / m well below 2 (franky-sim's 50 gives 3.3: the fingers chatter and a held part
walks along the pads)."""

HAND_BODY = "robot0_hand"
"""The MuJoCo body of the Franka Hand; its origin is the flange."""

FINGER_BODIES = ("robot0_left_finger", "robot0_right_finger")
"""The MuJoCo bodies of the Franka Hand's fingers (children of :data:`HAND_BODY`)."""

GRAVITY = np.array([0.0, 0.0, -9.81])
"""franky-sim's gravity [m/s^2], base frame."""

_FLANGE_IN_HAND = np.array([[np.sqrt(0.5), -np.sqrt(0.5), 0.0], [np.sqrt(0.5), np.sqrt(0.5), 0.0], [0.0, 0.0, 1.0]])
"""The flange's axes (libfranka's F frame) in the hand body's: the hand is mounted turned
-45° about z, so the flange is the hand turned +45°."""


@dataclass(frozen=True)
class Wrench:
    """The environment's wrench on the arm, base frame: ``force`` [N], ``torque`` [N m]
    about the TCP (libfranka's ``O_F_ext_hat_K``: pressing down reads +z), and ``tau``
    [N m] the arm's joint torques it makes (Jᵀ F, ``tau_ext_hat_filtered``)."""

    force: np.ndarray
    torque: np.ndarray
    tau: np.ndarray


class FlangeSensor:
    """A force/torque sensor at the flange of a compiled scene (the site and sensors of
    :func:`add_flange_sensor`): the wrench the environment exerts on the hand and what it
    holds, the weight of the hand's subtree and of the load (libfranka's ``set_load``)
    removed, as a wrist F/T sensor tared with the hand and load reads it."""

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, arm_dofs: Sequence[int]) -> None:
        self.model, self.data, self.arm_dofs = model, data, list(arm_dofs)
        self.hand = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, HAND_BODY)
        self.site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "flange_ft")
        self._force, self._torque = (int(model.sensor_adr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SENSOR, n)])
                                     for n in ("flange_force", "flange_torque"))
        self.hand_mass = float(model.body_subtreemass[self.hand])

    def wrench(self, tcp: np.ndarray, load_mass: float, load_com: Sequence[float]) -> Wrench:
        """The wrench at ``tcp`` [m] (base frame) with a load of ``load_mass`` [kg] whose
        centre of mass is ``load_com`` [m] in the flange frame. MuJoCo's sensors read the
        force and torque that the hand's parent exerts on the hand's subtree, in the
        site's axes; at rest the environment's share is minus that, minus the weights."""
        d = self.data
        axes = d.site_xmat[self.site].reshape(3, 3)
        origin = d.site_xpos[self.site]
        load = load_mass * GRAVITY
        force = -axes @ d.sensordata[self._force:self._force + 3] - self.hand_mass * GRAVITY - load
        hand_com = d.subtree_com[self.hand] - origin
        load_com_base = axes @ _FLANGE_IN_HAND @ np.asarray(load_com, dtype=float)
        torque = (-axes @ d.sensordata[self._torque:self._torque + 3]
                  - np.cross(hand_com, self.hand_mass * GRAVITY) - np.cross(load_com_base, load))
        torque = torque + np.cross(origin - tcp, force)  # the same wrench, about the TCP
        jacp, jacr = np.zeros((3, self.model.nv)), np.zeros((3, self.model.nv))
        mujoco.mj_jac(self.model, d, jacp, jacr, tcp, self.hand)
        tau = jacp[:, self.arm_dofs].T @ force + jacr[:, self.arm_dofs].T @ torque
        return Wrench(force, torque, tau)


def add_flange_sensor(sim: MujocoSimulator) -> None:
    """A site at the flange (the hand body's origin and axes) with a force and a torque
    sensor, added to the scene of ``sim`` before it starts."""
    hand = next(body for body in sim.worldbody.iter("body") if body.get("name") == HAND_BODY)
    ET.SubElement(hand, "site", name="flange_ft", pos="0 0 0")
    sensors = sim.scene.find("sensor")
    if sensors is None:
        sensors = ET.SubElement(sim.scene, "sensor")
    ET.SubElement(sensors, "force", name="flange_force", site="flange_ft")
    ET.SubElement(sensors, "torque", name="flange_torque", site="flange_ft")


COMMAND_WINDOW = 100
"""libfranka's ``control_command_success_rate`` is taken over the last this many control
cycles (ticks of 1 ms)."""


class CommandRate:
    """libfranka's ``control_command_success_rate`` for franky-sim: the share of the last
    :data:`COMMAND_WINDOW` ticks of a motion on which a new control command arrived (0 while
    no motion runs, as on the robot). franky-sim applies the last command again on a tick
    that got none, where a real arm counts it lost (and stops with a reflex when too many
    are)."""

    def __init__(self) -> None:
        self._ticks: deque[bool] = deque(maxlen=COMMAND_WINDOW)
        self.value = 0.0

    def tick(self, in_motion: bool, commanded: bool) -> None:
        """One tick: whether a motion runs, whether a command arrived on it. The count
        starts with a motion's first command (the client answers the state that follows
        the motion's start)."""
        if not in_motion:
            self._ticks.clear()
            self.value = 0.0
        elif self._ticks or commanded:
            self._ticks.append(commanded)
            self.value = sum(self._ticks) / len(self._ticks)


class CountingRobotServer(FrankaRobotServer):
    """franky-sim's robot server that counts, per tick, whether a control command arrived
    during a motion (:class:`CommandRate`). :class:`SimRobot` turns franky-sim's server into
    this class and sets ``rate``."""

    rate: CommandRate | None = None
    _commanded = False

    def _pre_process_commands(self) -> None:
        self._commanded = False
        super()._pre_process_commands()

    def _handle_udp_command(self, command_data: bytes) -> None:
        self._commanded = True
        super()._handle_udp_command(command_data)

    def _post_process_commands(self) -> None:
        if self.rate is not None:
            self.rate.tick(self.current_motion_id > 0, self._commanded)
        super()._post_process_commands()


class SensedRobot(FrankaMujocoRobot):
    """franky-sim's FR3 whose state carries the flange sensor's wrench (``O_F_ext_hat_K``,
    ``K_F_ext_hat_K``, ``tau_ext_hat_filtered``) and the pose measured from q (``O_T_EE``).
    franky-sim's ``add_robot`` makes the robot; :class:`SimRobot` turns it into this class
    (same attributes) and sets ``sensor`` once the scene is compiled."""

    sensor: FlangeSensor | None = None
    command_rate: CommandRate | None = None

    @property
    def state(self) -> FrankaRobotState:
        state = super().state
        if self.command_rate is not None:
            state = state.replace(control_command_success_rate=self.command_rate.value)
        if self.sensor is None:
            return state
        pose = self.kinematics(np.array(state.q)).copy()  # a copy: the next call overwrites the view
        wrench = self.sensor.wrench(pose.translation, self.m_load, self.F_x_Cload)
        k_axes = pose.rotation @ np.array(self.EE_T_K).reshape(4, 4, order="F")[:3, :3]
        return state.replace(
            O_T_EE=self.to_franka_pose(pose),
            O_F_ext_hat_K=(*wrench.force, *wrench.torque),
            K_F_ext_hat_K=(*(k_axes.T @ wrench.force), *(k_axes.T @ wrench.torque)),
            tau_ext_hat_filtered=tuple(wrench.tau),
        )


class GraspWelds:
    """The welds of :func:`executor.franka.sim_scene.add_grasp_welds` in a compiled scene:
    each part's, inactive until the fingers close on the part. Called from franky-sim's
    stepping thread between two steps (the gripper server runs there), so the data it reads
    and writes is that of the last step."""

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, parts: dict[str, int]) -> None:
        self.model, self.data = model, data
        body = mujoco.mjtObj.mjOBJ_BODY
        self.hand = mujoco.mj_name2id(model, body, HAND_BODY)
        self.fingers = tuple(mujoco.mj_name2id(model, body, name) for name in FINGER_BODIES)
        self.parts = dict(parts)
        self.welds = {pid: mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_EQUALITY, weld_name(pid)) for pid in parts}

    def held(self) -> set[str]:
        """The parts welded to the hand."""
        return {pid for pid, weld in self.welds.items() if self.data.eq_active[weld]}

    def touched(self) -> set[str]:
        """The parts in contact with both fingers at the last step."""
        touching: dict[int, set[int]] = {}
        for i in range(self.data.ncon):
            first, second = (int(self.model.geom_bodyid[g]) for g in self.data.contact[i].geom)
            for finger, other in ((first, second), (second, first)):
                if finger in self.fingers:
                    touching.setdefault(other, set()).add(finger)
        return {pid for pid, body in self.parts.items() if touching.get(body) == set(self.fingers)}

    def hold_touched(self) -> None:
        """Weld each part touched by both fingers to the hand at the pose it has now
        (the weld's relative pose set from the present poses: nothing jumps)."""
        d = self.data
        for pid in self.touched() - self.held():
            body, weld = self.parts[pid], self.welds[pid]
            hand_axes = d.xmat[self.hand].reshape(3, 3)
            hand_inverse = np.zeros(4)
            mujoco.mju_negQuat(hand_inverse, d.xquat[self.hand])
            relative = np.zeros(4)
            mujoco.mju_mulQuat(relative, hand_inverse, d.xquat[body])
            # MuJoCo's weld data: anchor on the part (3, its origin), the part's position and
            # orientation in the hand's frame (3 + 4), then the torque scale.
            self.model.eq_data[weld, 0:3] = 0.0
            self.model.eq_data[weld, 3:6] = hand_axes.T @ (d.xpos[body] - d.xpos[self.hand])
            self.model.eq_data[weld, 6:10] = relative
            d.eq_active[weld] = 1

    def release(self) -> None:
        """Let every welded part go."""
        self.data.eq_active[list(self.welds.values())] = 0


class WeldingGripperServer(FrankaGripperServer):
    """franky-sim's gripper server that welds the part it closed on to the hand and lets
    it go as it opens: a command that opens the fingers (a target wider than they are, or
    homing) releases at its start; a move or grasp welds, as it ends, each part that both
    fingers touch. :class:`SimRobot` turns franky-sim's server into this class and sets
    ``welds``."""

    welds: GraspWelds | None = None

    def start_move(self, width: float, speed: float, command_id: int, tcp_socket: socket.socket) -> None:
        self._release_if_opening(width)
        super().start_move(width, speed, command_id, tcp_socket)

    def start_grasp(self, width: float, speed: float, force: float, epsilon_inner: float, epsilon_outer: float,
                    command_id: int, tcp_socket: socket.socket) -> None:
        self._release_if_opening(width)
        super().start_grasp(width, speed, force, epsilon_inner, epsilon_outer, command_id, tcp_socket)

    def start_homing(self, command_id: int, tcp_socket: socket.socket) -> None:
        if self.welds is not None:
            self.welds.release()
        super().start_homing(command_id, tcp_socket)

    def _release_if_opening(self, width: float) -> None:
        if self.welds is not None and width > self._robot.hand_width:
            self.welds.release()

    def _check_motion_state(self) -> None:
        closing = self._motion_state in (_MotionState.MOVING, _MotionState.GRASPING)
        super()._check_motion_state()
        if closing and self._motion_state is _MotionState.IDLE and self.welds is not None:
            self.welds.hold_touched()


@dataclass(frozen=True)
class Truth:
    """The simulated world between two steps, for tests: ``time`` [s] since the start;
    ``poses`` of the parts (position [m] of the body frame, the bottom face centre, in
    the product frame; quaternion w x y z); ``plate_force`` [N], base axes, the plate's
    contact force on each part; ``wrench`` the one the arm reports, at the same step;
    ``held`` the parts welded to the hand (:class:`GraspWelds`)."""

    time: float
    poses: dict[str, tuple[np.ndarray, np.ndarray]]
    plate_force: dict[str, np.ndarray]
    wrench: Wrench | None
    held: frozenset[str] = frozenset()


class SimRobot:
    """franky-sim with ``product``'s plate and pegs in its scene and the four run-time
    fixes (module docstring), serving one arm at ``host`` from a background thread.
    ``realtime``: False steps as fast as it can (a free-running loop: 1 ms of simulated time
    per tick, a client or not), True paces at wall time, a number is a speed factor."""

    def __init__(self, product: str | Path, *, hostname: str | None = None, realtime: bool | float = False) -> None:
        self.geometry: CellGeometry = load_geometry(str(product))
        self._hostname, self._realtime = hostname, realtime
        self._sim: MujocoSimulator | None = None
        self._server: SimulationServer | None = None
        self._robot: SensedRobot | None = None
        self._welds: GraspWelds | None = None
        self._bodies: dict[str, int] = {}
        self._plate = -1
        self._wanted = threading.Event()
        self._taken = threading.Event()
        self._truth: Truth | None = None
        self._hand: GuidingHand | None = None

    @property
    def host(self) -> str:
        """The address a franky client connects to (``franky.Robot(host)``)."""
        if self._robot is None or self._robot.hostname is None:
            raise ExecutorError("the simulated arm is not running; start() it first")
        return str(self._robot.hostname)

    def start(self) -> str:
        """Build the scene, bind the arm's and the gripper's servers and start stepping;
        returns :attr:`host`."""
        sim = MujocoSimulator()
        sim.init()
        robot = sim.add_robot(kv=JOINT_KV)
        robot.__class__ = SensedRobot  # the state with the wrench; the robot keeps all it has
        robot._kp_hand = np.full(2, FINGER_GAIN)
        robot._kv_hand = np.full(2, FINGER_DAMPING)
        names = add_product(sim.scene, sim.worldbody, self.geometry)
        add_flange_sensor(sim)
        set_contact_options(sim.scene)
        add_grasp_welds(sim.scene, HAND_BODY, names)
        server = SimulationServer(sim) if self._hostname is None else SimulationServer(sim, [self._hostname])
        self._sim, self._server, self._robot = sim, server, robot
        try:
            server.init()
        except (OSError, RuntimeError) as exc:
            self.stop()
            raise ExecutorError(f"franky-sim could not serve the arm ({exc}); expected a free loopback address "
                                "for ports 1337 and 1338") from None
        model, data = sim.model, sim.data
        assert model is not None and data is not None  # compiled by server.init()
        self._robot.sensor = FlangeSensor(model, data, robot._dof_addrs)
        self._bodies = {pid: mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name) for pid, name in names.items()}
        self._plate = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "plate")
        self._welds = GraspWelds(model, data, self._bodies)
        for robot_server in server.robot_servers:
            robot_server.__class__ = CountingRobotServer  # as the robot's class: all it has is kept
            assert isinstance(robot_server, CountingRobotServer)
            robot_server.rate = robot.command_rate = CommandRate()
            gripper = robot_server.gripper_server
            if gripper is not None:
                gripper.__class__ = WeldingGripperServer  # as the robot's class: all it has is kept
                assert isinstance(gripper, WeldingGripperServer)
                gripper.welds = self._welds
        sim.register_pre_step_callback(self._before_step)
        sim.register_post_step_callback(self._after_step)
        server.run_async(self._realtime)
        return self.host

    def stop(self) -> None:
        """Stop stepping and close the servers (idempotent)."""
        server, sim = self._server, self._sim
        self._server = self._sim = None
        if server is not None:
            server.cleanup()
        if sim is not None and sim.is_initialized and not sim.is_cleaned_up:
            sim.cleanup()

    def truth(self, timeout: float = 5.0) -> Truth:
        """The world as it is between two steps (taken by the stepping thread)."""
        if self._server is None or not self._server.running:
            raise ExecutorError("the simulated arm is not running; start() it first")
        self._taken.clear()
        self._wanted.set()
        if not self._taken.wait(timeout):
            raise ExecutorError(f"franky-sim took no step in {timeout} s")
        assert self._truth is not None
        return self._truth

    def guide(self, part: str, waypoints: Sequence[Waypoint], hold: float) -> GuidingHand:
        """A person's hand takes hold of ``part`` and pulls it along ``waypoints`` (base
        frame), holds the last one ``hold`` [s] and lets go (:class:`GuidingHand`, from
        the next step on; its ``done`` tells when it let go)."""
        hand = GuidingHand(self._bodies[part], waypoints, hold)
        self._hand = hand
        return hand

    def _before_step(self, sim: MujocoSimulator) -> None:
        hand = self._hand
        if hand is not None and sim.model is not None and sim.data is not None:
            hand.apply(sim.model, sim.data)

    def _after_step(self, _sim: MujocoSimulator) -> None:
        if self._wanted.is_set():
            self._wanted.clear()
            self._truth = self._read_truth()
            self._taken.set()

    def _read_truth(self) -> Truth:
        sim, robot = self._sim, self._robot
        assert sim is not None and sim.model is not None and sim.data is not None and robot is not None
        model, data = sim.model, sim.data
        poses = {pid: (from_base(data.xpos[body].copy()), data.xquat[body].copy())
                 for pid, body in self._bodies.items()}
        forces = {pid: contact_force(model, data, body, self._plate) for pid, body in self._bodies.items()}
        wrench = None
        if robot.sensor is not None:  # the wrench of this very step, as the plate's force is
            tcp = robot.kinematics(np.array(robot.inner_state.q)).copy().translation
            wrench = robot.sensor.wrench(tcp, robot.m_load, robot.F_x_Cload)
        held = frozenset() if self._welds is None else frozenset(self._welds.held())
        return Truth(float(data.time), poses, forces, wrench, held)

    def __enter__(self) -> SimRobot:
        self.start()
        return self

    def __exit__(self, *_exc: object) -> None:
        self.stop()


@contextmanager
def sim_robot(product: str | Path, *, hostname: str | None = None, realtime: bool | float = False
              ) -> Iterator[SimRobot]:
    """A running :class:`SimRobot` for ``product`` (its ``host`` is the address), stopped on exit."""
    robot = SimRobot(product, hostname=hostname, realtime=realtime)
    robot.start()
    try:
        yield robot
    finally:
        robot.stop()


def poses_json(truth: Truth) -> str:
    """The parts' poses of ``truth`` as JSON: ``{"time": s, "parts": {id: {"position": [m],
    "quat_wxyz": [...]}}}``, product frame."""
    parts = {pid: {"position": [round(float(v), 9) for v in pos], "quat_wxyz": [round(float(v), 9) for v in quat]}
             for pid, (pos, quat) in sorted(truth.poses.items())}
    return json.dumps({"time": truth.time, "parts": parts}, indent=1) + "\n"


def main(argv: Sequence[str] | None = None) -> int:
    parser = ArgumentParser(prog="python -m executor.franka.sim_server",
                            description="Serve a simulated FR3 (franky-sim, MuJoCo) with a product's plate and pegs "
                                        "in its scene until SIGTERM or Ctrl-C.")
    add_assembly_argument(parser, "cranfield", purpose="the product whose plate and pegs are in the scene")
    parser.add_argument("--hostname", help="the loopback address to serve at (default: the first free of "
                                           "127.0.0.1, 127.0.0.2, ...)")
    parser.add_argument("--realtime", action="store_true", help="pace at wall time (default: as fast as it steps)")
    parser.add_argument("--poses-out", type=Path, metavar="FILE",
                        help="on stopping, write the parts' poses (JSON, product frame) to FILE")
    args = parser.parse_args(argv)

    def serve() -> int:
        robot = SimRobot(args.assembly, hostname=args.hostname, realtime=args.realtime)
        robot.start()
        try:
            print(f"franky-sim serving {robot.geometry.folder} at {robot.host}", flush=True)
            threading.Event().wait()
        finally:
            truth = robot.truth() if args.poses_out is not None else None
            robot.stop()
            if truth is not None:
                write_atomic(args.poses_out, poses_json(truth))
        return 0

    return run_command(serve, (ToolError,))


if __name__ == "__main__":
    raise SystemExit(main())
