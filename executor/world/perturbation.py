"""The uncertainty of a real cell (paper 3.1/3.2: "non-repeatable grasp configurations and
errors in the estimated object poses"), stated and seeded.

Every perturbation has a *systematic* part, drawn once per cell from its cell seed and
the same in every execution (what a calibration leaves behind), and a *random* part,
drawn per execution from the trial's random stream:

- lateral grasp offset of the part in the hand [m]: a habitual offset per part shape
  (≤ ``grasp_offset_bias``) plus a random one (≤ ``grasp_offset_random``);
- tilt of the part in the hand [°]: habitual per part shape (≤ ``grasp_tilt_bias``)
  plus random (≤ ``grasp_tilt_random``);
- error of the hole's estimated position (vision) [m]: a calibration bias per hole
  (≤ ``vision_bias``) plus a normal error (σ = ``vision_sigma`` per axis), the total
  at most ``vision_max``;
- error of a rect hole's estimated yaw (vision) [°], the same model: a calibration bias
  per hole (uniform, ≤ ``vision_yaw_bias``) plus a normal error (σ =
  ``vision_yaw_sigma``), the total at most ``vision_yaw_max``; drawn from streams of
  their own (the hole's, and one seeded by the attempt's search seed), so the draws of
  round and square holes are those of a cell without yaw errors;
- friction coefficient of the part in the hole: per hole, uniform in
  ``friction_min..friction_max``, plus at most ± ``friction_jitter`` per execution.

Offsets and biases are uniform over a disc (lateral) of the given radius; tilts about a
uniformly drawn horizontal axis with a uniform angle.  The robot knows none of them: the
hole search and the force adaptation (and, for the systematic part, ILC) must cope.
Magnitudes, defaults and reasons are in docs/cell.md.
"""

from __future__ import annotations

import math
import zlib
from dataclasses import dataclass, field

import msgspec
import numpy as np

from assembly_constraints.bridge.cell_settings import Magnitudes
from assembly_constraints.executor.evidence import AttemptSetup


def random_only(magnitudes: Magnitudes) -> Magnitudes:
    """The same random parts with every systematic part zero (friction: the middle of its
    range): what no learning across executions can remove."""
    mid = (magnitudes.friction_min + magnitudes.friction_max) / 2
    return msgspec.structs.replace(magnitudes, grasp_offset_bias=0.0, grasp_tilt_bias=0.0, vision_bias=0.0,
                                   vision_yaw_bias=0.0, friction_min=mid, friction_max=mid)


NO_PERTURBATION = Magnitudes(grasp_offset_bias=0.0, grasp_offset_random=0.0, grasp_tilt_bias=0.0,
                             grasp_tilt_random=0.0, vision_bias=0.0, vision_sigma=0.0, vision_max=0.0,
                             vision_yaw_bias=0.0, vision_yaw_sigma=0.0, vision_yaw_max=0.0,
                             friction_min=0.25, friction_max=0.25, friction_jitter=0.0)
"""A perfect cell: exact grasp, exact hole positions, the teaching friction (0.25)."""


def _disc(rng: np.random.Generator, radius: float) -> np.ndarray:
    """A point uniform over the disc of ``radius`` (x, y, 0)."""
    r, a = radius * np.sqrt(rng.uniform()), rng.uniform(0, 2 * np.pi)
    return np.array([r * np.cos(a), r * np.sin(a), 0.0])


def _tilt(rng: np.random.Generator, max_deg: float) -> np.ndarray:
    """A rotation vector [rad] about a uniform horizontal axis, angle uniform in 0..max."""
    axis = rng.uniform(0, 2 * np.pi)
    return np.radians(max_deg) * rng.uniform() * np.array([np.cos(axis), np.sin(axis), 0.0])


@dataclass
class CellBias:
    """The systematic part of one cell: per part shape a grasp offset [m] and tilt
    (rotation vector [rad]); per hole a vision bias [m] (x, y) and a friction coefficient,
    and per rect hole a yaw bias [rad].
    Drawn lazily, each from its own stream of (cell seed, name), so it does not depend on
    the order in which shapes and holes are first used."""

    magnitudes: Magnitudes
    seed: int
    grasp: dict[str, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict)
    holes: dict[str, tuple[np.ndarray, float]] = field(default_factory=dict)
    yaws: dict[str, float] = field(default_factory=dict)

    def _rng(self, kind: str, name: str) -> np.random.Generator:
        return np.random.default_rng([self.seed, zlib.crc32(kind.encode()), zlib.crc32(name.encode())])

    def of_shape(self, shape: str) -> tuple[np.ndarray, np.ndarray]:
        """Habitual grasp offset [m] and tilt [rad] of a part shape."""
        if shape not in self.grasp:
            rng = self._rng("grasp", shape)
            m = self.magnitudes
            self.grasp[shape] = (_disc(rng, m.grasp_offset_bias), _tilt(rng, m.grasp_tilt_bias))
        return self.grasp[shape]

    def of_hole(self, hole: str) -> tuple[np.ndarray, float]:
        """Vision bias (x, y) [m] and friction coefficient of a hole."""
        if hole not in self.holes:
            rng = self._rng("hole", hole)
            m = self.magnitudes
            self.holes[hole] = (_disc(rng, m.vision_bias)[:2], float(rng.uniform(m.friction_min, m.friction_max)))
        return self.holes[hole]

    def yaw_of_hole(self, hole: str) -> float:
        """Vision yaw bias of a rect hole [rad], uniform in ± ``vision_yaw_bias``."""
        if hole not in self.yaws:
            bias = self.magnitudes.vision_yaw_bias
            self.yaws[hole] = math.radians(float(self._rng("hole_yaw", hole).uniform(-bias, bias)))
        return self.yaws[hole]

    def draw(self, rng: np.random.Generator, shape: str, hole: str, oriented: bool = False) -> AttemptSetup:
        """One execution's circumstances: systematic + random parts (the random ones from
        ``rng``); ``oriented``: the hole's yaw is estimated too (a rect hole), with an error
        from a stream of its own (the hole's bias, then a stream of the search seed), so
        ``rng`` is drawn from the same way either way."""
        m = self.magnitudes
        offset0, tilt0 = self.of_shape(shape)
        vision0, friction0 = self.of_hole(hole)
        offset = offset0 + _disc(rng, m.grasp_offset_random)
        tilt = tilt0 + _tilt(rng, m.grasp_tilt_random)
        vision = vision0 + rng.normal(0.0, m.vision_sigma, 2)
        vision *= min(1.0, m.vision_max / max(float(np.linalg.norm(vision)), 1e-12))
        friction = max(0.0, friction0 + float(rng.uniform(-m.friction_jitter, m.friction_jitter)))
        search_seed = int(rng.integers(2**31))
        yaw = 0.0
        if oriented:
            stream = np.random.default_rng([search_seed, zlib.crc32(b"vision_yaw")])
            noise = float(stream.normal(0.0, m.vision_yaw_sigma))
            limit = math.radians(m.vision_yaw_max)
            yaw = float(np.clip(self.yaw_of_hole(hole) + math.radians(noise), -limit, limit))
        return AttemptSetup(offset, tilt, vision, search_seed, friction, yaw)
