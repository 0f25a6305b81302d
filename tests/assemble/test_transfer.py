"""A carry in free space: fast (:data:`executor.assembly.transfer.SPEED`) down from the
carrying height to :data:`executor.assembly.transfer.DESCENT_CLEARANCE` above its goal,
slowly (:data:`executor.assembly.transfer.DESCENT_SPEED`) only the rest of the way, and
at its goal at rest. From 10 mm under the carrying height to 5 mm above the clearance
(0.13 m, down to a peg's grip point on the tray) it takes 0.20 s of simulated time; all
the way at the slow speed it would take 0.50 s. Every move keeps the arm's joints within
their speed limits."""

from __future__ import annotations

from typing import Any
from unittest import mock

import numpy as np

from executor.assembly import step
from executor.assembly.grasp import Grasp
from executor.assembly.product import load_product
from executor.assembly.transfer import DESCENT_CLEARANCE, DESCENT_SPEED, SAFE_Z, carry
from executor.assembly.world import AssemblyWorld
from executor.campaign.rates import measure
from executor.cell_description import CellDescription
from executor.world.arm import LIMIT_MARGIN
from executor.world.geometry import JOINT_RATE_LIMITS
from executor.world.scene import TIME_STEP


def test_a_carry_goes_down_fast_to_its_clearance_and_slowly_the_rest() -> None:
    description = CellDescription()
    world = AssemblyWorld(load_product("spare", description), gains=description.gains)
    try:
        goal = world.tray_position("p1") + world.frames["p1"].grip  # the empty tool to a peg's grip point
        tips: list[np.ndarray] = []
        carry(world.motion, goal, lambda: tips.append(world.arm.read().tip_pos), tolerance=0.002)
        z = np.array([tip[2] for tip in tips])
        assert np.linalg.norm(tips[-1] - goal) < 0.002
        left = int(np.argmax(z < SAFE_Z - 0.01))  # leaves the carrying height
        near = int(np.argmax(z < goal[2] + DESCENT_CLEARANCE + 0.005))  # 5 mm above the clearance
        assert 0 < left < near
        assert (near - left) * TIME_STEP < 0.3, f"{(near - left) * TIME_STEP:.3f} s down to the clearance"
        below = np.flatnonzero(z < goal[2] + DESCENT_CLEARANCE - 0.005)
        down = -np.diff(z)[below[0]:] / TIME_STEP  # [m/s] in the last 25 mm
        assert down.max() < 2 * DESCENT_SPEED, f"{down.max():.3f} m/s in the last {DESCENT_CLEARANCE} m"
    finally:
        world.close()


def test_the_plate_carried_across_keeps_every_joint_within_its_speed_limit() -> None:
    """The plate's step on ``spare`` (seed 0): at the tip speed alone its move from the tray
    to the fixture turned A1 at 2.7 rad/s, its limit 1.48 rad/s; stretched where the arm's
    postures along the line ask more, no move of the step turns a joint faster than its
    limit, read from the simulated arm's joint rates after every control step. The plate
    picked with the tool unturned had A7 against its limit (the move to it took 3.1 s, the
    step 8.6 s of simulated time); picked turned by a half turn, A7 has room at the pick and
    the step takes 5.8 s, the plate at its goal."""
    picked: list[np.ndarray] = []

    def grasp(world: AssemblyWorld, part: str, *args: Any, **kwargs: Any) -> Grasp:
        picked.append(world.arm.read().q)
        return Grasp(world, part, *args, **kwargs)

    with mock.patch.object(step, "Grasp", grasp):
        recorder, records = measure("spare", [("bp", None)], 0)
    assert records[0].outcome == "fit" and records[0].pose_error < 1e-4
    limit = recorder.arm.rate_limit
    assert np.allclose(limit, np.radians(JOINT_RATE_LIMITS))  # the real arm's, from the URDF the cell loaded
    across = recorder.kinds["across"]
    assert across.moves == 2 and across.peak[0] > 0.7 * limit[0], across.peak  # A1 carries the plate across
    for kind, rates in recorder.kinds.items():
        assert np.all(rates.peak <= limit), f"{kind}: {np.round(rates.peak / limit, 2)} of the limits"
    arm = recorder.arm
    room = np.minimum(picked[0] - arm.lower, arm.upper - picked[0])
    assert room[6] > LIMIT_MARGIN, f"A7 {room[6]:.3f} rad from its limit at the pick"
    assert records[0].sim_time_s < 7.0, f"{records[0].sim_time_s:.2f} s simulated"
