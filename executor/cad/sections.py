"""Cross-sections of parts and holes from planar slices of their meshes.

A slice perpendicular to an insertion axis gives closed loops (trimesh's plane section).
A loop is classified as

- ``round`` when it has at least :data:`MIN_ROUND_POINTS` points, all within 2 % of one
  radius, and fills at least 98 % of that circle (a 24-gon fills 98.9 %);
- ``rect`` (``square`` when both sides agree within :data:`SQUARE_TOLERANCE`) when it fills
  its minimum-area rectangle to 99.5 %, with the long side a, the short side b and the yaw
  of a from the slice's first axis;
- ``other`` otherwise.

Sizes are what a fit depends on: a part's round section is its circumscribed circle (its
widest), a hole's its inscribed circle (its narrowest), so a polygonal hole's size is its
inradius and a tessellated cylinder's is within the tessellation's deflection. Where the
part's B-rep has a cylinder on the loop's axis (a STEP part), :func:`exact_round` takes its
diameter instead.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import trimesh
from matplotlib.path import Path as PolygonPath
from scipy.spatial import ConvexHull

from assembly_constraints.executor.cad.parts import Cylinder

MIN_ROUND_POINTS = 12
SQUARE_TOLERANCE = 1e-5
"""Sides within this [m] make a square (10 µm)."""


@dataclass(frozen=True)
class Loop:
    """A closed loop of a slice: its ``points`` (n, 2) [m] in the slice's frame."""

    points: np.ndarray

    @property
    def area(self) -> float:
        x, y = self.points[:, 0], self.points[:, 1]
        return abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))) / 2

    @property
    def centre(self) -> np.ndarray:
        """The area centroid [m] (a mean of the points would lean towards denser edges)."""
        x, y = self.points[:, 0], self.points[:, 1]
        cross = x * np.roll(y, -1) - np.roll(x, -1) * y
        signed = cross.sum() / 2
        if abs(signed) < 1e-18:
            return self.points.mean(axis=0)
        return np.array([np.sum((x + np.roll(x, -1)) * cross), np.sum((y + np.roll(y, -1)) * cross)]) / (6 * signed)

    def contains(self, point: np.ndarray) -> bool:
        return bool(PolygonPath(self.points).contains_point((float(point[0]), float(point[1]))))


@dataclass(frozen=True)
class Shape2D:
    """A classified loop: ``kind`` (round, square, rect, other), ``a`` ≥ ``b`` [m] (a round
    section: its diameter twice), ``yaw`` [°] of side a in (-90, 90] (square: (-45, 45]),
    ``centre`` (2,) [m] in the slice's frame."""

    kind: str
    a: float
    b: float
    yaw: float
    centre: np.ndarray


def frame_of(axis: np.ndarray) -> np.ndarray:
    """(2, 3): the slice's axes u, v for an insertion ``axis``; for ±z they are the cell's x
    and y (so a yaw is measured from the cell's x axis)."""
    axis = np.asarray(axis, dtype=float)
    helper = np.array([1.0, 0.0, 0.0]) if abs(axis[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = helper - np.dot(helper, axis) * axis
    u /= np.linalg.norm(u)
    return np.array([u, np.cross(axis, u) if axis[2] >= 0 else np.cross(u, axis)])


def slice_loops(mesh: trimesh.Trimesh, axis: np.ndarray, level: float) -> list[Loop]:
    """The closed loops of ``mesh`` cut by the plane ``dot(x, axis) = level`` [m]."""
    axis = np.asarray(axis, dtype=float)
    section = mesh.section(plane_origin=axis * level, plane_normal=axis)
    if section is None:
        return []
    frame = frame_of(axis)
    loops = []
    for polyline in section.discrete:
        points = np.asarray(polyline) @ frame.T
        if len(points) > 1 and np.allclose(points[0], points[-1]):
            points = points[:-1]
        if len(points) >= 3:
            loops.append(Loop(points))
    return loops


def _min_rectangle(points: np.ndarray) -> tuple[float, float, float]:
    """Sides (a ≥ b) [m] and the angle of a [rad] of the minimum-area rectangle around ``points``."""
    hull = points[ConvexHull(points).vertices] if len(points) > 3 else points
    best = (math.inf, 0.0, 0.0, 0.0)
    for i in range(len(hull)):
        edge = hull[(i + 1) % len(hull)] - hull[i]
        length = float(np.linalg.norm(edge))
        if length <= 0:
            continue
        angle = math.atan2(edge[1], edge[0])
        c, s = math.cos(angle), math.sin(angle)
        turned = hull @ np.array([[c, -s], [s, c]])
        extent = turned.max(axis=0) - turned.min(axis=0)
        if extent[0] * extent[1] < best[0]:
            best = (float(extent[0] * extent[1]), float(extent[0]), float(extent[1]), angle)
    _, w, h, angle = best
    return (w, h, angle) if w >= h else (h, w, angle + math.pi / 2)


def edge_distance(points: np.ndarray, centre: np.ndarray) -> float:
    """The smallest distance [m] from ``centre`` to the loop's edges."""
    start, end = points, np.roll(points, -1, axis=0)
    edge = end - start
    t = np.clip(np.einsum("ij,ij->i", centre - start, edge) / np.einsum("ij,ij->i", edge, edge), 0, 1)
    return float(np.min(np.linalg.norm(start + t[:, None] * edge - centre, axis=1)))


def classify(loop: Loop, *, hole: bool) -> Shape2D:
    """The loop's cross-section (the module docstring); ``hole`` picks the inscribed size."""
    points, centre = loop.points, loop.centre
    radii = np.linalg.norm(points - centre, axis=1)
    outer = float(radii.max())
    if (len(points) >= MIN_ROUND_POINTS and (outer - radii.min()) <= 0.02 * outer
            and loop.area >= 0.98 * math.pi * outer ** 2):
        d = 2 * (edge_distance(points, centre) if hole else outer)
        return Shape2D("round", d, d, 0.0, centre)
    a, b, angle = _min_rectangle(points)
    if loop.area >= 0.995 * a * b:
        square = a - b <= SQUARE_TOLERANCE
        yaw = math.degrees(angle)
        period, upper = (90.0, 45.0) if square else (180.0, 90.0)
        yaw = (yaw + period - upper) % period - (period - upper)
        if yaw <= -upper + 1e-9:
            yaw += period
        if square:
            a = b = (a + b) / 2
        return Shape2D("square" if square else "rect", a, b, round(yaw, 6), centre)
    return Shape2D("other", a, b, math.degrees(angle), centre)


ON_AXIS = 1e-6
"""A B-rep cylinder's axis within this [m] of a round loop's centre is the loop's."""


def exact_round(shape: Shape2D, cylinders: tuple[Cylinder, ...], axis: np.ndarray, level: float,
                tolerance: float) -> Shape2D:
    """``shape`` with the diameter of the B-rep cylinder it tessellates, if it is round and
    one of ``cylinders`` is parallel to ``axis``, on the loop's centre (``level`` [m] along
    the axis) and within ``tolerance`` [m] of its radius; else ``shape`` unchanged."""
    if shape.kind != "round":
        return shape
    axis = np.asarray(axis, dtype=float)
    centre = frame_of(axis).T @ shape.centre + axis * level
    for cylinder in cylinders:
        off = centre - cylinder.point
        if (abs(abs(float(cylinder.direction @ axis)) - 1.0) < 1e-9
                and np.linalg.norm(off - (off @ cylinder.direction) * cylinder.direction) < ON_AXIS
                and abs(2 * cylinder.radius - shape.a) <= 2 * tolerance):
            d = 2 * cylinder.radius
            return Shape2D("round", d, d, 0.0, shape.centre)
    return shape
