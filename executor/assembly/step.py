"""One plan step in the assembling cell: pick the part on the tray, carry it, place it.

Per kind of part (the ``skill`` of the step's record):

- ``fixture``: the back plate, carried kinematically into the fixture, whose locating pins
  put it at its goal;
- ``insert``: a peg into a hole of the plate: hole search around the vision estimate,
  then the taught force-monitored insertion (:func:`executor.skills.insertion.insert`);
  a part with a bore onto a pin of the base or of a part placed by hand likewise, resting
  on the parts already on that pin (:meth:`Assembler.stacked`); into a hole or onto a pin entered
  sideways, all of it in the feature's frame (:attr:`executor.world.geometry.HoleSpec.frame`),
  the part carried there along its axis; once past the feature's top, a part
  with a bore is centred on its pin by contact, and so is a peg with more room than
  :data:`CENTRING_ROOM` in its hole (:mod:`executor.skills.centring`);
- ``insert_over``: a part with openings down over the pins standing in its holes, by the
  same insertion skill, from above the pins to its resting height, aimed at the holes'
  centres without a search (a pin stands within half its hole's clearance of the centre,
  closer than the robot's own reading of where it inserted it, which carries that peg's
  unknown grasp offset; a spiral search fails on a long part tilting on the pin tops);
- ``insert_socket``: a head into the socket of its part, wherever that part is; it stays
  fixed to it from then on (screwed).
- ``manual``: a part the cell has no operation for (``[manual.*]`` of ``geometry.toml``),
  placed by hand where the CAD has it and fixed there (a static mesh); the arm does not move.

A failed attempt (the goal check fails) lifts the part and tries again with a fresh
vision estimate; after ``max_attempts`` the part is put back on the tray and the step is
``no_fit``, its reason read where the last attempt stopped (``blocked`` or ``jammed``,
:mod:`executor.assembly.failure`).  A part that reached its goal but does not stay there
once let go (nothing holds it: :data:`STAY_TOLERANCE`) is ``no_fit`` too (``unsupported``),
left where it lies.  Placed parts stay where they are; :meth:`Assembler.place_by_hand` puts
a part at its goal without the arm (the known state of a precedence experiment).

The uncertainty and the execution layer: by default :data:`ASSEMBLY_UNCERTAINTY` and the
layer ``pi_phase_stop`` (admittance PI and phase stopping, no ILC); a cell with
``--uncertainty cell`` gives its own :class:`CellBias` (systematic errors per part shape
and per hole from its cell seed), its layer, and an :class:`Ilc` keyed as in the single
trials, (part shape, hole), a cover or head being its own shape and hole.
"""

from __future__ import annotations

import time
from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import pybullet as pb

from bridge.cell_settings import Magnitudes
from bridge.precedence.experiment import FailureReason
from executor import ExecutorError
from executor.assembly.failure import carried_by, targets_of, why_stuck
from executor.assembly.grasp import Grasp
from executor.assembly.product import Product
from executor.assembly.transfer import DESCENT_SPEED, SAFE_Z, VIA_TOLERANCE, carry, freest_yaw, move_line, reorient
from executor.assembly.world import AssemblyWorld
from executor.backend_plugin import check_step
from executor.cell_description import CellDescription
from executor.control.detector import Detector
from executor.control.ilc import LAYERS, ExecutionLayer, Ilc
from executor.control.motion import APPROACH_SETTLE_TIME, StepLogger
from executor.evidence import AttemptSetup
from executor.skills.centring import centre_by_contact
from executor.skills.dmp import Skill, load_product_skill
from executor.skills.insertion import InsertionTask, insert_in_layer, needs_yaw_compliance
from executor.skills.search import hole_search
from executor.trial import APPROACH_HEIGHT, REACH_TOLERANCE, trial_rng
from executor.world.arm import tool_quat, turn_z
from executor.world.frames import HoleFrame, aligned_yaw, yaw_quat
from executor.world.geometry import fit_pose, margin
from executor.world.perturbation import CellBias
from executor.world.scene import PART_FRICTION, inertial_frame

ABOVE_PINS = 0.004  # [m] gap between a cover's bottom and the pin tops where its insertion starts
CENTRING_MARGIN = 0.005  # [m] the centring probes reach this beyond the farthest the feature can be
CENTRING_ROOM = 0.001
"""[m] a peg with more room than this all round in its hole is centred in it by contact
(:mod:`executor.skills.centring`): with less the hole itself holds it within the placed
parts' 2 mm (a square peg's corner direction: √2 × its room)."""
RETREAT = 0.03  # [m] the tool goes up (out of a hole entered sideways) this far after opening the gripper
SIDEWAYS_OUT = 0.05
"""[m] a part going into a hole entered sideways comes down this far out of its entry
along its axis, then goes in along the axis."""
GRIP_TOLERANCE = 0.002  # [m] of the empty tool at the grip point (the grasp error model sets the real offset)
ASSEMBLY_UNCERTAINTY = Magnitudes(
    grasp_offset_bias=0.0, grasp_offset_random=0.001, grasp_tilt_bias=0.0, grasp_tilt_random=1.0,
    vision_bias=0.0, vision_sigma=0.0015, vision_max=0.003, vision_yaw_bias=0.0, vision_yaw_sigma=0.5,
    vision_yaw_max=1.0, friction_min=0.25, friction_max=0.25, friction_jitter=0.0)
"""The assembling cell's uncertainty per execution: a grasp offset ≤ 1 mm and tilt ≤ 1°,
a vision error σ 1.5 mm (≤ 3 mm), a rect hole's yaw error σ 0.5° (≤ 1°), the teaching
friction; random parts only (the cell's systematic errors and ILC are used with
``--uncertainty cell``)."""
SETTLE_S = 0.5
"""How long parts set at their goals by hand are left to the physics before the check that they stayed [s]."""
DEFAULT_LAYER = LAYERS["pi_phase_stop"]
"""The insertion of a plan step unless the cell gives its layer: admittance PI, phase stopping, no ILC."""
GRASP_YAWS = (0.0, np.pi, -np.pi)
"""[rad] the tool yaws, about the part's z axis, at which the cell may pick the back plate
(the fixture's part): a two-finger gripper holds it by the same two sides turned by a half
turn (its fingers swapped), reached by the wrist turning either way. The plate keeps that
turn in the tool, and the tool keeps it at the fixture, so the plate reaches its goal pose
whatever its own symmetry; of these, the one whose postures on the way to the pick and on
to the fixture keep the joints farthest from their limits
(:func:`executor.assembly.transfer.freest_yaw`)."""
FLAT_GRASP_OFFSET = 0.3  # a cover's grasp offset, as a fraction of a peg's (no tilt)
SURFACE_RAYS = (8, 24)
"""The rays that measure where a peg's hole search presses (:meth:`Assembler.search_surface`):
this many rings about the hole's axis, this many rays a ring, plus one on the axis."""
SURFACE_MARGIN = 0.001
"""[m] beyond the peg's section about its hole's axis, the reach of those rays: the rim of
an opening over the hole (a bracket's flange about its bore), not a wall beside it (the
wall of ``occt_as1``'s bracket stands 10 mm from its bolts' axes, 5 mm from their shanks)."""
STAY_TOLERANCE = 0.005
"""A part let go at its goal must still be within this distance of it after the tool's
retreat [m] (placed parts are within 2 mm); else the step is ``no_fit`` and the part is
left where it lies (e.g. a peg let go in a hole of a plate that is not in its fixture
falls: the insertion itself met no resistance to tell it)."""


def _free_approach(skill: str) -> float:
    """How far above the entry of its place (a hole's top, the pin tops, a socket's top) a
    part's insertion starts [m]."""
    return APPROACH_HEIGHT if skill == "insert" else ABOVE_PINS


@dataclass
class StepRecord:
    """What one plan step did: ``outcome`` fit/no_fit, attempts, wall time [s], largest
    force deviation [N] of the insertions, distance of the part from its goal [m] after
    the step, simulated time [s], whether the hole search found the hole (pegs)."""

    part: str
    hole: str | None
    skill: str
    outcome: str
    attempts: int
    duration_s: float
    max_force_dev: float
    max_torque_dev: float
    pose_error: float
    sim_time_s: float
    reason: FailureReason | None = None
    """Why it failed: blocked, jammed (:func:`executor.assembly.failure.why_stuck`) or
    unsupported (it did not stay at its goal); None when it fit."""
    involved: tuple[str, ...] = ()
    """blocked: the other parts it touched where it stopped."""

    def to_json(self) -> dict:
        return {"part": self.part, "hole": self.hole, "skill": self.skill, "outcome": self.outcome,
                "attempts": self.attempts, "duration_s": self.duration_s, "max_force_dev": self.max_force_dev,
                "max_torque_dev": self.max_torque_dev, "pose_error_mm": self.pose_error * 1000.0,
                "sim_time_s": self.sim_time_s}


def check_product_step(product: Product, part: str, hole: str | None, placed: Collection[str]) -> None:
    """:func:`executor.backend_plugin.check_step` against ``product``, with ``placed`` parts;
    the hole a plan names for a part placed by hand is not checked (it goes to its goal in
    the CAD, on whatever feature: the planner's feature for it, as the truth backend takes it)."""
    check_step(part, None if part in product.manual else hole, parts=product.parts, pegs=product.pegs,
               holes=product.geometry.holes, placed=placed)


class Assembler:
    """The assembling cell: one :class:`AssemblyWorld` kept between steps."""

    def __init__(self, product: Product, logger: StepLogger | None = None, *, description: CellDescription,
                 bias: CellBias | None = None, layer: ExecutionLayer = DEFAULT_LAYER,
                 ilc: Ilc | None = None) -> None:
        """``description``: the cell's gains, thresholds and admittance (the product was
        loaded with its gripper); ``bias``: the errors of each execution, drawn around the
        cell's systematic errors (default from :data:`ASSEMBLY_UNCERTAINTY`, cell seed 0);
        ``layer``: the insertion's execution layer; ``ilc``: the corrections its ILC uses and
        updates (kept by the caller, e.g. across plan runs; required when ``layer.ilc``)."""
        if layer.ilc and ilc is None:
            raise ExecutorError(f"execution layer '{layer.name}' needs an ILC state")
        self.product, self.description = product, description
        self.world = AssemblyWorld(product, logger, gains=description.gains)
        self.thresholds = description.thresholds
        self._skills: dict[str, Skill] = {}
        self.placed: set[str] = set()
        self.hole_of: dict[str, str] = {}  # placed peg -> its hole
        self._screwed: dict[str, int] = {}
        self.blocked: set[str] = set()
        self._bias = CellBias(ASSEMBLY_UNCERTAINTY, 0) if bias is None else bias
        self._surface: dict[str, float] = {}  # hole -> where its search presses, measured this step
        self.layer, self.ilc = layer, ilc

    def skill_of(self, part: str) -> str:
        """The step's skill: fixture, insert, insert_over, insert_socket or manual."""
        p = self.product
        if part == p.base.id:
            return "fixture"
        if part in p.pegs:
            return "insert"
        if part in p.covers:
            return "insert_over"
        if part in p.heads:
            return "insert_socket"
        if part in p.manual:
            return "manual"
        raise ExecutorError(f"unknown part '{part}' (expected one of {', '.join(p.parts)})")

    def shape_of(self, part: str) -> str:
        """The part's shape for its systematic grasp error and ILC key: a peg's shape, else the part itself."""
        peg = self.product.pegs.get(part)
        return part if peg is None else peg.shape

    def _skill(self, name: str) -> Skill:
        if name not in self._skills:
            self._skills[name] = load_product_skill(self.product.geometry, name)
        return self._skills[name]

    def block_hole(self, hole: str) -> None:
        """An obstacle in ``hole`` (a fault injection): a box filling it from the bottom up to
        5 mm under its entry, so no peg reaches its goal there."""
        spec = self.product.geometry.holes.get(hole)
        if spec is None:
            holes = ", ".join(sorted(self.product.geometry.holes))
            raise ExecutorError(f"unknown hole '{hole}' (expected one of {holes})")
        if spec.sideways:
            raise ExecutorError(f"hole '{hole}' is entered along {spec.axis}: an obstacle in it is not modelled "
                                "(expected a hole entered down)")
        depth = spec.depth - 0.005
        a, b = spec.sides
        half = [a / 2 - 0.0002, b / 2 - 0.0002, depth / 2]
        col = pb.createCollisionShape(pb.GEOM_BOX, halfExtents=half, physicsClientId=self.world.client)
        pb.createMultiBody(0, col, -1, [*spec.position, spec.bottom_z + depth / 2], yaw_quat(spec.yaw),
                           physicsClientId=self.world.client)
        self.blocked.add(hole)

    def run_step(self, part: str, hole: str | None, seed: int, max_attempts: int = 2) -> StepRecord:
        """Place ``part`` (into ``hole`` for a peg); UnknownPair for an unknown id,
        InvalidStep for a step the product does not allow (:func:`check_step`), before
        anything moves."""
        check_product_step(self.product, part, hole, self.placed)
        skill = self.skill_of(part)
        world, motion = self.world, self.world.motion
        wall0, sim0 = time.perf_counter(), motion.steps
        if skill == "manual":
            return self._by_hand(part, wall0, sim0)
        rng = trial_rng(seed, part, hole or "none")
        if skill == "insert" and hole is not None:
            world.set_peg_goal(part, hole, self.stacked(part, hole, self.hole_of))
        setup = self._draw(rng, part, hole)
        grasp = self._pick(part, setup)
        self._surface.clear()
        if skill == "insert" and hole is not None and self._frame(hole, skill) is None:
            self._surface[hole] = self.search_surface(part, hole)  # the arm at the tray, clear of the product
        stuck: tuple[FailureReason | None, tuple[str, ...]] = (None, ())
        if skill == "fixture":
            carry(motion, world.frames[part].grip, grasp.follow, yaw=grasp.yaw)
            world.set_pose(part, world.goals[part])  # the fixture's locating pins
            outcomes = [(True, 0.0, 0.0)]
        else:
            outcomes = []
            for attempt in range(max_attempts):
                if attempt:
                    setup = self._draw(rng, part, hole)
                outcomes.append(self._insert(part, hole, skill, setup, grasp))
                if outcomes[-1][0]:
                    break
                stuck = self.why_stuck(part, hole, skill)
                here = motion.read().tip_pos  # up, or out along a sideways hole's axis
                move_line(motion, here + np.array([0.0, 0.0, 0.04]), tolerance=VIA_TOLERANCE)
        ok = outcomes[-1][0]
        if ok:
            stuck = (None, ())
        if not ok:  # back to the tray
            self._leave_frame()
            carry(motion, world.tray_position(part) + world.frames[part].tcp + np.array([0.0, 0.0, 0.002]))
        grasp.release()
        here = motion.read().tip_pos
        move_line(motion, here + np.array([0.0, 0.0, RETREAT]), tolerance=VIA_TOLERANCE)
        self._leave_frame()
        if ok and world.goal_error(part) > STAY_TOLERANCE:  # let go, it did not stay: nothing holds it there
            ok, stuck = False, ("unsupported", ())
        if ok:
            self._placed(part, hole)
        world.rest()
        error = world.goal_error(part) if ok else float(np.linalg.norm(world.position(part) - world.goals[part]))
        return StepRecord(part, hole, skill, "fit" if ok else "no_fit", len(outcomes), time.perf_counter() - wall0,
                          max(o[1] for o in outcomes), max(o[2] for o in outcomes), error,
                          (motion.steps - sim0) * 0.001, *stuck)

    def _placed(self, part: str, hole: str | None) -> None:
        """``part`` is at its goal: a head is screwed to its part, a peg locked in its hole."""
        self.placed.add(part)
        if part not in self._screwed:
            self._screw(part)
        if part in self.product.pegs and hole is not None:
            self.hole_of[part] = hole
            self.world.lock(part)

    def place_by_hand(self, placements: Sequence[tuple[str, str | None]], settle_s: float = SETTLE_S) -> list[str]:
        """Put each (part, hole) at its goal without the arm (a peg into its hole, a head into
        the socket of its part wherever that part is, screwed), let the world run ``settle_s``
        [s] so the physics decides whether each stays there, and return the parts that did not
        (more than :data:`STAY_TOLERANCE` from their goals); the others are placed (pegs locked
        in their holes). InvalidStep or UnknownPair, as for :meth:`run_step`, before anything moves."""
        placed = list(self.placed)
        for part, hole in placements:
            check_product_step(self.product, part, hole, placed)
            placed.append(part)
        world, on = self.world, dict(self.hole_of)
        holes = self.product.geometry.holes

        def later(placement: tuple[str, str | None]) -> tuple[bool, bool]:
            """Heads after their parts, parts onto a pin of another part after that part."""
            part, hole = placement
            return part in self.product.heads, hole is not None and holes[hole].owner is not None

        for part, hole in sorted(placements, key=later):
            if part in self.product.pegs and hole is not None:
                world.set_peg_goal(part, hole, self.stacked(part, hole, on))
                on[part] = hole
            socket = part in self.product.heads  # a head's goal is the socket where its part is now
            world.set_pose(part, self._goal_tcp(part, "insert_socket") - world.frames[part].tcp if socket
                           else world.goals[part], world.goal_quats.get(part, (0.0, 0.0, 0.0, 1.0)))
            self._screw(part)
            pb.changeDynamics(world.frames[part].body, -1, activationState=pb.ACTIVATION_STATE_WAKE_UP,
                              physicsClientId=world.client)
        world.settle(settle_s)
        fell = [part for part, _ in placements if world.goal_error(part) > STAY_TOLERANCE]
        for part, hole in placements:
            if part not in fell:
                self._placed(part, hole)
        world.rest()
        return fell

    def stacked(self, part: str, hole: str, on: Mapping[str, str]) -> float:
        """How far [m] out along pin ``hole``'s axis from its foot part ``part`` rests: the
        lengths of the parts ``on`` it (part -> its hole or pin) other than ``part``, each
        resting on the one before, end to end (a gear on a washer); 0 on an empty pin and
        in a hole (a peg stands on its bottom)."""
        if not self.product.geometry.holes[hole].pin:
            return 0.0
        return sum(self.product.pegs[q].length for q, h in on.items() if h == hole and q != part)

    def why_stuck(self, part: str, hole: str | None, skill: str) -> tuple[FailureReason, tuple[str, ...]]:
        """Why ``part``, stopped short of its goal and still held, is stuck
        (:func:`executor.assembly.failure.why_stuck`, the heads screwed into it moving with it),
        the entry of its place being where the insertion's free approach ends."""
        p = self.product
        frame = self._frame(hole, skill)
        goal = self._goal_tcp(part, skill)
        approach = self._approach(part, hole, skill, goal if frame is None else frame.points_in(goal))
        entry_z = float(approach[2] - _free_approach(skill))
        into = {h: spec.into for h, spec in p.heads.items()}
        targets = targets_of(part, skill, p.base.id, {c: spec.over for c, spec in p.covers.items()}, into,
                             self.hole_of)
        return why_stuck(self.world, part, targets, entry_z, self.placed, carried_by(part, into, self.placed),
                         frame)

    def _by_hand(self, part: str, wall0: float, sim0: int) -> StepRecord:
        """A part placed by hand (``manual``): at its goal, fixed there."""
        world = self.world
        world.set_pose(part, world.goals[part])
        self.placed.add(part)
        return StepRecord(part, None, "manual", "fit", 1, time.perf_counter() - wall0, 0.0, 0.0,
                          world.goal_error(part), (world.motion.steps - sim0) * 0.001)

    def _draw(self, rng: np.random.Generator, part: str, hole: str | None) -> AttemptSetup:
        """One execution's errors: of the part's shape and its hole (a cover or head: of
        itself), with a yaw error of the estimate for a peg's rect hole."""
        oriented = hole is not None and self.product.geometry.holes[hole].kind == "rect"
        return self._bias.draw(rng, self.shape_of(part), hole or part, oriented)

    def _yaw(self, part: str, hole: str | None, setup: AttemptSetup) -> float:
        """The tool yaw [rad] a peg is inserted with: aligned to its hole's estimated yaw,
        turned as the polygon relation passes it (0 for other parts and round pegs or holes)."""
        peg = self.product.pegs.get(part)
        if peg is None or hole is None:
            return 0.0
        spec = self.product.geometry.holes[hole]
        return aligned_yaw(peg.kind, spec.kind, spec.yaw + fit_pose(peg, spec)[0] + setup.vision_yaw)

    def _pick(self, part: str, setup: AttemptSetup) -> Grasp:
        """Carry the empty tool to the part's grip point and close the gripper."""
        world = self.world
        world.arm.set_grasp_error(np.zeros(3), np.array([0.0, 0.0, 0.0, 1.0]))
        pos, quat = world.pose(part)
        grip = np.array(pb.multiplyTransforms(list(pos), list(quat), list(world.frames[part].grip), [0, 0, 0, 1])[0])
        yaw = 0.0  # the parts lie on the tray unturned
        if self.skill_of(part) == "fixture":  # placed at its grip point's goal, turned as it is held
            yaw = freest_yaw(world.motion, np.array([grip, world.frames[part].grip]), GRASP_YAWS)
        carry(world.motion, grip, tolerance=GRIP_TOLERANCE, yaw=yaw)
        if part in self.product.covers:  # a flat part lies against the palm, centred by the fingers
            return Grasp(world, part, FLAT_GRASP_OFFSET * setup.grasp_offset, np.zeros(3))
        return Grasp(world, part, setup.grasp_offset, setup.grasp_tilt, yaw)

    def _goal_tcp(self, part: str, skill: str) -> np.ndarray:
        """Where the TCP is when the part is placed [m] (a head: in its part's socket now)."""
        world = self.world
        if skill == "insert_socket":
            into = self.product.heads[part].into
            return world.position(into) + world.socket_offset[part] + world.frames[part].tcp
        return world.goals[part] + world.frames[part].tcp

    def _centring_reach(self, part: str, hole: str | None) -> float | None:
        """How far [m] the centring probes of a peg found in ``hole`` reach each way, None
        where it is not centred: a bore on a pin, its circumradius (the pin's axis is
        at most that far from the bore's centre) + :data:`CENTRING_MARGIN`; a peg with more room than
        :data:`CENTRING_ROOM` in a hole, twice its room (from one wall to the other) +
        :data:`CENTRING_MARGIN`."""
        peg = self.product.pegs.get(part)
        if peg is None or hole is None:
            return None
        feature = self.product.geometry.holes[hole]
        if feature.pin:
            return peg.circumradius + CENTRING_MARGIN
        room = margin(peg, feature) / 2
        return 2 * room + CENTRING_MARGIN if room > CENTRING_ROOM else None

    def search_surface(self, part: str, hole: str) -> float:
        """The height [m] where the hole search for peg ``part`` presses at ``hole`` (entered
        down; a pin of a peg where that peg is): the hole's top, or higher the highest point
        of a placed part other than the base within the peg's section (its circumradius)
        plus :data:`SURFACE_MARGIN` of the hole's axis (a bracket's flange over the hole, the
        peg going through its bore), measured by rays straight down onto the world (a ray
        that meets anything else, the arm or the held part, goes on under its bounding box)."""
        world, spec = self.world, self.product.geometry.holes[hole]
        bodies = {world.frames[q].body for q in self.placed if q not in (part, self.product.base.id)}
        reach = self.product.pegs[part].circumradius + SURFACE_MARGIN
        rings, per_ring = SURFACE_RAYS
        entry = np.array([*spec.position, spec.top_z])
        if spec.owner in self.product.pegs:  # a pin of a peg: where that peg is (AssemblyWorld.on_owner)
            entry = world.on_owner(spec.owner, entry)[0]
        xy = [entry[:2]]
        for r in np.linspace(reach / rings, reach, rings):
            xy += [xy[0] + r * np.array([np.cos(a), np.sin(a)])
                   for a in np.linspace(0.0, 2 * np.pi, per_ring, endpoint=False)]
        starts = [[x, y, SAFE_Z + 0.5] for x, y in xy]
        top = bottom = float(entry[2])
        while starts:
            hits = pb.rayTestBatch(starts, [[x, y, bottom] for x, y, _ in starts], physicsClientId=world.client)
            going_on = []
            for start, (body, link, _, position, _) in zip(starts, hits, strict=True):
                if body in bodies:
                    top = max(top, float(position[2]))
                elif body >= 0:  # on under what it met
                    under = float(pb.getAABB(body, link, physicsClientId=world.client)[0][2]) - 1e-4
                    if bottom < under < start[2]:
                        going_on.append([start[0], start[1], under])
            starts = going_on
        return top

    def _approach(self, part: str, hole: str | None, skill: str, goal: np.ndarray) -> np.ndarray:
        """Where the insertion starts [m]: above the entry of ``hole`` (pegs; above the part
        over it where one is placed: :meth:`search_surface`, measured as the step began), above the pin
        tops (covers: the longest peg standing in the highest of its holes), above the
        socket (heads)."""
        p = self.product
        if skill == "insert" and hole is not None:
            top = self._surface.get(hole, p.geometry.holes[hole].top_z)
            return np.array([goal[0], goal[1], top + APPROACH_HEIGHT])
        if skill == "insert_over":
            longest = max(s.length for s in p.pegs.values())
            holes = [p.geometry.holes[h] for h in p.covers[part].over]
            pins_top = max(h.top_z + longest - h.depth for h in holes)
            return np.array([goal[0], goal[1], pins_top + ABOVE_PINS])
        head = p.heads[part]
        cover = p.covers[head.into]
        return np.array([goal[0], goal[1], self.world.position(head.into)[2] + cover.thickness + ABOVE_PINS])

    def _insert(self, part: str, hole: str | None, skill: str, setup: AttemptSetup,
                grasp: Grasp) -> tuple[bool, float, float]:
        """One attempt from above the goal: (goal reached, max force dev [N], max torque dev [Nm])."""
        world, motion, p = self.world, self.world.motion, self.product
        frame = self._frame(hole, skill)  # a hole entered sideways: the attempt runs in its frame
        goal = self._goal_tcp(part, skill)
        if frame is not None:
            goal = frame.points_in(goal)
        approach = self._approach(part, hole, skill, goal)
        if skill != "insert_over":  # a cover is aimed at its holes' centres (module docstring)
            approach[:2] += setup.vision_error
        yaw = self._yaw(part, hole, setup)
        quat = tool_quat(yaw)
        if frame is None:
            carry(motion, approach, yaw=yaw)
        else:
            self._enter(frame, approach, yaw)
        motion.hold(approach, quat, APPROACH_SETTLE_TIME)
        world.arm.tare_sensor()
        centred = False
        if skill == "insert_over":
            skill_obj, xy = self._skill(p.covers[part].skill), approach[:2]
        else:
            # The hole search around the estimate, on the plate or on the socket's part.
            surface = approach[2] - _free_approach(skill)
            found = hole_search(motion, approach[:2], surface, approach[2], quat,
                                np.random.default_rng(setup.search_seed), self.description.search)
            xy = found.hole_xy
            reach = self._centring_reach(part, hole) if skill == "insert" and found.found else None
            centred = reach is not None and hole is not None
            # the free length of the hole or pin: a pin's less the parts already on it
            free = 0.0 if hole is None else p.geometry.holes[hole].depth - self.stacked(part, hole, self.hole_of)
            if reach is not None and hole is not None:  # in the feature's room, not touching it yet
                xy = centre_by_contact(motion, motion.read().tip_pos, quat, reach, free)[:2]
            if skill == "insert" and hole is not None:  # the peg's skill, its goal at this hole's bottom
                peg = p.pegs[part]
                skill_obj = self._skill(peg.shape).in_hole(free)
            else:
                skill_obj = self._skill(p.heads[part].skill)
        origin = np.array([xy[0], xy[1], goal[2] - skill_obj.end_position[2]])
        if centred:  # the skill's end aimed at the centre found: its taught end is off the hole frame's
            origin[:2] -= turn_z(skill_obj.end_position, yaw)[:2]  # axis where the taught hole left room
        detector = Detector(self.thresholds)
        lever = float(np.linalg.norm(world.frames[part].grip - world.frames[part].tcp))
        layer, key = self.layer, f"{self.shape_of(part)}:{hole or part}"
        correction = self.ilc.correction(key)[0] if layer.ilc and self.ilc is not None else None
        plate = world.frames[p.base.id].body
        if skill == "insert" and setup.friction is not None:  # the hole's friction: Bullet multiplies the two
            pb.changeDynamics(plate, -1, lateralFriction=setup.friction / PART_FRICTION, physicsClientId=world.client)
        compliant = skill == "insert" and hole is not None and needs_yaw_compliance(
            p.pegs[part].kind, p.geometry.holes[hole].kind)
        task = InsertionTask(origin, lever, yaw, yaw_compliant=compliant, correction=correction)
        result = insert_in_layer(motion, skill_obj, detector, task, layer, description=self.description)
        pb.changeDynamics(plate, -1, lateralFriction=PART_FRICTION, physicsClientId=world.client)
        if result.reached and result.trace is not None and self.ilc is not None:
            self.ilc.update(key, result.trace)
        return result.reached, detector.max_force_dev, detector.max_torque_dev

    def _frame(self, hole: str | None, skill: str) -> HoleFrame | None:
        """The frame of a peg's hole or a bore's pin entered sideways
        (:attr:`executor.world.geometry.HoleSpec.frame`), else None."""
        return self.product.geometry.holes[hole].frame if skill == "insert" and hole is not None else None

    def _enter(self, frame: HoleFrame, approach: np.ndarray, yaw: float) -> None:
        """Bring the held part to ``approach`` [m, in ``frame``] of a hole entered sideways: up
        to the carrying height, across above the point :data:`SIDEWAYS_OUT` out of the entry
        along the hole's axis while the tool turns down that axis (:func:`reorient`), down to
        that point, and in to the approach (from where a failed attempt backed out, only in)."""
        motion = self.world.motion
        outside = approach + np.array([0.0, 0.0, SIDEWAYS_OUT])
        if motion.frame is not frame:
            self._leave_frame()
            here = motion.read().tip_pos
            if here[2] < SAFE_Z - 1e-3:
                move_line(motion, np.array([here[0], here[1], SAFE_Z]), tolerance=VIA_TOLERANCE)
            above = frame.points_to_cell(outside)
            reorient(motion, np.array([above[0], above[1], max(SAFE_Z, float(above[2]))]), frame, yaw)
        move_line(motion, outside, tolerance=VIA_TOLERANCE, yaw=yaw)
        move_line(motion, approach, speed=DESCENT_SPEED)
        missed = float(np.linalg.norm(motion.read().tip_pos - approach))
        if missed > REACH_TOLERANCE:  # out of the arm's reach: no outcome to report
            where = ", ".join(f"{1e3 * v:.1f}" for v in frame.points_to_cell(approach))
            raise ExecutorError(f"the arm does not reach the approach to a hole or pin entered sideways at ({where}) "
                                f"mm: its tip stays {1e3 * missed:.1f} mm from it; expected a pose within its reach "
                                "(place the product nearer the arm: import --place X,Y)")

    def _leave_frame(self) -> None:
        """After a hole entered sideways: the tool straight up to the carrying height, turning
        to point down the cell's z again (nothing to do outside a hole's frame)."""
        motion = self.world.motion
        if motion.frame is not None:
            here = motion.controller.arm.read().tip_pos
            reorient(motion, np.array([here[0], here[1], max(SAFE_Z, float(here[2]))]), None, 0.0)

    def _screw(self, part: str) -> None:
        """A head placed in its socket stays fixed to that part."""
        head = self.product.heads.get(part)
        if head is None:
            return
        world = self.world
        into, me = world.frames[head.into].body, world.frames[part].body
        pos, quat = world.pose(head.into)
        mine = world.pose(part)
        inv = pb.invertTransform(list(pos), list(quat))
        rel_pos, rel_quat = pb.multiplyTransforms(*inv, list(mine[0]), list(mine[1]))
        c = world.client
        parent = pb.multiplyTransforms(*pb.invertTransform(*inertial_frame(c, into)), rel_pos, rel_quat)
        child = pb.invertTransform(*inertial_frame(c, me))
        self._screwed[part] = pb.createConstraint(into, -1, me, -1, pb.JOINT_FIXED, (0, 0, 0),
                                                  parentFramePosition=parent[0], childFramePosition=child[0],
                                                  parentFrameOrientation=parent[1], childFrameOrientation=child[1],
                                                  physicsClientId=c)

    def pose_errors(self) -> dict[str, float]:
        """Distance of every part from its goal [m] (a peg without a goal: from its tray pose)."""
        return {pid: self.world.goal_error(pid) if pid in self.world.goals else float("nan")
                for pid in self.product.parts}

    def close(self) -> None:
        self.world.close()


