"""What the geometry of an assembled product decides: insertion axes, holes with their
cross-sections, and the geometric precedence by disassembly.

Disassembly: the base stays (it is the fixture); every other part is swept out along
each of :data:`assembly_constraints.executor.cad.sweep.DIRECTIONS` by the product's size, everything else
fixed, which gives its blockers per direction (blocking is pairwise, so these are the
blockers at every stage). Stage by stage, every part that some direction frees from the
parts still in place leaves along the first such direction: its **insertion axis** is the
reverse. A part that no stage frees never comes out (an error naming it). **Geometric
precedence**: A must precede B when B blocks A's path out along A's axis, and the base
precedes every part touching it. Parts fixed to another (a head screwed into its lever)
move with it: neither blocks the other. The **locating rule**
(:mod:`assembly_constraints.executor.cad.locating`, a stated assumption, off with reach 0)
adds Y before X when Y alone keeps X from moving sideways.

**Holes** are the inner loops of the base's slices perpendicular to the axes, at the middle
of each part's depth in the base (or, with no part reaching into it, at the base's middle
along z). A part is in the hole whose loop holds its slice's centre. Measured: both
cross-sections, their clearance, the hole's entry (the base's highest point around it
along the axis), depth (entry to the first face down its centre line, or through the
base), entry chamfer (the loop's growth just below the entry, taken as 45°). An empty
loop that is no round, square or rect section is a pocket, reported but no hole.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import trimesh

from assembly_constraints.executor import ExecutorError
from assembly_constraints.executor.cad.locating import LOCATING_REACH, locating_pairs, locators
from assembly_constraints.executor.cad.parts import STEP_DEFLECTION, CadPart
from assembly_constraints.executor.cad.sections import Loop, Shape2D, classify, exact_round, frame_of, slice_loops
from assembly_constraints.executor.cad.sweep import DIRECTIONS, Sweeper

_ENTRY_PROBE = 2e-5  # the chamfer is measured this far [m] below the entry
_SAME_HOLE = 1e-4  # hole centres closer than this [m] across the axis are one hole


@dataclass(frozen=True)
class HoleFit:
    """A hole of the base (``id`` h1, h2, ... by position) entered against ``axis`` (the
    removal direction of the parts in it), with its measured section, the part standing in
    it (None: an empty hole) and that part's section."""

    id: str
    axis: str
    hole: Shape2D
    centre: tuple[float, float, float]
    entry: float
    depth: float
    chamfer: float
    outer: Shape2D | None
    """The loop of the base around the hole at mid-depth (a boss), None when there is none."""
    part: str | None = None
    section: Shape2D | None = None

    @property
    def position(self) -> tuple[float, float]:
        """The hole's centre in the cell's x, y [m]."""
        return self.centre[0], self.centre[1]


@dataclass
class Derived:
    """Everything :func:`derive` finds; ``free`` the directions each part leaves the whole
    product along, ``axis`` its insertion axis (the name of the removal direction),
    ``stages`` the disassembly stages, ``edges`` the geometric must-precede pairs and
    ``reasons`` why each holds (``blocks``: B blocks A's way out; ``base``: the base
    precedes the parts touching it; ``locates``: the locating rule,
    :mod:`assembly_constraints.executor.cad.locating`), ``located`` each moving body's
    locators per direction across its axis, ``dropped`` the locating pairs the blocking
    contradicts, ``reach`` the locating reach [m] (0: the rule is off)."""

    base: str
    parts: dict[str, CadPart]
    blockers: dict[tuple[str, str], set[str]] = field(default_factory=dict)
    axis: dict[str, str] = field(default_factory=dict)
    stages: list[list[str]] = field(default_factory=list)
    edges: set[tuple[str, str]] = field(default_factory=set)
    reasons: dict[tuple[str, str], str] = field(default_factory=dict)
    located: dict[str, dict[str, set[str]]] = field(default_factory=dict)
    dropped: set[tuple[str, str]] = field(default_factory=set)
    reach: float = 0.0
    holes: dict[str, HoleFit] = field(default_factory=dict)
    pockets: list[HoleFit] = field(default_factory=list)
    """Empty inner loops of the base that are no round, square or rect section: not holes."""
    queries: int = 0

    def free(self, part: str) -> list[str]:
        return [d for d in DIRECTIONS if not self.blockers[(part, d)]]

    @property
    def hole_of(self) -> dict[str, HoleFit]:
        """Part → the hole it stands in."""
        return {fit.part: fit for fit in self.holes.values() if fit.part is not None}


def derive(parts: list[CadPart], base: str, fixed_to: dict[str, str], reach: float = LOCATING_REACH) -> Derived:
    """Axes, stages, precedence and holes of ``parts`` with ``base`` the fixture;
    ``fixed_to`` maps a part to the part it moves with; ``reach`` [m]: the locating rule's
    (0: off). ExecutorError naming the parts that never come out."""
    by_id = {p.id: p for p in parts}
    result = Derived(base, by_id, reach=reach)
    sweeper = Sweeper({p.id: p.mesh for p in parts})
    lower = np.min([p.mesh.bounds[0] for p in parts], axis=0)
    upper = np.max([p.mesh.bounds[1] for p in parts], axis=0)
    length = 2 * float(np.linalg.norm(upper - lower))
    group = {pid: {pid} | {c for c, host in fixed_to.items() if host == pid} for pid in by_id}
    for pid in by_id:
        if pid == base:
            continue
        for name, vector in DIRECTIONS.items():
            hit = sweeper.blockers(pid, np.array(vector), length)
            result.blockers[(pid, name)] = hit - group[pid] - {fixed_to.get(pid, "")}
    remaining = set(by_id) - {base}
    while remaining:
        stage = sorted(pid for pid in remaining if any(
            not (result.blockers[(pid, d)] & (remaining | {base})) for d in DIRECTIONS))
        if not stage:
            stuck = ", ".join(sorted(remaining))
            raise ExecutorError(f"part(s) {stuck} never come out of the assembled product: each is blocked along "
                                f"{', '.join(DIRECTIONS)} (expected a straight way out for every part but the base)")
        for pid in stage:
            result.axis[pid] = next(d for d in DIRECTIONS
                                    if not (result.blockers[(pid, d)] & (remaining | {base})))
        result.stages.append(stage)
        remaining -= set(stage)
    for pid, direction in result.axis.items():
        result.reasons |= {(pid, other): "blocks" for other in result.blockers[(pid, direction)] if other != base}
    result.reasons |= {(base, pid): "base" for pid in result.axis if sweeper.touching(base, pid)}
    if reach > 0:
        result.located = {pid: locators(sweeper, group[pid], result.axis[pid], reach)
                          for pid in result.axis if pid not in fixed_to}
        kept, result.dropped = locating_pairs(result.located, base, set(result.reasons))
        result.reasons |= {pair: "locates" for pair in kept if pair not in result.reasons}
    result.edges = set(result.reasons)
    found = _holes(by_id[base], [by_id[pid] for pid in sorted(result.axis)], result.axis)
    result.pockets = [fit for fit in found if fit.part is None and fit.hole.kind == "polygon"]
    holes = [fit for fit in found if fit not in result.pockets]
    result.holes = {f"h{k}": HoleFit(f"h{k}", *_fields(fit)) for k, fit in enumerate(holes, start=1)}
    result.queries = sweeper.queries
    return result


def first_hit(mesh: trimesh.Trimesh, origin: np.ndarray, direction: np.ndarray) -> float | None:
    """Distance [m] along the unit ``direction`` from ``origin`` to the first triangle of
    ``mesh`` (Möller-Trumbore over all triangles), None when the ray meets none."""
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
    return float(t[hit].min()) if np.any(hit) else None


def _part_slice(part: CadPart, base: CadPart, axis: np.ndarray) -> tuple[float, Loop] | None:
    """The level [m] in the middle of the part's depth inside the base along ``axis`` and
    the part's one loop there; None when the part does not reach into the base or its
    slice there is not one loop."""
    along, base_along = part.mesh.vertices @ axis, base.mesh.vertices @ axis
    low, high = max(along.min(), base_along.min()), min(along.max(), base_along.max())
    if high - low <= 1e-6:
        return None
    level = float(low + high) / 2
    own = slice_loops(part.mesh, axis, level)
    return (level, own[0]) if len(own) == 1 else None


def _holes(base: CadPart, parts: list[CadPart], axes: dict[str, str]) -> list[HoleFit]:
    """Every inner loop of the base's slices (at the levels of the parts in it, or at its
    middle along +z), with the part in it where one is, in order of position."""
    slices: dict[tuple[str, float], list[tuple[CadPart, Loop]]] = {}
    for part in parts:
        found = _part_slice(part, base, np.array(DIRECTIONS[axes[part.id]]))
        if found is not None:
            slices.setdefault((axes[part.id], round(found[0], 7)), []).append((part, found[1]))
    if not slices:
        z = base.mesh.vertices[:, 2]
        slices[("+z", round(float(z.min() + z.max()) / 2, 7))] = []
    fits: list[HoleFit] = []
    for (name, level), members in sorted(slices.items()):
        axis = np.array(DIRECTIONS[name])
        loops = slice_loops(base.mesh, axis, level)
        for loop in loops:
            around = sorted((o for o in loops if o is not loop and o.area > loop.area and o.contains(loop.centre)),
                            key=lambda o: o.area)
            if len(around) % 2 == 0:
                continue  # an outline, not a hole
            frame = frame_of(axis)
            centre = frame.T @ loop.centre + axis * level
            occupant = next(((p, own) for p, own in members if loop.contains(own.centre)), None)
            same = [k for k, f in enumerate(fits) if f.axis == name and np.linalg.norm(
                np.array(f.centre) - centre - axis * np.dot(np.array(f.centre) - centre, axis)) < _SAME_HOLE]
            if same and (occupant is None or fits[same[0]].part is not None):
                continue
            # a hole met empty at another part's level (a shallower one beside a deeper) is its occupant's
            fit = _measure(base, name, loop, level, around[0] if around else None, occupant)
            if same:
                fits[same[0]] = fit
            else:
                fits.append(fit)
    fits.sort(key=lambda f: (round(f.centre[0], 6), round(f.centre[1], 6), round(f.centre[2], 6)))
    return fits


def _fields(fit: HoleFit) -> tuple:
    return (fit.axis, fit.hole, fit.centre, fit.entry, fit.depth, fit.chamfer, fit.outer, fit.part, fit.section)


def _measure(base: CadPart, name: str, loop: Loop, level: float, outer: Loop | None,
             occupant: tuple[CadPart, Loop] | None) -> HoleFit:
    """Section, entry, depth (to the first face of the base down the hole's centre line;
    through the base when there is none) and chamfer of the hole ``loop``."""
    axis = np.array(DIRECTIONS[name])
    frame = frame_of(axis)
    hole = exact_round(classify(loop, hole=True), base.cylinders, axis, level, STEP_DEFLECTION)
    base_along = base.mesh.vertices @ axis
    radial = base.mesh.vertices @ frame.T - hole.centre
    entry = float(base_along[np.linalg.norm(radial, axis=1) <= max(hole.a, hole.b)].max())
    centre = frame.T @ hole.centre + axis * level
    bottom = first_hit(base.mesh, centre, -axis)
    depth = entry - (level - bottom if bottom is not None else float(base_along.min()))
    probe = [o for o in slice_loops(base.mesh, axis, entry - _ENTRY_PROBE) if o.contains(hole.centre)]
    chamfer = 0.0
    if probe:
        top = classify(min(probe, key=lambda o: o.area), hole=True)
        chamfer = max(0.0, (top.b - hole.b) / 2 + _ENTRY_PROBE) if top.b > hole.b + 1e-7 else 0.0
    part, section = (None, None) if occupant is None else (
        occupant[0].id, exact_round(classify(occupant[1], hole=False), occupant[0].cylinders, axis, level,
                                    STEP_DEFLECTION))
    return HoleFit("", name, hole, (float(centre[0]), float(centre[1]), float(entry)), entry, depth, chamfer,
                   None if outer is None else classify(outer, hole=False), part, section)
