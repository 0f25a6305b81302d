"""Swept collision along a straight removal path, exact (no sampled poses).

A part moving by ``length`` along ``direction`` collides with a fixed part B exactly when
some triangle of its boundary, swept along the path, meets B's interior (the sweep of a
solid is bounded by the sweeps of its boundary triangles, and the two start apart). So
the moving part is replaced by convex swept pieces: the convex hull of its start and end
poses when the part is convex, else one prism per boundary triangle (the triangle and its
translate). Each piece meets each fixed part's triangle mesh in python-fcl (GJK/EPA on
the triangles its BVH keeps); a contact deeper than :data:`TOUCH` is a collision, so
parts that only touch (a peg on its hole's bottom, a cover on its spacer) slide apart.

:attr:`Sweeper.queries` counts the narrow-phase queries (one moving piece set against one
fixed part whose bounding box meets the sweep's).
"""

from __future__ import annotations

import fcl
import numpy as np
import trimesh
from scipy.spatial import ConvexHull

TOUCH = 1e-5
"""Contacts at most this deep [m] are touching, not colliding (10 µm: below every
clearance a cell can insert with; Cranfield's tight fit is 50 µm a side)."""
DIRECTIONS: dict[str, tuple[float, float, float]] = {
    "+z": (0.0, 0.0, 1.0), "-z": (0.0, 0.0, -1.0), "+x": (1.0, 0.0, 0.0),
    "-x": (-1.0, 0.0, 0.0), "+y": (0.0, 1.0, 0.0), "-y": (0.0, -1.0, 0.0),
}
"""The removal directions tried, in order of preference (the cell inserts from above)."""


def opposite(direction: str) -> str:
    """The name of the direction opposite ``direction`` (a removal direction's insertion axis)."""
    return ("-" if direction[0] == "+" else "+") + direction[1]
_MAX_CONTACTS = 100_000


def bvh(mesh: trimesh.Trimesh) -> fcl.CollisionObject:
    """The triangles of ``mesh`` as an fcl object (its BVH)."""
    model = fcl.BVHModel()
    model.beginModel(len(mesh.vertices), len(mesh.faces))
    model.addSubModel(np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces, dtype=np.int32))
    model.endModel()
    return fcl.CollisionObject(model, fcl.Transform())


def convex_object(hull: trimesh.Trimesh) -> fcl.CollisionObject:
    """A convex mesh as an fcl convex shape (GJK/EPA against other objects)."""
    flat = np.hstack([np.full((len(hull.faces), 1), 3), hull.faces]).astype(np.int32).ravel()
    return _convex(hull.vertices, len(hull.faces), flat)


def _convex(vertices: np.ndarray, count: int, flat: np.ndarray) -> fcl.CollisionObject:
    """A convex piece of ``count`` faces given as fcl's flat list (size, indices...)."""
    return fcl.CollisionObject(fcl.Convex(np.asarray(vertices, dtype=float), count, flat), fcl.Transform())


_PRISM_FACES = np.array([3, 0, 2, 1, 3, 3, 4, 5, 4, 0, 1, 4, 3, 4, 1, 2, 5, 4, 4, 2, 0, 3, 5], dtype=np.int32)
"""A triangle (0 1 2) and its translate (3 4 5): two triangles and three quads."""


def swept_pieces(mesh: trimesh.Trimesh, shift: np.ndarray) -> list[fcl.CollisionObject]:
    """Convex pieces whose union's boundary contains the sweep of ``mesh`` by ``shift`` [m]."""
    if mesh.is_convex:
        points = np.vstack([mesh.vertices, mesh.vertices + shift])
        hull = ConvexHull(points)
        flat = np.hstack([np.full((len(hull.simplices), 1), 3), hull.simplices]).astype(np.int32).ravel()
        return [_convex(points, len(hull.simplices), flat)]
    return [_convex(np.vstack([triangle, triangle + shift]), 5, _PRISM_FACES) for triangle in mesh.triangles]


class Sweeper:
    """The fixed parts' collision meshes, and swept tests of one part against them."""

    def __init__(self, meshes: dict[str, trimesh.Trimesh]) -> None:
        self.meshes = meshes
        self._objects = {pid: bvh(mesh) for pid, mesh in meshes.items()}
        self.queries = 0
        """Narrow-phase queries made so far."""

    def blockers(self, part: str, direction: np.ndarray, length: float) -> set[str]:
        """The other parts that ``part`` collides with when moved by ``length`` [m] along
        the unit vector ``direction``, everything else fixed."""
        mesh = self.meshes[part]
        shift = np.asarray(direction, dtype=float) * length
        low = np.minimum(mesh.bounds[0], mesh.bounds[0] + shift)
        high = np.maximum(mesh.bounds[1], mesh.bounds[1] + shift)
        pieces: list[fcl.CollisionObject] | None = None
        hit: set[str] = set()
        for other, other_mesh in self.meshes.items():
            if other == part:
                continue
            if np.any(np.minimum(high, other_mesh.bounds[1]) - np.maximum(low, other_mesh.bounds[0]) <= TOUCH):
                continue
            if pieces is None:
                pieces = swept_pieces(mesh, shift)
            self.queries += 1
            if self._meets(pieces, self._objects[other]):
                hit.add(other)
        return hit

    def touching(self, a: str, b: str) -> bool:
        """Whether parts ``a`` and ``b`` are within :data:`TOUCH` of each other."""
        request = fcl.DistanceRequest()
        result = fcl.DistanceResult()
        self.queries += 1
        return bool(fcl.distance(self._objects[a], self._objects[b], request, result) <= TOUCH)

    @staticmethod
    def _meets(pieces: list[fcl.CollisionObject], fixed: fcl.CollisionObject) -> bool:
        """Whether a piece meets ``fixed`` deeper than :data:`TOUCH`: a first query without
        contacts, the contacts' depths only for the pieces that meet at all."""
        first = fcl.CollisionRequest()
        deep = fcl.CollisionRequest(num_max_contacts=_MAX_CONTACTS, enable_contact=True)
        for piece in pieces:
            if not fcl.collide(piece, fixed, first, fcl.CollisionResult()):
                continue
            result = fcl.CollisionResult()
            fcl.collide(piece, fixed, deep, result)
            if any(contact.penetration_depth > TOUCH for contact in result.contacts):
                return True
        return False
