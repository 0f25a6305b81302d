"""The cell on a Franka arm: the product fixed on the table, its pegs standing on the table
at their tray positions (``start`` of ``assembly.toml``), the Franka Hand picking them.

One insertion runs as in the PyBullet cell (:mod:`executor.trial`), with the same skill
code on the arm behind :class:`executor.franka.arm.FrankyController`: pick the part with the
hand, carry it above the hole's calibrated position (franky's own Cartesian motions: exact
positioning, planned within the arm's limits; the PyBullet cell's impedance-tracked
transfers lag by millimetres here, and a part grasped off-centre tilts in the fingers),
tare the wrench estimate, the hole search (:func:`executor.skills.search.hole_search`), the
taught skill under the cell's execution layer
(:func:`executor.skills.insertion.insert_in_layer`: DMP, admittance, phase stopping,
eqs. (6)/(7), the wiggle, the goal check; ILC corrections per (part shape, hole) kept in
memory), then the part is let go in the hole (a plan step) or carried back to its tray
position (an experiment). Into a hole entered sideways, as the assembling PyBullet cell enters it
(:mod:`executor.assembly.step`): the attempt (and teaching) runs in the hole's frame
(:attr:`executor.world.geometry.HoleSpec.frame`, ``Motion.frame``), the part carried with
the tool turned along the hole's axis to :data:`executor.assembly.step.SIDEWAYS_OUT` out
of the entry and in along the axis to the approach, out along the axis after. What
differs from the simulated cell: the grasp and the hole's
position carry the real errors, none is drawn; the hole's position is where the product's
geometry puts it, moved by the calibrated ``offset`` of the product frame in the robot's
base frame (axes parallel).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import trimesh

from executor import ExecutorError
from executor.assembly.step import SIDEWAYS_OUT
from executor.assembly.transfer import SAFE_Z
from executor.cell_description import CellDescription
from executor.control.detector import Detector
from executor.control.ilc import ExecutionLayer, Ilc
from executor.control.motion import APPROACH_SETTLE_TIME, Motion
from executor.franka.arm import FrankyArm, FrankyController
from executor.franka.safety import Limits, Workspace
from executor.skills.dmp import Skill, load_product_skill
from executor.skills.insertion import InsertionResult, InsertionTask, insert_in_layer, needs_yaw_compliance
from executor.skills.search import SearchResult, hole_search
from executor.trial import APPROACH_HEIGHT
from executor.world.arm import quat_to_matrix, tool_quat
from executor.world.frames import HoleFrame, aligned_yaw, hole_frame
from executor.world.geometry import CellGeometry, PartSpec, fit_pose

OPEN_MARGIN = 0.02  # [m] the fingers open this much wider than the part before a pick
TOLERANCE = 0.002  # [m] a move ends when the measured tool tip is this close to its goal
ARRIVAL = 30.0  # [s] of wall time a move waits for the arm to arrive after its path ended
REST_SPEED = 0.0005
"""[m/s] the arm is at rest when its tool tip moves slower than this: the hand closes on a
part only then (closing while the arm still came down the last 2 mm of its move gripped
the part 0.8 mm higher than ``grasp_depth`` in franky-sim, docs/franka.md)."""
RETREAT = 0.03  # [m] the tool goes back along its axis (up, or out of a sideways hole) after opening the hand
GRIPPER_SPEED = 0.05  # [m/s] of the fingers
HELD_FRACTION = 0.3
"""The hand holds the part when its width after closing is at least this fraction of the
part's (closed on nothing it is about 0; franky-sim's fingers read 7.1 mm on a 10 mm peg at
40 N, their contact soft)."""
ABOVE_TRAY = 0.002  # [m] a part carried back is let go this far above the table
DOWN = tool_quat(0.0)  # the tool pointing down (xyzw), the hand's fingers closing along y
READY = (0.0, 0.0, 0.0, -1.57, 0.0, 1.57, 0.785)
"""[rad] the joint positions the arm turns the tool's axis from (franky-sim's start pose:
the tool pointing down, the end effector at (0.55, 0, 0.52) m): the Cartesian motions
then start from one configuration of the redundant arm. Against franky-sim, turned from
wherever the carry was, the wrist came to the tool along +x in another configuration, and
a peg that fits ended 4 mm short in its hole, a false ``no_fit`` (docs/franka.md)."""
TURN = 0.1  # [rad] a carry that turns the tool's axis by more than this turns it from READY


def turn_between(a: np.ndarray, b: np.ndarray) -> float:
    """[rad] the angle of the rotation between two orientations (quaternions xyzw)."""
    return 2 * math.acos(min(1.0, abs(float(np.dot(a, b)))))


def axis_turn(a: np.ndarray, b: np.ndarray) -> float:
    """[rad] the angle between the tool axes (z) of two orientations (quaternions xyzw)."""
    return math.acos(max(-1.0, min(1.0, float(quat_to_matrix(a)[:, 2] @ quat_to_matrix(b)[:, 2]))))


def wrist_yaw(frame: HoleFrame | None, part_kind: str, hole_kind: str, yaw: float) -> float:
    """The tool yaw [rad] in a hole's ``frame`` for the pair's aligned ``yaw``
    (:func:`executor.world.frames.aligned_yaw`): for a round part or hole entered sideways,
    whose yaw is free, the quarter turn from it that turns the hand least from pointing
    down (along +x the frame's x is the cell's y: yaw 0 would turn the hand by 120° about
    a skew axis, -π/2 pitches it by 90°; docs/franka.md); else ``yaw``."""
    if frame is None or "round" not in (part_kind, hole_kind):
        return yaw
    turns = [yaw + k * math.pi / 2 for k in (0, -1, 1, 2)]
    return min(turns, key=lambda turn: turn_between(DOWN, frame.pose_to_cell(np.zeros(3), tool_quat(turn))[1]))


def part_width(geometry: CellGeometry, spec: PartSpec) -> float:
    """[m] how wide a part of ``geometry`` is across its axis at most: its mesh's largest
    extent across it where it has one (a ring's outside, where its section is its bore's),
    else its section's largest side."""
    if spec.mesh is None:
        return max(spec.sides)
    (x0, y0, _), (x1, y1, _) = trimesh.load(geometry.folder / spec.mesh.file, force="mesh").bounds
    return float(max(x1 - x0, y1 - y0))


@dataclass(frozen=True)
class FrankaOptions:
    """The Franka cell's settings (``--backend-option KEY=VALUE``, docs/franka.md):
    ``host`` the arm's FCI address; ``offset`` [m] of the product frame in the robot's base
    frame; ``grasp_force`` [N];
    ``realtime``: libfranka's real-time check enforced (a real-time kernel; False for the
    simulator); ``limits``, ``workspace``: :mod:`executor.franka.safety`."""

    host: str
    offset: tuple[float, float, float] = (0.0, 0.0, 0.0)
    grasp_force: float = 40.0
    realtime: bool = True
    limits: Limits = field(default_factory=Limits)
    workspace: Workspace = field(default_factory=Workspace)


def connect(options: FrankaOptions) -> tuple[Any, Any]:
    """franky's ``Robot`` and ``Gripper`` at ``options.host``, errors recovered, the
    collision behaviour set; ExecutorError naming the host when the arm does not answer."""
    import franky

    config = franky.RealtimeConfig.Enforce if options.realtime else franky.RealtimeConfig.Ignore
    limits = options.limits
    try:
        robot = franky.Robot(options.host, relative_dynamics_factor=limits.dynamics, realtime_config=config)
        robot.recover_from_errors()
        robot.set_collision_behavior([limits.torque_threshold] * 7, [limits.force_threshold] * 6)
        gripper = franky.Gripper(options.host)
    except (franky.Exception, franky.GripperException) as exc:
        raise ExecutorError(f"franka: cannot drive the arm at {options.host} ({exc}); expected a Franka with FCI "
                            "enabled (docs/franka.md)") from None
    return robot, gripper


class FrankaCell:
    """The arm, its hand and the product (``geometry``), with the cell ``description``'s
    gains, thresholds and admittance and the execution ``layer``."""

    def __init__(self, geometry: CellGeometry, description: CellDescription, layer: ExecutionLayer,
                 options: FrankaOptions) -> None:
        self.geometry, self.description, self.layer, self.options = geometry, description, layer, options
        self.robot, self.gripper = connect(options)
        self.arm = FrankyArm(self.robot)
        self.controller = FrankyController(self.arm, description.gains, options.workspace)
        self.motion: Motion[FrankyController] = Motion(self.controller)
        self.ilc = Ilc(description.ilc, description.gains, description.admittance)
        self._skills: dict[str, Skill] = {}
        self._widths: dict[str, float] = {}
        self.held: str | None = None
        self.quat = DOWN
        """The tool's orientation (xyzw, base frame) the moves last commanded."""
        self.outside: np.ndarray | None = None
        """[m] where the tip came in along the axis of a hole entered sideways (base frame),
        None when the tool is out of such a hole."""

    def to_base(self, point: np.ndarray) -> np.ndarray:
        """A point [m] of the product frame in the robot's base frame."""
        return np.asarray(point, dtype=float) + np.array(self.options.offset)

    def skill(self, shape: str) -> Skill:
        if shape not in self._skills:
            self._skills[shape] = load_product_skill(self.geometry, shape)
        return self._skills[shape]

    def move_to(self, tip: np.ndarray, quat: np.ndarray | None = None) -> None:
        """The tool tip [m] in a straight line to ``tip``, the tool turning to the
        orientation ``quat`` (xyzw; None: as it is), by franky's own Cartesian motion (its path planned
        within the arm's limits scaled by the dynamics factor; the impedance tracking is
        stopped meanwhile); returns once the measured tip is within :data:`TOLERANCE`
        (franky returns when the path ends, the arm trails it). SafetyStop when the goal
        is outside the workspace (the straight line between two points of the box stays in it)."""
        import franky

        self.options.workspace.check(tip)
        self.controller.stop()
        quat = self.quat if quat is None else np.asarray(quat, dtype=float)
        ee = tip - quat_to_matrix(quat)[:, 2] * self.arm.tcp
        self.robot.move(franky.CartesianMotion(franky.Affine(ee, quat), franky.ReferenceType.Absolute,
                                               franky.RelativeDynamicsFactor(self.options.limits.dynamics)))
        self.quat = quat
        deadline = time.monotonic() + ARRIVAL
        while np.linalg.norm(self.arm.read().tip_pos - tip) > TOLERANCE:
            if time.monotonic() > deadline:
                raise ExecutorError(f"the arm did not reach {np.round(tip, 4).tolist()} m (at "
                                    f"{np.round(self.arm.read().tip_pos, 4).tolist()} m)")
            time.sleep(0.01)

    def settle(self) -> None:
        """Wait until the arm is at rest (:data:`REST_SPEED`): franky's motion ends while the
        arm still trails its path. ExecutorError after :data:`ARRIVAL` s of wall time."""
        deadline = time.monotonic() + ARRIVAL
        while np.linalg.norm(self.arm.read().tip_vel) > REST_SPEED:
            if time.monotonic() > deadline:
                here = np.round(self.arm.read().tip_pos, 4).tolist()
                raise ExecutorError(f"the arm did not come to rest at {here} m")
            time.sleep(0.01)

    def carry_to(self, goal: np.ndarray, quat: np.ndarray = DOWN) -> None:
        """Out of a hole entered sideways (:meth:`back_out`), up to the carrying height,
        across turning the tool to ``quat`` (xyzw) (from :data:`READY` when its axis turns
        by more than :data:`TURN`), down to ``goal`` [m]."""
        self.back_out()
        here = self.arm.read().tip_pos
        high = max(SAFE_Z + self.options.offset[2], float(goal[2]), float(here[2]))
        if here[2] < high - 1e-3:
            self.move_to(np.array([here[0], here[1], high]))
        if axis_turn(self.quat, quat) > TURN:
            self.ready()
        self.move_to(np.array([goal[0], goal[1], high]), quat)
        self.move_to(goal)

    def ready(self) -> None:
        """The arm to the joint positions :data:`READY` (franky's joint motion), at rest."""
        import franky

        self.controller.stop()
        self.robot.move(franky.JointMotion(np.array(READY), franky.ReferenceType.Absolute,
                                           franky.RelativeDynamicsFactor(self.options.limits.dynamics)))
        self.settle()
        self.quat = np.asarray(self.arm.read().tip_quat_xyzw, dtype=float)

    def back_out(self) -> None:
        """The tip back along the tool's axis to where it came into a hole entered sideways
        (:attr:`outside`); nothing outside such a hole."""
        if self.outside is None:
            return
        axis = quat_to_matrix(self.quat)[:, 2]  # into the hole
        here = self.arm.read().tip_pos
        self.move_to(here + axis * float(axis @ (self.outside - here)))
        self.outside = None

    def enter(self, point: np.ndarray, quat: np.ndarray) -> None:
        """The tip to ``point`` [m], the tool at ``quat`` (xyzw), both in the motion's frame:
        carried there (:meth:`carry_to`), or for a hole entered sideways carried to
        :data:`SIDEWAYS_OUT` out of ``point`` along the hole's axis, the tool turned along
        it, then in along the axis."""
        frame = self.motion.frame
        if frame is None:
            self.carry_to(point, quat)
            return
        tip, turned = frame.pose_to_cell(point, quat)
        outside = frame.points_to_cell(point + np.array([0.0, 0.0, SIDEWAYS_OUT]))
        self.carry_to(outside, turned)
        self.outside = outside
        self.move_to(tip)

    def _open(self, width: float) -> None:
        if not self.gripper.move(width, GRIPPER_SPEED):
            raise ExecutorError(f"the hand did not open to {width * 1000:.0f} mm")

    def pick(self, part: str) -> None:
        """Open the hand, carry it to the part's grip point on the table, close it on the
        part; the tool tip becomes the part's tip. ExecutorError when the hand holds nothing,
        or for a part the product holds on the suction cup (the Franka's hand has none)."""
        spec = self.geometry.parts[part]
        if spec.tool == "suction":
            raise ExecutorError(f"part {part} is held by the suction cup (geometry.toml [part_shapes.{spec.shape}] "
                                "tool = \"suction\"): the Franka's hand has fingers only")
        self.arm.set_tcp(0.0)
        width = self.width(spec)
        self._open(width + OPEN_MARGIN)
        grip = self.to_base(np.array([*spec.start, self.lever(spec)]))
        self.carry_to(grip + np.array([0.0, 0.0, 0.05]))
        self.move_to(grip)
        self.settle()
        # Closed toward zero width with the grasp force, held when the fingers stopped on
        # the part (the hand's width) rather than on nothing; franky-sim's fingers are a
        # spring toward the commanded width, which squeezes only when it is below the part's.
        self.gripper.grasp(0.0, GRIPPER_SPEED, self.options.grasp_force, epsilon_inner=0.001,
                           epsilon_outer=width + OPEN_MARGIN)
        closed = float(self.gripper.width)
        if closed < HELD_FRACTION * width:
            self._open(width + OPEN_MARGIN)
            raise ExecutorError(f"the hand closed on nothing at part {part}'s place on the table "
                                f"({np.round(grip, 4).tolist()} m): its fingers closed to {closed * 1000:.1f} mm, "
                                f"the part is {width * 1000:.1f} mm wide")
        self.held = part
        self.arm.set_tcp(self.lever(spec))

    def lever(self, spec: PartSpec) -> float:
        """[m] from the grip point to the part's tip (a part with a bore is held at most
        half its length deep: :meth:`executor.world.geometry.PartSpec.held_depth`)."""
        return spec.length - spec.held_depth(self.geometry.gripper)

    def width(self, spec: PartSpec) -> float:
        """[m] how wide the part is between the fingers at most (:func:`part_width`)."""
        if spec.shape not in self._widths:
            self._widths[spec.shape] = part_width(self.geometry, spec)
        return self._widths[spec.shape]

    def release(self) -> None:
        """Open the hand where it is and go back along the tool's axis by :data:`RETREAT`
        (up, or out of a hole entered sideways)."""
        if self.held is None:
            return
        spec = self.geometry.parts[self.held]
        self._open(self.width(spec) + OPEN_MARGIN)
        self.held = None
        self.arm.set_tcp(0.0)
        self.move_to(self.arm.read().tip_pos - quat_to_matrix(self.quat)[:, 2] * RETREAT)

    def put_back(self) -> None:
        """Carry the held part back to its place on the table and let it go."""
        if self.held is None:
            return
        spec = self.geometry.parts[self.held]
        self.carry_to(self.to_base(np.array([*spec.start, ABOVE_TRAY])))
        self.release()

    def insert(self, part: str, hole: str, rng: np.random.Generator) -> tuple[InsertionResult, Detector,
                                                                                SearchResult]:
        """One attempt with the held part: above the hole (out of its entry along its axis,
        for a hole entered sideways), the search, the skill, all in the hole's frame; the
        ILC correction of (part shape, hole) updated after a success with ILC. The
        controller's ``lowest_rate`` is that of this attempt's search and skill."""
        spec, hole_spec = self.geometry.parts[part], self.geometry.holes[hole]
        skill = self.skill(spec.shape).in_hole(hole_spec.depth)
        turn, shift = fit_pose(spec, hole_spec)
        entry = self.to_base(np.array([*hole_spec.position, hole_spec.top_z]))
        frame = hole_frame(hole_spec.axis, (float(entry[0]), float(entry[1]), float(entry[2])))
        est = entry + np.array([shift[0], shift[1], 0.0])  # in the hole's frame, which shares the entry's centre
        yaw = wrist_yaw(frame, spec.kind, hole_spec.kind, aligned_yaw(spec.kind, hole_spec.kind, hole_spec.yaw + turn))
        key = f"{spec.shape}:{hole}"
        correction = self.ilc.correction(key)[0] if self.layer.ilc else None
        self.controller.watch_rate()
        self.motion.frame = frame
        try:
            found = self.search(est, tool_quat(yaw), rng)
            task = InsertionTask(np.array([found.hole_xy[0], found.hole_xy[1], est[2]]), self.lever(spec), yaw,
                                 needs_yaw_compliance(spec.kind, hole_spec.kind), correction)
            detector = Detector(self.description.thresholds)
            result = insert_in_layer(self.motion, skill, detector, task, self.layer, description=self.description)
        finally:
            self.motion.frame = None
        if result.reached and result.trace is not None:
            self.ilc.update(key, result.trace)
        return result, detector, found

    def search(self, entry: np.ndarray, quat: np.ndarray, rng: np.random.Generator) -> SearchResult:
        """The held part brought to :data:`executor.trial.APPROACH_HEIGHT` above the hole's
        calibrated entry ``entry`` [m] (its centre at the entry, in the motion's frame: the
        hole's), the tool at ``quat`` (xyzw, the same frame) (:meth:`enter`), held still,
        the wrench estimate tared, then the hole search
        (:func:`executor.skills.search.hole_search` with the cell description's ``search``,
        its spiral drawn from ``rng``) around
        it: where the part sinks into the hole, in the robot's reading of the tip."""
        approach = entry + np.array([0.0, 0.0, APPROACH_HEIGHT])
        self.enter(approach, quat)
        self.motion.hold(approach, quat, APPROACH_SETTLE_TIME)
        self.arm.tare_sensor()
        return hole_search(self.motion, entry[:2], entry[2], approach[2], quat, rng, self.description.search)

    def lift(self) -> None:
        """The tool out of a hole entered sideways (:meth:`back_out`), then straight up to
        the carrying height."""
        self.back_out()
        here = self.arm.read().tip_pos
        self.move_to(np.array([here[0], here[1], max(SAFE_Z + self.options.offset[2], float(here[2]))]))

    def stop(self) -> None:
        """Stop the arm (the tracking motion ends, the arm comes to rest) and clear its
        errors; what is held stays held."""
        import franky

        try:
            self.controller.stop()
        except franky.Exception:
            pass  # the motion already ended with the error being handled
        self.robot.recover_from_errors()
