"""Why a plan step failed, read from a real PyBullet world (:mod:`executor.assembly.failure`):
the parts blamed for blocking a part are the ones its geometry meets, never a part fixed to it."""

from __future__ import annotations

import numpy as np
import pybullet as pb
import pytest

from executor.assembly.failure import TOUCH_DISTANCE
from executor.assembly.product import load_product
from executor.assembly.step import Assembler
from executor.cell_description import CellDescription


@pytest.mark.slow
def test_a_pendulum_on_the_front_plate_is_blocked_by_the_plate_not_by_its_own_head() -> None:
    description = CellDescription()
    assembler = Assembler(load_product("cranfield", description), description=description)
    try:
        fell = assembler.place_by_hand([("bp", None), ("p1", "r1"), ("p2", "r2"), ("p3", "s1"), ("p4", "s2"),
                                        ("sh", "br"), ("sp", None), ("ph", None), ("fp", None)])
        assert fell == []
        world, client = assembler.world, assembler.world.client
        # the pendulum (its head screwed on, on the tray) lowered over its goal onto the front
        # plate (resting without it, tilted), its head moving with it, until it touches the plate
        head_offset = world.position("ph") - world.position("pd")
        to = world.goals["pd"] + np.array([0.0, 0.0, 0.05])
        for _ in range(20):
            world.set_pose("pd", to)
            world.set_pose("ph", to + head_offset)
            gap = min(point[8] for point in pb.getClosestPoints(
                world.frames["pd"].body, world.frames["fp"].body, 1.0, physicsClientId=client))
            if gap < TOUCH_DISTANCE:
                break
            to = to - np.array([0.0, 0.0, gap - TOUCH_DISTANCE / 2])
        assert 0.0 <= gap < TOUCH_DISTANCE
        assert assembler.why_stuck("pd", None, "insert_over") == ("blocked", ("fp",))
    finally:
        assembler.close()
