"""What the geometry of an assembled product decides: insertion axes, holes with their
cross-sections, and the geometric precedence by disassembly.

Disassembly: the base stays (it is the fixture); every other part is swept out along
each of :data:`executor.cad.sweep.DIRECTIONS` by the product's size, everything else
fixed, which gives its blockers per direction (blocking is pairwise, so these are the
blockers at every stage). Stage by stage, every part that some direction frees from the
parts still in place leaves along the first such direction: its **insertion axis** is the
reverse. A part that no stage frees never comes out (an error naming it). **Geometric
precedence**: A must precede B when B blocks A's path out along A's axis, and the base
precedes every part touching it. Parts fixed to another (a head screwed into its lever)
move with it: neither blocks the other.

A part is **in a hole** when the base's slice at the middle of the part's depth in the
base (perpendicular to the axis) has a loop around the part's slice: that loop is the
hole; its cross-section, the part's, their clearance, the hole's entry (the base's
highest point around it along the axis), depth (entry to the part's deepest point) and
entry chamfer (the loop's growth just below the entry, taken as 45°) are measured.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from executor import ExecutorError
from executor.cad.parts import CadPart
from executor.cad.sections import Shape2D, classify, frame_of, slice_loops
from executor.cad.sweep import DIRECTIONS, Sweeper

_ENTRY_PROBE = 2e-5  # the chamfer is measured this far [m] below the entry


@dataclass(frozen=True)
class HoleFit:
    """A part in a hole of the base: the hole's and the part's sections, measured."""

    part: str
    hole: Shape2D
    section: Shape2D
    position: tuple[float, float]
    entry: float
    depth: float
    chamfer: float
    outer: Shape2D | None
    """The loop of the base around the hole at mid-depth (a boss), None when there is none."""

    @property
    def clearance(self) -> tuple[float, float]:
        """Hole minus part along a and b [m] (round: the diameters)."""
        return self.hole.a - self.section.a, self.hole.b - self.section.b


@dataclass
class Derived:
    """Everything :func:`derive` finds; ``free`` the directions each part leaves the whole
    product along, ``axis`` its insertion axis (the name of the removal direction),
    ``stages`` the disassembly stages, ``edges`` the geometric must-precede pairs."""

    base: str
    parts: dict[str, CadPart]
    blockers: dict[tuple[str, str], set[str]] = field(default_factory=dict)
    axis: dict[str, str] = field(default_factory=dict)
    stages: list[list[str]] = field(default_factory=list)
    edges: set[tuple[str, str]] = field(default_factory=set)
    holes: dict[str, HoleFit] = field(default_factory=dict)
    queries: int = 0

    def free(self, part: str) -> list[str]:
        return [d for d in DIRECTIONS if not self.blockers[(part, d)]]


def derive(parts: list[CadPart], base: str, fixed_to: dict[str, str]) -> Derived:
    """Axes, stages, precedence and holes of ``parts`` with ``base`` the fixture;
    ``fixed_to`` maps a part to the part it moves with. ExecutorError naming the parts that
    never come out."""
    by_id = {p.id: p for p in parts}
    result = Derived(base, by_id)
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
        result.edges |= {(pid, other) for other in result.blockers[(pid, direction)] if other != base}
    result.edges |= {(base, pid) for pid in result.axis if sweeper.touching(base, pid)}
    for pid, direction in result.axis.items():
        fit = _hole_fit(by_id[pid], by_id[base], np.array(DIRECTIONS[direction]))
        if fit is not None:
            result.holes[pid] = fit
    result.queries = sweeper.queries
    return result


def _hole_fit(part: CadPart, base: CadPart, axis: np.ndarray) -> HoleFit | None:
    """The hole of ``base`` that ``part`` occupies along ``axis``, None when it is in none."""
    along = part.mesh.vertices @ axis
    base_along = base.mesh.vertices @ axis
    low, high = max(along.min(), base_along.min()), min(along.max(), base_along.max())
    if high - low <= 1e-6:
        return None
    level = (low + high) / 2
    own = slice_loops(part.mesh, axis, level)
    if len(own) != 1:
        return None
    centre = own[0].centre
    around = sorted((loop for loop in slice_loops(base.mesh, axis, level) if loop.contains(centre)),
                    key=lambda loop: loop.area)
    if not around:
        return None
    hole = classify(around[0], hole=True)
    frame = frame_of(axis)
    reach = max(hole.a, hole.b)
    radial = base.mesh.vertices @ frame.T - hole.centre
    near = np.linalg.norm(radial, axis=1) <= reach
    entry = float(base_along[near].max())
    probe = [loop for loop in slice_loops(base.mesh, axis, entry - _ENTRY_PROBE) if loop.contains(centre)]
    chamfer = 0.0
    if probe:
        top = classify(min(probe, key=lambda loop: loop.area), hole=True)
        chamfer = max(0.0, (top.b - hole.b) / 2 + _ENTRY_PROBE) if top.b > hole.b + 1e-7 else 0.0
    return HoleFit(part.id, hole, classify(own[0], hole=False), (float(hole.centre[0]), float(hole.centre[1])),
                   entry, entry - float(along.min()), chamfer,
                   classify(around[1], hole=False) if len(around) > 1 else None)
