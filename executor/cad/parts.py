"""Reading a product's parts in the assembled pose and checking them.

A source is a folder of ``*.stl``/``*.obj`` meshes (one part per file, the id is the file
name's stem, units given by the caller) or a STEP assembly (one part per leaf of its
assembly tree, the id from its name, the placement of the tree applied, units as the file
states them: the reader converts to mm). Every part becomes a :class:`trimesh.Trimesh` in
metres in the CAD frame; :func:`turned` turns them so that the CAD's up is the cell's +z
(``import --up``) and :func:`translated` moves them into the cell (``import --place``).

A mesh file is read within a size bound (:data:`MAX_TRIANGLES` for the product, its
triangles counted before the mesh is built), its coordinates must be finite (the line or
triangle of the first that is not is named) and its vertices are merged by position (an
OBJ that repeats a vertex once per normal or texture coordinate is one surface). An OBJ
whose objects are each closed but together no manifold (boxes that touch or overlap) is
their union (:func:`_united_objects`).

Checks (:func:`check_parts`; the last, the overlaps, can run in a process of its own
while the import goes on: :func:`overlaps_checked`), each an :class:`executor.ExecutorError` naming the part:
a mesh that is not closed (its boundary edges counted, one located), a closed mesh whose
triangles are wound inconsistently (made consistent when the part is one shell, refused
otherwise: which shells are cavities is not known), parts whose sizes differ by a factor the
units explain (one part in mm among parts in m), a product too small or too large for its
stated units, and parts that overlap (intersection volume above :data:`OVERLAP_VOLUME`,
leaving out what lies within a zero-clearance fit's tolerance of its two faces: coaxial
cylinders of one nominal radius, each tessellated on its own, overlap by up to the larger
deflection however coarse the tessellation; :func:`executor.cad.fits.faces.zero_clearance_fits`;
and the annulus a thread or a pressed shaft is drawn into its hole's wall by, over the
stretch the two share: :func:`executor.cad.fits.threads.screwed_pairs`,
:func:`executor.cad.fits.threads.cosmetic_pairs`, :func:`executor.cad.fits.faces.press_fits`).
"""

from __future__ import annotations

import contextlib
import fnmatch
import gc
import hashlib
import io
import itertools
import math
import multiprocessing
import multiprocessing.connection
import re
import traceback
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import BinaryIO

import manifold3d
import numpy as np
import shapely
import trimesh

from bridge.assembly import is_id
from executor import ExecutorError
from executor.cad.fits.faces import (
    TOUCH,
    CylinderFace,
    PrismFace,
    Slide,
    fit_faces,
    press_fits,
    zero_clearance_fits,
)
from executor.cad.fits.threads import cosmetic_pairs, lone_thread, screwed_pairs

UNITS = {"mm": 1e-3, "m": 1.0}
"""``--units``: metres per unit of a mesh file."""
MERGE_DIGITS = 11
"""A mesh's vertices are merged by their position [m] rounded to this many decimals (10⁻¹¹
m, 10⁻⁸ mm) whatever the file's unit: merged in the file's unit, a part in metres merged
vertices 4 nm apart that in millimetres stay two (Meta-World's ring was then refused)."""
MESH_SUFFIXES = (".stl", ".obj")
STEP_SUFFIXES = (".step", ".stp")
OVERLAP_VOLUME = 1e-9
"""Two parts overlap when their intersection, less what lies within their zero-clearance
fits' tolerance of the mated faces, is larger than this [m³] (1 mm³); touching faces and
fits with clearance have none."""
PRODUCT_EXTENT = (0.005, 5.0)
"""A product's largest extent must lie in this range [m] (a cell's products), else its
units are doubted."""
UNIT_RATIO = 300.0
"""A part larger than the median part by this factor (or smaller) is taken as a unit
mismatch (mm vs m is 1000)."""
STEP_DEFLECTION = 1e-6
"""Tessellation of STEP faces: largest distance of a triangle from its surface [m] (the
planes, cylinders and cones always; the other faces too where the product stays within its
bound of triangles, else :data:`executor.cad.step.COARSE_DEFLECTIONS`)."""
MAX_TRIANGLES = 1_000_000
"""The most triangles of a product's parts together (``import --max-triangles`` sets
another bound): the import's peak memory grows by about 1.9 kB per triangle (a plate and
a peg of 290k triangles: 0.53 GB, of 416k: 0.76 GB), so 1 million stay near 1.9 GB."""
_STL_HEADER = 84
"""A binary STL's bytes before its triangles (an 80-byte header, then the count, uint32)."""
_STL_TRIANGLE = 50
"""A binary STL's bytes per triangle."""


@dataclass(frozen=True)
class Cylinder:
    """A cylindrical face of a part's B-rep: a ``point`` (3,) [m] on its axis, the axis
    ``direction`` (3,) (unit) and the ``radius`` [m], in the frame of its mesh."""

    point: np.ndarray
    direction: np.ndarray
    radius: float


@dataclass(frozen=True)
class CadPart:
    """One part in the assembled pose: ``id`` (an ASP constant), the ``name`` the source
    gives, its closed ``mesh`` [m] in the CAD frame (the cell frame once :func:`turned` and :func:`translated`),
    ``source`` (file, or file#name), the ``cylinders`` of its B-rep and ``remesh``, its
    B-rep tessellated again to a given linear deflection [m] (a STEP part's; none for a mesh);
    ``coarse_faces``, how many faces of its B-rep (no plane, cylinder or cone) its mesh
    holds within ``coarse_deflection`` [m] instead of :data:`STEP_DEFLECTION`."""

    id: str
    name: str
    mesh: trimesh.Trimesh
    source: str
    cylinders: tuple[Cylinder, ...] = ()
    remesh: Callable[[float], trimesh.Trimesh] | None = None
    coarse_faces: int = 0
    coarse_deflection: float = STEP_DEFLECTION


def _mapped(parts: list[CadPart], point: Callable[[np.ndarray], np.ndarray],
            direction: Callable[[np.ndarray], np.ndarray]) -> list[CadPart]:
    """The parts with every point [m] mapped by ``point`` (their meshes' vertices, their
    B-rep cylinders' points, the meshes ``remesh`` makes) and their cylinders' directions by
    ``direction`` (the parts given are not changed)."""
    def mapped_mesh(mesh: trimesh.Trimesh) -> trimesh.Trimesh:
        copy = mesh.copy()
        copy.vertices = point(np.asarray(mesh.vertices))
        return copy

    def mapped_remesh(remesh: Callable[[float], trimesh.Trimesh]) -> Callable[[float], trimesh.Trimesh]:
        return lambda deflection: mapped_mesh(remesh(deflection))

    return [replace(part, mesh=mapped_mesh(part.mesh),
                    cylinders=tuple(replace(c, point=point(c.point), direction=direction(c.direction))
                                    for c in part.cylinders),
                    remesh=None if part.remesh is None else mapped_remesh(part.remesh)) for part in parts]


def translated(parts: list[CadPart], offset: tuple[float, float, float]) -> list[CadPart]:
    """The parts moved by ``offset`` (x, y, z) [m]: their meshes, their B-rep cylinders
    and the meshes of ``remesh`` (the parts given are not changed)."""
    shift = np.array(offset, dtype=float)
    if not shift.any():
        return parts
    return _mapped(parts, lambda points: points + shift, lambda direction: direction)


UP_AXES = ("+x", "-x", "+y", "-y", "+z", "-z")
"""The CAD axes that ``import --up`` may name as the one pointing up."""
_TURNS: dict[str, tuple[tuple[int, int, int], tuple[float, float, float], str]] = {
    "+z": ((0, 1, 2), (1.0, 1.0, 1.0), "no turn"),
    "-z": ((0, 1, 2), (1.0, -1.0, -1.0), "about x by 180 deg"),
    "+y": ((0, 2, 1), (1.0, -1.0, 1.0), "about x by 90 deg"),
    "-y": ((0, 2, 1), (1.0, 1.0, -1.0), "about x by -90 deg"),
    "+x": ((2, 1, 0), (-1.0, 1.0, 1.0), "about y by -90 deg"),
    "-x": ((2, 1, 0), (1.0, 1.0, -1.0), "about y by 90 deg"),
}
"""Each ``up`` axis -> the rotation taking it to +z as a permutation with signs (the cell's
coordinate k is ``signs[k]`` times the CAD's coordinate ``order[k]``; a proper rotation,
determinant +1, so a mesh keeps its outward winding) and its description."""


def turn_text(up: str) -> str:
    """The rotation of :func:`turned` for ``up`` in words: ``about x by 90 deg, (x, y, z) -> (x, -z, y)``."""
    order, signs, about = _TURNS[up]
    image = ", ".join(("-" if sign < 0 else "") + "xyz"[k] for k, sign in zip(order, signs, strict=True))
    return f"{about}, (x, y, z) -> ({image})"


def turn_points(points: np.ndarray, up: str) -> np.ndarray:
    """``points`` (..., 3) in the CAD frame turned so that its axis ``up`` points along +z:
    coordinates permuted and negated, so exactly (no rounding; -0 made 0)."""
    order, signs, _ = _TURNS[up]
    return points[..., list(order)] * np.array(signs) + 0.0


def turned(parts: list[CadPart], up: str) -> list[CadPart]:
    """The parts turned so that the CAD's axis ``up`` (one of :data:`UP_AXES`) points
    along the cell's +z (:func:`turn_points`): their meshes, their B-rep cylinders' points
    and directions and the meshes of ``remesh`` (the parts given are not changed)."""
    if up == "+z":
        return parts
    return _mapped(parts, lambda points: turn_points(points, up), lambda direction: turn_points(direction, up))


def quarter_turned(parts: list[CadPart], turn: int) -> list[CadPart]:
    """The parts turned by ``turn`` [deg, a multiple of 90] about the z axis, counterclockwise
    seen from above: x and y permuted and negated, so exactly (their meshes, their B-rep
    cylinders' points and directions and the meshes of ``remesh``; the parts given are not
    changed)."""
    quarters = turn // 90 % 4
    if not quarters:
        return parts

    def turn_xy(points: np.ndarray) -> np.ndarray:
        for _ in range(quarters):
            points = np.stack([-points[..., 1], points[..., 0], points[..., 2]], axis=-1)
        return points + 0.0

    return _mapped(parts, turn_xy, turn_xy)


PART_ID_CHARS = 48
"""The longest part id the import makes from a name: the ids of a part's features add to
it (``_hole12``, ``_pin3``) within the 64 characters of an id."""


def part_id(name: str, source: str) -> str:
    """An ASP constant from a file stem or a STEP name (lower case, ``_`` for other
    characters, ``part_`` before a leading digit: a part number, ``01_02_01-block``; one
    longer than :data:`PART_ID_CHARS` cut to its first 39 characters and 8 hex digits of
    its SHA-1, so that names alike to their end stay apart); ExecutorError naming
    ``source`` when none can be made."""
    candidate = re.sub(r"[^a-z0-9_]", "_", name.strip().lower())
    candidate = f"part_{candidate}" if candidate[:1].isdigit() else candidate
    if len(candidate) > PART_ID_CHARS:
        digest = hashlib.sha1(candidate.encode()).hexdigest()[:8]
        candidate = f"{candidate[:PART_ID_CHARS - 9]}_{digest}"
    if not is_id(candidate):
        raise ExecutorError(f"{source}: part name {name!r} gives no part id (expected a letter first, "
                            "then letters, digits or _)")
    return candidate


_LISTED = 8
"""The ids an unmatched ``leave_out`` or ``one_part`` name lists (the others counted)."""

Kept = Callable[[list[str]], set[str]]
"""Of a product's part ids, as read and before any is tessellated or counted, those to keep."""


def matching(ids: Sequence[str], names: Sequence[str], setting: str, what: str = "part") -> set[str]:
    """The ``ids`` one of ``names`` matches (an id or an ``fnmatch`` pattern on ids,
    ``screw_*``; compared in lower case, as ids are made: :func:`part_id`); ExecutorError
    naming ``setting`` when a name matches no id (listing a few, each one ``what``)."""
    matched: set[str] = set()
    for name in names:
        hits = fnmatch.filter(ids, name.strip().lower())
        if not hits:
            listed = ", ".join(sorted(set(ids))[:_LISTED]) or "none"
            more = f" and {len(set(ids)) - _LISTED} more" if len(set(ids)) > _LISTED else ""
            raise ExecutorError(f"{setting}: {name!r} matches no {what} (expected a {what} id or a pattern such as "
                                f"'screw_*' on the ids: {listed}{more})")
        matched.update(hits)
    return matched


def left_out(ids: Sequence[str], names: Sequence[str], setting: str) -> set[str]:
    """The ``ids`` one of ``names`` matches (:func:`matching`); ExecutorError naming
    ``setting`` when a name matches no id or every id matches."""
    matched = matching(ids, names, setting)
    if matched == set(ids):
        raise ExecutorError(f"{setting}: every part left out (expected some part kept)")
    return matched


def load_meshes(folder: Path, units: str, max_triangles: int = MAX_TRIANGLES,
                kept: Kept | None = None) -> list[CadPart]:
    """Every ``*.stl``/``*.obj`` of ``folder`` as a part, scaled by ``units`` to metres,
    its vertices merged by position (:data:`MERGE_DIGITS`); ExecutorError naming the file when the files hold
    more than ``max_triangles`` together or a coordinate is not finite; only the files whose
    ids ``kept`` keeps are counted and read (None: all)."""
    files = sorted(p for p in folder.iterdir() if p.suffix.lower() in MESH_SUFFIXES)
    if not files:
        raise ExecutorError(f"{folder}: no mesh files (expected *.stl or *.obj, one per part)")
    if kept is not None:
        keep = kept([part_id(path.stem, str(path)) for path in files])
        files = [path for path in files if part_id(path.stem, str(path)) in keep]
    parts: list[CadPart] = []
    total = 0
    for path in files:
        total = count_triangles(str(path), triangles_in(path), total, max_triangles)
        try:
            mesh = trimesh.load(path, force="mesh", process=False)  # processing drops non-finite vertices
        except (ValueError, OSError, IndexError) as exc:
            raise ExecutorError(f"{path}: not a readable mesh ({exc})") from None
        if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
            raise ExecutorError(f"{path}: no triangles (expected one closed mesh per part)")
        if not np.all(np.isfinite(mesh.vertices)):
            raise ExecutorError(f"{_non_finite(path, mesh)}: a coordinate that is not a finite number (expected "
                                "finite coordinates)")
        mesh.apply_scale(UNITS[units])
        mesh.merge_vertices(merge_tex=True, merge_norm=True, digits_vertex=MERGE_DIGITS)
        if not mesh.is_watertight and path.suffix.lower() == ".obj":
            mesh = _united_objects(path, UNITS[units]) or mesh
        parts.append(CadPart(part_id(path.stem, str(path)), path.stem, mesh, str(path)))
    return parts


def _united_objects(path: Path, scale: float) -> trimesh.Trimesh | None:
    """The union of an OBJ's objects (its ``o`` records) as one closed mesh [m], each
    object scaled by ``scale`` and taken as a solid of its own (its triangles wound
    consistently and outwards); None when the file has fewer than two objects or one of
    them is not closed (the part's crack is then located as for any open mesh); objects
    are told apart by their records, not their names. A part modelled as boxes that touch
    or overlap, each closed (Blender's objects, a MuJoCo model's convex pieces joined in
    one file), is one mesh with edges of four faces and T-junctions, not a manifold: the
    union (exact booleans, manifold3d in double precision) is the solid the objects fill."""
    count = itertools.count()  # each record its own object: Blender names repeat in files joined together
    text = re.sub(rb"(?m)^o\b[^\r\n]*", lambda _: b"o object_%d" % next(count), path.read_bytes())
    scene = trimesh.load(io.BytesIO(text), file_type="obj", split_objects=True, group_material=False, process=False)
    objects = list(scene.geometry.values()) if isinstance(scene, trimesh.Scene) else []
    if len(objects) < 2:
        return None
    solids = []
    for shell in objects:
        shell.apply_scale(scale)
        shell.merge_vertices(merge_tex=True, merge_norm=True, digits_vertex=MERGE_DIGITS)
        if not shell.is_watertight:
            return None
        if not shell.is_winding_consistent:
            trimesh.repair.fix_winding(shell)
        if shell.volume < 0:
            shell.invert()
        solids.append(manifold3d.Manifold(manifold3d.Mesh64(
            vert_properties=np.asarray(shell.vertices, dtype=np.float64),
            tri_verts=np.asarray(shell.faces, dtype=np.uint32))))
    union = manifold3d.Manifold.batch_boolean(solids, manifold3d.OpType.Add).to_mesh64()
    return trimesh.Trimesh(np.asarray(union.vert_properties)[:, :3], np.asarray(union.tri_verts), process=False)


def count_triangles(source: str, count: int, total: int, bound: int) -> int:
    """``total`` plus the ``count`` triangles of ``source``; ExecutorError naming it when
    that exceeds ``bound``."""
    if total + count > bound:
        before = f" (with the {total} before it, {total + count})" if total else ""
        raise ExecutorError(f"{source}: {count} triangles{before}, beyond the bound of {bound} for a product "
                            "(the import needs about 1.9 kB of memory per triangle; --max-triangles N raises it)")
    return total + count


def triangles_in(path: Path) -> int:
    """The triangles of a mesh file, counted without building the mesh: a binary STL's
    count (its header's, when the file's size matches it), an ASCII STL's ``endfacet``
    records, an OBJ's faces (a face of n corners is n - 2 triangles)."""
    binary = _binary_stl(path)
    if binary is not None:
        return binary
    with path.open("rb") as file:
        if path.suffix.lower() == ".stl":
            return _occurrences(file, b"endfacet")
        return sum(max(len(line.split()) - 3, 0) for line in file if line[:2] in (b"f ", b"f\t"))


def _binary_stl(path: Path) -> int | None:
    """The triangles a binary STL's header states, None when ``path`` is no STL or its
    size does not match that count (an ASCII STL, whose first line may look alike)."""
    if path.suffix.lower() != ".stl":
        return None
    with path.open("rb") as file:
        head = file.read(_STL_HEADER)
    count = int.from_bytes(head[80:], "little")
    return count if len(head) == _STL_HEADER and path.stat().st_size == _STL_HEADER + _STL_TRIANGLE * count else None


def _occurrences(file: BinaryIO, word: bytes) -> int:
    """How often ``word`` occurs in the rest of ``file`` (read in blocks)."""
    count, carry = 0, b""
    while block := file.read(1 << 20):
        text = carry + block
        count += text.count(word)
        carry = text[-(len(word) - 1):]  # too short to hold a whole word: none is counted twice
    return count


def _non_finite(path: Path, mesh: trimesh.Trimesh) -> str:
    """Where ``path`` first states a coordinate that is not finite: ``file:line`` of a
    text file's vertex, else the binary STL's triangle (``mesh`` read unprocessed)."""
    keyword = b"v" if path.suffix.lower() == ".obj" else b"vertex"
    if _binary_stl(path) is None:
        with path.open("rb") as file:
            for number, line in enumerate(file, 1):
                words = line.split()
                if words[:1] == [keyword] and not all(math.isfinite(_number(w)) for w in words[1:4]):
                    return f"{path}:{number}"
    triangle = int(np.argmax(~np.all(np.isfinite(mesh.vertices[mesh.faces]), axis=(1, 2))))
    return f"{path}: triangle {triangle + 1}"


def _number(word: bytes) -> float:
    """``word`` as a float, 0 when it is none (the mesh reader accepted the file)."""
    try:
        return float(word)
    except ValueError:
        return 0.0


def check_parts(parts: list[CadPart], units: str) -> None:
    """The checks of the module docstring, in that order; ExecutorError naming the part."""
    check_solids(parts, units)
    _check_overlaps(parts)


def check_solids(parts: list[CadPart], units: str) -> None:
    """The checks of the module docstring but the overlaps (:func:`overlaps_checked`), in
    that order; ExecutorError naming the part."""
    seen: dict[str, str] = {}
    for part in parts:
        if part.id in seen:
            raise ExecutorError(f"{part.source}: part id '{part.id}' also given by {seen[part.id]}")
        seen[part.id] = part.source
        _make_solid(part, units)
    extents = {p.id: float(np.max(p.mesh.extents)) for p in parts}
    median = float(np.median(list(extents.values())))
    for part in parts:
        ratio = extents[part.id] / median
        if ratio > UNIT_RATIO or ratio < 1 / UNIT_RATIO:
            raise ExecutorError(f"{part.source}: part '{part.id}' is {ratio:.3g} times the median part's size "
                                f"({1000 * extents[part.id]:.4g} vs {1000 * median:.4g} mm): a unit mismatch "
                                "(expected all parts in one unit)")
    lower, upper = np.min([p.mesh.bounds[0] for p in parts], axis=0), np.max([p.mesh.bounds[1] for p in parts],
                                                                                 axis=0)
    size = float(np.max(upper - lower))
    if not PRODUCT_EXTENT[0] <= size <= PRODUCT_EXTENT[1]:
        raise ExecutorError(f"the product is {size:.4g} m across with --units {units}: a unit mismatch "
                            f"(expected {PRODUCT_EXTENT[0]} to {PRODUCT_EXTENT[1]} m; try the other --units)")


def _make_solid(part: CadPart, units: str) -> None:
    """Check that ``part``'s mesh is closed (ExecutorError locating a crack in ``units``),
    wind its triangles consistently (ExecutorError naming it when it has several shells)
    and outwards."""
    mesh = part.mesh
    if not mesh.is_watertight:
        edges, uses = np.unique(mesh.edges_sorted, axis=0, return_counts=True)
        start, end = mesh.vertices[edges[np.argmax(uses != 2)]] / UNITS[units]
        raise ExecutorError(f"{part.source}: part '{part.id}' is an open mesh ({int(np.sum(uses == 1))} boundary "
                            f"edges, {int(np.sum(uses > 2))} edges of more than two faces; one from "
                            f"({', '.join(f'{v:.6g}' for v in start)}) to ({', '.join(f'{v:.6g}' for v in end)}) "
                            f"{units}; expected a closed manifold solid)")
    if not mesh.is_winding_consistent and mesh.body_count == 1:
        trimesh.repair.fix_winding(mesh)
    if not mesh.is_winding_consistent:
        why = ("which shells are cavities is not known" if mesh.body_count > 1 else
               "no winding makes it so: a surface with one side")
        raise ExecutorError(f"{part.source}: part '{part.id}' is a closed mesh of {mesh.body_count} "
                            f"shell{'s' if mesh.body_count > 1 else ''} whose "
                            "triangles are wound inconsistently (expected each edge run in opposite directions by its "
                            f"two triangles; {why})")
    if mesh.volume < 0:
        mesh.invert()
    if not mesh.is_volume:
        raise ExecutorError(f"{part.source}: part '{part.id}' encloses no volume (expected a solid)")


@contextlib.contextmanager
def overlaps_checked(parts: list[CadPart], forked: bool) -> Iterator[Callable[[], None]]:
    """The overlap check of ``parts`` (the last of :func:`check_parts`) around the block,
    which is handed the function that starts it: with ``forked``, in a process forked when
    the block calls that function (the two share nothing: the check only reads the parts;
    the import calls it where its own process would otherwise run alone, as the sweeps
    begin), its ExecutorError raised on leaving, before any error of the block, as when it
    ran first (not started by then, it runs on leaving); else before the block, the
    function doing nothing."""
    if not forked:
        _check_overlaps(parts)
        yield lambda: None
        return
    started: list[tuple[multiprocessing.connection.Connection, multiprocessing.process.BaseProcess]] = []

    def start() -> None:
        if started:
            return
        receiver, sender = multiprocessing.get_context("fork").Pipe(duplex=False)
        child = multiprocessing.get_context("fork").Process(target=_overlaps_to, args=(parts, sender), daemon=True)
        child.start()
        sender.close()
        started.append((receiver, child))

    try:
        yield start
    except Exception:
        if not started:  # the block failed before it started the check: the check's error first
            _check_overlaps(parts)
        raise
    finally:
        if started:
            receiver, child = started[0]
            try:
                found = receiver.recv()
            except EOFError:  # it ended without an answer (killed)
                found = None
            child.join()
            if found is None and child.exitcode != 0:
                found = ("crash", f"its process ended with exit code {child.exitcode}")
            receiver.close()
            if found is not None:
                kind, text = found
                raise ExecutorError(text) if kind == "error" else RuntimeError(f"the overlap check failed:\n{text}")
    if not started:
        _check_overlaps(parts)


def _overlaps_to(parts: list[CadPart], sender: multiprocessing.connection.Connection) -> None:
    """In the process :func:`overlaps_checked` forks: :func:`_check_overlaps`, its answer
    sent (None: no overlap; ``("error", message)`` its ExecutorError; ``("crash",
    traceback)`` any other exception). The objects it inherits are frozen for the garbage
    collector, as in a pool's workers (:func:`bridge.cli_types.forked_worker`)."""
    gc.freeze()
    try:
        _check_overlaps(parts)
        found = None
    except ExecutorError as exc:
        found = ("error", str(exc))
    except Exception:  # noqa: BLE001  (handed to the parent, which raises it)
        found = ("crash", traceback.format_exc())
    sender.send(found)
    sender.close()


def _check_overlaps(parts: list[CadPart]) -> None:
    """ExecutorError naming the first pair whose intersection exceeds :data:`OVERLAP_VOLUME`
    (exact booleans by manifold3d on the pairs whose bounding boxes meet), less what of it
    lies within their zero-clearance fits' tolerance of the mated faces (:func:`_beyond_fits`)."""
    faces: dict[str, list[CylinderFace | PrismFace]] = {}
    solids: dict[str, manifold3d.Manifold] = {}
    for i, a in enumerate(parts):
        for b in parts[i + 1:]:
            low = np.maximum(a.mesh.bounds[0], b.mesh.bounds[0])
            high = np.minimum(a.mesh.bounds[1], b.mesh.bounds[1])
            if np.any(high - low <= 0):
                continue
            for part in (a, b):
                if part.id not in solids:
                    solids[part.id] = _manifold(part.mesh)
            common = solids[a.id] ^ solids[b.id]
            volume = max(common.volume(), 0.0)
            if volume > OVERLAP_VOLUME:
                for part in (a, b):
                    if part.id not in faces:
                        faces[part.id] = fit_faces(part.mesh)
                seated = [s for s in zero_clearance_fits({a.id: faces[a.id], b.id: faces[b.id]}) if s.seated]
                volume = _beyond_fits(common, seated)
            if volume > OVERLAP_VOLUME:  # a thread or a pressed shaft in its hole's wall: excused in its annulus
                annuli = (screwed_pairs({a.id: a.mesh, b.id: b.mesh})
                          or cosmetic_pairs({a.id: faces[a.id], b.id: faces[b.id]}))
                annuli += press_fits({a.id: faces[a.id], b.id: faces[b.id]})
                if annuli:
                    volume = _beyond_fits(_beyond_annuli(common, annuli), seated)
            if volume > OVERLAP_VOLUME:
                raise ExecutorError(f"{b.source}: parts '{a.id}' and '{b.id}' overlap by "
                                    f"{volume * 1e9:.4g} mm³ in the assembled pose (expected solids "
                                    "that at most touch, or coaxial cylinders of one radius within their "
                                    "tessellations' deflection)" + lone_thread({a.id: a.mesh, b.id: b.mesh}))


TUBE_SEGMENTS = 256
"""Sides of the polygonal tube :func:`_beyond_annuli` cuts an annulus with."""


def _beyond_annuli(common: manifold3d.Manifold, pairs: list[Slide]) -> manifold3d.Manifold:
    """The intersection ``common`` of two parts less, for each screwed pair or press fit of ``pairs``
    (:func:`executor.cad.fits.threads.screwed_pairs`, :func:`executor.cad.fits.threads.cosmetic_pairs`,
    :func:`executor.cad.fits.faces.press_fits`), the annulus about its axis from the hole's
    radius (less its deflection and :data:`TOUCH`) out to the shaft's radius (a thread's
    major; plus its deflection and TOUCH, the polygon's sides outside that circle) over the
    stretch both faces share (plus TOUCH at each end): the screw's thread, or the pressed
    shaft, drawn into the hole's wall."""
    for slide in pairs:
        face, hole = slide.face, slide.hole
        span = hole.span if face.direction @ hole.direction > 0 else (-hole.span[1], -hole.span[0])
        low, high = max(face.span[0], span[0]) - TOUCH, min(face.span[1], span[1]) + TOUCH
        if high <= low:
            continue
        outer = (face.radius + face.deflection + TOUCH) / np.cos(np.pi / TUBE_SEGMENTS)
        inner = max(hole.radius - hole.deflection - TOUCH, 0.0)
        tube = (manifold3d.Manifold.cylinder(high - low, outer, outer, TUBE_SEGMENTS)
                - manifold3d.Manifold.cylinder(high - low, inner, inner, TUBE_SEGMENTS))
        across = np.eye(3)[int(np.argmin(np.abs(face.direction)))]
        first = np.cross(face.direction, across)
        first /= np.linalg.norm(first)
        frame = np.column_stack([first, np.cross(face.direction, first), face.direction,
                                 face.point + low * face.direction])
        common = common - tube.transform(frame)
    return common


def _manifold(mesh: trimesh.Trimesh) -> manifold3d.Manifold:
    """A closed ``mesh`` as manifold3d takes it in trimesh's booleans (single precision),
    made once per part: its triangle index (its collider) is built with it and serves
    every pair the part is in."""
    return manifold3d.Manifold(manifold3d.Mesh(vert_properties=np.array(mesh.vertices, dtype=np.float32),
                                               tri_verts=np.array(mesh.faces, dtype=np.uint32)))


def _beyond_fits(common: manifold3d.Manifold, slides: list[Slide]) -> float:
    """The volume [m³] of the intersection ``common`` outside every fit's tolerance of its
    shaft's and its bore's faces (:func:`_near_face`: the overlap of two tessellations of one
    nominal cylinder, as the sweeps take it, :mod:`executor.cad.sweep`). A volume, not a
    count of pieces: the booleans' triangulation of ``common`` differs with the order of the
    two parts (a sheet of touching end faces joins its pieces in one order only)."""
    for slide in slides:
        for face in (slide.face, slide.hole):
            common = common - _near_face(face, slide.tolerance)
    return max(common.volume(), 0.0)


def _near_face(face: CylinderFace | PrismFace, tolerance: float) -> manifold3d.Manifold:
    """The solid of the points within ``tolerance`` [m] of ``face`` (of its radius or its
    outline) and of its span (:func:`executor.cad.fits.faces.near`), a little wider: a circle
    is a polygon around it, its inner one within it, of sides whose sagitta is at most a
    tenth of ``tolerance``."""
    across = np.linalg.svd(face.direction[None, :])[2][1:] if isinstance(face, CylinderFace) else face.frame
    swapped = np.linalg.det(np.array([*across, face.direction])) < 0  # the solid's frame turned, not mirrored
    across = across[::-1] if swapped else across
    if isinstance(face, CylinderFace):
        sides = max(8, math.ceil(math.pi / math.acos(1 - min(tolerance / 10 / (face.radius + tolerance), 1.0))))
        centre = shapely.Point(across @ face.point)
        outer = centre.buffer((face.radius + tolerance) / math.cos(math.pi / sides), quad_segs=math.ceil(sides / 4))
        band = outer.difference(centre.buffer(max(face.radius - tolerance, 0.0), quad_segs=math.ceil(sides / 4)))
    else:
        outline = shapely.Polygon(np.asarray(face.outline.exterior.coords)[:, ::-1 if swapped else 1])
        band = outline.buffer(tolerance).difference(outline.buffer(-tolerance))
    contours = [np.asarray(ring.coords)[:-1] for polygon in getattr(band, "geoms", [band])
                for ring in (shapely.geometry.polygon.orient(polygon, 1.0).exterior,
                             *shapely.geometry.polygon.orient(polygon, 1.0).interiors)]
    low, high = face.span
    solid = manifold3d.Manifold.extrude(manifold3d.CrossSection(contours), high - low + 2 * tolerance)
    turn = np.column_stack([*across, face.direction, face.direction * (float(face.point @ face.direction) + low
                                                                       - tolerance)])
    return solid.transform(turn)
