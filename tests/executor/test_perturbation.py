"""The cell's uncertainty: seeded (same seeds, same draws), bounded, systematic parts
constant per cell and random parts fresh per execution."""

from __future__ import annotations

import numpy as np
import pytest

from bridge.cell_settings import Magnitudes
from executor.trial import trial_rng
from executor.world.perturbation import CellBias, random_only

MODEL = Magnitudes()


def _draws(cell_seed: int, n: int = 50, shape: str = "round_peg", hole: str = "r1") -> list:
    bias = CellBias(MODEL, cell_seed)
    return [bias.draw(trial_rng(seed, "p1", hole), shape, hole) for seed in range(n)]


def test_same_seeds_same_draws_and_other_seeds_differ() -> None:
    a, b = _draws(3), _draws(3)
    for x, y in zip(a, b):
        assert np.array_equal(x.grasp_offset, y.grasp_offset) and np.array_equal(x.grasp_tilt, y.grasp_tilt)
        assert np.array_equal(x.vision_error, y.vision_error) and x.friction == y.friction
        assert x.search_seed == y.search_seed
    assert not np.array_equal(_draws(4)[0].grasp_tilt, a[0].grasp_tilt)  # another cell, other biases


def test_draws_stay_within_their_magnitudes() -> None:
    m = MODEL
    for setup in _draws(1, 400):
        assert np.linalg.norm(setup.grasp_offset) <= m.grasp_offset_bias + m.grasp_offset_random + 1e-12
        assert np.degrees(np.linalg.norm(setup.grasp_tilt)) <= m.grasp_tilt_bias + m.grasp_tilt_random + 1e-9
        assert setup.grasp_tilt[2] == 0.0  # a tilt about a horizontal axis
        assert np.linalg.norm(setup.vision_error) <= m.vision_max + 1e-12
        assert setup.friction is not None
        assert m.friction_min - m.friction_jitter <= setup.friction <= m.friction_max + m.friction_jitter


def test_systematic_part_is_the_same_in_every_execution_and_independent_of_use_order() -> None:
    bias = CellBias(MODEL, 7)
    tilt, offset = bias.of_shape("round_peg")[1], bias.of_shape("round_peg")[0]
    assert np.linalg.norm(tilt) > 0 and np.linalg.norm(offset) > 0
    # Many executions: the mean tilt tends to the habitual one (the random part is centred).
    tilts = np.array([s.grasp_tilt for s in _draws(7, 400)])
    assert np.linalg.norm(tilts.mean(axis=0) - tilt) < 0.25 * np.radians(MODEL.grasp_tilt_random)
    other = CellBias(MODEL, 7)
    other.of_hole("s1")  # first used in another order
    assert np.array_equal(other.of_shape("round_peg")[1], tilt)
    assert bias.of_hole("r1")[1] != bias.of_hole("s1")[1]  # each hole its own friction (and bias)


def test_random_only_has_no_systematic_part() -> None:
    bias = CellBias(random_only(MODEL), 7)
    assert not np.any(bias.of_shape("round_peg")[1]) and not np.any(bias.of_hole("r1")[0])
    assert bias.of_hole("r1")[1] == bias.of_hole("s1")[1]


def test_a_negative_magnitude_is_refused_naming_it() -> None:
    with pytest.raises(ValueError, match="grasp_tilt_bias"):
        Magnitudes(grasp_tilt_bias=-1.0)
