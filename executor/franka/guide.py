"""Teaching by hand-guiding (``executor teach --backend franka --demonstration hand``): a
person guides the part in the hand from above its ``demo_hole`` into it, the arm compliant.

The arm brings the part :data:`GUIDE_HEIGHT` above the hole's entrance where the hole
search found it (:meth:`executor.franka.teach.FrankaTeacher.find_hole`) (tool
pointing down, turned to the hole's yaw), takes the held part as its load (its gravity
compensation carries the part's weight, :func:`carried`), tares the wrench estimate and
hands itself over:
Cartesian impedance with no spring on the translation (only :data:`GUIDE_DAMPING`, felt as
a light drag) and the orientation held by the cell's rotational gains, so the part stays
upright and turned to the hole while the hand moves it. The recorder samples the tip's
pose and the wrench estimate at every robot cycle (1 kHz, stamped with the robot's clock)
from the handover on; a tip leaving the workspace stops the arm (``SafetyStop``).

The triggers are the motion itself, no button: the demonstration **ends** when the tip has
been at rest (slower than :data:`REST_SPEED`) for :data:`REST_TIME` below the skill's start
depth (:data:`executor.skills.teach.DEMO_START_HEIGHT`, 2 mm inside the entrance, where the
hole search leaves a part); a pause above that depth does not end it. It **starts** at the
last moment the tip was still at that depth or above, so a hesitation at the entrance is not
part of it, and the rest at the end is cut off. No demonstration within
:data:`GUIDE_TIMEOUT` of robot time is an error. The span is resampled onto the skills' 1 ms
step and moved into the hole frame, then taught as the scripted one is
(:func:`executor.skills.teach.teach_shape`): encoded as the DMP, replayed by the arm to record
the reference wrench, checked against the goal. The wrench sampled while guided is the
hand's push and the contact together (the arm's estimate cannot tell them apart), so it is
reported, not taught.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np

from executor import ExecutorError
from executor.control.motion import Motion
from executor.franka.arm import FrankyController
from executor.franka.cell import FrankaCell
from executor.franka.teach import FrankaTeacher
from executor.skills.teach import DEMO_START_HEIGHT, Demonstration, TeachingCell
from executor.world.arm import tool_quat, turn_quats_z, turn_z
from executor.world.scene import TIME_STEP

GUIDE_HEIGHT = 0.02  # [m] above the hole's entrance: where the arm hands the part over
GUIDE_DAMPING = 20.0  # [N s/m] per translational axis while guided: 0.4 N against a hand moving 2 cm/s
REST_SPEED = 0.001  # [m/s] the tip is at rest below this speed
REST_TIME = 1.0  # [s] of robot time at rest below the start depth: the demonstration is over
GUIDE_TIMEOUT = 300.0  # [s] of robot time from the handover to the end of the demonstration
MIN_DURATION = 0.05  # [s] a shorter span between the triggers is refused
LET_GO = 2.0  # [s] of wall time between the line that asks to let go and the arm's next motion
LOAD_INERTIA = (1e-5, 0.0, 0.0, 0.0, 1e-5, 0.0, 0.0, 0.0, 1e-5)
"""[kg m^2] the held part's inertia as the arm's load (column-major): a small part's is
negligible beside the hand's; only its weight matters to the gravity compensation."""


@dataclass(frozen=True)
class Recording:
    """What the recorder sampled, one row per robot cycle: ``times`` [s] of the robot's
    clock, tip ``positions`` [m] and quaternions ``quats`` (xyzw), base frame, tip speeds
    ``speeds`` [m/s] and ``wrenches`` (N, 6) [N, N m], the arm's estimate at the tip."""

    times: np.ndarray
    positions: np.ndarray
    quats: np.ndarray
    speeds: np.ndarray
    wrenches: np.ndarray


def demonstration_span(rec: Recording, start_z: float) -> tuple[int, int]:
    """The first and last sample of the demonstration in ``rec``: from the last sample
    whose tip was at ``start_z`` [m] or above to the first sample of the rest at the end
    (:data:`REST_SPEED`). ExecutorError when the tip never went below ``start_z`` or the
    span is shorter than :data:`MIN_DURATION`."""
    above = np.flatnonzero(rec.positions[:, 2] >= start_z)
    if len(above) == 0 or above[-1] == len(rec.times) - 1:
        raise ExecutorError(f"the part was not guided below {start_z:.4f} m (2 mm inside the hole's entrance); "
                            "expected a demonstration from above the hole into it")
    first = int(above[-1])
    moving = np.flatnonzero(rec.speeds[first:] >= REST_SPEED)
    last = first + (int(moving[-1]) + 1 if len(moving) else 0)
    last = min(last, len(rec.times) - 1)
    if rec.times[last] - rec.times[first] < MIN_DURATION:
        raise ExecutorError(f"a demonstration of {rec.times[last] - rec.times[first]:.3f} s: expected at least "
                            f"{MIN_DURATION} s of motion from the hole's entrance into it")
    return first, last


def resample(times: np.ndarray, positions: np.ndarray, quats: np.ndarray
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The samples on a grid of TIME_STEP from ``times[0]`` [s] (the robot's cycles a
    Python loop missed filled in linearly; quaternions made sign-continuous, interpolated
    and normalised); times from 0."""
    grid = np.arange(0.0, times[-1] - times[0] + 0.5 * TIME_STEP, TIME_STEP)
    t = times - times[0]
    quats = quats.copy()
    for k in range(1, len(quats)):
        if np.dot(quats[k], quats[k - 1]) < 0:
            quats[k] = -quats[k]
    pos = np.column_stack([np.interp(grid, t, positions[:, i]) for i in range(3)])
    q = np.column_stack([np.interp(grid, t, quats[:, i]) for i in range(4)])
    return grid, pos, q / np.linalg.norm(q, axis=1, keepdims=True)


def record_guided(controller: FrankyController, start_z: float, timeout: float = GUIDE_TIMEOUT) -> Recording:
    """Hand the arm over (:meth:`FrankyController.guide`) and sample every robot cycle until
    the tip has rested :data:`REST_TIME` below ``start_z`` [m]; the arm is stopped (at
    rest, the tracking ended) on return and on any error. ExecutorError after ``timeout``
    [s] of robot time, SafetyStop when the tip leaves the workspace."""
    times: list[float] = []
    positions: list[np.ndarray] = []
    quats: list[np.ndarray] = []
    speeds: list[float] = []
    wrenches: list[np.ndarray] = []
    controller.guide(GUIDE_DAMPING)
    try:
        rest_since: float | None = None
        while True:
            now, s = controller.sample()
            controller.workspace.check(s.tip_pos)
            speed = float(np.linalg.norm(s.tip_vel))
            times.append(now)
            positions.append(s.tip_pos)
            quats.append(s.tip_quat_xyzw)
            speeds.append(speed)
            wrenches.append(np.concatenate([s.force, s.torque]))
            if speed >= REST_SPEED or s.tip_pos[2] > start_z:
                rest_since = None
            elif rest_since is None:
                rest_since = now
            elif now - rest_since >= REST_TIME:
                break
            if now - times[0] > timeout:
                raise ExecutorError(f"no demonstration within {timeout:g} s: expected the part guided into "
                                    f"the hole and held still there for {REST_TIME:g} s")
    finally:
        controller.stop()
    return Recording(np.array(times), np.array(positions), np.array(quats), np.array(speeds), np.array(wrenches))


@contextmanager
def carried(cell: FrankaCell) -> Iterator[None]:
    """Meanwhile, the arm at rest (its motion ended) carries the held part as its load
    (``Robot.set_load``: its gravity compensation takes the part's weight, at its centre
    of mass) and the wrench estimate is tared with it; the load is set back on exit.
    Without it, a 40 g part would move the spring-less guided arm down at 20 mm/s
    against :data:`GUIDE_DAMPING`."""
    if cell.held is None:
        raise ExecutorError("a demonstration by hand-guiding needs a part in the hand")
    spec = cell.geometry.parts[cell.held]
    cell.controller.stop()
    robot = cell.robot
    before = robot.state
    centre = np.asarray(before.F_T_EE.translation) + np.array([0.0, 0.0, cell.lever(spec) - spec.length / 2])
    robot.set_load(spec.mass, centre.tolist(), list(LOAD_INERTIA))
    try:
        cell.arm.tare_sensor()
        yield
    finally:
        robot.set_load(before.m_load, np.asarray(before.F_x_Cload, dtype=float).tolist(),
                       np.asarray(before.I_load, dtype=float).flatten(order="F").tolist())


class HandGuiding:
    """A :data:`executor.skills.teach.Demonstrator` that records a person's demonstration
    on the arm (module docstring); ``prompt`` gets one line for the person before each
    demonstration and one after it; ``timeout`` [s] of robot time for each."""

    def __init__(self, prompt: Callable[[str], None], timeout: float = GUIDE_TIMEOUT) -> None:
        self.prompt, self.timeout = prompt, timeout

    def __call__(self, cell: TeachingCell, motion: Motion, origin: np.ndarray, bottom: float,
                 yaw: float) -> Demonstration:
        if not isinstance(cell, FrankaTeacher):
            raise ExecutorError("a demonstration by hand-guiding needs the Franka backend (--backend franka)")
        cell.hold_at(motion, origin + np.array([0.0, 0.0, GUIDE_HEIGHT]), tool_quat(yaw))
        start_z = float(origin[2] + DEMO_START_HEIGHT)
        with carried(cell.cell):
            self.prompt(f"guide the part into the hole ({np.round(origin, 4).tolist()} m, "
                        f"{bottom * 1000:.1f} mm deep) and hold it still at the bottom for {REST_TIME:g} s")
            rec = record_guided(cell.cell.controller, start_z, self.timeout)
        first, last = demonstration_span(rec, start_z)
        times, pos, quats = resample(rec.times[first:last + 1], rec.positions[first:last + 1],
                                     rec.quats[first:last + 1])
        force = np.linalg.norm(rec.wrenches[first:last + 1, :3], axis=1).max()
        self.prompt(f"recorded {times[-1]:.2f} s, {1000 * (pos[0, 2] - pos[-1, 2]):.1f} mm down, the largest force "
                    f"{force:.1f} N (the hand's and the contact's); let go of the part: the arm replays it in "
                    f"{LET_GO:g} s")
        time.sleep(LET_GO)
        return Demonstration(times, turn_z(pos - origin, -yaw), turn_quats_z(quats, -yaw), pos[0])
