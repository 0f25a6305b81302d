"""Outlines the section tests share."""

from __future__ import annotations

import math

import numpy as np
import shapely


def splined(outer: float, root: float, teeth: int, tooth: float) -> shapely.Polygon:
    """A splined outline (in the unit of ``outer`` and ``root``): ``teeth`` teeth ``tooth``
    [rad] wide at radius ``outer``, the root at radius ``root``."""
    ring = []
    pitch = 2 * math.pi / teeth
    for k in range(teeth):
        start = k * pitch - tooth / 2
        ring += [(outer * math.cos(t), outer * math.sin(t)) for t in np.linspace(start, start + tooth, 6)]
        ring += [(root * math.cos(t), root * math.sin(t)) for t in np.linspace(start + tooth, start + pitch, 6)[1:-1]]
    return shapely.Polygon(ring)
