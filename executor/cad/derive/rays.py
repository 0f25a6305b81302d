"""Rays cast at a part's mesh: how far to its first triangle (:func:`first_hit`), and
whether that triangle faces the ray (:func:`roofed`: the ray enters the solid there)."""

from __future__ import annotations

import numpy as np
import trimesh


def first_hit(mesh: trimesh.Trimesh, origin: np.ndarray, direction: np.ndarray) -> float | None:
    """Distance [m] along the unit ``direction`` from ``origin`` to the first triangle of
    ``mesh`` (Möller-Trumbore over all triangles), None when the ray meets none."""
    t, _ = _hits(mesh, origin, direction)
    return float(t.min()) if len(t) else None


def roofed(mesh: trimesh.Trimesh, origin: np.ndarray, direction: np.ndarray) -> bool:
    """Whether the first triangle of ``mesh`` the ray from ``origin`` along the unit
    ``direction`` meets faces it (its outward normal against the ray): the ray goes into
    the solid there, as up a pocket cut into a base's underside to its ceiling."""
    t, facing = _hits(mesh, origin, direction)
    return bool(len(t)) and bool(facing[np.argmin(t)])


def _hits(mesh: trimesh.Trimesh, origin: np.ndarray, direction: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The distances [m] along the unit ``direction`` from ``origin`` at which the ray
    meets triangles of ``mesh`` (Möller-Trumbore over all triangles), and whether each
    triangle met faces the ray."""
    a, b, c = (mesh.triangles[:, k] for k in range(3))
    e1, e2 = b - a, c - a
    p = np.cross(direction, e2)
    det = np.einsum("ij,ij->i", e1, p)
    ok = np.abs(det) > 1e-15
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    t_vec = origin - a
    u = np.einsum("ij,ij->i", t_vec, p) * inv
    q = np.cross(t_vec, e1)
    v = (q @ direction) * inv
    t = np.einsum("ij,ij->i", e2, q) * inv
    hit = ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 1e-9)
    return t[hit], det[hit] > 0  # det = -direction . (e1 x e2)
