"""The faces of nominal zero-clearance fits: cylinders and prisms fitted on a part's mesh,
the fits an outward face of one part and an inward face of another make, and a part as
swept along its fits' axes (:func:`slid`, for the sweeps of :mod:`executor.cad.sweep`).

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
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass, replace

import numpy as np
import shapely
import trimesh

TOUCH = 1e-5
"""Contacts at most this deep [m] are touching, not colliding (10 µm: below every
clearance a cell can insert with; Cranfield's tight fit is 50 µm a side)."""
SMOOTH = np.radians(35.0)
"""Adjacent triangles meeting at less than this angle are one smooth face (a 12-gon's is 30°)."""
TILT = 0.05
"""How far a cylindrical face's triangle normals may lean along its axis (the cosine: 2.9°):
a tessellation whose rings are not lined up (a vertex of one end between two of the
other, as Open CASCADE meshes a B-spline bore) leans them by about its chord error over
the face's length (a 3 mm nut's bore at 0.02 mm: 1.4e-3). That the vertices lie on one
circle is what makes the face a cylinder (a cone or a sphere fails it)."""


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
    edge radii join it smoothly to the ring's end faces: the bore, not the radii), a band
    that is none without the edge radii's triangles it took in (:func:`_off_rim`)."""
    angles = mesh.face_adjacency_angles
    smooth = mesh.face_adjacency[angles < SMOOTH]
    faces: list[CylinderFace] = []
    for region in trimesh.graph.connected_components(smooth, min_len=6):
        face = _cylinder(mesh, region)
        if face is not None:
            faces.append(face)
            continue
        axis, bands = _bands(mesh, region, smooth)
        for band in bands:
            face = _cylinder(mesh, band)
            if face is None and len(rim := _off_rim(mesh, band, axis)) >= 6:
                face = _cylinder(mesh, rim)
            if face is not None:
                faces.append(face)
    return faces


def _off_rim(mesh: trimesh.Trimesh, band: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """The triangles of ``band`` with no corner off its cylinder, none when their corners
    leave a wider angle about its axis uncovered than the band's (and than :data:`SMOOTH`:
    a rounded rect's four corners each touch the circle through their farthest points in a
    few triangles, 60 deg and more apart). A band can take in the
    first triangles of an edge radius tessellated coarsely (Open CASCADE's, from the
    cylinder's rim to a point of the radius a few tens of µm inside it, its normal within
    :data:`TILT` of the band's), whose corners the cylinder's circle does not hold. The
    circle is about the band's ``axis`` (:func:`_bands`: its bends', which those triangles
    do not tilt as they tilt its normals), through the centre fitted to its corners (then to
    the outer half of them, twice, for an outward band, the inner for an inward one), and
    of their farthest distance from it for an outward band (an edge radius bends inwards
    from a shaft's face), their nearest for an inward one (outwards from a bore's); a
    corner is on it within 1 µm plus 1e-4 of it."""
    normals = mesh.face_normals[band]
    frame = np.linalg.svd(axis[None, :])[2][1:]
    ring = np.unique(mesh.faces[band].ravel())
    flat = mesh.vertices[ring] @ frame.T
    centre = _centre(flat)
    across = mesh.triangles_center[band] @ frame.T - centre
    outward = float(np.mean(np.einsum("ij,ij->i", normals @ frame.T, across))) > 0
    for _ in range(2):  # refitted on the outer (inner) half of the corners: the radii's pull it off
        apart = np.linalg.norm(flat - centre, axis=1)
        middle = (apart.max() + apart.min()) / 2
        centre = _centre(flat[apart >= middle if outward else apart <= middle])
    distance = np.zeros(len(mesh.vertices))
    distance[ring] = np.linalg.norm(flat - centre, axis=1)
    radius = distance[ring].max() if outward else distance[ring].min()
    on = np.abs(distance - radius) <= 1e-6 + 1e-4 * radius
    rim = band[on[mesh.faces[band]].all(axis=1)]
    covered = _widest_gap(mesh, rim, frame, centre) <= max(_widest_gap(mesh, band, frame, centre), SMOOTH)
    return rim if covered else rim[:0]


def _centre(flat: np.ndarray) -> np.ndarray:
    """The centre of the circle fitted to the points ``flat`` (n, 2) [m] (least squares)."""
    design = np.column_stack([2 * flat, np.ones(len(flat))])
    return np.linalg.lstsq(design, np.sum(flat ** 2, axis=1), rcond=None)[0][:2]


def _widest_gap(mesh: trimesh.Trimesh, triangles: np.ndarray, frame: np.ndarray, centre: np.ndarray) -> float:
    """The widest angle [rad] about ``centre`` (across the axis, in ``frame``) between the
    corners of ``triangles`` (2 pi when they have none)."""
    if len(triangles) == 0:
        return 2 * np.pi
    flat = mesh.vertices[np.unique(mesh.faces[triangles].ravel())] @ frame.T - centre
    angles = np.sort(np.arctan2(flat[:, 1], flat[:, 0]))
    return float(np.max(np.diff(np.append(angles, angles[0] + 2 * np.pi))))


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


def _bands(mesh: trimesh.Trimesh, region: np.ndarray, smooth: np.ndarray) -> tuple[np.ndarray, list[np.ndarray]]:
    """The smooth ``region`` of ``mesh`` split where it stops being a band parallel to one
    axis. Adjacent triangles that bend (:data:`BEND`) bend about their normals' cross
    product: on a cylinder all about its axis, on an edge radius or a sphere about
    directions that vary. The axis is the bend shared (within :data:`TILT`) by most of the
    region's bending pairs (tried among :data:`CANDIDATES` of them), averaged over those; the
    bands are the connected sets of at least six of the region's triangles whose normals
    are perpendicular to it (within :data:`TILT`), joined by the ``smooth`` adjacencies: a
    bore's band, not its edge radii (their normals lean along the axis) nor the end faces
    beyond them. Each band is a cylinder only if :func:`_cylinder` finds it one. One axis a
    region: bands about another axis in the same smooth region are not looked for. The
    axis (a unit vector; any, with no band) and the bands."""
    inside = np.zeros(len(mesh.faces), dtype=bool)
    inside[region] = True
    pairs = smooth[inside[smooth].all(axis=1)]
    bends = np.cross(mesh.face_normals[pairs[:, 0]], mesh.face_normals[pairs[:, 1]])
    sizes = np.linalg.norm(bends, axis=1)
    bends = bends[sizes > BEND] / sizes[sizes > BEND, None]
    if len(bends) < 2:
        return np.eye(3)[2], []
    tried = bends[np.linspace(0, len(bends) - 1, min(CANDIDATES, len(bends))).astype(int)]
    shared = np.abs(tried @ bends.T) >= np.sqrt(1 - TILT ** 2)
    best = tried[np.argmax(shared.sum(axis=1))]
    along = bends[np.abs(bends @ best) >= np.sqrt(1 - TILT ** 2)]
    axis = np.linalg.eigh(along.T @ along)[1][:, -1]
    lateral = np.zeros(len(mesh.faces), dtype=bool)
    lateral[region] = np.abs(mesh.face_normals[region] @ axis) <= TILT
    return axis, list(trimesh.graph.connected_components(pairs[lateral[pairs].all(axis=1)], min_len=6))


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
    pair** (:func:`executor.cad.fits.threads.screwed_pairs`: a modelled thread, ``shaft`` the
    screw and ``bore`` the nut, a tapped hole drawn at its tap drill or a plain hole a cosmetic
    thread is drawn in: :func:`executor.cad.fits.threads.cosmetic_pairs`) has the thread's ``pitch`` and ``lead`` [m] (0
    for any other fit) and ``thread``, how it is drawn (the report's words)."""

    shaft: str
    bore: str
    face: CylinderFace | PrismFace
    hole: CylinderFace | PrismFace
    tolerance: float
    thinner: float
    seated: bool
    pitch: float = 0.0
    lead: float = 0.0
    thread: str = ""
    interference: float = 0.0

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


PRESS_FIT = 0.01
"""The most a shaft's cylinder may be wider than a coaxial bore's, relative to its radius,
to be named a press fit (:func:`press_fits`; ISO 286's interference fits are some
thousandths of the diameter): a wider one is no fit of the two."""


def coaxial(outer: list[CylinderFace | PrismFace], inner: list[CylinderFace | PrismFace]
            ) -> Iterator[tuple[CylinderFace, CylinderFace, float, float]]:
    """Every outward cylinder ``a`` of ``outer`` and inward one ``b`` of ``inner`` (one
    part's faces and another's), parallel (within 1e-4 rad) and coaxial within their
    tolerance (the larger deflection plus :data:`TOUCH`): (a, b, that tolerance [m], their
    axes' offset [m])."""
    for a in (f for f in outer if isinstance(f, CylinderFace) and f.outward):
        for b in (f for f in inner if isinstance(f, CylinderFace) and not f.outward):
            tolerance = max(a.deflection, b.deflection) + TOUCH
            if np.linalg.norm(np.cross(a.direction, b.direction)) > 1e-4:
                continue
            offset = b.point - a.point
            apart = float(np.linalg.norm(offset - a.direction * (offset @ a.direction)))
            if apart <= tolerance:
                yield a, b, tolerance, apart


def press_fits(faces: dict[str, list[CylinderFace | PrismFace]]) -> list[Slide]:
    """Every pair of an outward cylinder of one part and an inward one of another, parallel
    (within 1e-4 rad), coaxial within their tolerance (the larger deflection plus
    :data:`TOUCH`) and seated, the shaft's circle wider than the bore's by more than TOUCH
    and by at most :data:`PRESS_FIT` of its radius: a part drawn pressed into its bore.
    The circles are those of the faces' corners, which both tessellations put on the
    drawn circles: they tell a press fit of 0.025 mm per side from a zero-clearance fit
    however coarse the tessellations (the faces' own overlap, up to the larger deflection,
    is no interference). Each is a seated :class:`Slide` of that ``interference``, swept as
    a zero-clearance fit: the shaft's cylinder taken in to under the bore's radius
    (``thinner``: the interference, the bore's deflection, the axes' offset and :data:`TOUCH`)."""
    found: list[Slide] = []
    for shaft, outer in faces.items():
        for bore, inner in faces.items():
            if bore == shaft:
                continue
            for a, b, tolerance, apart in coaxial(outer, inner):
                if TOUCH < a.radius - b.radius <= PRESS_FIT * a.radius and _seated(a, b, tolerance):
                    thinner = a.radius - b.radius + b.deflection + apart + TOUCH
                    found.append(Slide(shaft, bore, a, b, tolerance, thinner, True, interference=a.radius - b.radius))
    return found


def zero_clearance_fits(faces: dict[str, list[CylinderFace | PrismFace]]) -> list[Slide]:
    """Every pair of an outward face of one part and an inward face of another: cylinders
    parallel (within 1e-4 rad), coaxial and of equal radius within their tolerance (the
    shaft's circle no wider than the bore's by more than :data:`TOUCH`: wider, it is
    pressed in, :func:`press_fits`); prisms
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
            for a, b, tolerance, apart in coaxial(outer, inner):
                if abs(a.radius - b.radius) <= tolerance and a.radius - b.radius <= TOUCH:
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


def _pressed_band(along: np.ndarray, radial: np.ndarray, slide: Slide) -> np.ndarray:
    """Which vertices of a press fit's shaft part (``along`` its axis and ``radial`` off
    it [m], :func:`near`) its sweep takes in: those between the bore's inner circle (its
    radius less its deflection and :data:`TOUCH`) and the shaft's outer one (its radius
    plus its tolerance), over the stretch of the two faces together: the shaft's face and
    the edge radii or chamfers that leave it wider than the bore, which would catch on the
    bore's rim."""
    face, hole = slide.face, slide.hole
    span = hole.span if face.direction @ hole.direction > 0 else (-hole.span[1], -hole.span[0])
    low, high = min(face.span[0], span[0]) - slide.tolerance, max(face.span[1], span[1]) + slide.tolerance
    distance = np.linalg.norm(radial, axis=1)
    return ((distance >= hole.radius - hole.deflection - TOUCH) & (distance <= face.radius + slide.tolerance)
            & (along >= low) & (along <= high))


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
        if slide.interference and face is slide.face:
            on = _pressed_band(along, radial, slide)
        mated |= np.all(on[mesh.faces], axis=1) & (np.abs(mesh.face_normals @ face.direction) < TILT)
        if face is slide.face:
            distance = np.linalg.norm(radial[on], axis=1)
            inward = slide.thinner * (distance / face.radius if isinstance(face, PrismFace) else 1.0)
            scale = np.maximum(distance - inward, 0.0) / distance
            vertices[on] = face.point + np.outer(along[on], face.direction) + radial[on] * scale[:, None]
    return trimesh.Trimesh(vertices, mesh.faces[~mated], process=False)
