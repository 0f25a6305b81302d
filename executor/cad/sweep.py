"""Swept collision along a straight removal path, exact (no sampled poses), with nominal
zero-clearance fits sliding along their axis (the fits: :mod:`executor.cad.fits.faces`,
:mod:`executor.cad.fits.threads`).

**Exact sweep.** A body (one part, or parts fixed to each other) moving by ``length``
along ``direction`` collides with a fixed part B exactly when some triangle of its
boundary, swept along the path, meets B's interior (the sweep of a solid is bounded by
the sweeps of its boundary triangles, and the two start apart). Each swept triangle is a
convex prism (the triangle and its translate) tested against B's triangle BVH in
python-fcl (GJK/EPA); a contact deeper than :data:`executor.cad.fits.faces.TOUCH` is a
collision, so parts that only touch (a peg on its hole's bottom, a cover on its spacer)
slide apart.

**Conservative first.** Penetration depth only grows with the moving set, so a convex
superset that meets B no deeper than :data:`executor.cad.fits.faces.TOUCH` clears every
prism inside it: first the sweep of the part's convex hull (one query: the answer for a convex part), then down a
tree of the part's triangles (halves of nearby ones): a node whose swept box misses B's
box, or meets no cell of B's grid that B's triangles' boxes meet (:meth:`_Triangles.meets`:
no contact is found in it), or whose swept hull clears B, is done; the prisms are tested only in leaves of
:data:`CHUNK` triangles that still meet B. The tree is searched depth first, the half
holding more of the few triangles that lead the sweep into B's box (:func:`_front`)
first: where the part is blocked, they usually meet B deeply, so the search ends soon;
the order changes no answer. Same answer as testing every prism. A piece that meets B is
decided by fcl's depths of B's triangles, the likeliest deep ones first (:func:`_meets`).

:attr:`Sweeper.queries` counts the narrow-phase queries (one moving part against one fixed
part whose bounding box meets the sweep's); a test asked again (A moved against B, then B
moved back against A along the same path) is answered from the first, and so is one that
a sweep of the same pair along the same direction entails (a longer one free frees a
shorter, a shorter one colliding blocks a longer: the locating rule's short sweeps after
the long ones out). The tests asked together (:meth:`Sweeper.blocked`) run in
:attr:`Sweeper.workers` processes forked from this one, each the same test on a copy of
the same parts (the fixed parts' BVHs made before the fork, so not once per worker): the
answers and their count are those of one process.
"""

from __future__ import annotations

import multiprocessing
import multiprocessing.pool
import os
import weakref
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import NamedTuple, TypeVar, cast

import fcl
import numpy as np
import trimesh
from scipy.spatial import ConvexHull, HalfspaceIntersection, QhullError

from bridge.cli_types import forked_worker
from executor import ExecutorError
from executor.cad.fits.faces import TOUCH, CylinderFace, PrismFace, Slide, fit_faces, slid

DIRECTIONS: dict[str, tuple[float, float, float]] = {
    "+z": (0.0, 0.0, 1.0), "-z": (0.0, 0.0, -1.0), "+x": (1.0, 0.0, 0.0),
    "-x": (-1.0, 0.0, 0.0), "+y": (0.0, 1.0, 0.0), "-y": (0.0, -1.0, 0.0),
}
"""The removal directions tried, in order of preference (the cell inserts from above)."""
CHUNK = 8
"""Triangles of a leaf of the conservative test's tree (nearby ones: median splits of their centres)."""
HULL_POINTS = 96
"""Sets of more points are not hulled for the conservative test (fcl's cost grows with them):
their halves are."""
FRONT = 16
"""Leading triangles whose part of the tree is searched first (:func:`_front`)."""
HULL_SAMPLE = 1000
"""Vertices of the sample whose hull shows a large part not convex (:func:`_is_convex`)."""
_FLAT = 1e-12
"""Adjacent triangles whose vertices lie at most this fraction of the mesh's size beyond
each other's planes meet flat or convex (rounding: 1e-16)."""
_MAX_CONTACTS = 100_000
_FEW_CONTACTS = 8
LIKELY = 64
"""Triangles of a fixed part tested first against a piece (:func:`_meets`)."""


def opposite(direction: str) -> str:
    """The name of the direction opposite ``direction`` (a removal direction's insertion axis)."""
    return ("-" if direction[0] == "+" else "+") + direction[1:]


def axis_name(vector: np.ndarray) -> str:
    """A direction's name: ``+x`` ... for the axes of :data:`DIRECTIONS`, else
    ``+(x,y,z)`` with the unit vector's components (the sign of its first nonzero one)."""
    for name, known in DIRECTIONS.items():
        if np.dot(vector, known) > 1 - 1e-9:
            return name
    first = vector[np.flatnonzero(np.abs(vector) > 1e-9)[0]]
    unit = vector if first > 0 else -vector
    return ("+" if first > 0 else "-") + "(" + ",".join(f"{c:.4f}" for c in unit) + ")"


def bvh(mesh: trimesh.Trimesh) -> fcl.CollisionObject:
    """The triangles of ``mesh`` as an fcl object (its BVH)."""
    return _bvh(np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces, dtype=np.int32))


def _bvh(vertices: np.ndarray, faces: np.ndarray) -> fcl.CollisionObject:
    """The triangles ``faces`` (int32 indices into ``vertices`` [m]) as an fcl object."""
    model = fcl.BVHModel()
    model.beginModel(len(vertices), len(faces))
    model.addSubModel(vertices, faces)
    model.endModel()
    return fcl.CollisionObject(model, fcl.Transform())


def convex_object(hull: trimesh.Trimesh) -> fcl.CollisionObject:
    """A convex mesh as an fcl convex shape (GJK/EPA against other objects)."""
    flat = np.hstack([np.full((len(hull.faces), 1), 3), hull.faces]).astype(np.int32).ravel()
    return _convex(hull.vertices, len(hull.faces), flat)


def _convex(vertices: np.ndarray, count: int, flat: np.ndarray) -> fcl.CollisionObject:
    """A convex piece of ``count`` faces given as fcl's flat list (size, indices...)."""
    return fcl.CollisionObject(fcl.Convex(np.asarray(vertices, dtype=float), count, flat), fcl.Transform())


class _Piece:
    """A convex piece swept against a fixed part: its ``points`` [m] (the hull's vertices)
    and its fcl shape (made on first use)."""

    def __init__(self, points: np.ndarray, faces: tuple[int, np.ndarray]) -> None:
        """``faces``: their count and fcl's flat list of them (size, indices ...)."""
        self.points = points
        self._faces = faces
        self._object: fcl.CollisionObject | None = None

    @property
    def object(self) -> fcl.CollisionObject:
        if self._object is None:
            self._object = _convex(self.points, *self._faces)
        return self._object


def _hull_piece(points: np.ndarray) -> _Piece | None:
    """The convex hull of ``points`` [m] (its vertices only); None when the points span no
    volume (the caller then tests the prisms)."""
    try:
        hull = ConvexHull(points)
    except QhullError:
        return None
    used, faces = np.unique(hull.simplices, return_inverse=True)
    flat = np.hstack([np.full((len(hull.simplices), 1), 3), faces.reshape(-1, 3)]).astype(np.int32).ravel()
    return _Piece(points[used], (len(hull.simplices), flat))


_PRISM_FACES = np.array([3, 0, 2, 1, 3, 3, 4, 5, 4, 0, 1, 4, 3, 4, 1, 2, 5, 4, 4, 2, 0, 3, 5], dtype=np.int32)
"""A triangle (0 1 2) and its translate (3 4 5): two triangles and three quads."""


def swept_pieces(triangles: np.ndarray, shift: np.ndarray) -> list[_Piece]:
    """The prisms of ``triangles`` (n, 3, 3) [m] swept by ``shift`` [m]."""
    return [_Piece(np.vstack([triangle, triangle + shift]), (5, _PRISM_FACES)) for triangle in triangles]


GRID = 128
"""Cells of the fixed part's grid along its longest side (:meth:`_Triangles.meets`)."""
BLOCK = 64
"""Triangles of a block of the fixed part's index (:class:`_Triangles`)."""


class _Triangles:
    """A fixed part's triangles: their ``corners`` (n, 3, 3) [m], ``centres``, boxes and blocks of
    :data:`BLOCK` nearby ones (in the order of their centres' Morton codes) with their
    boxes, to find those near a piece (:func:`_likely`), and a grid of the cells their
    boxes meet, to find that none is near a box (:func:`_collides`)."""

    def __init__(self, corners: np.ndarray, low: np.ndarray, high: np.ndarray, centres: np.ndarray) -> None:
        """``low``, ``high``, ``centres``: the triangles' lowest and highest corners and
        their centres [m] (:attr:`_Solid.extents`)."""
        self.corners = corners
        self.low, self.high, self.centres = low, high, centres
        cells = ((centres - centres.min(axis=0)) / max(float(np.ptp(centres)), 1e-12) * 1023).astype(np.int64)
        code = np.zeros(len(corners), dtype=np.int64)
        for bit in range(10):
            for axis in range(3):
                code |= ((cells[:, axis] >> bit) & 1) << (3 * bit + axis)
        order = np.argsort(code, kind="stable")
        self.blocks = np.concatenate([order, np.full(-len(order) % BLOCK, -1)]).reshape(-1, BLOCK)
        """Triangle indices, the last block's padded with -1."""
        low, high = np.vstack([self.low, np.full(3, np.inf)]), np.vstack([self.high, np.full(3, -np.inf)])
        self.block_low, self.block_high = low[self.blocks].min(axis=1), high[self.blocks].max(axis=1)
        self.origin = self.low.min(axis=0)
        self.cell = max(float(np.max(self.high.max(axis=0) - self.origin)) / GRID, 1e-12)
        """The grid's corner and its cells' side [m]."""
        first = np.floor((self.low - self.origin) / self.cell).astype(int)
        last = np.floor((self.high - self.origin) / self.cell).astype(int)
        starts = np.zeros(last.max(axis=0) + 2, dtype=np.int64)  # +1, -1 at a box's corners: summed, its cells
        for corner in np.ndindex(2, 2, 2):
            np.add.at(starts, tuple(np.where(corner, last + 1, first).T), (-1) ** sum(corner))
        occupied = starts.cumsum(axis=0).cumsum(axis=1).cumsum(axis=2)[:-1, :-1, :-1] > 0
        self.grid = np.zeros(np.array(occupied.shape) + 1, dtype=np.int32)
        """The summed-volume table of the cells that a triangle's box meets: the count of
        those with indices below (i, j, k) at [i, j, k]."""
        self.grid[1:, 1:, 1:] = occupied.cumsum(axis=0).cumsum(axis=1).cumsum(axis=2)

    def near(self, low: np.ndarray, high: np.ndarray) -> np.ndarray:
        """The triangles whose boxes meet the box ``low``, ``high`` [m]."""
        blocks = np.all(np.minimum(high, self.block_high) >= np.maximum(low, self.block_low), axis=1)
        found = self.blocks[blocks].ravel()
        found = found[found >= 0]
        return found[np.all(np.minimum(high, self.high[found]) >= np.maximum(low, self.low[found]), axis=1)]

    def meets(self, low: np.ndarray, high: np.ndarray) -> bool:
        """Whether the box ``low``, ``high`` [m] meets a cell of :attr:`grid` that a
        triangle's box meets (False: it meets no triangle's box; cells are compared by
        their indices, which rounding keeps in order)."""
        first = np.floor((low - self.origin) / self.cell)
        last = np.floor((high - self.origin) / self.cell)
        shape = np.array(self.grid.shape) - 1
        if np.any(last < 0) or np.any(first >= shape):
            return False
        a, b = np.maximum(first, 0).astype(int), np.minimum(last, shape - 1).astype(int) + 1
        ends = (b, a)  # the cells below b less those below a on some axis: inclusion-exclusion
        inside = sum((-1) ** sum(c) * int(self.grid[ends[c[0]][0], ends[c[1]][1], ends[c[2]][2]])
                     for c in np.ndindex(2, 2, 2))
        return inside > 0


@dataclass(frozen=True)
class _Arrays:
    """A mesh's ``vertices`` [m], ``faces`` and triangle ``centres`` [m], as plain arrays
    (trimesh checks its cache by hashing the mesh on each use)."""

    vertices: np.ndarray
    faces: np.ndarray
    centres: np.ndarray


class _Node:
    """Nearby triangles of a mesh (``faces``), their ``points`` [m] and their bounds, and
    the two halves they split into (none: at most :data:`CHUNK` triangles); each made on
    first use, as most nodes lie in no sweep's way."""

    def __init__(self, mesh: _Arrays, faces: np.ndarray) -> None:
        self.mesh = mesh
        self.faces = faces
        self._points: np.ndarray | None = None
        self._children: list[_Node] | None = None
        self.low: np.ndarray
        self.high: np.ndarray
        """The bounds of ``points`` [m] (set with them)."""

    @property
    def points(self) -> np.ndarray:
        if self._points is None:
            self._points = self.mesh.vertices[np.unique(self.mesh.faces[self.faces])]
            self.low, self.high = self._points.min(axis=0), self._points.max(axis=0)
        return self._points

    @property
    def children(self) -> list[_Node]:
        """The halves: split at the median of the triangles' centres along their widest extent."""
        if self._children is None:
            self._children = []
            if len(self.faces) > CHUNK:
                centres = self.mesh.centres[self.faces]
                order = self.faces[np.argsort(centres[:, int(np.argmax(np.ptp(centres, axis=0)))], kind="stable")]
                self._children = [_Node(self.mesh, order[:len(order) // 2]), _Node(self.mesh, order[len(order) // 2:])]
        return self._children


def _is_convex(mesh: trimesh.Trimesh) -> bool:
    """Whether the closed ``mesh`` is convex: no concave edge (trimesh's test, whose
    tolerance passes the fine facets of a bore) and its hull's volume its own (within
    1e-6). Decided without the hull where that is certain (qhull takes seconds on the
    thousands of co-circular points of a finely tessellated cylinder): no edge concave by
    more than :data:`_FLAT` of the mesh's size (a closed surface convex at every edge is
    convex), or the hull of :data:`HULL_SAMPLE` of its vertices (a fixed random choice)
    already too large (it lies inside the hull)."""
    if not mesh.is_convex:
        return False
    if np.max(mesh.face_adjacency_projections) <= _FLAT * mesh.scale:
        return True
    volume = abs(mesh.volume)
    vertices = np.asarray(mesh.vertices, dtype=float)
    if len(vertices) > HULL_SAMPLE:
        sample = vertices[np.random.default_rng(0).choice(len(vertices), HULL_SAMPLE, replace=False)]
        try:
            if ConvexHull(sample).volume * (1 - 1e-6) > volume:
                return False
        except QhullError:
            pass  # a flat sample: the whole hull decides
    return bool(ConvexHull(vertices).volume * (1 - 1e-6) <= volume)


def _outer_hull(points: np.ndarray) -> tuple[np.ndarray, bool]:
    """The vertices of the convex hull of ``points`` [m] when it has at most
    :data:`HULL_POINTS` (tried for at most four times as many points), else of a polytope
    around it of fewer (its supporting planes along the 26 directions of a cube's faces,
    edges and corners and, around each axis of the frame, as many as keep a cylinder about
    that axis within :data:`executor.cad.fits.faces.TOUCH` / 2), and whether it is the hull itself."""
    hull = points
    if len(points) <= 4 * HULL_POINTS:
        hull = points[ConvexHull(points).vertices]
        if len(hull) <= HULL_POINTS:
            return hull, True
    centre = hull.mean(axis=0)
    cube = np.array([v for v in np.ndindex(3, 3, 3) if v != (1, 1, 1)], dtype=float) - 1
    normals = [cube / np.linalg.norm(cube, axis=1)[:, None]]
    for axis in range(3):
        across = np.delete(hull - centre, axis, axis=1)
        radius = float(np.max(np.linalg.norm(across, axis=1)))
        count = min(256, int(np.ceil(np.pi / np.arccos(radius / (radius + TOUCH / 2)))))
        turn = np.linspace(0, 2 * np.pi, count, endpoint=False)
        ring = np.zeros((count, 3))
        ring[:, [k for k in range(3) if k != axis]] = np.column_stack([np.cos(turn), np.sin(turn)])
        normals.append(ring)
    planes = np.vstack(normals)
    offsets = np.max((hull - centre) @ planes.T, axis=0)
    corners = HalfspaceIntersection(np.column_stack([planes, -offsets]), np.zeros(3)).intersections
    return corners + centre, False


class Survey(NamedTuple):
    r"""What the sweeps and the fits need of one closed part, made once: its ``faces``
    (:func:`executor.cad.fits.faces.fit_faces`), the vertices [m] of its ``hull`` (:func:`_outer_hull`: a convex
    superset), whether that is ``exact``\ ly the hull, and whether the part is ``convex``
    (:func:`_is_convex`)."""

    faces: list[CylinderFace | PrismFace]
    hull: np.ndarray
    exact: bool
    convex: bool


def _survey(mesh: trimesh.Trimesh) -> Survey:
    """:class:`Survey` of the closed ``mesh``."""
    return Survey(fit_faces(mesh), *_outer_hull(np.asarray(mesh.vertices, dtype=float)), _is_convex(mesh))


def surveys(meshes: dict[str, trimesh.Trimesh]) -> dict[str, Survey]:
    """:class:`Survey` of each closed mesh, in :func:`processes` of them (:func:`forked_map`),
    the largest parts first: each part's made alone from its mesh and handed back whole."""
    found = forked_map(lambda pid: _survey(meshes[pid]), list(meshes), processes(meshes.values()),
                       cost=lambda pid: len(meshes[pid].faces))
    return dict(zip(meshes, found))


_Item = TypeVar("_Item")
_Result = TypeVar("_Result")


def forked_map(function: Callable[[_Item], _Result], items: Sequence[_Item], workers: int,
               cost: Callable[[_Item], float] | None = None) -> list[_Result]:
    """``function`` of each of ``items``, in their order: in ``workers`` processes forked now
    (each a copy of this one: ``function``, the items and what it reads need no pickling,
    its results do) where there are more than one and more than one item, else here. The items
    are handed out the costliest first (``cost``; None: in order), each to the next free
    worker. An :class:`executor.ExecutorError` of an item is raised here, that of the first
    item in order of those that raised one, as one process raises it."""
    if workers < 2 or len(items) < 2:
        return [function(item) for item in items]
    order = sorted(range(len(items)), key=lambda k: -cost(items[k])) if cost is not None else list(range(len(items)))
    global _MAPPED
    _MAPPED = lambda k: function(items[k])  # noqa: E731  (the workers' copy, forked now)
    pool = multiprocessing.get_context("fork").Pool(min(workers, len(items)), initializer=forked_worker)
    _MAPPED = None
    try:
        answers = pool.map(_mapped, order, chunksize=1)
        pool.close()  # the workers end on their own once the tasks are done
    except BaseException:
        pool.terminate()
        raise
    finally:
        pool.join()  # reaped: their CPU is this process's children's
    found: list[tuple[bool, object]] = [(True, None)] * len(items)
    for k, answer in zip(order, answers):
        found[k] = answer
    for done, value in found:
        if not done:
            raise cast(ExecutorError, value)
    return [cast(_Result, value) for _, value in found]


_MAPPED: Callable[[int], object] | None = None
"""The function of an item's index that :func:`forked_map` is forking workers for: a
worker's copy of it answers :func:`_mapped`."""


def _mapped(index: int) -> tuple[bool, object]:
    """In a worker forked by :func:`forked_map`: (True, the function of item ``index``), or
    (False, its :class:`executor.ExecutorError`), handed back to be raised in order."""
    assert _MAPPED is not None, "a worker forked without its function"
    try:
        return True, _MAPPED(index)
    except ExecutorError as error:
        return False, error


class _Solid:
    """One part's mesh for the sweeps: its BVH, hull vertices and triangle tree (made on first use)."""

    def __init__(self, mesh: trimesh.Trimesh, convex: bool | None = None, survey: Survey | None = None) -> None:
        """``convex``: whether the part is (None: ``mesh`` is the closed part, tested);
        ``survey``: the closed part's, made already (None: made here)."""
        self.mesh = mesh
        self._bvh: fcl.CollisionObject | None = None
        self._tree: _Node | None = None
        self.pieces: dict[tuple[float, ...], dict[int, _Piece | None]] = {}
        """Shift -> tree node (its id; -1: the whole part) -> its swept hull, kept for the other parts' tests."""
        self._hull = None if survey is None else (survey.hull, survey.exact)
        self.convex = survey.convex if survey is not None else _is_convex(mesh) if convex is None else convex
        self.bounds = np.array(mesh.bounds)
        """The mesh's box [m] (a copy: trimesh checks its cache by hashing the mesh on each use)."""
        self.triangles = np.array(mesh.triangles)
        """(n, 3, 3): the triangles' corners [m]."""
        self._extents: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
        self._leading: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None = None
        self._index: _Triangles | None = None

    @property
    def hull(self) -> np.ndarray:
        """A convex superset's vertices [m] (:func:`_outer_hull`; of a part slid at its fits,
        made where it is first swept, or before the sweeps' workers fork: :meth:`Sweeper._prepare`)."""
        if self._hull is None:
            self._hull = _outer_hull(np.asarray(self.mesh.vertices, dtype=float))
        return self._hull[0]

    @property
    def exact(self) -> bool:
        """Whether :attr:`hull` is the hull itself."""
        _ = self.hull
        assert self._hull is not None
        return self._hull[1]

    @property
    def bvh(self) -> fcl.CollisionObject:
        if self._bvh is None:
            self._bvh = bvh(self.mesh)
        return self._bvh

    @property
    def index(self) -> _Triangles:
        """The triangles, to find those near a piece (:func:`_likely`)."""
        if self._index is None:
            self._index = _Triangles(self.triangles, *self.extents)
        return self._index

    @property
    def extents(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The triangles' lowest and highest corners and their centres [m], made once for
        :attr:`leading` and :attr:`index` (the least and most of three corners compared
        pairwise: a reduction over an axis of three is several times slower)."""
        if self._extents is None:
            first, second, third = self.triangles[:, 0], self.triangles[:, 1], self.triangles[:, 2]
            self._extents = (np.minimum(np.minimum(first, second), third), np.maximum(np.maximum(first, second), third),
                             self.triangles.mean(axis=1))
        return self._extents

    @property
    def leading(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The triangles' lowest and highest corners, normals and centres [m] (:func:`_front`)."""
        if self._leading is None:
            low, high, centres = self.extents
            self._leading = (low, high, np.array(self.mesh.face_normals), centres)
        return self._leading

    @property
    def tree(self) -> _Node:
        if self._tree is None:
            arrays = _Arrays(np.array(self.mesh.vertices), np.array(self.mesh.faces), self.leading[3])
            self._tree = _Node(arrays, np.arange(len(arrays.faces)))
        return self._tree


PARALLEL_TRIANGLES = 100_000
"""Parts of fewer triangles together are swept in one process (:func:`default_workers`)."""
WORKERS: int | None = None
"""The processes every :class:`Sweeper` runs its queries in, and the import's work part by
part (:func:`processes`) (None: :func:`default_workers`; ``bench import --workers`` sets it)."""


def processes(meshes: Iterable[trimesh.Trimesh]) -> int:
    """The processes the import's work on ``meshes`` runs in: :data:`WORKERS`, else
    :func:`default_workers`."""
    return WORKERS or default_workers(meshes)


def default_workers(meshes: Iterable[trimesh.Trimesh]) -> int:
    """The processes to sweep ``meshes`` in: the cores this process may use, at most two,
    where the meshes have :data:`PARALLEL_TRIANGLES` triangles or more (below, forking costs
    about what it saves); else one."""
    if sum(len(mesh.faces) for mesh in meshes) < PARALLEL_TRIANGLES:
        return 1
    return min(2, len(os.sched_getaffinity(0)))


class Sweeper:
    """The parts' collision meshes, and swept tests of one body against the others;
    ``slides`` the zero-clearance fits among them."""

    def __init__(self, meshes: dict[str, trimesh.Trimesh], slides: Iterable[Slide] = (),
                 workers: int | None = None, made: dict[str, Survey] | None = None) -> None:
        """``workers``: the processes the queries run in (None: :data:`WORKERS`, else
        :func:`default_workers` of the meshes); ``made``: the parts' :func:`surveys`
        where made already."""
        self.meshes = meshes
        self.workers = workers or processes(meshes.values())
        self._pool: multiprocessing.pool.Pool | None = None
        self._ended: weakref.finalize | None = None
        self._solids = {pid: _Solid(mesh, survey=(made or {}).get(pid)) for pid, mesh in meshes.items()}
        self._slides: dict[tuple[str, str], list[Slide]] = {}
        for slide in slides:
            self._slides.setdefault((slide.shaft, slide.bore), []).append(slide)
        self._slid: dict[tuple[str, str, str], _Solid] = {}
        self.queries = 0
        """Narrow-phase queries made so far."""
        self._along: dict[tuple[int, int, tuple[float, ...]], list[tuple[float, bool]]] = {}
        """(moving solid, fixed solid (their ids), unit direction) -> (length [m], whether the
        sweep collides) of each query made: what they entail (:meth:`_entailed`)."""
        self._answers: dict[tuple[int, int, tuple[float, ...]], bool] = {}
        """(moving solid, fixed solid (their ids), shift [m]) -> whether the sweep collides:
        A moved against B and B moved back against A are one test."""

    def add(self, slides: Iterable[Slide]) -> None:
        """Take ``slides`` too (screwed pairs found once the disassembly stopped): the
        sweeps of their pairs along their axes are asked anew (their slid solids are new);
        the workers, forked with the slides as they were, end here (a later query forks them
        anew)."""
        self.close()
        for slide in slides:
            self._slides.setdefault((slide.shaft, slide.bore), []).append(slide)

    def blockers(self, body: str | Iterable[str], direction: np.ndarray, length: float) -> set[str]:
        """The other parts that the part (or the parts, moved together) ``body`` collides
        with when moved by ``length`` [m] along the unit vector ``direction``, everything
        else fixed."""
        return self.blocked([(body, direction, length)])[0]

    def blocked(self, requests: Sequence[tuple[str | Iterable[str], np.ndarray, float]]) -> list[set[str]]:
        """:meth:`blockers` of each request (body, direction, length), their queries made
        together: a body's members one after the other (a part one member hits is not
        tested again for the next), the queries of every request's member of one rank at
        once, in :attr:`workers` processes."""
        bodies = [sorted({body} if isinstance(body, str) else set(body)) for body, _, _ in requests]
        units = [np.asarray(direction, dtype=float) for _, direction, _ in requests]
        shifts = [unit * length for unit, (_, _, length) in zip(units, requests)]
        hits: list[set[str]] = [set() for _ in requests]
        for rank in range(max(map(len, bodies), default=0)):
            tests: list[tuple[int, str, str]] = []  # (request, member, other)
            for k, members in enumerate(bodies):
                if rank >= len(members):
                    continue
                member, shift = members[rank], shifts[k]
                bounds = self._solids[member].bounds
                low = np.minimum(bounds[0], bounds[0] + shift)
                high = np.maximum(bounds[1], bounds[1] + shift)
                for other, solid in self._solids.items():
                    if other in members or other in hits[k]:
                        continue
                    if np.any(np.minimum(high, solid.bounds[1]) - np.maximum(low, solid.bounds[0]) <= TOUCH):
                        continue
                    tests.append((k, member, other))
            answers = self._sweeps([(member, other, units[k], float(requests[k][2])) for k, member, other in tests])
            for (k, _, other), collides in zip(tests, answers):
                if collides:
                    hits[k].add(other)
        return hits

    def _sweeps(self, tests: list[tuple[str, str, np.ndarray, float]]) -> list[bool]:
        """Whether part ``member`` moved by ``length`` [m] along the unit vector
        ``direction`` collides with part ``other``, for each test (member, other,
        direction, length): one narrow-phase query each unless asked before or entailed by
        a sweep of the pair along the same direction answered before (:meth:`_entailed`),
        the new ones in :attr:`workers` processes when there are several."""
        keys = []
        pending: dict[tuple[int, int, tuple[float, ...]], tuple[str, str, np.ndarray]] = {}
        size: dict[tuple[int, int, tuple[float, ...]], int] = {}
        ways: dict[tuple[int, int, tuple[float, ...]], tuple[tuple[int, int, tuple[float, ...]], float]] = {}
        for member, other, direction, length in tests:
            shift = direction * length
            moving, fixed, relative = self._oriented(member, other, shift)
            key = (id(moving), id(fixed), tuple(relative))
            keys.append(key)
            way = (id(moving), id(fixed), tuple(direction if relative is shift else -direction))
            ways[key] = (way, length)
            if key in self._answers or key in pending:
                continue
            entailed = self._entailed(way, length)
            if entailed is not None:
                self._answers[key] = entailed
                continue
            pending[key] = (member, other, shift)
            size[key] = len(moving.triangles) + len(fixed.triangles)
        self.queries += len(pending)
        if self.workers > 1 and len(pending) > 1:
            pending = {key: pending[key] for key in sorted(pending, key=lambda k: -size[k])}  # the larger first
            if self._pool is None:
                self._prepare(pending.values())
                global _FORKED
                _FORKED = self  # the workers' copy, forked now
                self._pool = multiprocessing.get_context("fork").Pool(self.workers, initializer=forked_worker)
                _FORKED = None
                # the workers end (and are reaped) with the sweeper, or at close
                self._ended = weakref.finalize(self, self._pool.terminate)
            self._answers.update(zip(pending, self._pool.map(_swept, pending.values(), chunksize=1)))
        else:
            self._answers.update((key, _collides(*self._oriented(*test))) for key, test in pending.items())
        for key in pending:
            way, length = ways[key]
            self._along.setdefault(way, []).append((length, self._answers[key]))
        return [self._answers[key] for key in keys]

    def close(self) -> None:
        """End the processes the queries ran in, if any (and reap them): what the import
        forks next has both cores. A later query forks them anew."""
        if self._ended is not None:
            self._ended()
        self._pool, self._ended = None, None

    def _entailed(self, way: tuple[int, int, tuple[float, ...]], length: float) -> bool | None:
        """The answer of the sweep ``way`` (moving solid, fixed solid (their ids), unit
        direction) by ``length`` [m] that a sweep of the same solids along the same
        direction answered before entails, or None: a shorter sweep's motion is part of a
        longer one's, so a longer sweep that is free (no prism of it meets the fixed part
        deeper than :data:`executor.cad.fits.faces.TOUCH`) frees the shorter, and a shorter one that collides
        blocks the longer (penetration depth only grows with the moving set)."""
        for done, collides in self._along.get(way, []):
            if collides == (done <= length):
                return collides
        return None

    def _prepare(self, tests: Iterable[tuple[str, str, np.ndarray]]) -> None:
        """Make the BVHs of the fixed solids of ``tests`` (member, other, shift), their
        triangle indices where the moving solid is not convex, and the outer hulls of the
        moving ones (a part slid at its fits has none from the surveys), in this process,
        before its workers are forked: each worker then has them, rather than making its
        own (a slid part's hull, swept in both workers, was made in each). A convex moving
        solid is tested whole first (:func:`_collides`), which mostly decides without an
        index (a slid shaft along its bores): the index is made where it is needed, in the
        worker."""
        for test in tests:
            moving, fixed, _ = self._oriented(*test)
            _ = fixed.bvh, moving.hull
            if not moving.convex:
                _ = fixed.index

    def _oriented(self, member: str, other: str, shift: np.ndarray) -> tuple[_Solid, _Solid, np.ndarray]:
        """The moving solid, the fixed one and the shift [m] of the test whether part
        ``member`` swept by ``shift`` collides with part ``other``: the same relative
        motion with the cheaper part moving."""
        moving, fixed = self._solid(member, other, shift), self._solid(other, member, shift)
        if not moving.convex and (fixed.convex or len(fixed.mesh.faces) < len(moving.mesh.faces)):
            return fixed, moving, -shift
        return moving, fixed, shift

    def touching(self, a: str, b: str) -> bool:
        """Whether parts ``a`` and ``b`` are within :data:`executor.cad.fits.faces.TOUCH` of each other: their
        distance, unless their boxes or one's convex superset and the other are farther
        apart (no nearer than the part itself), or they meet."""
        one, other = self._solids[a], self._solids[b]
        gap = np.maximum(one.bounds[0] - other.bounds[1], other.bounds[0] - one.bounds[1])
        if np.any(gap > TOUCH):
            return False
        self.queries += 1
        for solid, against in ((one, other), (other, one)):
            around = _hull_piece(solid.hull)
            if around is not None and fcl.distance(around.object, against.bvh, fcl.DistanceRequest(),
                                                   fcl.DistanceResult()) > TOUCH:
                return False
        if fcl.collide(one.bvh, other.bvh, fcl.CollisionRequest(), fcl.CollisionResult()):
            return True
        return bool(fcl.distance(one.bvh, other.bvh, fcl.DistanceRequest(), fcl.DistanceResult()) <= TOUCH)

    def _solid(self, part: str, against: str, shift: np.ndarray) -> _Solid:
        """``part``'s solid for a sweep by ``shift`` against (or of) ``against``: at their
        zero-clearance fits along the shift, :func:`executor.cad.fits.faces.slid`."""
        unit = shift / np.linalg.norm(shift)

        def along(slides: list[Slide]) -> list[Slide]:
            return [s for s in slides if abs(float(unit @ s.direction)) > 1 - 1e-9]

        shafts, bores = along(self._slides.get((part, against), [])), along(self._slides.get((against, part), []))
        if not shafts and not bores:
            return self._solids[part]
        key = (part, against, axis_name(unit)[1:])
        if key not in self._slid:
            self._slid[key] = _Solid(slid(self.meshes[part], shafts, bores), self._solids[part].convex)
        return self._slid[key]


_FORKED: Sweeper | None = None
"""The sweeper whose pool is being forked: a worker's copy of it answers :func:`_swept`."""


def _swept(test: tuple[str, str, np.ndarray]) -> bool:
    """In a worker forked by :meth:`Sweeper._sweeps`: whether part ``member`` swept by
    ``shift`` [m] collides with part ``other``, for ``test`` (member, other, shift), on the
    worker's copy of the sweeper (its solids, made or completed there)."""
    assert _FORKED is not None, "a sweep worker forked without its sweeper"
    return _collides(*_FORKED._oriented(*test))


def _collides(moving: _Solid, fixed: _Solid, shift: np.ndarray) -> bool:
    """Whether ``moving`` swept by ``shift`` meets ``fixed`` deeper than :data:`executor.cad.fits.faces.TOUCH`
    (the module docstring: the hull, then down the triangle tree, the prisms of a leaf last)."""
    pieces = moving.pieces.setdefault(tuple(shift), {})
    if moving.convex or moving.exact:
        if -1 not in pieces:
            pieces[-1] = _hull_piece(np.vstack([moving.hull, moving.hull + shift]))
        whole = pieces[-1]
        if whole is not None and not _meets([whole], fixed):
            return False
        if whole is not None and moving.convex and moving.exact:
            return True
    low, high = fixed.bounds
    leading = np.zeros(len(moving.triangles), dtype=int)
    leading[_front(moving, low, high, shift)] = 1
    pending = [moving.tree]
    while pending:
        node = pending.pop()
        points = node.points
        start, end = np.minimum(node.low, node.low + shift), np.maximum(node.high, node.high + shift)
        if np.any(np.minimum(end, high) - np.maximum(start, low) <= TOUCH):
            continue
        if len(points) <= HULL_POINTS:
            if not fixed.index.meets(start - TOUCH, end + TOUCH):
                continue  # every piece in the swept box lies farther than TOUCH from fixed's triangles: no contact
            if id(node) not in pieces:
                pieces[id(node)] = _hull_piece(np.vstack([points, points + shift]))
            piece = pieces[id(node)]
            if piece is not None and not _meets([piece], fixed):
                continue
        if node.children:
            # the half holding more leading triangles first (popped last pushed); the
            # answer does not depend on the order, only how soon a blocked sweep ends
            pending += sorted(node.children, key=lambda child: int(leading[child.faces].sum()))
        elif _meets(swept_pieces(moving.triangles[node.faces], shift), fixed):
            return True
    return False


def _front(solid: _Solid, low: np.ndarray, high: np.ndarray, shift: np.ndarray) -> np.ndarray:
    """The :data:`FRONT` triangles of ``solid`` that lead its sweep by ``shift`` [m] into
    the box ``low``, ``high`` [m]: facing along the shift, swept into the box, farthest
    along the shift (where a blocked part meets what blocks it)."""
    start, end, normals, centres = solid.leading
    inside = np.all(np.minimum(np.maximum(end, end + shift), high)
                    - np.maximum(np.minimum(start, start + shift), low) > TOUCH, axis=1)
    found = np.flatnonzero(inside & (normals @ shift > 0))
    ahead = centres[found] @ shift
    return found[np.argsort(-ahead, kind="stable")[:FRONT]]


def _meets(pieces: list[_Piece], fixed: _Solid) -> bool:
    """Whether a piece meets ``fixed`` deeper than :data:`executor.cad.fits.faces.TOUCH` (fcl's depth of a triangle
    of ``fixed`` it meets): a first query without contacts, then the depths of the first
    :data:`_FEW_CONTACTS` contacts; then, in a query of their own, the :data:`LIKELY`
    triangles of ``fixed`` that reach deepest into the piece along the line between their
    centres (:func:`_likely`: fcl's depth is found along that line); then the depths of 16
    times as many contacts, of all only when none of those is deeper. fcl finds each
    triangle's contact on its own, whatever the other triangles, so the likely ones answer
    only where all would answer the same; where the piece meets a face along its whole
    length (a zero-clearance fit) they spare the thousands of shallow contacts before the
    deep one."""
    first = fcl.CollisionRequest()
    for piece in pieces:
        if not fcl.collide(piece.object, fixed.bvh, first, fcl.CollisionResult()):
            continue
        deeper, count = _deeper(piece.object, fixed.bvh, _FEW_CONTACTS)
        if deeper:
            return True
        if count < _FEW_CONTACTS:
            continue
        likely = _likely(piece, fixed.index)
        if len(likely):
            corners = fixed.index.corners[likely].reshape(-1, 3)
            if _deeper(piece.object, _bvh(corners, np.arange(len(corners), dtype=np.int32).reshape(-1, 3)),
                       len(likely))[0]:
                return True
        for most in (16 * _FEW_CONTACTS, _MAX_CONTACTS):
            deeper, count = _deeper(piece.object, fixed.bvh, most)
            if deeper:
                return True
            if count < most:
                break
    return False


def _deeper(piece: fcl.CollisionObject, fixed: fcl.CollisionObject, most: int) -> tuple[bool, int]:
    """Whether one of the first ``most`` contacts of ``piece`` with ``fixed`` is deeper than
    :data:`executor.cad.fits.faces.TOUCH`, and how many contacts fcl gave."""
    result = fcl.CollisionResult()
    fcl.collide(piece, fixed, fcl.CollisionRequest(num_max_contacts=most, enable_contact=True), result)
    return any(contact.penetration_depth > TOUCH for contact in result.contacts), len(result.contacts)


def _likely(piece: _Piece, triangles: _Triangles) -> np.ndarray:
    """The (at most :data:`LIKELY`) triangles near ``piece`` that reach farthest into it,
    deeper than :data:`executor.cad.fits.faces.TOUCH`, along the line from its centre to theirs: the piece's extent
    beyond the triangle's nearest corner along that line, what fcl's depth (libccd's portal
    refinement from the centres' difference) approaches. The extent is measured only on the
    triangles whose bound (the piece's box's extent instead, plus :data:`_SLACK`) reaches
    the :data:`LIKELY`-th extent of the twice as many the bound ranks first: no other can
    be among the farthest (a long sweep's piece has thousands of triangles near it)."""
    low, high = piece.points.min(axis=0), piece.points.max(axis=0)
    found = triangles.near(low, high)
    if not len(found):
        return found
    toward = triangles.centres[found] - piece.points.mean(axis=0)
    lengths = np.linalg.norm(toward, axis=1, keepdims=True)
    toward = np.divide(toward, lengths, out=np.zeros_like(toward), where=lengths > 0)
    nearest = np.min(np.einsum("mvc,mc->mv", triangles.corners[found], toward), axis=1)
    bound = toward @ ((low + high) / 2) + np.abs(toward) @ ((high - low) / 2) - nearest + _SLACK
    kept = np.flatnonzero(bound > TOUCH)
    if len(kept) > 4 * LIKELY:
        first = kept[np.argpartition(-bound[kept], 2 * LIKELY)[:2 * LIKELY]]
        least = np.partition(-_reach(piece, toward[first], nearest[first]), LIKELY - 1)[LIKELY - 1]
        kept = kept[bound[kept] >= -least]
    reach = _reach(piece, toward[kept], nearest[kept])
    order = np.argsort(-reach, kind="stable")[:LIKELY]
    return found[kept[order[reach[order] > TOUCH]]]


_SLACK = 1e-9
"""Added to the bound of :func:`_likely` [m]: far above the rounding of either side."""


def _reach(piece: _Piece, toward: np.ndarray, nearest: np.ndarray) -> np.ndarray:
    """The extent [m] of ``piece`` along each unit vector ``toward`` beyond ``nearest`` (:func:`_likely`)."""
    return np.max(toward @ piece.points.T, axis=1) - nearest
