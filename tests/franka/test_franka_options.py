"""The franka backend's options and safety checks, without an arm: each bad value named."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from executor import ExecutorError
from executor.assembly.product import load_product
from executor.franka.backend import by_hand_reason, franka_options
from executor.franka.cell import FrankaCell, part_width
from executor.franka.safety import MAX_TRANSLATIONAL_STIFFNESS, SafetyStop, Workspace, capped
from executor.world.geometry import load_geometry


def test_options_parse_into_the_cell_settings() -> None:
    options = franka_options({"host": "172.16.0.2", "offset": "0.01,-0.02,0.005",
                              "realtime": "ignore", "dynamics": "0.1", "workspace": "0.1,-0.5,0,0.8,0.5,0.6"})
    assert options.host == "172.16.0.2" and options.offset == (0.01, -0.02, 0.005)
    assert not options.realtime and options.limits.dynamics == 0.1
    assert options.workspace.low == (0.1, -0.5, 0.0) and options.workspace.high == (0.8, 0.5, 0.6)
    assert franka_options({"host": "x"}).realtime  # the real-time check is on unless switched off


@pytest.mark.parametrize(("options", "message"), [
    ({}, "needs --backend-option host=ADDRESS"),
    ({"host": "x", "speed": "1"}, "speed: unknown to the franka backend"),
    ({"host": "x", "grasp-force": "200"}, r"grasp-force=200: expected a number in \(0, 70\]"),
    ({"host": "x", "grasp-force": "firm"}, "grasp-force=firm: expected 1 comma-separated numbers"),
    ({"host": "x", "offset": "0,0"}, "offset=0,0: expected 3 comma-separated numbers"),
    ({"host": "x", "realtime": "maybe"}, "realtime=maybe: expected enforce or ignore"),
    ({"host": "x", "dynamics": "0"}, r"dynamics=0: expected a number in \(0, 1\]"),
    ({"host": "x", "force-threshold": "500"}, r"force-threshold=500: expected a number in \(0, 100\]"),
    ({"host": "x", "workspace": "1,1,1,0,0,0"}, "expected low < high on every axis"),
])
def test_a_bad_option_is_named(options: dict[str, str], message: str) -> None:
    with pytest.raises(ExecutorError, match=message):
        franka_options(options)


def test_a_pose_outside_the_workspace_is_stopped_before_it_is_sent() -> None:
    box = Workspace((0.2, -0.5, 0.0), (0.8, 0.5, 0.6))
    box.check(np.array([0.5, 0.0, 0.1]))
    with pytest.raises(SafetyStop, match=r"outside the workspace"):
        box.check(np.array([0.5, 0.0, -0.001]))


def test_the_stiff_layer_is_capped_to_what_the_arm_is_sent() -> None:
    assert capped(20000.0, 600.0) == (MAX_TRANSLATIONAL_STIFFNESS, 300.0)
    assert capped(2000.0, 60.0) == (2000.0, 60.0)


def test_the_arm_places_the_pegs_and_leaves_covers_and_heads_to_an_operator() -> None:
    product = load_product("cranfield")
    assert [part for part in product.parts if by_hand_reason(product, part) is None] == [
        "bp", "p1", "p2", "p3", "p4", "sh"]
    assert by_hand_reason(product, "sp") == "'sp' is a cover (it goes over the pegs standing in s1, s2)"
    assert by_hand_reason(product, "ph") == "'ph' is a head (it goes into the socket of pd)"


def test_the_hand_opens_to_a_ring_s_outside_not_its_bore() -> None:
    # tests/franka/data/pins: the ring's section is its bore's (d 10.8 mm), its mesh 32 mm across
    geometry = load_geometry(str(Path(__file__).parent / "data" / "pins"))
    ring, peg = geometry.parts["r1"], load_geometry(str(Path(__file__).parent / "data" / "side")).parts["p1"]
    assert max(ring.sides) == pytest.approx(0.0108, abs=1e-4)
    assert part_width(geometry, ring) == pytest.approx(0.032, abs=1e-4)
    assert part_width(geometry, peg) == pytest.approx(0.010)


def test_a_part_held_by_the_suction_cup_is_refused_by_the_franka_hand() -> None:
    # The hand has fingers only: a part the product gives the suction cup is refused before
    # the arm moves (the check is the first thing pick does; no arm is needed to reach it).
    geometry = load_geometry(str(Path(__file__).parent / "data" / "pins"))
    cupped = dataclasses.replace(geometry.parts["r1"], tool="suction")
    cell = SimpleNamespace(geometry=SimpleNamespace(parts={"r1": cupped}))
    with pytest.raises(ExecutorError, match=r"part r1 is held by the suction cup .*the Franka's hand has fingers only"):
        FrankaCell.pick(cell, "r1")  # type: ignore[arg-type]
