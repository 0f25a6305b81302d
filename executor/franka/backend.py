"""The ``franka`` backend of a cell node (``executor serve --backend franka
--backend-option host=ADDRESS``): insertion experiments and plan steps on a Franka arm
through franky (:class:`executor.franka.cell.FrankaCell`).

- An experiment (``run``): the part is picked, inserted (up to two attempts, lifted to the
  carrying height between them, as the PyBullet cell's trials), carried back to its place
  on the table and let go; ``fit`` when the goal check passed.
- A plan step (``run_step``): the base is the product fixed on the table (the step moves
  nothing); a peg is picked and inserted, let go in its hole on success, else carried back
  (``no_fit``); its pose error is the robot's own reading, the tip's distance from the
  goal where the insertion ended. A cover, a head or a part placed by hand (``[manual.*]``)
  is a ``manual`` step (:func:`by_hand_reason`): the arm has no skill for it and does not
  move; the step is answered ``fit`` with skill ``manual`` and 0 attempts (an operator sets
  the part at its goal, as the PyBullet cell sets a ``[manual.*]`` part), logged as a
  warning, and the part is left out of the pose errors (nothing measured it).
- An attempt whose torque loop fell behind (fewer than :data:`MIN_COMMAND_RATE` of the
  robot's cycles got its command, :mod:`executor.franka.arm`) is no evidence: it is lifted
  and repeated, not counted; after :data:`LATE_REPEATS` repeats the part is carried back and
  the request fails naming the load. Each attempt's outcome, goal error, force and the
  torque loop's share are logged (INFO).
- A stop on any error: whatever raises during a request (a franky exception, a reflex, a
  pose outside the workspace, a failed grasp) stops the arm, clears its errors and answers
  the request with ``failed``; the node keeps serving. A part the hand held stays in it.

Options (``--backend-option KEY=VALUE``, :func:`franka_options`) are in docs/franka.md.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager

import numpy as np

from bridge.cell_settings import ServeSettings
from bridge.messages import Evidence, InsertRequest, Result, StepEvidence, StepRequest
from executor import ExecutorError, UnknownPair
from executor.assembly.product import Product, load_product
from executor.assembly.step import check_product_step
from executor.backend_plugin import StepOutcome, check_run
from executor.control.detector import Detector
from executor.control.ilc import layer_named
from executor.franka.cell import FrankaCell, FrankaOptions
from executor.franka.safety import Limits, Workspace
from executor.skills.dmp import check_product_skills
from executor.skills.insertion import InsertionResult
from executor.trial import CellSetup, cell_setup, trial_rng
from executor.world.geometry import load_geometry

MAX_ATTEMPTS = 2
MIN_COMMAND_RATE = 0.5
"""An attempt whose torque loop got fewer of the robot's cycles than this share (libfranka's
``control_command_success_rate``, lowest over the attempt) is no evidence: the arm ran on
stale torques (docs/franka.md, "The torque loop"). At a load average of 9 on 2 cores the
lowest measured was 0.83."""
LATE_REPEATS = 2
"""How many times an attempt without evidence is repeated before the request fails."""
OPTIONS = ("host", "offset", "grasp-force", "realtime", "dynamics", "torque-threshold", "force-threshold",
           "workspace")
"""The keys of ``--backend-option`` the backend reads."""

LOG = logging.getLogger(__name__)


def by_hand_reason(product: Product, part: str) -> str | None:
    """Why the arm cannot place ``part`` of ``product`` (None: the base, fixed on the table,
    or a peg, which the arm inserts): it has a skill for pegs only."""
    if part in product.covers:
        return f"'{part}' is a cover (it goes over the pegs standing in {', '.join(product.covers[part].over)})"
    if part in product.heads:
        return f"'{part}' is a head (it goes into the socket of {product.heads[part].into})"
    if part in product.manual:
        return f"'{part}' is placed by hand ({product.manual[part].reason})"
    return None


def _floats(key: str, text: str, count: int) -> tuple[float, ...]:
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        values = ()
    if len(values) != count or not all(abs(v) < 1e6 for v in values):
        raise ExecutorError(f"--backend-option {key}={text}: expected {count} comma-separated numbers")
    return values


def franka_options(options: Mapping[str, str]) -> FrankaOptions:
    """The :class:`FrankaOptions` of ``--backend-option`` pairs; ExecutorError naming the key
    and what was expected (``host`` is required)."""
    unknown = sorted(set(options) - set(OPTIONS))
    if unknown:
        raise ExecutorError(f"--backend-option {unknown[0]}: unknown to the franka backend (expected one of "
                            f"{', '.join(OPTIONS)})")
    if not options.get("host"):
        raise ExecutorError("the franka backend needs --backend-option host=ADDRESS (the arm's FCI address)")

    def number(key: str, default: float, low: float, high: float) -> float:
        if key not in options:
            return default
        value = _floats(key, options[key], 1)[0]
        if not low < value <= high:
            raise ExecutorError(f"--backend-option {key}={options[key]}: expected a number in ({low:g}, {high:g}]")
        return value

    realtime = options.get("realtime", "enforce")
    if realtime not in ("enforce", "ignore"):
        raise ExecutorError(f"--backend-option realtime={realtime}: expected enforce or ignore")
    offset = _floats("offset", options["offset"], 3) if "offset" in options else (0.0, 0.0, 0.0)
    limits = Limits(number("dynamics", Limits.dynamics, 0.0, 1.0),
                    number("torque-threshold", Limits.torque_threshold, 0.0, 87.0),
                    number("force-threshold", Limits.force_threshold, 0.0, 100.0))
    workspace = Workspace()
    if "workspace" in options:
        box = _floats("workspace", options["workspace"], 6)
        workspace = Workspace((box[0], box[1], box[2]), (box[3], box[4], box[5]))
    return FrankaOptions(options["host"], (offset[0], offset[1], offset[2]),
                         number("grasp-force", 40.0, 0.0, 70.0), realtime == "enforce", limits, workspace)


def franka_starter(settings: ServeSettings) -> Callable[[], FrankaBackend]:
    """Check the options, the cell description and the product's skills before the node
    opens its session; return what connects to the arm."""
    options = franka_options(settings.backend_options)
    setup = cell_setup(settings.cell)
    check_product_skills(load_geometry(settings.assembly, setup.description))
    return lambda: FrankaBackend(settings, setup, options)


class FrankaBackend:
    """Experiments and plan steps on the arm (module docstring)."""

    def __init__(self, settings: ServeSettings, setup: CellSetup, options: FrankaOptions) -> None:
        self.product = load_product(settings.assembly, setup.description)
        layer = setup.layer if not isinstance(setup.layer, str) else layer_named(setup.layer)
        self.cell = FrankaCell(self.product.geometry, setup.description, layer, options)
        self._run: str | None = None
        self._placed: dict[str, float] = {}
        self._by_hand: set[str] = set()

    @contextmanager
    def _stop_on_error(self) -> Iterator[None]:
        """Any exception: the arm stopped, its errors cleared, ExecutorError naming what happened."""
        try:
            yield
        except Exception as exc:  # noqa: BLE001 - every error stops the arm (module docstring)
            self.cell.stop()
            raise ExecutorError(f"franka: {type(exc).__name__}: {exc}; the arm was stopped") from None

    def _pick_and_insert(self, part: str, hole: str, seed: int) -> tuple[bool, int, float, float, float]:
        """Pick ``part``, up to :data:`MAX_ATTEMPTS` insertions into ``hole``; (reached,
        attempts, max force dev [N], max torque dev [Nm], end error [m]). The part is in the
        hand at the end of the last attempt."""
        rng = trial_rng(seed, part, hole)
        self.cell.pick(part)
        forces, torques = [], []
        for attempt in range(1, MAX_ATTEMPTS + 1):
            result, detector = self._attempt(part, hole, attempt, rng)
            forces.append(detector.max_force_dev)
            torques.append(detector.max_torque_dev)
            if result.reached or attempt == MAX_ATTEMPTS:
                return result.reached, attempt, max(forces), max(torques), result.end_error
            self.cell.lift()
        raise AssertionError("unreachable")

    def _attempt(self, part: str, hole: str, attempt: int, rng: np.random.Generator) -> tuple[InsertionResult,
                                                                                                 Detector]:
        """Insertion ``attempt`` of the held part, repeated (lifted first) while its torque
        loop got fewer than :data:`MIN_COMMAND_RATE` of the robot's cycles; after
        :data:`LATE_REPEATS` repeats the part is carried back and ExecutorError says why."""
        for _ in range(LATE_REPEATS + 1):
            result, detector, found = self.cell.insert(part, hole, rng)
            rate = self.cell.controller.lowest_rate
            if rate >= MIN_COMMAND_RATE:
                LOG.info("%s into %s, attempt %d: %s (goal error %.2f mm, largest force deviation %.1f N, hole "
                         "%s at %s m, torque loop on %.0f%% of the cycles at least)", part, hole, attempt,
                         "reached" if result.reached else "not reached", 1000 * result.end_error,
                         detector.max_force_dev, "found" if found.found else "not found",
                         [round(float(v), 4) for v in found.hole_xy], 100 * rate)
                return result, detector
            LOG.warning("%s into %s, attempt %d: the torque loop got %.0f%% of the robot's cycles (at least %.0f%% "
                        "needed): no evidence, repeated", part, hole, attempt, 100 * rate, 100 * MIN_COMMAND_RATE)
            self.cell.lift()
        self.cell.put_back()
        raise ExecutorError(f"the arm's torque loop got {rate:.0%} of the robot's cycles in {LATE_REPEATS + 1} "
                            f"insertions of {part} into {hole} (at least {MIN_COMMAND_RATE:.0%} needed): the "
                            "machine is too loaded for a 1 kHz loop; no outcome recorded")

    def run(self, request: InsertRequest) -> tuple[Result, Evidence | None]:
        geometry = self.product.geometry
        if request.part not in geometry.parts or request.hole not in geometry.holes:
            raise UnknownPair(f"unknown pair ({request.part},{request.hole}); expected a part of "
                              f"{tuple(sorted(geometry.parts))} and a hole of {tuple(sorted(geometry.holes))}")
        start = time.perf_counter()
        with self._stop_on_error():
            reached, attempts, force, torque, error = self._pick_and_insert(request.part, request.hole, request.seed)
            self.cell.lift()
            self.cell.put_back()
        return ("fit" if reached else "no_fit"), Evidence(attempts=attempts, max_force_dev=force,
                                                          max_torque_dev=torque, end_error=error,
                                                          duration_s=time.perf_counter() - start)

    def run_step(self, request: StepRequest) -> StepOutcome:
        p = self.product
        check_run(self._run, request.assembly, p.parts, {*self._placed, *self._by_hand})
        fresh = request.assembly != self._run
        check_product_step(p, request.part, request.hole, placed=() if fresh else {*self._placed, *self._by_hand})
        if fresh:
            self._run, self._placed, self._by_hand = request.assembly, {}, set()
        start = time.perf_counter()
        if request.part == p.base.id:  # the product is fixed on the table
            self._placed[request.part] = 0.0
            evidence = StepEvidence(skill="fixture", attempts=1, max_force_dev=0.0, max_torque_dev=0.0,
                                    duration_s=0.0, sim_time_s=0.0, pose_error_mm=0.0)
            return "fit", evidence, dict(self._placed)
        reason = by_hand_reason(p, request.part)
        if reason is not None:
            LOG.warning("step %d: %s; the arm has no skill for it: placed by hand (manual), the arm does not move",
                        request.step, reason)
            self._by_hand.add(request.part)
            evidence = StepEvidence(skill="manual", attempts=0, max_force_dev=0.0, max_torque_dev=0.0,
                                    duration_s=0.0, sim_time_s=0.0, pose_error_mm=0.0)
            return "fit", evidence, dict(self._placed)
        assert request.hole is not None  # check_step: a peg has a hole
        with self._stop_on_error():
            robot0 = self.cell.arm.robot_time()
            reached, attempts, force, torque, error = self._pick_and_insert(request.part, request.hole, request.seed)
            if reached:
                self.cell.release()
                self._placed[request.part] = error * 1000.0
            else:
                self.cell.lift()
                self.cell.put_back()
            robot_time = self.cell.arm.robot_time() - robot0
        evidence = StepEvidence(skill="insert", attempts=attempts, max_force_dev=force, max_torque_dev=torque,
                                duration_s=time.perf_counter() - start,
                                sim_time_s=robot_time,
                                pose_error_mm=error * 1000.0)
        return ("fit" if reached else "no_fit"), evidence, dict(self._placed)

    def close(self) -> None:
        self.cell.stop()

