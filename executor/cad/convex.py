"""Parts the simulated cell builds from their own meshes, decided and written at import.

A peg or a head is a **primitive** when its mesh's volume is within
:data:`PRIMITIVE_TOLERANCE` of the prism of its cross-section over its length (a cylinder,
a box or a polygon peg's prism of its outline: the cell builds it as one; a head's box has
the cell's axes); a cover when the
symmetric difference of its mesh and the cell's cover (its outline less square openings
of its holes' sizes plus its clearance, and its socket) is within that of its volume;
the base when its volume is within that of its bounding box less its holes (cross-section
times depth: the cell's plate) and each hole is the prism of its section
(:func:`straight_walls`: a tapered mortise is not, though its volume is). Any other part is written as its own mesh
(``meshes/<id>.obj``, Wavefront OBJ [m]): a peg in its part frame (origin at the centre of
its section at its bottom, z up its axis, x along its section's long side), a cover in its
frame (origin at the centre of the holes it goes over at its bottom, the cell's axes), a
head in its (the centre of its section at its bottom, the cell's axes), the base in the
cell frame. A moving part also gets its convex pieces
(``meshes/<id>.convex.obj``, one OBJ object each, the first line naming the mesh and its
SHA-256): its convex hull when the hull's volume is within :data:`CONVEX_TOLERANCE` of
the mesh's, else (for a peg with a layer thinner than the cell collides as within the
section next to it, the prisms of its sections first: :func:`executor.world.rings.prism_pieces`) a convex
decomposition by CoACD (seeds :data:`SEEDS`, so an import is repeatable),
each piece cut down to at most :data:`PIECE_VERTICES` of its vertices (the cell's contact
cost grows with them: a 900-vertex piece ran 40 steps/s, a 32-vertex one 270), each next
one the farthest beyond the hull of those kept; the file's second line states how far the dropped vertices
reach beyond the kept pieces' face planes. The pieces must fit where the part is: they
must leave each part near it (:data:`NEAR`: a cover's pins and head, a head's cover, a
peg's base) :data:`ROOM_KEPT` of the room its mesh leaves it, and overlap none it touches
(measured with python-fcl in the assembled pose) but one at a stated zero-clearance fit or
passage with it (:class:`executor.cad.fits.faces.Slide`: the mesh leaves it room 0, and a
decomposition's hulls reach beyond the mesh by its error), which they may overlap by up to
:data:`NOMINAL_OVERLAP`; each piece at least 1.952 mm thick (the
cell's hull margin twice less what it resolves: :mod:`executor.world.meshes`); CoACD's
:data:`THRESHOLDS` are tried in turn with each seed until they do (the third line names the threshold, the seed
and the least room left), a seed's finer thresholds not after a piece too thin (a finer
threshold cuts more, smaller pieces: it is for pieces that took too much room), and
a part whose pieces never do is named and gets none (:func:`executor.cad.write.folder.write_folder`
places it by hand with why). The decomposition is made here, never when a cell starts.
"""

from __future__ import annotations

import contextlib
import contextvars
import hashlib
import io
import math
import resource
import signal
import subprocess
import sys
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path

import fcl
import numpy as np
import scipy.spatial
import shapely
import trimesh

from bridge.files import make_folder, write_atomic
from bridge.product import CONVEX_HEADER, Mesh
from bridge.product.nominal import NOMINAL_FIT_ROOM
from executor.assembly.product import Box
from executor.cad.derive import Derived, HoleFit
from executor.cad.fits.faces import TOUCH
from executor.cad.parts import STEP_DEFLECTION, CadPart
from executor.cad.sections import Shape2D, classify, exact_round, slice_loops
from executor.cad.sweep import bvh, convex_object
from executor.world import SIZE_RESOLUTION
from executor.world.meshes import MIN_THICKNESS, URDF_HULL_MARGIN, eroded, narrowed, obj_text
from executor.world.rings import Prisms, prism_pieces

PRIMITIVE_TOLERANCE = 0.01
"""A part is the primitive its sections describe when their volumes differ by less than
this fraction of the part's."""
CONVEX_TOLERANCE = 1e-3
"""A part is convex (one piece, its hull) when its hull is larger by less than this fraction."""
THRESHOLDS = (0.05, 0.03, 0.02, 0.01)
"""CoACD's concavity thresholds (the largest concavity left in a piece, relative to the
part's size) tried in turn, its default first, until the pieces fit (:data:`ROOM_KEPT`);
after a piece thinner than the cell's hull margin twice, none finer with that seed (the
rocker switch of nop_rocker_switches, 0.5 mm spade terminals: 23, 57 and 103 thin pieces
at 0.05, 0.03 and 0.02, 15, 24 and 38 s of CPU)."""
ITERATIONS = 150
"""CoACD's tree-search iterations per cut (its default)."""
SEEDS = (0, 1)
"""CoACD's random seeds, each with every threshold in turn until the pieces fit: a seed
can cut a piece thinner than the cell's hull margin twice where another cuts none (an
occt_pulley bolt, a hexagonal head on a d 6 shank, at seed 0)."""
ROOM_KEPT = 0.5
"""A part's convex pieces must leave each part near it at least this share of the room
its mesh leaves it in the assembled pose (a hull bridging an opening would fill it)."""
NEAR = 0.002
"""The parts whose bounding boxes come this close [m] to a part's are its neighbours."""
PIECE_VERTICES = 64
"""The most vertices a convex piece keeps (the 12 mm shaft of the tests then within 0.06 mm)."""
NOMINAL_OVERLAP = NOMINAL_FIT_ROOM
"""How deep [m] a part's convex pieces may overlap a part at a stated zero-clearance fit or
passage with it (their meshes touch: any decomposition error is an overlap there): the
room per side the simulated cell models a nominal zero-clearance fit with
(:data:`bridge.product.nominal.NOMINAL_FIT_ROOM`), so that in that model the pieces clear it."""
MESH_FOLDER = "meshes"
YAW_TOLERANCE = 0.01
"""A square section within this of the cell's axes [°] is not turned."""


def section_area(kind: str, a: float, b: float) -> float:
    """The area [m²] of a section: round of diameter a, square of side a, rect a × b."""
    return math.pi * a * a / 4 if kind == "round" else a * (a if kind == "square" else b)


def is_close(volume: float, primitive: float) -> bool:
    """Whether a part's ``volume`` and its primitive's [m³] differ by less than :data:`PRIMITIVE_TOLERANCE` of it."""
    return abs(volume - primitive) < PRIMITIVE_TOLERANCE * volume


def peg_is_primitive(fit: HoleFit, mesh: trimesh.Trimesh) -> bool:
    """Whether the peg in ``fit`` is the prism of its section over its length along z (a
    polygon section's: of its outline, which the cell builds as exact convex pieces)."""
    assert fit.section is not None  # a peg has a section
    section = fit.section
    area = (shapely.Polygon(section.outline).area if section.kind == "polygon"
            else section_area(section.kind, section.a, section.b))
    return is_close(mesh.volume, area * float(mesh.extents[2]))


WALL_LEVELS = (0.25, 0.75)
"""Where a hole's section is compared with its measured one (:func:`straight_walls`): these
fractions of the way from the foot of its entry chamfer to its bottom."""


def straight_walls(base: CadPart, fit: HoleFit) -> bool:
    """Whether hole ``fit`` of ``base``, entered from above, is the prism of its measured
    section (at mid-depth): its section at :data:`WALL_LEVELS` differs from it by at most
    :data:`executor.world.SIZE_RESOLUTION` per side. A tapered mortise is not (asap_beam's,
    2.5° per side: 0.11 mm per side a quarter of the way down): the cell's straight hole
    of its mid-depth section would stop a tapered tenon half way in."""
    up = np.array([0.0, 0.0, 1.0])
    for share in WALL_LEVELS:
        level = fit.entry - fit.chamfer - share * (fit.depth - fit.chamfer)
        loops = [loop for loop in slice_loops(base.mesh, up, level) if loop.contains(fit.hole.centre)]
        if not loops:
            return False
        here = exact_round(classify(min(loops, key=lambda loop: loop.area), hole=True), base.cylinders, up, level,
                           STEP_DEFLECTION)
        if max(abs(here.a - fit.hole.a), abs(here.b - fit.hole.b)) > 2 * SIZE_RESOLUTION:
            return False
    return True


def base_is_primitive(derived: Derived) -> bool:
    """Whether the base is its bounding box less its holes (each its section times its
    depth, :func:`straight_walls`); never with a polygon hole or one with rounded corners
    (the plate's bosses are round, square or sharp rect)."""
    base = derived.parts[derived.base]
    if any(fit.hole.kind == "polygon" or fit.hole.corner or not straight_walls(base, fit)
           for fit in derived.holes.values()):
        return False
    mesh = base.mesh
    holes = sum(section_area(fit.hole.kind, fit.hole.a, fit.hole.b) * fit.depth for fit in derived.holes.values())
    return is_close(mesh.volume, float(np.prod(mesh.extents)) - holes)


def cover_is_primitive(mesh: trimesh.Trimesh, boxes: Sequence[Box]) -> bool:
    """Whether a cover's ``mesh`` (in its frame) is the cell's solid of ``boxes`` (its
    outline less square openings: :func:`executor.assembly.product.cover_spec`):
    their symmetric difference is less than :data:`PRIMITIVE_TOLERANCE` of the mesh's
    volume. The boxes are disjoint, so it is both volumes less twice the mesh's
    intersections with each box (exact booleans, manifold3d)."""
    solid = sum(8 * float(np.prod(box.half)) for box in boxes)
    common = 0.0
    for box in boxes:
        piece = trimesh.creation.box(2 * np.asarray(box.half))
        piece.apply_translation(box.centre)
        inside = trimesh.boolean.intersection([mesh, piece], engine="manifold")
        common += float(inside.volume) if len(inside.faces) else 0.0
    return bool(mesh.volume + solid - 2 * common < PRIMITIVE_TOLERANCE * mesh.volume)


def head_is_primitive(section: Shape2D, mesh: trimesh.Trimesh) -> bool:
    """Whether a head is the cylinder or box of its ``section`` over its length along z with
    the cell's axes (the cell's head box is not turned: a square head with a yaw is none)."""
    turned = section.kind != "round" and abs(section.yaw) > YAW_TOLERANCE
    return not turned and is_close(mesh.volume, section_area(section.kind, section.a, section.b)
                                   * float(mesh.extents[2]))


def peg_frame(section: Shape2D, mesh: trimesh.Trimesh) -> np.ndarray:
    """The 4 × 4 transform from the cell frame to the part frame of a peg of ``section``
    (module docstring), or of a part with a bore of that ``section`` (its origin the centre
    of the bore at the part's bottom)."""
    x, y = section.centre
    yaw = math.radians(section.yaw) if section.kind != "round" else 0.0
    turn = trimesh.transformations.rotation_matrix(-yaw, (0, 0, 1))
    shift = trimesh.transformations.translation_matrix((-x, -y, -float(mesh.bounds[0][2])))
    return turn @ shift


PIECES_CPU = 60.0
"""The most CPU time [s] CoACD may spend on one part's pieces in an import, over all its
thresholds, seeds and tree searches (import.toml's ``pieces_cpu_s``): then the part gets
none, and is placed by hand with why. The corpus's longest search of pieces that fit took
17.5 s (a ring, two runs); a knob of 2414 triangles ran for minutes."""
_CHILD = """
import io, resource, sys
import numpy as np
limit = int(sys.argv[1])
resource.setrlimit(resource.RLIMIT_CPU, (limit, limit + 1))
import coacd
coacd.set_log_level("error")
given = np.load(io.BytesIO(sys.stdin.buffer.read()))
found = coacd.run_coacd(coacd.Mesh(given["vertices"], given["faces"]), threshold=float(sys.argv[2]),
                        seed=int(sys.argv[3]), mcts_iterations=int(sys.argv[4]))
out = io.BytesIO()
np.savez(out, *[np.asarray(vertices, dtype=float) for vertices, _ in found])
sys.stdout.buffer.write(out.getvalue())
"""
"""The program a CoACD run is made by, in a process of its own under a CPU limit [s] (its first argument)."""


class Budget:
    """The CPU time [s] CoACD may spend on each part's pieces (``seconds``) and what it has
    spent on each (by part id) in one import."""

    def __init__(self, seconds: float) -> None:
        self.seconds = seconds
        self.spent: dict[str, float] = {}

    def left(self, pid: str) -> float:
        """The CPU time [s] CoACD may still spend on part ``pid``."""
        return self.seconds - self.spent.get(pid, 0.0)


_BUDGET: contextvars.ContextVar[Budget | None] = contextvars.ContextVar("pieces_budget", default=None)
"""The budget of the import under way (None: each search of pieces gets :data:`PIECES_CPU` of its own)."""


@contextlib.contextmanager
def pieces_budget(seconds: float) -> Iterator[Budget]:
    """Within it, CoACD spends at most ``seconds`` of CPU on each part's pieces, over all its searches."""
    budget = Budget(seconds)
    token = _BUDGET.set(budget)
    try:
        yield budget
    finally:
        _BUDGET.reset(token)


def budget_assumption(seconds: float) -> str:
    """What ``import`` prints of the CPU time CoACD may spend on a part's pieces."""
    return (f"CoACD spends at most {seconds:g} s of CPU on one part's convex pieces (pieces_cpu_s; a part whose "
            "pieces are not found within it is placed by hand)")


class OverBudget(str):
    """Why a part has no convex pieces: CoACD's CPU time for it ran out."""


def _decomposed(pid: str, mesh: trimesh.Trimesh, threshold: float, seed: int, iterations: int, budget: Budget
                ) -> list[trimesh.Trimesh] | OverBudget:
    """CoACD's convex pieces of part ``pid``'s closed mesh at a concavity ``threshold``, a
    random ``seed`` and ``iterations`` of its tree search per cut, made in a process of its
    own (:data:`_CHILD`) under the CPU time part ``pid`` has left in ``budget``, which it
    is charged; or why not, when that runs out."""
    over = OverBudget(f"part '{pid}' has no convex pieces within {budget.seconds:g} s of CoACD's CPU time "
                      "(pieces_cpu_s in import.toml)")
    left = budget.left(pid)
    if left <= 0:
        return over
    given = io.BytesIO()
    np.savez(given, vertices=np.asarray(mesh.vertices, dtype=float), faces=np.asarray(mesh.faces, dtype=np.int64))
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    done = subprocess.run([sys.executable, "-c", _CHILD, str(math.ceil(left)), repr(threshold), str(seed),
                           str(iterations)], input=given.getvalue(), capture_output=True, check=False)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    budget.spent[pid] = budget.spent.get(pid, 0.0) + (after.ru_utime - before.ru_utime) + (
        after.ru_stime - before.ru_stime)
    if done.returncode in (-signal.SIGXCPU, -signal.SIGKILL) or budget.left(pid) < 0:  # its soft limit, hard one
        return over
    if done.returncode != 0:
        raise RuntimeError(f"CoACD failed on part '{pid}' (exit {done.returncode}): "
                           f"{done.stderr.decode(errors='replace')[-500:]}")
    found = np.load(io.BytesIO(done.stdout))
    return [trimesh.convex.convex_hull(found[name]) for name in found.files]


def _room(pieces: list[fcl.CollisionObject], other: fcl.CollisionObject) -> float:
    """The least distance [m] between ``pieces`` and ``other``; where they overlap, minus
    the deepest overlap."""
    room = math.inf
    for piece in pieces:
        found = fcl.CollisionResult()
        if fcl.collide(piece, other, fcl.CollisionRequest(num_max_contacts=100, enable_contact=True), found):
            room = min(room, -max((c.penetration_depth for c in found.contacts), default=0.0))
        else:
            room = min(room, fcl.distance(piece, other, fcl.DistanceRequest(), fcl.DistanceResult()))
    return room


def fitted(derived: Derived, pid: str) -> set[str]:
    """The parts at a stated zero-clearance fit or passage with part ``pid`` (either side)."""
    return ({s.bore for s in derived.slides if s.shaft == pid}
            | {s.shaft for s in derived.slides if s.bore == pid})


def overlap_assumption(derived: Derived) -> list[str]:
    """The assumption of :data:`NOMINAL_OVERLAP`, as ``import`` prints it (none without a
    zero-clearance fit or passage)."""
    return [f"convex pieces of a part may overlap a part at a zero-clearance fit or passage with it by up to "
            f"{1e3 * NOMINAL_OVERLAP:g} mm (a decomposition's error where the meshes touch; the room the cell "
            "models a nominal zero-clearance fit with)"] if derived.slides else []


def fitting_pieces(pid: str, mesh: trimesh.Trimesh, neighbours: dict[str, trimesh.Trimesh],
                   fits: frozenset[str] = frozenset(), thresholds: Sequence[float] = THRESHOLDS,
                   iterations: int = ITERATIONS, prisms: bool = False, only_prisms: bool = False
                   ) -> tuple[list[tuple[trimesh.Trimesh, float]], str] | str:
    """The convex pieces of part ``pid``'s closed mesh (module docstring; each with how far
    its dropped vertices reach) and a line on what they leave its ``neighbours`` (the
    parts near it in the assembled pose, in its frame); or why no decomposition leaves
    each of them :data:`ROOM_KEPT` of the room the mesh leaves it (touching: none
    deeper than :data:`executor.cad.fits.faces.TOUCH`; those in ``fits``, at a stated
    zero-clearance fit or passage with it: none deeper than :data:`NOMINAL_OVERLAP`)
    with every piece at least :data:`executor.world.meshes.MIN_THICKNESS` thick (CoACD's tree search
    making ``iterations`` per cut). For a peg (``prisms``) with a layer of parts thinner
    than that within the section next to it, which :func:`executor.world.rings.prism_pieces`
    fills to that section (a switch's 0.5 mm spade terminals under its body, which CoACD's
    pieces follow), the prisms of its sections are tried first, under the same checks;
    ``only_prisms``: its hull or those prisms alone, filled or not (a peg the cell narrows
    about its axis: :func:`write_mesh`). CoACD spends at most the import's
    :func:`pieces_budget` on the part (:data:`PIECES_CPU` outside an import):
    :class:`OverBudget` when it runs out."""
    allowed = {name: NOMINAL_OVERLAP if name in fits else TOUCH for name in neighbours}
    others = {name: bvh(other) for name, other in sorted(neighbours.items())}
    own = bvh(mesh)
    rooms = {name: fcl.distance(own, other, fcl.DistanceRequest(), fcl.DistanceResult())
             for name, other in others.items()}
    hull = mesh.convex_hull
    convex = hull.volume < (1 + CONVEX_TOLERANCE) * mesh.volume
    left: dict[str, float] = {}
    short: list[str] = []
    thin: set[int] = set()  # the seeds whose pieces were too thin at a threshold
    tries = 0
    budget = _BUDGET.get() or Budget(PIECES_CPU)
    found = prism_pieces(pid, mesh) if (prisms or only_prisms) and not convex else None
    if only_prisms and isinstance(found, str):
        return f"{found}; the cell narrows a peg whose pieces are its hull or the prisms of its sections only"
    stacked = found if isinstance(found, Prisms) and (found.filled > 0 or only_prisms) else None
    first = [] if stacked is None else [(-1, 0.0)]  # seed -1: the prisms
    coacd = [] if only_prisms else [(s, t) for s in SEEDS for t in thresholds]
    for seed, threshold in [(0, 0.0)] if convex else first + coacd:
        if seed in thin:
            continue  # a finer threshold cuts more, smaller pieces: it mends no piece too thin
        tries += 1
        if stacked is not None and seed < 0:
            kept = [reduced(piece) for piece, _ in stacked.pieces]
        else:
            made = [hull] if convex else _decomposed(pid, mesh, threshold, seed, iterations, budget)
            if isinstance(made, OverBudget):
                return OverBudget(f"{made}, {tries - 1} CoACD run(s) done")
            kept = [reduced(piece) for piece in made]
        if any(eroded(piece.vertices, URDF_HULL_MARGIN) is None for piece, _ in kept):
            thin.add(seed)
            continue  # a piece the cell cannot collide as
        objects = [convex_object(piece) for piece, _ in kept]
        left = {name: _room(objects, other) for name, other in others.items()}
        short = [name for name in others if left[name] < ROOM_KEPT * rooms[name] - allowed[name]]
        if not short:
            kind = "its hull" if convex else f"the prisms of its sections: {stacked.made}" if (
                stacked is not None and seed < 0) else (
                f"CoACD at threshold {threshold:g}" + (f", seed {seed}" if seed else "")
                                              + (f", {iterations} tree-search iterations" if iterations != ITERATIONS
                                                 else ""))
            apart = [name for name in rooms if rooms[name] > TOUCH]
            over = sorted(name for name in rooms if left[name] < -TOUCH)
            touching = (f"; they overlap none of the parts they touch ({' '.join(sorted(set(rooms) - set(apart)))})"
                        if not over else "; they overlap " + ", ".join(
                            f"{name} {-1e3 * left[name]:.3f} mm (a zero-clearance fit)" for name in over))
            if not apart:
                return kept, kind + (touching if rooms else "")
            name = min(apart, key=lambda n: left[n] / rooms[n])
            return kept, (f"{kind}; they leave {name} {1e3 * left[name]:.3f} of {1e3 * rooms[name]:.3f} mm"
                          + (touching if len(apart) < len(rooms) else ""))
    tried = "the prisms of its sections" if only_prisms else (
        ("the prisms of its sections, " if first else "")
        + f"CoACD's thresholds {', '.join(f'{t:g}' for t in thresholds)}, seeds {', '.join(map(str, SEEDS))}"
        + (f", {iterations} tree-search iterations" if iterations != ITERATIONS else "")
        + (f"; {tries} tried: seed(s) {', '.join(map(str, sorted(thin)))} no finer after a piece too thin"
           if thin else ""))
    if not short:
        return (f"part '{pid}' has no convex pieces the cell can collide as ({tried}: each gave a piece thinner than "
                f"{1e3 * MIN_THICKNESS:g} mm, the cell's hull margin twice less what it resolves)")
    name = min(short, key=lambda n: left[n] - ROOM_KEPT * rooms[n] + allowed[n])
    expected = (f"at a zero-clearance fit with it, expected an overlap of at most {1e3 * NOMINAL_OVERLAP:g} mm"
                if name in fits else f"expected at least {ROOM_KEPT:.0%}")
    return (f"the convex pieces of part '{pid}' leave '{name}' {1e3 * left[name]:.3f} mm of the "
            f"{1e3 * rooms[name]:.3f} mm its mesh leaves it ({tried}; {expected})")


def pin_pieces(pid: str, mesh: trimesh.Trimesh, pin: trimesh.Trimesh, allowed: float
               ) -> tuple[list[tuple[trimesh.Trimesh, float]], str] | str:
    """The convex pieces of part ``pid`` with a bore whose closed ``mesh`` is no stack of
    prisms (a torus ring): :func:`fitting_pieces` with its ``pin`` (the pin's solid in the
    part's frame, where the part rests on it) as its neighbour, which they may leave at most
    ``allowed`` [m] less room than the mesh leaves it (the cell's bore smaller by at most
    that, as :func:`executor.world.rings.coarser_bores`), CoACD's :data:`PIN_THRESHOLDS` tried
    in turn, each with :data:`PIN_ITERATIONS` in turn, within the part's CPU time
    (:func:`pieces_budget`); or why they do not. Made once for a mesh and the file written
    of it (alike within the 0.1 µm the file keeps) and a budget."""
    budget = _BUDGET.get()
    key = hashlib.sha256(pid.encode() + np.float64(allowed).tobytes() + np.round(pin.vertices, 7).tobytes()
                         + np.float64(PIECES_CPU if budget is None else budget.seconds).tobytes()
                         + _shape_key(mesh)).digest()
    if key not in _PIN_PIECES:
        _PIN_PIECES[key] = _pin_pieces(pid, mesh, pin, allowed)
    return _PIN_PIECES[key]


_PIN_PIECES: dict[bytes, tuple[list[tuple[trimesh.Trimesh, float]], str] | str] = {}
""":func:`pin_pieces` of each part, mesh and pin asked for."""


def _shape_key(mesh: trimesh.Trimesh) -> bytes:
    """The bytes of ``mesh``'s shape whatever the order of its vertices and faces: its
    vertices (:func:`apart`, on the 0.1 µm grid a written file keeps) in sorted order, and
    its triangles as the indices of their corners in that order, each turned to start at
    its least index (its winding kept), sorted. Two meshes alike within the grid have one
    key; the same vertices joined by other triangles (another shape) have another."""
    points, inverse = np.unique(np.round(apart(mesh.vertices), 7), axis=0, return_inverse=True)
    faces = inverse.reshape(-1)[np.asarray(mesh.faces)]
    first = np.argmin(faces, axis=1)[:, None]
    faces = np.take_along_axis(faces, (first + np.arange(3)) % 3, axis=1)
    faces = faces[np.lexsort(faces.T[::-1])]
    return points.tobytes() + faces.astype(np.int64).tobytes()


def _pin_pieces(pid: str, mesh: trimesh.Trimesh, pin: trimesh.Trimesh, allowed: float
                ) -> tuple[list[tuple[trimesh.Trimesh, float]], str] | str:
    """:func:`pin_pieces`, made."""
    room = fcl.distance(bvh(mesh), bvh(pin), fcl.DistanceRequest(), fcl.DistanceResult())
    bound = min(allowed, CENTRED)
    size = float(max(mesh.extents))
    thresholds = [t for t in PIN_THRESHOLDS if t * size <= CONCAVITY_REACH * bound]
    if not thresholds:
        finest = min(PIN_THRESHOLDS)
        return (f"CoACD's finest threshold for it, {finest:g} of its {1e3 * size:.3f} mm size, allows pieces "
                f"{1e3 * finest * size:.3f} mm concave, over {CONCAVITY_REACH:g} times the {1e3 * bound:.3f} mm they "
                f"may take from the {1e3 * room:.3f} mm its mesh leaves its pin (not sought)")
    why = ""
    for threshold, iterations in [(t, n) for t in thresholds for n in PIN_ITERATIONS]:
        found = fitting_pieces(pid, mesh, {"its pin": pin}, thresholds=(threshold,), iterations=iterations)
        if isinstance(found, OverBudget):
            return found
        if isinstance(found, str):
            why = found
            continue
        left = _room([convex_object(piece) for piece, _ in found[0]], bvh(pin))
        if room - left <= bound:
            return found
        why = (f"the convex pieces of part '{pid}' (CoACD at threshold {threshold:g}, {iterations} tree-search "
               f"iterations) leave its pin {1e3 * left:.3f} of the {1e3 * room:.3f} mm its mesh leaves it "
               f"(expected at most {1e3 * bound:.3f} mm less)")
    return why


PIN_THRESHOLDS = (0.02, 0.01)
"""CoACD's concavity thresholds tried in turn for a part with a bore (:func:`pin_pieces`):
finer than a part's default, for a bore round enough to be centred on its pin."""
CENTRED = 0.002
"""The most [m] a part's pieces may take from the room its mesh leaves its pin, whatever
its room: the cell centres it on the pin by contact with them, so its bore's centre is
then within half of that of the mesh's (Meta-World's ring: CoACD at 0.05 took 5.4 mm of
17.3 and left it 2.1 mm off its goal; at 0.02, 1.5 mm)."""
CONCAVITY_REACH = 4.0
"""A threshold of :data:`PIN_THRESHOLDS` is tried (:func:`pin_pieces`) only when the
concavity it allows a piece, the threshold times the part's longest extent (CoACD's
concavity is relative to the part's size), is at most this many times what the pieces may
take from the room its mesh leaves its pin: CoACD's pieces took about two fifths of that
concavity from it (Meta-World's ring at 0.02: 1.6 of 4.7 mm; asm4_disk_arm's disk, a d 21
bore in a d 240 disk, at 0.02: 2.0 of 4.8 mm, where 0.24 mm may be taken), and a finer
threshold on a large part runs for minutes (that disk at 0.01: over 50 s of CPU for one
seed without finishing), so a part beyond this reach is placed by hand at once."""
PIN_ITERATIONS = (30, ITERATIONS)
"""CoACD's tree-search iterations per cut tried in turn at each of :data:`PIN_THRESHOLDS`
(:func:`pin_pieces`): a fifth of its default first, then its default; the pieces of
either are kept only when they pass the same checks. Its search is most of an import
with a ring: Meta-World's (1612 triangles, threshold 0.02) took 14.3 s of CPU at 150
iterations, 4.6 s at 30, and those pieces leave its pin 15.660 of 17.284 mm."""


Pieces = Callable[[str, trimesh.Trimesh], tuple[list[tuple[trimesh.Trimesh, float]], str] | str]
"""A part's own convex pieces (its id and its closed mesh in its frame -> the pieces, each
with how far dropped vertices reach, and how they were made; or why it has none)."""


def _beyond(planes: tuple[np.ndarray, np.ndarray], points: np.ndarray) -> np.ndarray:
    """How far [m] each point lies beyond the face ``planes`` of a convex hull (their
    outward unit normals and each normal's dot with its face's first corner; <= 0 inside)."""
    normals, offsets = planes
    return np.max(points @ normals.T - offsets, axis=1)


def _planes(hull: trimesh.Trimesh) -> tuple[np.ndarray, np.ndarray]:
    """The face planes (:func:`_beyond`) of a convex ``hull``."""
    return hull.face_normals, np.einsum("ij,ij->i", hull.face_normals, hull.triangles[:, 0])


def _hull_planes(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The face planes (:func:`_beyond`) of ``trimesh.convex.convex_hull(points)``, the same
    numbers without making the mesh (a third of the cost): qhull's triangles with their
    degenerate ones left out, each wound outwards from the area-weighted centroid of the
    triangles' centres, its normal its corners' unit cross product; trimesh's repair after
    that (winding mended across neighbours) changes no face of a hull qhull gives whole.
    Where qhull refuses the points (flat), trimesh's own hull (it joggles them)."""
    try:
        hull = scipy.spatial.ConvexHull(points, qhull_options=str(trimesh.convex.QHULL_DEFAULT))
    except scipy.spatial.QhullError:
        return _planes(trimesh.convex.convex_hull(points))
    crosses = trimesh.triangles.cross(points[hull.simplices])
    normals, valid = trimesh.util.unitize(crosses, check_valid=True)
    faces = hull.simplices[valid]
    centres = points[faces].mean(axis=1)
    centroid = np.average(centres, weights=trimesh.triangles.area(crosses=crosses[valid]), axis=0)
    backwards = trimesh.util.diagonal_dot(normals, centres - centroid) < 0.0
    faces[backwards] = np.fliplr(faces[backwards])
    normals, _ = trimesh.triangles.normals(points[faces])
    return normals, np.einsum("ij,ij->i", normals, points[faces[:, 0]])


def reduced(piece: trimesh.Trimesh, count: int = PIECE_VERTICES) -> tuple[trimesh.Trimesh, float]:
    """The hull of at most ``count`` vertices of a convex ``piece`` and how far [m] the
    piece's vertices reach beyond its face planes (0 when it keeps them all): from the
    four vertices of the largest tetrahedron found greedily, the vertex farthest beyond
    the kept hull (:func:`_hull_planes`) is added until ``count`` are kept."""
    points = np.asarray(piece.vertices)
    if len(points) <= count:
        return piece, 0.0
    first = int(np.argmax(np.linalg.norm(points - points.mean(axis=0), axis=1)))
    second = int(np.argmax(np.linalg.norm(points - points[first], axis=1)))
    line = points[second] - points[first]
    third = int(np.argmax(np.linalg.norm(np.cross(points - points[first], line), axis=1)))
    normal = np.cross(line, points[third] - points[first])
    fourth = int(np.argmax(np.abs((points - points[first]) @ normal)))
    chosen = [first, second, third, fourth]
    while len(chosen) < count:
        chosen.append(int(np.argmax(_beyond(_hull_planes(points[chosen]), points))))
    kept = trimesh.convex.convex_hull(points[chosen])
    return kept, float(max(0.0, np.max(_beyond(_planes(kept), points))))


APART = 2e-7
"""Distinct vertices of a written mesh are at least this far apart [m]: twice the 0.1 µm
its file keeps, so that rounding and a loader's merge (trimesh: 10 nm) keep them two."""


def apart(vertices: np.ndarray) -> np.ndarray:
    """``vertices`` (n, 3) [m] with each pair closer than :data:`APART` (a source's seam
    where two sheets meet, 4 nm apart in a CAD drawn in mm) moved apart along the line
    through them to that distance, each by at most half of it."""
    moved = np.array(vertices, dtype=float)
    for i, j in sorted(scipy.spatial.cKDTree(moved).query_pairs(APART)):
        gap = moved[j] - moved[i]
        size = float(np.linalg.norm(gap))
        if size > 0:
            shift = gap / size * (APART - size) / 2
            moved[i] -= shift
            moved[j] += shift
    return moved


def as_written(mesh: trimesh.Trimesh) -> trimesh.Trimesh:
    """``mesh`` as :func:`write_mesh` writes it and reads it back (its vertices moved
    :func:`apart` and kept to 0.1 µm, loaded as trimesh loads the file): the mesh whose
    pieces are written, so that they are found once, before it is (:func:`pin_pieces` and
    :func:`executor.world.rings.ring_pieces` keep what they found by the mesh)."""
    text = obj_text([("mesh", apart(mesh.vertices), mesh.faces)], "# as written")
    loaded = trimesh.load(io.StringIO(text), file_type="obj", force="mesh")
    assert isinstance(loaded, trimesh.Trimesh)  # one object, closed as given
    return loaded


def write_mesh(folder: Path, pid: str, mesh: trimesh.Trimesh, made: str,
               neighbours: dict[str, trimesh.Trimesh] | None, frame: str = "its part frame",
               exact: Pieces | None = None, fits: frozenset[str] = frozenset(), prisms: bool = False,
               narrow: float = 0.0) -> tuple[Mesh, list[Path]] | str:
    """Write ``mesh`` (already in ``frame`` [m]; ``made``: how, for its header) as
    ``meshes/<pid>.obj`` in the assembly ``folder`` and, for a moving part
    (``neighbours``: the parts near it, in its frame; None for a static one: the base, a
    part placed by hand), its convex pieces (:func:`fitting_pieces`, or ``exact``'s:
    :func:`executor.world.rings.ring_pieces`; ``fits``: the neighbours at a stated
    zero-clearance fit or passage with it; ``prisms``: a peg's, whose prisms of its sections
    may serve; ``narrow`` [m]: a peg the cell narrows, its hull or the prisms of its sections
    alone, each piece :func:`narrowed` by that about its axis, z); returns the ``mesh``
    entry of ``geometry.toml`` and the paths written, or why no pieces fit."""
    make_folder(folder / MESH_FOLDER)
    name = f"{MESH_FOLDER}/{pid}.obj"
    text = obj_text([(pid, apart(mesh.vertices), mesh.faces)],
                    f"# {pid}: its closed mesh [m] in {frame}, {made}, by ./run.sh import")
    written = [write_atomic(folder / name, text)]
    digest = hashlib.sha256(text.encode()).hexdigest()
    if neighbours is None:
        return Mesh(file=name, sha256=digest), written
    # The pieces of the mesh as written (0.1 µm), so that they are pieces of that file.
    written_mesh = trimesh.load(folder / name, force="mesh")
    assert isinstance(written_mesh, trimesh.Trimesh)  # the closed mesh just written
    found = (fitting_pieces(pid, written_mesh, neighbours, fits, prisms=prisms, only_prisms=narrow > 0)
             if exact is None else exact(pid, written_mesh))
    if isinstance(found, str):
        return found
    kept, made = found
    if narrow:
        shrunk = [narrowed(piece.vertices, narrow) for piece, _ in kept]
        if thin := [k + 1 for k, piece in enumerate(shrunk)
                    if piece is None or eroded(piece.vertices, URDF_HULL_MARGIN) is None]:
            return (f"piece {thin[0]} of part '{pid}' narrowed by {1e3 * narrow:g} mm per side (a fit whose room the "
                    f"cell does not resolve) is thinner than {1e3 * MIN_THICKNESS:g} mm, the cell's hull margin twice "
                    "less what it resolves")
        kept = [(piece, reach) for piece, (_, reach) in zip(shrunk, kept, strict=True) if piece is not None]
        made += f"; each narrowed by {1e3 * narrow:g} mm about its axis (a fit whose room the cell does not resolve)"
    convex = f"{MESH_FOLDER}/{pid}.convex.obj"
    pieces = [(f"{pid}_{k + 1}", piece.vertices, piece.faces) for k, (piece, _) in enumerate(kept)]
    header = (CONVEX_HEADER.format(file=name, sha256=digest) + f"\n# {len(kept)} piece(s) of at most {PIECE_VERTICES} "
              f"vertices; the dropped vertices reach {1e6 * max(d for _, d in kept):.1f} um beyond their face planes"
              f"\n# {made}")
    written.append(write_atomic(folder / convex, obj_text(pieces, header)))
    return Mesh(file=name, sha256=digest, convex=convex), written
