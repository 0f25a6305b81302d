"""Swept collision along a straight removal path, exact (no sampled poses), with nominal
zero-clearance fits sliding along their axis.

**Exact sweep.** A body (one part, or parts fixed to each other) moving by ``length``
along ``direction`` collides with a fixed part B exactly when some triangle of its
boundary, swept along the path, meets B's interior (the sweep of a solid is bounded by
the sweeps of its boundary triangles, and the two start apart). Each swept triangle is a
convex prism (the triangle and its translate) tested against B's triangle BVH in
python-fcl (GJK/EPA); a contact deeper than :data:`TOUCH` is a collision, so parts that
only touch (a peg on its hole's bottom, a cover on its spacer) slide apart.

**Conservative first.** Penetration depth only grows with the moving set, so a convex
superset that meets B no deeper than :data:`TOUCH` clears every prism inside it: first the
sweep of the part's convex hull (one query: the answer for a convex part), then down a
tree of the part's triangles (halves of nearby ones): a node whose swept box misses B's
box, or meets no cell of B's grid that B's triangles' boxes meet (:meth:`_Triangles.meets`:
no contact is found in it), or whose swept hull clears B, is done; the prisms are tested only in leaves of
:data:`CHUNK` triangles that still meet B. The tree is searched depth first, the half
holding more of the few triangles that lead the sweep into B's box (:func:`_front`)
first: where the part is blocked, they usually meet B deeply, so the search ends soon;
the order changes no answer. Same answer as testing every prism. A piece that meets B is
decided by fcl's depths of B's triangles, the likeliest deep ones first (:func:`_meets`).

**Zero-clearance fits** (:func:`zero_clearance_fits`). Real CAD models a shaft in a bore at
one nominal diameter, each tessellated on its own, so the two polygons overlap by up to
the tessellation's deflection. Cylindrical faces are fitted on the mesh (smooth regions
whose normals are all perpendicular to one axis and whose vertices lie on one circle,
their triangles within a 35° chord's sagitta of it: :data:`COARSEST`; of
a smooth region that is none, as a bore joined to its ring's end faces by edge radii,
its bands whose normals are perpendicular to the axis most of its bends turn about);
an outward face (a shaft) and an inward one (a bore) of two parts, coaxial and of equal
radius within the pair's tolerance (the larger deflection of the two faces plus
:data:`TOUCH`), are a fit, wherever on the way along the axis they meet: seated (their
spans overlap in the assembled pose) or a passage (a bore passing a collar of that size
on its way out). Swept along its axis against the bore's part, the shaft's part
is taken thinner there (its vertices within the tolerance of that radius moved towards
the axis by the bore's deflection, the radii's and the axes' difference and
:data:`TOUCH`): overlap below the tolerance across the axis is not a collision, every
other face (a shoulder, an end wall) still is. Prismatic faces along the cell's axes (a
spline, a cross axle: :func:`prism_faces`) are a fit when the peg's outline, shrunk by
:data:`TOUCH`, lies in the hole's and the two come within it of each other; the peg's
part is then scaled towards the axis so that each of its sides moves in by at least
twice :data:`TOUCH`.

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

import math
import multiprocessing
import multiprocessing.pool
import os
import weakref
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, replace
from typing import NamedTuple, TypeVar, cast

import fcl
import numpy as np
import shapely
import trimesh
from scipy.spatial import ConvexHull, HalfspaceIntersection, QhullError

from bridge.cli_types import forked_worker
from executor import ExecutorError

TOUCH = 1e-5
"""Contacts at most this deep [m] are touching, not colliding (10 µm: below every
clearance a cell can insert with; Cranfield's tight fit is 50 µm a side)."""
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
SMOOTH = np.radians(35.0)
"""Adjacent triangles meeting at less than this angle are one smooth face (a 12-gon's is 30°)."""
TILT = 0.05
"""How far a cylindrical face's triangle normals may lean along its axis (the cosine: 2.9°):
a tessellation whose rings are not lined up (a vertex of one end between two of the
other, as Open CASCADE meshes a B-spline bore) leans them by about its chord error over
the face's length (a 3 mm nut's bore at 0.02 mm: 1.4e-3). That the vertices lie on one
circle is what makes the face a cylinder (a cone or a sphere fails it)."""
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


@dataclass(frozen=True)
class CylinderFace:
    """A cylindrical face fitted on a mesh: a ``point`` on its axis and the unit axis
    ``direction`` [m], the ``radius`` [m], the ``span`` of its vertices along the axis
    [m] (projections on ``direction``), ``outward`` (a shaft's face; False: a bore's) and
    the ``deflection`` [m]: the largest distance of one of its triangles from the circle."""

    point: np.ndarray
    direction: np.ndarray
    radius: float
    span: tuple[float, float]
    outward: bool
    deflection: float


def cylinder_faces(mesh: trimesh.Trimesh) -> list[CylinderFace]:
    """The cylindrical faces of ``mesh`` (the module docstring): smooth regions of at least
    six triangles that are one cylinder (:func:`_cylinder`), and of every other smooth
    region its bands lateral to its axis (:func:`_bands`) that are cylinders (a bore whose
    edge radii join it smoothly to the ring's end faces: the bore, not the radii)."""
    angles = mesh.face_adjacency_angles
    smooth = mesh.face_adjacency[angles < SMOOTH]
    faces: list[CylinderFace] = []
    for region in trimesh.graph.connected_components(smooth, min_len=6):
        face = _cylinder(mesh, region)
        if face is not None:
            faces.append(face)
            continue
        faces.extend(f for band in _bands(mesh, region, smooth) if (f := _cylinder(mesh, band)) is not None)
    return faces


def _cylinder(mesh: trimesh.Trimesh, region: np.ndarray) -> CylinderFace | None:
    """The triangles ``region`` of ``mesh`` as one cylindrical face, or None: their normals
    perpendicular to one axis (within :data:`TILT`) and spanning more than a flat face's,
    their vertices on one circle (within 1 µm plus 1e-4 of the radius), their normals
    all pointing away from the axis or all towards it, and no triangle farther from the
    circle than :data:`COARSEST` of the radius (:func:`_deflection`, the face's deflection)."""
    normals = mesh.face_normals[region]
    scatter = normals.T @ normals / len(region)
    values, vectors = np.linalg.eigh(scatter)
    axis = vectors[:, 0]
    if values[1] < 1e-3 or np.max(np.abs(normals @ axis)) > TILT:
        return None  # flat, or no cylinder (a cone, a sphere)
    ring = np.unique(mesh.faces[region].ravel())
    frame = np.linalg.svd(axis[None, :])[2][1:]  # two unit vectors across the axis
    flat = mesh.vertices[ring] @ frame.T
    design = np.column_stack([2 * flat, np.ones(len(flat))])
    solution = np.linalg.lstsq(design, np.sum(flat ** 2, axis=1), rcond=None)[0]
    centre = solution[:2]
    radius = float(np.sqrt(solution[2] + centre @ centre))
    if not np.all(np.abs(np.linalg.norm(flat - centre, axis=1) - radius) <= 1e-6 + 1e-4 * radius):
        return None
    point = centre @ frame
    outwards = np.einsum("ij,ij->i", normals, (mesh.triangles_center[region] @ frame.T - centre) @ frame)
    if not (np.all(outwards > 0) or np.all(outwards < 0)):
        return None
    deflection = _deflection(mesh.triangles[region] @ frame.T - centre, radius)
    if deflection > COARSEST * radius:
        return None  # coarser than a ring of smooth facets can be: no tessellated cylinder
    along = mesh.vertices[ring] @ axis
    return CylinderFace(point, axis, radius, (float(along.min()), float(along.max())),
                        bool(outwards[0] > 0), deflection)


COARSEST = 1 - np.cos(SMOOTH / 2)
"""The largest deflection of a cylindrical face as a fraction of its radius (4.6%): the
sagitta of a chord of :data:`SMOOTH`, the coarsest angular step a ring of facets meeting
smoothly has (a d 20 bore: 0.46 mm; a regular ring has at least 11 facets a turn, a
12-gon's 30° chords 3.4%)."""


def _deflection(corners: np.ndarray, radius: float) -> float:
    """The largest distance [m] of triangles from a circle of ``radius`` [m] about the
    origin, their ``corners`` (n, 3, 2) [m] given across its axis: their edges' nearest
    points to the axis inside it (a chord's sagitta), their corners beyond it. A sliver
    whose plane passes far inside the circle (two corners a few µm apart, each within the
    fit's µm of the circle) lies no farther from it than its corners."""
    start = corners
    edge = np.roll(corners, -1, axis=1) - start
    length = np.maximum(np.einsum("ijk,ijk->ij", edge, edge), 1e-30)
    t = np.clip(-np.einsum("ijk,ijk->ij", start, edge) / length, 0.0, 1.0)
    nearest = np.linalg.norm(start + t[..., None] * edge, axis=2)
    return float(max(radius - nearest.min(), np.linalg.norm(corners, axis=2).max() - radius, 0.0))


BEND = 1e-2
"""Adjacent triangles whose normals differ by more than this (the sine: 0.6°) bend about
an axis, their normals' cross product (:func:`_bands`); flatter pairs show none."""
CANDIDATES = 256
"""Bends of a smooth region tried as its axis (:func:`_bands`; evenly spaced among them)."""


def _bands(mesh: trimesh.Trimesh, region: np.ndarray, smooth: np.ndarray) -> list[np.ndarray]:
    """The smooth ``region`` of ``mesh`` split where it stops being a band parallel to one
    axis. Adjacent triangles that bend (:data:`BEND`) bend about their normals' cross
    product: on a cylinder all about its axis, on an edge radius or a sphere about
    directions that vary. The axis is the bend shared (within :data:`TILT`) by most of the
    region's bending pairs (tried among :data:`CANDIDATES` of them), averaged over those; the
    bands are the connected sets of at least six of the region's triangles whose normals
    are perpendicular to it (within :data:`TILT`), joined by the ``smooth`` adjacencies: a
    bore's band, not its edge radii (their normals lean along the axis) nor the end faces
    beyond them. Each band is a cylinder only if :func:`_cylinder` finds it one. One axis a
    region: bands about another axis in the same smooth region are not looked for."""
    inside = np.zeros(len(mesh.faces), dtype=bool)
    inside[region] = True
    pairs = smooth[inside[smooth].all(axis=1)]
    bends = np.cross(mesh.face_normals[pairs[:, 0]], mesh.face_normals[pairs[:, 1]])
    sizes = np.linalg.norm(bends, axis=1)
    bends = bends[sizes > BEND] / sizes[sizes > BEND, None]
    if len(bends) < 2:
        return []
    tried = bends[np.linspace(0, len(bends) - 1, min(CANDIDATES, len(bends))).astype(int)]
    shared = np.abs(tried @ bends.T) >= np.sqrt(1 - TILT ** 2)
    best = tried[np.argmax(shared.sum(axis=1))]
    along = bends[np.abs(bends @ best) >= np.sqrt(1 - TILT ** 2)]
    axis = np.linalg.eigh(along.T @ along)[1][:, -1]
    lateral = np.zeros(len(mesh.faces), dtype=bool)
    lateral[region] = np.abs(mesh.face_normals[region] @ axis) <= TILT
    return list(trimesh.graph.connected_components(pairs[lateral[pairs].all(axis=1)], min_len=6))


_PRISM_FRAMES = tuple((axis, np.array([np.roll(axis, 1), np.roll(axis, 2)])) for axis in np.eye(3))
"""The cell's axes a prismatic face is looked for along, each with the two others (its section's frame)."""


@dataclass(frozen=True)
class PrismFace:
    """A prismatic face fitted on a mesh along one of the cell's axes: its ``outline``
    (the section of its triangles at mid-span, in ``frame``'s coordinates [m]), a
    ``point`` on its axis (the outline's centroid) and the unit axis ``direction``, the
    ``span`` of its vertices along the axis [m], ``outward`` (a peg's face; False: a
    hole's), ``radius`` [m] the least distance of its sides' lines from the axis (a
    thinning towards the axis by a factor 1 - t / radius moves every side in by at least
    t) and ``deflection`` 0 (its sides are planes)."""

    point: np.ndarray
    direction: np.ndarray
    frame: np.ndarray
    outline: shapely.Polygon
    span: tuple[float, float]
    outward: bool
    radius: float
    deflection: float = 0.0


def prism_faces(mesh: trimesh.Trimesh) -> list[PrismFace]:
    """The prismatic faces of ``mesh`` along the cell's axes: connected sets of at least
    four triangles whose normals are perpendicular to the axis (within :data:`TILT`), not
    all meeting smoothly (those are cylinders, :func:`cylinder_faces`), whose section at
    mid-span is one closed loop around its centroid (every side's line off it), the
    triangles cut there all facing out of it or all into it: the face is the set's
    triangles on that loop (within :data:`TOUCH`) facing the same way, its span theirs."""
    faces: list[PrismFace] = []
    smooth = mesh.face_adjacency_angles < SMOOTH
    for axis, frame in _PRISM_FRAMES:
        lateral = np.abs(mesh.face_normals @ axis) < TILT
        pairs = lateral[mesh.face_adjacency].all(axis=1)
        for region in trimesh.graph.connected_components(mesh.face_adjacency[pairs], min_len=4):
            if np.all(smooth[pairs & np.isin(mesh.face_adjacency, region).all(axis=1)]):
                continue
            along = mesh.vertices[np.unique(mesh.faces[region].ravel())] @ axis
            low, high = float(along.min()), float(along.max())
            if high - low <= TOUCH:
                continue
            part = mesh.submesh([region], append=True)
            segments = trimesh.intersections.mesh_plane(part, axis, axis * (low + high) / 2)
            lines = shapely.union_all([shapely.LineString(s) for s in np.round(segments @ frame.T, 9)])
            polygons = list(shapely.polygonize([lines]).geoms)  # its ends joined to 1 nm
            if len(polygons) != 1 or polygons[0].area <= 0:
                continue
            outline = shapely.normalize(polygons[0])
            centre = np.array(outline.centroid.coords[0])
            ring = np.asarray(outline.exterior.coords)
            sides = ring[1:] - ring[:-1]
            normals = np.column_stack([sides[:, 1], -sides[:, 0]]) / np.linalg.norm(sides, axis=1)[:, None]
            reach = float(np.min(np.abs(np.einsum("ij,ij->i", ring[:-1] - centre, normals))))
            # the face is the region's triangles on the outline, facing as those cut at mid-span do
            corners = mesh.triangles[region] @ frame.T
            on = np.all(shapely.distance(outline.exterior, shapely.points(corners)) <= TOUCH, axis=1)
            probe = mesh.triangles_center[region] @ frame.T + 1e-6 * (mesh.face_normals[region] @ frame.T)
            inside = shapely.contains_xy(outline, probe[:, 0], probe[:, 1])
            heights = mesh.triangles[region] @ axis
            cut = (heights.min(axis=1) < (low + high) / 2) & (heights.max(axis=1) > (low + high) / 2)
            if reach <= TOUCH or len(set(inside[cut])) != 1:
                continue
            kept = heights[on & (inside == inside[cut][0])]
            if not kept.size:  # every triangle leans off the mid-span section: a taper within TILT, no prism
                continue
            faces.append(PrismFace(centre @ frame, axis, frame, outline, (float(kept.min()), float(kept.max())),
                                   not bool(inside[cut][0]), reach))
    return faces


@dataclass(frozen=True)
class Slide:
    """A nominal zero-clearance fit: part ``shaft``'s outward ``face`` in part ``bore``'s
    inward face ``hole``, coaxial and of equal radius (prisms: the peg's outline within the
    hole's) within ``tolerance`` [m]; along the axis the shaft's part is swept (or met)
    ``thinner`` [m] there (module docstring). ``seated``: the two faces' spans along the
    axis overlap by more than the tolerance in the assembled pose (the shaft is in the
    bore); else it is a **passage**, the faces meeting only on a way along the axis (a
    pulley's bore passing a collar of its hub on its way off the hub's end). A **screwed
    pair** (:func:`screwed_pairs`: a modelled thread, ``shaft`` the
    screw and ``bore`` the nut) has the thread's ``pitch`` and ``lead`` [m] (0 for any other fit)."""

    shaft: str
    bore: str
    face: CylinderFace | PrismFace
    hole: CylinderFace | PrismFace
    tolerance: float
    thinner: float
    seated: bool
    pitch: float = 0.0
    lead: float = 0.0

    @property
    def direction(self) -> np.ndarray:
        return self.face.direction


def fit_faces(mesh: trimesh.Trimesh) -> list[CylinderFace | PrismFace]:
    """The faces of ``mesh`` a zero-clearance fit may slide on: its cylinders and prisms."""
    return [*cylinder_faces(mesh), *prism_faces(mesh)]


def _seated(a: CylinderFace | PrismFace, b: CylinderFace | PrismFace, tolerance: float) -> bool:
    """Whether the spans of the parallel faces ``a`` and ``b`` along ``a``'s axis overlap
    by more than ``tolerance`` [m]."""
    low, high = (b.span if a.direction @ b.direction > 0 else (-b.span[1], -b.span[0]))
    return min(a.span[1], high) - max(a.span[0], low) > tolerance


def _prism_fit(a: PrismFace, b: PrismFace) -> Slide | None:
    """The fit of the outward prism ``a`` in the inward ``b`` (the parts' names filled in
    by the caller) when they share their axis, the outline of ``a`` shrunk by
    :data:`TOUCH` lies in that of ``b`` and the two outlines come within it of each other
    (else there is room); seated when their spans overlap by more than it."""
    if not np.array_equal(a.direction, b.direction):
        return None
    if (not shapely.covers(b.outline, a.outline.buffer(-TOUCH, join_style="mitre"))
            or shapely.distance(a.outline.exterior, b.outline.exterior) > TOUCH):
        return None
    return Slide("", "", a, b, TOUCH, 2 * TOUCH, _seated(a, b, TOUCH))


def zero_clearance_fits(faces: dict[str, list[CylinderFace | PrismFace]]) -> list[Slide]:
    """Every pair of an outward face of one part and an inward face of another: cylinders
    parallel (within 1e-4 rad), coaxial and of equal radius within their tolerance; prisms
    along one of the cell's axes whose outlines are one within :data:`TOUCH`
    (:func:`_prism_fit`). Each slides along its axis wherever the two faces meet on the
    way, in the assembled pose (``seated``) or only on it (a passage)."""
    found: list[Slide] = []
    for shaft, outer in faces.items():
        for bore, inner in faces.items():
            if bore == shaft:
                continue
            for p in (f for f in outer if isinstance(f, PrismFace) and f.outward):
                for q in (f for f in inner if isinstance(f, PrismFace) and not f.outward):
                    if (prism := _prism_fit(p, q)) is not None:
                        found.append(replace(prism, shaft=shaft, bore=bore))
            for a in (f for f in outer if isinstance(f, CylinderFace) and f.outward):
                for b in (f for f in inner if isinstance(f, CylinderFace) and not f.outward):
                    tolerance = max(a.deflection, b.deflection) + TOUCH
                    if (np.linalg.norm(np.cross(a.direction, b.direction)) > 1e-4
                            or abs(a.radius - b.radius) > tolerance):
                        continue
                    offset = b.point - a.point
                    apart = float(np.linalg.norm(offset - a.direction * (offset @ a.direction)))
                    if apart > tolerance:
                        continue
                    thinner = max(0.0, a.radius - b.radius) + b.deflection + apart + TOUCH
                    found.append(Slide(shaft, bore, a, b, tolerance, thinner, _seated(a, b, tolerance)))
    return found


def near(points: np.ndarray, face: CylinderFace | PrismFace,
         tolerance: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Which ``points`` [m] lie within ``tolerance`` of ``face`` (of its radius or its
    outline, within its span), their coordinates along the axis and their radial offsets from it."""
    relative = points - face.point
    along = relative @ face.direction
    radial = relative - np.outer(along, face.direction)
    if isinstance(face, PrismFace):
        off = shapely.distance(face.outline.exterior, shapely.points(points @ face.frame.T))
    else:
        off = np.abs(np.linalg.norm(radial, axis=1) - face.radius)
    near = (off <= tolerance) & (along >= face.span[0] - tolerance) & (along <= face.span[1] + tolerance)
    return near, along, radial


def slid(mesh: trimesh.Trimesh, shafts: Iterable[Slide], bores: Iterable[Slide]) -> trimesh.Trimesh:
    """``mesh`` as swept along the axis of its zero-clearance fits: its vertices on each
    of ``shafts``' faces moved ``thinner`` towards the axis (a prism's scaled towards it so
    that every side moves in by at least that), and the triangles of those
    faces and of ``bores``' holes (the mated surfaces) left out, whose sliding on each
    other is the fit; what meets them meets the part's other triangles first."""
    vertices = np.array(mesh.vertices, dtype=float)
    mated = np.zeros(len(mesh.faces), dtype=bool)
    for slide, face in [*((s, s.face) for s in shafts), *((s, s.hole) for s in bores)]:
        on, along, radial = near(np.asarray(mesh.vertices), face, slide.tolerance)
        mated |= np.all(on[mesh.faces], axis=1) & (np.abs(mesh.face_normals @ face.direction) < TILT)
        if face is slide.face:
            distance = np.linalg.norm(radial[on], axis=1)
            inward = slide.thinner * (distance / face.radius if isinstance(face, PrismFace) else 1.0)
            scale = np.maximum(distance - inward, 0.0) / distance
            vertices[on] = face.point + np.outer(along[on], face.direction) + radial[on] * scale[:, None]
    return trimesh.Trimesh(vertices, mesh.faces[~mated], process=False)


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

    def __init__(self, corners: np.ndarray) -> None:
        self.corners = corners
        self.low, self.high = corners.min(axis=1), corners.max(axis=1)
        self.centres = corners.mean(axis=1)
        centres = self.centres
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
    that axis within :data:`TOUCH` / 2), and whether it is the hull itself."""
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
    (:func:`fit_faces`), the vertices [m] of its ``hull`` (:func:`_outer_hull`: a convex
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
            self._index = _Triangles(self.triangles)
        return self._index

    @property
    def leading(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The triangles' lowest and highest corners, normals and centres [m] (:func:`_front`)."""
        if self._leading is None:
            self._leading = (self.triangles.min(axis=1), self.triangles.max(axis=1), np.array(self.mesh.face_normals),
                             self.triangles.mean(axis=1))
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
        deeper than :data:`TOUCH`) frees the shorter, and a shorter one that collides
        blocks the longer (penetration depth only grows with the moving set)."""
        for done, collides in self._along.get(way, []):
            if collides == (done <= length):
                return collides
        return None

    def _prepare(self, tests: Iterable[tuple[str, str, np.ndarray]]) -> None:
        """Make the BVHs and triangle indices of the fixed solids of ``tests`` (member,
        other, shift), and the outer hulls of the moving ones (a part slid at its fits has
        none from the surveys), in this process, before its workers are forked: each worker
        then has them, rather than making its own (a slid part's hull, swept in both
        workers, was made in each)."""
        for test in tests:
            moving, fixed, _ = self._oriented(*test)
            _ = fixed.bvh, fixed.index, moving.hull

    def _oriented(self, member: str, other: str, shift: np.ndarray) -> tuple[_Solid, _Solid, np.ndarray]:
        """The moving solid, the fixed one and the shift [m] of the test whether part
        ``member`` swept by ``shift`` collides with part ``other``: the same relative
        motion with the cheaper part moving."""
        moving, fixed = self._solid(member, other, shift), self._solid(other, member, shift)
        if not moving.convex and (fixed.convex or len(fixed.mesh.faces) < len(moving.mesh.faces)):
            return fixed, moving, -shift
        return moving, fixed, shift

    def touching(self, a: str, b: str) -> bool:
        """Whether parts ``a`` and ``b`` are within :data:`TOUCH` of each other: their
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
        zero-clearance fits along the shift, :func:`slid`."""
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
    """Whether ``moving`` swept by ``shift`` meets ``fixed`` deeper than :data:`TOUCH`
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
    """Whether a piece meets ``fixed`` deeper than :data:`TOUCH` (fcl's depth of a triangle
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
    :data:`TOUCH`, and how many contacts fcl gave."""
    result = fcl.CollisionResult()
    fcl.collide(piece, fixed, fcl.CollisionRequest(num_max_contacts=most, enable_contact=True), result)
    return any(contact.penetration_depth > TOUCH for contact in result.contacts), len(result.contacts)


def _likely(piece: _Piece, triangles: _Triangles) -> np.ndarray:
    """The (at most :data:`LIKELY`) triangles near ``piece`` that reach farthest into it,
    deeper than :data:`TOUCH`, along the line from its centre to theirs: the piece's extent
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


THREAD_ANGLES = 8
"""Half-planes about a thread's axis its surface is cut with (:func:`thread_profiles`): a
turn in eighths, so a lead of up to four pitches (four starts) shifts the profile by less than half a pitch."""
THREAD_SAMPLES = 2048
"""Levels along the axis each half-plane's profile is sampled at, over the part's extent."""
THREAD_MATCH = 0.15
"""Two profiles are one (shifted) when their mean difference is at most this fraction of
the thread's depth (the profile's 5th to 95th percentile)."""


@dataclass(frozen=True)
class Thread:
    """A helical surface measured on a part (:func:`helix`): about the axis through
    ``point`` along the unit ``direction`` [m], its profile's period ``pitch`` [m] along the
    axis and its ``lead`` [m] (the advance per turn, counterclockwise about ``direction``:
    positive for a right-handed thread; a multiple of the pitch for several starts), its
    least and largest radii ``inner`` and ``outer`` [m] over ``span`` (along ``direction``
    from ``point``: the levels where every half-plane meets it within those radii)."""

    point: np.ndarray
    direction: np.ndarray
    pitch: float
    lead: float
    inner: float
    outer: float
    span: tuple[float, float]


def thread_profiles(mesh: trimesh.Trimesh, point: np.ndarray, direction: np.ndarray,
                    levels: np.ndarray, outermost: bool, rows: Iterable[int] = range(THREAD_ANGLES)) -> np.ndarray:
    """The radius [m] of ``mesh``'s surface about the axis through ``point`` along the unit
    ``direction``, in the half-planes ``rows`` of :data:`THREAD_ANGLES` bounded by the axis
    (row k at angle 0.1234 + 2πk/K rad, counterclockwise about ``direction``: off the
    frame's axes) at each of ``levels`` [m] along the axis: the surface crossing the
    half-plane's line at that level nearest the axis (a nut's thread) or, ``outermost``,
    farthest from it (a screw's); NaN where none crosses (and in the rows not asked)."""
    across = np.eye(3)[int(np.argmin(np.abs(direction)))]
    first = np.cross(direction, across)
    first /= np.linalg.norm(first)
    second = np.cross(direction, first)
    found = np.full((THREAD_ANGLES, len(levels)), np.nan)
    for k in rows:
        angle = 0.1234 + 2 * np.pi * k / THREAD_ANGLES
        out = np.cos(angle) * first + np.sin(angle) * second
        segments = trimesh.intersections.mesh_plane(mesh, np.cross(direction, out), point)
        if len(segments) == 0:
            continue
        z = (segments - point) @ direction
        r = (segments - point) @ out
        order = np.argsort(levels)
        best = np.full(len(levels), -np.inf if outermost else np.inf)
        for (z0, z1), (r0, r1) in zip(z, r):  # each segment over the levels it spans
            if z1 == z0:
                continue
            lo, hi = np.searchsorted(levels[order], [min(z0, z1), max(z0, z1)], side="left")
            at = order[lo:hi]
            radius = r0 + (levels[at] - z0) / (z1 - z0) * (r1 - r0)
            radius = np.where(radius > 0, radius, -np.inf if outermost else np.inf)
            best[at] = np.maximum(best[at], radius) if outermost else np.minimum(best[at], radius)
        found[k] = np.where(np.isfinite(best), best, np.nan)
    return found


def _mismatch(a: np.ndarray, b: np.ndarray) -> float:
    """The mean absolute difference of two profiles where both are measured, over the 90 %
    of levels where they differ least (a stretch's ends may reach a head, a chamfer or a
    run-out); inf where they share under half their levels."""
    both = np.isfinite(a) & np.isfinite(b)
    if both.sum() * 2 < min(len(a), len(b)):
        return math.inf
    differences = np.sort(np.abs(a[both] - b[both]))
    return float(np.mean(differences[:max(1, int(0.9 * len(differences)))]))


def period(profile: np.ndarray, levels: np.ndarray, within: tuple[float, float]) -> tuple[int, float] | None:
    """The period (in levels) and the depth [m] (5th to 95th percentile) of one
    :func:`thread_profiles` row at the evenly spaced ``levels`` [m], over the levels
    ``within``: its smallest shift, above a sixteenth of the stretch and under a half,
    under which it matches itself within :data:`THREAD_MATCH` of its depth, at a local
    minimum of the difference; None where it has none (or is measured on under half the stretch)."""
    base = profile[(levels >= within[0]) & (levels <= within[1])]
    if len(base) == 0 or np.isnan(base).mean() > 0.5:
        return None
    depth = float(np.nanpercentile(base, 95) - np.nanpercentile(base, 5))
    if depth <= 2 * TOUCH:
        return None
    shifts = np.arange(max(1, len(base) // 16), len(base) // 2)
    if len(shifts) < 3:
        return None
    differences = np.array([_mismatch(base[s:], base[:-s]) for s in shifts])
    minima = [i for i in range(1, len(shifts) - 1) if differences[i] <= THREAD_MATCH * depth
              and differences[i] <= differences[i - 1] and differences[i] <= differences[i + 1]]
    return (int(shifts[minima[0]]), depth) if minima else None


def helix(profiles: np.ndarray, levels: np.ndarray, within: tuple[float, float]) -> tuple[float, float] | None:
    """(pitch, lead) [m] of :func:`thread_profiles` ``profiles`` at the evenly spaced
    ``levels`` [m], over the levels ``within`` (along the axis), when they are one helical
    surface: the first profile periodic along the axis (:func:`period`: the pitch) and each half-plane's profile
    the first one shifted by k times one shift s (within :data:`THREAD_MATCH`), s at least a
    sixteenth of the pitch from 0 (a surface of revolution, rings or grooves, has s = 0);
    the lead is K·s, taken as the nearest whole number of pitches (the starts; K·s measured
    within K levels of it, else None). None otherwise."""
    inside = (levels >= within[0]) & (levels <= within[1])
    rows = profiles[:, inside]
    step = float(levels[1] - levels[0])
    base = rows[0]
    found = period(profiles[0], levels, within)
    if found is None:
        return None
    cycle, depth = found
    half = cycle // 2
    options = np.arange(-half, half + 1)

    def shifted(row: np.ndarray, s: int) -> float:
        return _mismatch(row[s:], base[:-s]) if s > 0 else _mismatch(row[:s or None], base[-s:])

    one = int(options[np.argmin([shifted(rows[1], int(s)) for s in options])])
    if abs(one) * 16 < cycle:
        return None
    for k in range(1, len(rows)):
        s = (k * one + half) % cycle - half
        if shifted(rows[k], s) > THREAD_MATCH * depth:
            return None
    # one is a whole number of levels (±0.5), K·one within ±K/2 of the lead: the lead is the
    # nearest whole number of pitches (the starts), where K·one lies within K levels of it
    starts = round(len(rows) * abs(one) / cycle)
    if starts < 1 or abs(len(rows) * abs(one) - starts * cycle) > len(rows):
        return None
    return cycle * step, float(np.sign(one)) * starts * cycle * step


def _thread(mesh: trimesh.Trimesh, point: np.ndarray, direction: np.ndarray, overlap: tuple[float, float],
            outermost: bool) -> Thread | None:
    """``mesh``'s helical surface about the axis (:func:`helix`) measured over ``overlap``
    (along the axis from ``point`` [m]), on its outermost crossings (a screw) or innermost
    (a nut), or None; its span the levels about ``overlap`` where every half-plane meets it
    within its radii."""
    along = (mesh.vertices - point) @ direction
    levels = np.linspace(float(along.min()), float(along.max()), THREAD_SAMPLES)
    profiles = thread_profiles(mesh, point, direction, levels, outermost, rows=[0])
    if period(profiles[0], levels, overlap) is None:  # the cheap reject: one half-plane
        return None
    profiles = thread_profiles(mesh, point, direction, levels, outermost)
    found = helix(profiles, levels, overlap)
    if found is None:
        return None
    inside = (levels >= overlap[0]) & (levels <= overlap[1])
    inner, outer = float(np.nanmin(profiles[:, inside])), float(np.nanmax(profiles[:, inside]))
    on = np.all((profiles >= inner - TOUCH) & (profiles <= outer + TOUCH), axis=0)
    middle = int(np.flatnonzero(inside)[np.sum(inside) // 2])
    if not on[middle]:
        return None
    low = middle
    while low > 0 and on[low - 1]:
        low -= 1
    high = middle
    while high < len(on) - 1 and on[high + 1]:
        high += 1
    return Thread(point, direction, found[0], found[1], inner, outer, (float(levels[low]), float(levels[high])))


def screwed_pairs(meshes: dict[str, trimesh.Trimesh], pairs: Iterable[tuple[str, str]] | None = None) -> list[Slide]:
    """The screwed pairs among ``meshes`` (of ``pairs``, either way round, where given: the
    import asks only of parts the disassembly leaves and their blockers): a part's outermost surface (a screw's) and
    another's innermost (a nut's, a tapped hole's), about one axis along an axis of the
    frame through the centre of the smaller part's box across it, over the stretch where
    both parts are, each a helical surface (:func:`helix`) of one pitch and one lead
    (within 2 %), the screw's crest outside the nut's minor radius (they interlock).
    Each is a :class:`Slide` along that axis: swept against its mate
    only, the screw's thread is taken in to under the nut's minor radius (its vertices
    from that radius out to twice its crest less it, on its thread's span, moved in by
    its crest less that radius plus :data:`TOUCH`), so
    the pair slides along the axis where nothing else (a head, a bottom) stops it."""
    found: list[Slide] = []
    ids = sorted(meshes)
    asked = None if pairs is None else {frozenset(pair) for pair in pairs}
    for a in ids:
        for b in ids:
            if a == b or (asked is not None and frozenset((a, b)) not in asked):
                continue
            low = np.maximum(meshes[a].bounds[0], meshes[b].bounds[0])
            high = np.minimum(meshes[a].bounds[1], meshes[b].bounds[1])
            if np.any(high - low <= TOUCH):
                continue
            for axis in range(3):
                slide = _screwed(meshes[a], meshes[b], axis, (float(low[axis]), float(high[axis])))
                if slide is not None:
                    found.append(replace(slide, shaft=a, bore=b))
    return found


def lone_thread(meshes: dict[str, trimesh.Trimesh]) -> str:
    """For two overlapping parts (``meshes``: id -> mesh [m]) that are no screwed pair, what
    the import says of a modelled thread among them: the part whose outermost surface is a
    helical thread (:func:`helix`) about an axis of the frame through the smaller part's box
    centre, over the stretch both share, in the other part, whose innermost surface there is
    none (a tapped hole drawn at its tap drill); "" where neither is such a thread."""
    (a, one), (b, other) = sorted(meshes.items())
    low, high = np.maximum(one.bounds[0], other.bounds[0]), np.minimum(one.bounds[1], other.bounds[1])
    for axis in range(3):
        direction = np.eye(3)[axis]
        across = [i for i in range(3) if i != axis]
        smaller = min((one, other), key=lambda m: float(np.prod(m.extents[across])))
        point = smaller.bounds.mean(axis=0) * (1 - direction)
        for screw, mesh, hole in ((a, one, b), (b, other, a)):
            thread = _thread(mesh, point, direction, (float(low[axis]), float(high[axis])), outermost=True)
            if thread is not None:
                return (f"; '{screw}' has a modelled thread (pitch {1000 * thread.pitch:.3f} mm, d "
                        f"{2000 * thread.outer:.3f} mm, along {axis_name(direction)[1:]}) in '{hole}', which has "
                        "no thread there (a tapped hole drawn at its tap drill?): the import takes a modelled "
                        "thread only screwed into another")
    return ""


def _plain_bore(male: Thread, screw: trimesh.Trimesh, nut: trimesh.Trimesh, overlap: tuple[float, float]
                ) -> Slide | None:
    """The thread ``male`` of ``screw`` in a plain bore of ``nut`` drawn at its crest
    diameter (a clearance or tapped hole drawn at the screw's nominal size), or None:
    ``nut``'s innermost surface about the thread's axis, over the thread's span within
    ``overlap`` [m] (where both parts are, along the axis from the thread's point), a ring
    whose crossings lie between its largest radius and that less :data:`COARSEST` of it (a
    tessellated cylinder's chords), and the crest's vertex circle there within the two
    tessellations' deflections (the ring's spread, the crest's vertices beyond its
    crossings) plus :data:`TOUCH` of that largest radius. A zero-clearance fit (pitch 0),
    no screwed pair: the screw's thread taken in to under the bore's least radius, it
    slides along the axis out of the bore."""
    low, high = max(male.span[0], overlap[0]) + TOUCH, min(male.span[1], overlap[1]) - TOUCH
    if high <= low:
        return None
    levels = np.linspace(low, high, THREAD_SAMPLES // 8)
    profiles = thread_profiles(nut, male.point, male.direction, levels, outermost=False)
    if np.isnan(profiles).any():
        return None
    least, largest = float(profiles.min()), float(profiles.max())
    relative = screw.vertices - male.point
    along = relative @ male.direction
    radii = np.linalg.norm(relative - np.outer(along, male.direction), axis=1)
    crest = float(radii[(along >= low) & (along <= high)].max(initial=male.outer))
    if (largest - least > COARSEST * largest
            or abs(crest - largest) > largest - least + crest - male.outer + TOUCH):
        return None
    reach = crest - least + TOUCH
    face = CylinderFace(male.point, male.direction, crest, male.span, True, 0.0)
    hole = CylinderFace(male.point, male.direction, largest, male.span, False, 0.0)
    return Slide("", "", face, hole, reach, reach + TOUCH, True)


def _screwed(screw: trimesh.Trimesh, nut: trimesh.Trimesh, axis: int, overlap: tuple[float, float]) -> Slide | None:
    """The screwed pair (:func:`screwed_pairs`) of ``screw`` in ``nut`` along the frame's
    ``axis`` (0, 1, 2) over the stretch ``overlap`` [m] along it where both are, or None."""
    direction = np.eye(3)[axis]
    across = [i for i in range(3) if i != axis]
    smaller = min((screw, nut), key=lambda m: float(np.prod(m.extents[across])))
    point = smaller.bounds.mean(axis=0) * (1 - direction)
    male = _thread(screw, point, direction, overlap, outermost=True)
    if male is None:
        return None
    female = _thread(nut, point, direction, overlap, outermost=False)
    if female is None:
        return _plain_bore(male, screw, nut, overlap)
    if (abs(male.pitch - female.pitch) > 0.02 * male.pitch
            or abs(male.lead - female.lead) > 0.02 * abs(male.lead) or male.outer <= female.inner):
        return None
    reach = male.outer - female.inner + TOUCH
    face = CylinderFace(point, direction, male.outer, male.span, True, 0.0)
    hole = CylinderFace(point, direction, female.inner, female.span, False, 0.0)
    return Slide("", "", face, hole, reach, reach + TOUCH, True, pitch=male.pitch, lead=male.lead)
