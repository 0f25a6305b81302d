"""``executor teach`` reproducibility: teaching again gives the stored demonstration
within the bounds of ``tests/_tolerances.py`` (never bit for bit: the stored files come
from another process, maybe another CPU), and the stored skills give the documented outcomes
and stay within the thresholds on this machine."""

from __future__ import annotations

import numpy as np
import pytest

from assembly_constraints.executor.skills.dmp import Skill, load_skill
from assembly_constraints.executor.skills.teach import teach_shape
from assembly_constraints.executor.trial import Cell, CellSetup
from tests._tolerances import END_BOUND, FORCE_BOUND, PATH_BOUND, TORQUE_BOUND

SHAPES = ("round_peg", "square_peg", "shaft", "tight_peg")


def _path(skill: Skill) -> tuple[np.ndarray, np.ndarray]:
    """The skill's DMP rolled out from its own demonstration start to goal: positions [m]
    and quaternions (xyzw) over time."""
    start, goal = skill.demo_start, skill.demo_goal
    _, pos, quat = skill.rollout(start[:3], np.roll(start[3:], -1), goal[:3], np.roll(goal[3:], -1))
    return pos, quat


@pytest.fixture(scope="module")
def cell():
    c = Cell(setup=CellSetup(layer="pi_phase_stop"))
    yield c
    c.close()


@pytest.mark.slow
@pytest.mark.parametrize("shape", SHAPES)
def test_teaching_reproduces_the_stored_demonstration(cell: Cell, shape: str) -> None:
    taught = teach_shape(cell, shape)
    stored = load_skill(cell.geometry.folder, shape)
    assert taught.shape == stored.shape
    assert abs(taught.execution_time - stored.execution_time) < 1e-9  # [s]: a count of 1 ms time steps
    (taught_pos, taught_quat), (stored_pos, stored_quat) = _path(taught), _path(stored)
    assert np.max(np.abs(taught_pos - stored_pos)) < PATH_BOUND
    # A quaternion difference of q is a rotation of about 2q [rad]; over a 30 mm peg the
    # tip moves 0.06 q [m]: the same tenth of the 0.1 mm clearance.
    assert np.max(np.abs(taught_quat - stored_quat)) < PATH_BOUND / 0.06
    assert np.max(np.abs(taught.end_position - stored.end_position)) < END_BOUND
    wrench = np.abs(taught.wrench.weights - stored.wrench.weights)
    assert np.max(wrench[:, :3]) < FORCE_BOUND and np.max(wrench[:, 3:]) < TORQUE_BOUND


@pytest.mark.slow
@pytest.mark.parametrize("shape", SHAPES)
def test_the_stored_skill_fits_its_demonstration_hole_within_the_thresholds(cell: Cell, shape: str) -> None:
    """What teaching must guarantee on any machine: each stored skill, executed in the hole
    it was taught in, is a fit at the first attempt, below F_stop, M_stop and the goal
    tolerance, with the margins the thresholds were chosen for."""
    part = next(p for p in sorted(cell.geometry.parts.values(), key=lambda p: p.id) if p.shape == shape)
    result = cell.run_trial(part.id, part.demo_hole, seed=0)
    assert result.outcome == "fit" and result.attempts == 1, result.to_json()
    evidence = result.evidence[0]
    th = cell.thresholds
    assert evidence.max_force_dev < th.f_stop - FORCE_BOUND
    assert evidence.max_torque_dev < th.m_stop - TORQUE_BOUND
    assert evidence.end_error < th.goal_tolerance - END_BOUND
