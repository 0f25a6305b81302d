"""What the geometry of an assembled product decides: insertion axes, holes with their
cross-sections, and the geometric precedence by disassembly.

Disassembly: the base stays (it is the fixture); every moving body (a part with the parts
``fixed_to`` it, moved as one) is swept out along each direction tried by the product's
size, everything else fixed, which gives its blockers per direction (blocking is
pairwise, so these are the blockers at every stage). The directions tried are
:data:`executor.cad.sweep.DIRECTIONS` and both senses of the axis of
every zero-clearance fit (:func:`executor.cad.fits.faces.zero_clearance_fits`).
Stage by stage, every part that some direction frees from the parts still in place leaves.
Its **insertion axis** is the reverse of the way out :func:`_way_out` chooses (up, down, the
ways the arm reaches sideways, then the product's geometry) among the directions free of the
parts present as the cell meets it: those in place at its stage and those the precedence
puts before it, less those it puts after it (:func:`_ways_in`). Where parts are
left, the screwed pairs (modelled threads, :func:`executor.cad.fits.threads.screwed_pairs`, in a nut or a
plain hole at their tap drill; cosmetic ones, :func:`executor.cad.fits.threads.cosmetic_pairs`)
between them and their blockers slide along their axes, their parts are swept again and
the stages made anew. A part that no stage frees never comes out (an error naming it and,
per direction, its blockers).

**Geometric precedence** (:func:`forced`): A must precede B (``blocks``) when A cannot go
in once B is there: of the directions the base leaves A free along, B blocks one, and B
or parts present whenever B is (its body, the base, parts already found to precede B)
block every one. The base precedes every part touching it (``base``), the owner of a
feature every part going into or onto it (``feature``, :func:`owner_pairs`). Two stated rules
of placing (:mod:`executor.cad.locating`) add ``supports`` (a part
resting on parts other than the base goes after them) and ``locates`` (whichever way a part
goes in, one other part alone locates it across that way; off with reach 0);
a pair of theirs that the blocking contradicts is dropped and reported.

**Holes** are the inner loops of the base's slices perpendicular to the axes, at the middle
of each part's depth in the base (or, with no part reaching into it, at the base's middle
along z). A part is in the hole whose loop holds its slice's centre, unless that hole is
floored and wider than the part by more than :data:`CAVITY_ROOM` (a tray's cavity the part
rests in: no hole for it, nor is a moving part's loop so wide); an empty floored hole so
much wider than every part left in a hole is none (:func:`_open_box`). Measured: both
cross-sections, their clearance, the hole's entry (the base's highest point around it
along the axis), depth (entry to the first face down its centre line, or through the
base), entry chamfer (the loop's growth just below the entry, taken as 45°). An empty
loop whose section is a polygon is a hole only when it has rotational symmetry about its
centre (:func:`receives`), else a pocket, reported but no hole. Both sections are those
over the stretch the part passes, from its end to the entry
(:func:`executor.cad.sections.over_span`: the hole's narrowest, the part's widest); an
empty hole's over the stretch a part goes in, from its floor (or through) to its entry,
so alike holes are measured alike, occupied or not. Where those do not pass, the part is
swept out of its hole level by level (:func:`swept_fits`: a taper in its own taper passes).

**Holes of moving parts** (:func:`part_holes`): a moving part in no hole of the base and
onto no pin is in the hole of another moving part that the geometric precedence puts
before it when its outline across its insertion axis lies in an inner loop of that part
(a rod through a bracket's bore), measured as a hole of the base is; a part onto a pin is
so in the hole of a part the precedence does not put after it (a clutch plate's splined
outside in the outer holder's hole as its bore goes down the shaft), the parts in one hole
its occupants.

**Pins** (:func:`pins`): a moving part whose slice across its insertion axis, at the middle
of its extent along it, has an inner loop (a **bore**: a nut's, a washer's, a gear's)
around a solid loop of another part there (the base's pin, another part's shaft), that
part the base or one the geometric precedence puts before it, goes onto that pin (onto
every pin of such parts in a bore of its own: a plate on two dowel pins of the base, an
arm on the base's pivot pin through its bore and on a disk's nipple through its slot); a peg
standing in a hole of the base is a pin only of a part going in along another axis (a
nut onto a bolt's end under the plate; one going in along the peg's, over it, is a
cover), or of a part going in along its axis that rests on such pegs alone (a foot down
onto a table leg's tenon, on nothing but the leg's shoulder: no cover, which rests on the
base or on covers). The pin is a
feature of its owner (``<owner>_pin1``, ``_pin2``, ... by position), its section measured
on the owner's slice; the fit is the pin's section inside the bore's, so the planner
learns which part goes onto which pin as it learns pegs in holes. At those levels and
along those axes, a pin of the base no part is on is found too when it stands out with
its free end along the axis and some bore passes over it (:func:`_standing_pins`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field, replace

import networkx as nx
import numpy as np
import shapely
import trimesh

from executor import ExecutorError
from executor.cad.fits.faces import COARSEST, SMOOTH, TOUCH, CylinderFace, PrismFace, Slide, zero_clearance_fits
from executor.cad.fits.threads import cosmetic_pairs, screwed_pairs
from executor.cad.locating import (
    LOCATING_REACH,
    consistent,
    locators,
    placing_pairs,
    support_pairs,
)
from executor.cad.parts import STEP_DEFLECTION, CadPart
from executor.cad.sections import (
    OUTLINE_TOUCH,
    Loop,
    Passage,
    Shape2D,
    Slicer,
    classify,
    exact_round,
    faceted,
    frame_of,
    over_span,
    passage,
    passes,
    section_room,
    slice_loops,
    zero_clearance,
)
from executor.cad.sweep import DIRECTIONS, Sweeper, axis_name, forked_map, opposite, processes, surveys
from executor.world.polygon_fit import OutlineError, polygon, symmetry

_ENTRY_PROBE = 2e-5  # the chamfer is measured this far [m] below the entry
_SAME_HOLE = 1e-4  # hole centres closer than this [m] across the axis are one hole
_ON_PIN = 1e-6  # a vertex of the base this close [m] to a pin's outline is on it
_GRID = 1e-8  # the grid [m] the union of a pin's sections is snapped to (far below a fit's room)
_JITTER = 5e-8  # [m] a vertex of that union this close to the line through its neighbours is dropped
PREFERRED = (("+z",), ("-z",), ("-x", "+y", "-y"), ("+x",))
"""The classes a part's way out (its insertion axis reversed) is chosen by among those it
is free along, in order: up (the cell inserts from above), down, the horizontal ones whose
insertion the cell's arm was measured to reach sideways (-x, +y, -y: the insertions +x,
-y, +y of :data:`executor.cad.operations.SIDEWAYS_HOLE_REACH`), so a part free both ways
along x goes in along +x however the CAD is turned about z, then +x; a zero-clearance
fit's axis that is none of these, last. Within a class the product's geometry chooses
(:func:`_way_out`)."""
LEAVING = tuple(d for kind in PREFERRED for d in kind)
"""The six axes in :data:`PREFERRED`'s order: the last rule between ways out the geometry
leaves tied (:func:`_way_out`)."""
TIED = 1e-6
"""Two ways out whose travels (or mass balances) differ by at most this [m] are tied for
that rule of :func:`_way_out` (a turn about z changes them by rounding alone)."""
CAVITY_ROOM = 2 * LOCATING_REACH
"""[m] A hole whose narrowest width exceeds a part's widest by more than this (6 mm)
leaves that part, wherever it lies in it, free to move the locating rule's default reach
one way or the other across: with a floor under it, a cavity that locates nothing of that
size (an open tray's, a case's without its lid), no hole for it (:func:`_open_box`)."""
_HOLE_LEVELS = 8
"""How many levels :func:`_hole_around` slices an owner at, and :func:`_pin_of` a part on a pin, at most,
to find the hole or the pin."""
_PIN_LEVELS = 64
"""How many spans :func:`_pin_of` measures a part's bore and its pin over, split at the ends of the longest."""


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
    owner: str | None = None
    """The moving part the hole is in (:func:`part_holes`), None for a hole of the base."""
    more: tuple[tuple[str, Shape2D], ...] = ()
    """The further parts in a moving part's hole with their sections, after ``part`` (the
    deepest): plates stacked on a shaft whose outsides stand in a ring's hole."""

    @property
    def position(self) -> tuple[float, float]:
        """The hole's centre in the cell's x, y [m]."""
        return self.centre[0], self.centre[1]

    @property
    def occupants(self) -> dict[str, Shape2D]:
        """Every part in the hole (``part`` first, then ``more``) -> its section there."""
        first = {} if self.part is None or self.section is None else {self.part: self.section}
        return first | dict(self.more)


@dataclass(frozen=True)
class PinFit:
    """A pin (``id`` ``<owner>_pin<k>``) of part ``owner`` that ``parts`` go onto against
    ``axis`` (their removal direction), with its measured ``section`` (circumscribed, as a
    peg's) and ``centre`` [m] on the slice that found it."""

    id: str
    owner: str
    axis: str
    section: Shape2D
    centre: tuple[float, float, float]
    parts: tuple[str, ...]

    @property
    def position(self) -> tuple[float, float]:
        """The pin's centre in the cell's x, y [m]."""
        return self.centre[0], self.centre[1]


@dataclass
class Derived:
    """Everything :func:`derive` finds; ``free`` the directions each part leaves the whole
    product along, ``axis`` its insertion axis (the name of the removal direction),
    ``stages`` the disassembly stages, ``edges`` the geometric must-precede pairs and
    ``reasons`` why each holds (``blocks``: :func:`forced`, its blockers per direction in
    ``detail``; ``base``: the base precedes the parts touching it; ``feature``: the
    owner of a feature precedes the parts going into or onto it; ``supports`` and
    ``locates``: the rules of :mod:`executor.cad.locating`),
    ``located`` each moving body's locators per direction (of the six axes), ``dropped``
    the locating pairs and ``dropped_supports`` the supporting pairs the blocking
    contradicts, ``reach`` the locating reach [m] (0: the rule is off), ``bodies`` the
    moving bodies (:func:`bodies`), ``directions`` those tried (name -> unit vector),
    ``slides`` the zero-clearance fits."""

    base: str
    parts: dict[str, CadPart]
    blockers: dict[tuple[str, str], set[str]] = field(default_factory=dict)
    directions: dict[str, tuple[float, float, float]] = field(default_factory=lambda: dict(DIRECTIONS))
    bodies: dict[str, set[str]] = field(default_factory=dict)
    slides: list[Slide] = field(default_factory=list)
    detail: dict[tuple[str, str], str] = field(default_factory=dict)
    dropped_supports: set[tuple[str, str]] = field(default_factory=set)
    axis: dict[str, str] = field(default_factory=dict)
    stages: list[list[str]] = field(default_factory=list)
    edges: set[tuple[str, str]] = field(default_factory=set)
    reasons: dict[tuple[str, str], str] = field(default_factory=dict)
    located: dict[str, dict[str, set[str]]] = field(default_factory=dict)
    later: dict[str, set[str]] = field(default_factory=dict)
    """Each moving body's parts that the placing pairs put after it (not counted among its locators)."""
    dropped: set[tuple[str, str]] = field(default_factory=set)
    reach: float = 0.0
    holes: dict[str, HoleFit] = field(default_factory=dict)
    pockets: list[HoleFit] = field(default_factory=list)
    """Empty inner loops of the base whose polygon section has no rotational symmetry (:func:`receives`)."""
    pins: dict[str, PinFit] = field(default_factory=dict)
    bores: dict[str, Shape2D] = field(default_factory=dict)
    """Part -> the section of its bore around the first pin it is on (:func:`pins`), the one it
    is compared with every pin by."""
    further_bores: dict[tuple[str, str], Shape2D] = field(default_factory=dict)
    """(part, pin) -> the section of another bore of the part, around a further pin it is on
    (a plate's second dowel pin, the arm's slot over the disk's nipple), the one its pair with that
    pin is measured by (:func:`pins`)."""
    part_holes: dict[str, HoleFit] = field(default_factory=dict)
    """The holes of moving parts, each with the part through it (:func:`part_holes`)."""
    supports: set[tuple[str, str]] = field(default_factory=set)
    """The supporting pairs (Y, X): X rests on Y and not on the base
    (:func:`executor.cad.locating.support_pairs`)."""
    swept: dict[tuple[str, str], tuple[Shape2D, Shape2D, float]] = field(default_factory=dict)
    """(peg, hole) and (part with a bore, pin) -> the sections of the peg (the pin) and the
    hole (the bore) at the levels of least room on the way in and that room [m] (diametral),
    for the pairs the sweep admits where the sections over the whole stretch do not
    (:func:`swept_fits`)."""
    queries: int = 0

    def free(self, part: str) -> list[str]:
        """The directions ``part`` leaves the whole product along."""
        return [d for d in self.directions if not self.blockers[(part, d)]]

    def ways(self, part: str) -> dict[str, tuple[float, float, float]]:
        """The directions tried (name -> unit vector) that the base does not block ``part``
        along: its ways out (reversed, in) in any state of the fixture."""
        return {d: vector for d, vector in self.directions.items() if self.base not in self.blockers[(part, d)]}

    def assumptions(self) -> list[str]:
        """The stated assumptions of the disassembly, as ``import`` prints them."""
        fits = [s for s in self.slides if not s.pitch]
        largest = max((s.tolerance for s in fits), default=0.0)
        return ["the support rule: a part resting on parts other than the base goes after them",
                "zero-clearance fits: coaxial cylinders of one radius within the larger tessellation deflection "
                "(a face's triangles' largest distance from its circle; a face whose triangles lie farther than "
                f"{100 * COARSEST:.1f}% of its radius from it, the sagitta of a chord of {math.degrees(SMOOTH):.0f}°, "
                "is no cylinder) plus 10 µm, and prisms along a cell axis whose outlines are one within 10 µm, "
                "slide along their axis where they sit and on the way "
                f"({sum(s.seated for s in fits)} fit(s) and "
                f"{sum(not s.seated for s in fits)} passage(s) found"
                + (f", tolerances up to {1e6 * largest:.1f} µm)" if fits else ")"),
                "modelled threads (sought where the disassembly leaves parts, between them and their blockers): "
                "a part's outermost surface and another's innermost, each helical about one axis "
                "of the frame (through the smaller part's box centre) with one pitch and lead within 2 %, "
                "interlocking, or the screw's in a plain coaxial hole between its minor and major radii (its tap "
                "drill), or a plain cylinder in a plain coaxial hole, their diameters a standard thread's (ISO metric, "
                "UNC, UNF) major and tap drill (a cosmetic thread), are screwed: they slide along that axis against "
                "each other (the screw's thread taken in under the nut's minor radius; "
                f"{sum(1 for s in self.slides if s.pitch)} pair(s) found)"]

    def notes(self) -> list[str]:
        """What the report says beyond the axes and holes: the zero-clearance fits, each
        blocking pair's blockers, the supporting pairs dropped."""
        lines = [f"screwed pair {s.shaft} in {s.bore} ({s.thread}): d {2000 * s.face.radius:.3f} mm in a minor "
                 f"d {2000 * s.hole.radius:.3f} mm along {axis_name(s.direction)[1:]}, pitch {1000 * s.pitch:.3f} mm, "
                 f"lead {1000 * abs(s.lead):.3f} mm, {'right' if s.lead > 0 else 'left'}-handed about "
                 f"{axis_name(s.direction)}; slides along the axis against each other, the cell does not screw"
                 for s in self.slides if s.pitch]
        lines += [(f"zero-clearance fit {s.shaft} in {s.bore}: " if s.seated else
                  f"zero-clearance passage {s.shaft} through {s.bore} (met only on a way along the axis): ")
                 + f"{_face_size(s.face)} along {axis_name(s.direction)[1:]}, "
                  f"overlap up to {1e6 * s.tolerance:.1f} µm across it taken as sliding"
                  for s in self.slides if not s.pitch]
        lines += [f"{a}->{b} blocks: of {a}'s ways out the base leaves, blocked by {detail}"
                  for (a, b), detail in sorted(self.detail.items())]
        lines += [f"supporting pair {y}->{x} dropped: the blocking needs {x} before {y}"
                  for y, x in sorted(self.dropped_supports)]
        return lines

    def screwed(self, part: str, other: str) -> Slide | None:
        """The screwed pair (a thread, modelled or cosmetic) of parts ``part`` and ``other``, either in
        the other, or None."""
        return next((s for s in self.slides if s.pitch and {s.shaft, s.bore} == {part, other}), None)

    def pin_of(self, part: str) -> PinFit:
        """The first pin ``part`` (one with a bore) is on: the one its bore of :attr:`bores` is around."""
        return next(pin for pin in self.pins.values() if part in pin.parts and (part, pin.id) not in self.further_bores)

    def bore_on(self, part: str, pin: str) -> Shape2D:
        """The section of ``part``'s bore that is compared with ``pin``: the one around it
        where the part is on it, else its first (:attr:`bores`)."""
        return self.further_bores.get((part, pin), self.bores[part])

    @property
    def hole_of(self) -> dict[str, HoleFit]:
        """Part → the hole of the base it stands in."""
        return {fit.part: fit for fit in self.holes.values() if fit.part is not None}

    @property
    def in_holes(self) -> dict[str, HoleFit]:
        """Part → the hole it is in: of the base, else the first of a moving part's it passes."""
        found = {pid: fit for fit in reversed(self.part_holes.values()) for pid in fit.occupants}
        return found | self.hole_of


def _face_size(face: CylinderFace | PrismFace) -> str:
    """A fitted face's size as the report gives it: a cylinder's diameter, a prism's extents [mm]."""
    if isinstance(face, PrismFace):
        x0, y0, x1, y1 = face.outline.bounds
        return f"prism {1000 * (x1 - x0):.3f} x {1000 * (y1 - y0):.3f} mm"
    return f"d {2000 * face.radius:.3f} mm"


def derive(parts: list[CadPart], base: str, fixed_to: dict[str, str], reach: float = LOCATING_REACH,
           beside: Callable[[], None] = lambda: None) -> Derived:
    """Axes, stages, precedence and holes of ``parts`` with ``base`` the fixture;
    ``fixed_to`` maps a part to the part it moves with; ``reach`` [m]: the locating rule's
    (0: off); ``beside`` is called once the parts' surveys are made, as the sweeps begin
    (the import starts its overlap check there: the sweeps' first work, making the fixed
    parts' BVHs before their workers fork, runs in this process alone). ExecutorError
    naming the parts that never come out with their blockers."""
    by_id = {p.id: p for p in parts}
    result = Derived(base, by_id, reach=reach)
    made = surveys({p.id: p.mesh for p in parts})
    beside()
    result.slides = zero_clearance_fits({pid: survey.faces for pid, survey in made.items()})
    for slide in result.slides:
        result.directions.setdefault(axis_name(slide.direction), tuple(slide.direction))
        result.directions.setdefault(axis_name(-slide.direction), tuple(-slide.direction))
    sweeper = Sweeper({p.id: p.mesh for p in parts}, result.slides, made=made)
    lower = np.min([p.mesh.bounds[0] for p in parts], axis=0)
    upper = np.max([p.mesh.bounds[1] for p in parts], axis=0)
    length = 2 * float(np.linalg.norm(upper - lower))
    result.bodies = bodies(by_id, base, fixed_to)
    requests = [(members, name) for members in result.bodies.values() for name in result.directions]
    hits = sweeper.blocked([(members, np.array(result.directions[name]), length) for members, name in requests])
    for (members, name), hit in zip(requests, hits):
        result.blockers |= {(pid, name): hit for pid in members}
    remaining = _disassembled(result)
    if remaining:  # modelled threads: sought only where a part is left, between it and its blockers
        blocked_by = {(pid, other) for pid in remaining for d in result.directions
                      for other in result.blockers[(pid, d)]}
        screwed = screwed_pairs({p.id: p.mesh for p in parts}, blocked_by)
        threaded = {frozenset((s.shaft, s.bore)) for s in screwed}
        screwed += [s for s in cosmetic_pairs({pid: survey.faces for pid, survey in made.items()}, blocked_by)
                    if frozenset((s.shaft, s.bore)) not in threaded]
        if screwed:
            result.slides += screwed
            sweeper.add(screwed)
            paired = {pid for s in screwed for pid in (s.shaft, s.bore)}
            again = [(members, name) for members, name in requests if members & paired]
            hits = sweeper.blocked([(members, np.array(result.directions[name]), length) for members, name in again])
            for (members, name), hit in zip(again, hits):
                result.blockers |= {(pid, name): hit for pid in members}
            result.axis, result.stages = {}, []
            remaining = _disassembled(result)
    if remaining:
        stuck = "; ".join(f"{pid} along " + ", ".join(
            f"{d} by {' '.join(sorted(result.blockers[(pid, d)] & (remaining | {base})))}"
            for d in result.directions) for pid in sorted(remaining))
        raise ExecutorError(f"part(s) {', '.join(sorted(remaining))} never come out of the assembled product, "
                            f"blocked: {stuck} (expected a straight way out for every part but the base)")
    result.reasons = forced(result)
    result.reasons |= {(base, pid): "base" for pid in result.axis if sweeper.touching(base, pid)}
    if reach > 0:
        result.located = locators(sweeper, result.bodies, reach)
    ways = {root: result.ways(root) for root in result.bodies}
    result.supports = support_pairs(sweeper, result.bodies, base)
    sweeper.close()  # its last sweep: what follows forks its own workers
    placing, result.later = placing_pairs(result.supports, result.located, ways, result.bodies, base,
                                          set(result.reasons))
    kept, dropped = consistent(sorted(placing), set(result.reasons))
    result.reasons |= {pair: placing[pair] for pair in kept if pair not in result.reasons}
    result.dropped = {pair for pair in dropped if placing[pair] == "locates"}
    result.dropped_supports = {pair for pair in dropped if placing[pair] == "supports"}
    result.edges = set(result.reasons)
    _ways_in(result)
    order = nx.DiGraph(list(result.edges))
    found = _holes(by_id[base], [by_id[pid] for pid in sorted(result.axis) if result.axis[pid] in DIRECTIONS],
                   result.axis, {pid: [by_id[p] for p in sorted(nx.ancestors(order, pid)) if p != base]
                                 for pid in result.axis if pid in order})
    result.pockets = [fit for fit in found if fit.part is None and not receives(fit)]
    holes = [fit for fit in found if fit not in result.pockets]
    result.holes = {f"h{k}": HoleFit(f"h{k}", *_fields(fit)) for k, fit in enumerate(holes, start=1)}
    result.pins, result.bores, result.further_bores = pins(result)
    result.part_holes = part_holes(result)
    result.swept = swept_fits(result)
    result.reasons |= owner_pairs(result)
    result.edges = set(result.reasons)
    result.queries = sweeper.queries
    return result


def _disassembled(result: Derived) -> set[str]:
    """Stage by stage, every part that some direction frees from the parts still in place
    leaves along the one :func:`_way_out` chooses of them (``result``'s ``axis`` and ``stages``
    filled in); the parts no stage frees."""
    remaining = set(result.parts) - {result.base}
    while remaining:
        stage = sorted(pid for pid in remaining if any(
            not (result.blockers[(pid, d)] & (remaining | {result.base})) for d in result.directions))
        if not stage:
            break
        for pid in stage:
            result.axis[pid] = _way_out(result, pid, [d for d in result.directions if not (
                result.blockers[(pid, d)] & (remaining | {result.base}))], remaining | {result.base})
        result.stages.append(stage)
        remaining -= set(stage)
    return remaining


def _way_out(result: Derived, pid: str, free: list[str], present: set[str]) -> str:
    """The way out part ``pid`` leaves along, of the directions ``free`` of the parts
    ``present`` (the base and the parts still in place): the first class of
    :data:`PREFERRED` holding one of them (a zero-clearance fit's axis of none of them,
    last), then within it by the product's geometry, each rule in the product's own terms,
    so that a turn about z chooses the same way:

    1. the shortest travel: the least distance [m] the part's body (it and the parts fixed
       to it) moves along the direction until it is past every triangle of the present
       parts in line with it (whose extent across the direction overlaps the body's by
       more than :data:`executor.cad.fits.faces.TOUCH`): a shaft free both ways goes in
       from the end nearer the product's face it passes, a wall beside that face, out of
       its line, not counted;
    2. the way away from the present parts' mass: the least component along the direction
       of the vector from the body's centre of mass to theirs (uniform density);
    3. :data:`LEAVING`'s order (a fit's axis after the six, in the order found).

    Ways within :data:`TIED` of the best are tied for a rule. Rule 3 is the cell frame's:
    a part that reaches it (equal travels, the present parts' mass centred across the ways,
    as in a product alike seen from either way) may go in from its other end with the
    product turned 180° about z."""
    def kind(d: str) -> int:
        return next((k for k, ways in enumerate(PREFERRED) if d in ways), len(PREFERRED))
    best = min(kind(d) for d in free)
    ways = [d for d in free if kind(d) == best]
    if len(ways) == 1:
        return ways[0]
    body = next(members for members in result.bodies.values() if pid in members)
    others = sorted(present - body)
    moving = np.vstack([result.parts[p].mesh.vertices for p in sorted(body)])
    fixed = np.vstack([result.parts[p].mesh.triangles for p in others])

    def travel(d: str) -> float:
        vector = np.array(result.directions[d])
        across = frame_of(vector)  # the cell's axes for the six: a quarter turn maps the boxes onto each other
        own = moving @ across.T
        theirs = fixed @ across.T
        inline = np.all((theirs.min(axis=1) < own.max(axis=0) - TOUCH)
                        & (theirs.max(axis=1) > own.min(axis=0) + TOUCH), axis=1)
        ahead = float((fixed[inline] @ vector).max()) if inline.any() else -math.inf
        return max(0.0, ahead - float((moving @ vector).min()))

    def mass_centre(ids: Iterable[str]) -> np.ndarray:
        meshes = [result.parts[p].mesh for p in ids]
        volumes = np.array([abs(m.volume) for m in meshes])
        return np.sum([v * m.center_mass for v, m in zip(volumes, meshes)], axis=0) / volumes.sum()

    apart = mass_centre(others) - mass_centre(sorted(body))
    for rule in (travel, lambda d: float(np.dot(apart, result.directions[d]))):
        values = {d: rule(d) for d in ways}
        least = min(values.values())
        ways = [d for d in ways if values[d] <= least + TIED]
        if len(ways) == 1:
            return ways[0]
    order = list(LEAVING) + [d for d in result.directions if d not in LEAVING]
    return min(ways, key=order.index)


def _ways_in(result: Derived) -> None:
    """Each part's insertion axis judged as the cell meets the part (``result.axis`` set
    anew): of the directions free of the parts present then, the one :func:`_way_out`
    chooses. Present are the base, the parts still in place at the part's disassembly stage and
    the parts ``result.edges`` put before its body; absent, the parts they put after it (the
    parts it supports, those its ``blocks`` and ``locates`` pairs put later), in place at its
    stage or not (a box the box resting on it leaves free only sideways goes in from above,
    before that one). Where the parts put before it and
    not in place at its stage leave it no way, the stage's own, less the parts after it."""
    order = nx.DiGraph(list(result.edges))
    root = {pid: r for r, members in result.bodies.items() for pid in members}

    def related(pid: str, find: Callable[[nx.DiGraph, str], set[str]]) -> set[str]:
        return set().union(*(find(order, m) for m in result.bodies[root[pid]] if m in order))

    def free(pid: str, present: set[str]) -> list[str]:
        return [d for d in result.directions if not result.blockers[(pid, d)] & present]

    for k, stage in enumerate(result.stages):
        in_place = set().union(*result.stages[k:]) | {result.base}
        for pid in stage:
            later = related(pid, nx.descendants)
            present = (in_place | related(pid, nx.ancestors)) - later
            if not free(pid, present):  # the stage's own way out is free of every part in place
                present = in_place - later
            result.axis[pid] = _way_out(result, pid, free(pid, present), present)


def receives(fit: HoleFit) -> bool:
    """Whether the empty hole ``fit`` is one a part goes into along its axis: its section is
    round, square or rect, or a simple polygon that turns onto itself about its centre by
    a fraction of a turn (:func:`executor.world.polygon_fit.symmetry` of order 2 or more:
    a hexagon, a spline, a cross, a 16-gon). A polygon with no such axis is a pocket: the
    open corner beside a turned boss, a relieved corner or a slot left around a pin of the
    base's own in its hole, the gap between two of its bodies; a sliver whose mean width
    (twice its area over its perimeter) is at most :data:`executor.cad.fits.faces.TOUCH` is a
    gap between faces that touch, whatever symmetry rounding lends it (one of a Technic
    pin's slits, 0.816 x 0.000 mm, was a hole with ``ldraw_axles`` turned 90 deg about z)."""
    if fit.hole.kind != "polygon":
        return True
    try:
        shape = polygon(fit.hole.outline, "hole")
    except OutlineError:  # no simple polygon: a gap of no area between faces that touch
        return False
    return 2 * shape.area > TOUCH * shape.length and symmetry(shape) >= 2


def owner_pairs(derived: Derived) -> dict[tuple[str, str], str]:
    """The ``feature`` pairs: the owner of a feature before each part that goes into or
    onto it (the base, or the moving part a hole is in, before the part in the hole; a
    pin's owner before the parts on it), where ``derived.edges`` do not order them already.
    The cell inserts a part into its feature, so the feature's owner must be in place
    first: a precondition of the insertion, not a consequence of the blocking (a peg
    standing on the floor through a hole of the base, touching none of it, has every way in
    free whatever the order, and the base would be carried into its fixture over it)."""
    order = nx.DiGraph(list(derived.edges))
    wanted = [(derived.base if fit.owner is None else fit.owner, part)
              for fit in [*derived.holes.values(), *derived.part_holes.values()] for part in fit.occupants]
    wanted += [(pin.owner, part) for pin in derived.pins.values() for part in pin.parts]
    return {(owner, part): "feature" for owner, part in sorted(set(wanted))
            if not (owner in order and part in order and nx.has_path(order, owner, part))}


def bodies(parts: dict[str, CadPart], base: str, fixed_to: dict[str, str]) -> dict[str, set[str]]:
    """The moving bodies: each part not fixed to another (not the base) -> it and the
    parts fixed to it, directly or through others."""
    def root(pid: str) -> str:
        seen = {pid}
        while pid in fixed_to and fixed_to[pid] not in seen:
            pid = fixed_to[pid]
            seen.add(pid)
        return pid
    found: dict[str, set[str]] = {}
    for pid in parts:
        if pid != base:
            found.setdefault(root(pid), set()).add(pid)
    return found


def forced(derived: Derived) -> dict[tuple[str, str], str]:
    """The ``blocks`` pairs: A before B when, of the directions the base leaves A free
    along, B blocks one and B or the parts present whenever B is (its body, the base, the
    bodies already found to precede it) block every one; repeated until no pair is added,
    then every pair the rule gives with those, also where A already precedes B through
    others (so the pairs do not depend on the order of the ids). Each pair's blockers per
    direction in ``derived.detail``."""
    rep = {root: min(members) for root, members in derived.bodies.items()}
    before: dict[str, set[str]] = {root: set() for root in derived.bodies}
    pairs: dict[tuple[str, str], str] = {}

    def ahead(root: str) -> set[str]:
        seen: set[str] = set()
        todo = [root]
        while todo:
            for prior in before[todo.pop()] - seen:
                seen.add(prior)
                todo.append(prior)
        return seen

    def found(a: str, b: str, known: bool) -> bool:
        """Whether the rule puts body ``a`` before body ``b`` (recorded); ``known``: also
        where ``a`` is already found to precede ``b``."""
        ways, prior = list(derived.ways(rep[a])), ahead(b)
        if b == a or (a in prior and not known) or not ways:
            return False
        present = derived.bodies[b].union(*(derived.bodies[p] for p in prior - {a}))
        blocking = {d: derived.blockers[(rep[a], d)] & present for d in ways}
        if not all(blocking.values()) or not any(hit & derived.bodies[b] for hit in blocking.values()):
            return False
        detail = "; ".join(f"{d} {' '.join(sorted(hit))}" for d, hit in blocking.items())
        for x in sorted(derived.bodies[a]):
            for y in sorted(derived.bodies[b] & set().union(*blocking.values())):
                pairs[(x, y)] = "blocks"
                derived.detail[(x, y)] = detail
        return True

    grown = True
    while grown:
        grown = False
        for a in derived.bodies:
            for b in derived.bodies:
                if found(a, b, known=False):
                    before[b].add(a)
                    grown = True
    # every pair the rule gives once nothing is added, those already ordered through others
    # too: which ones the loop skipped depends on the order of the ids
    for a in derived.bodies:
        for b in derived.bodies:
            if a in ahead(b):
                found(a, b, known=True)
    return pairs


def first_hit(mesh: trimesh.Trimesh, origin: np.ndarray, direction: np.ndarray) -> float | None:
    """Distance [m] along the unit ``direction`` from ``origin`` to the first triangle of
    ``mesh`` (Möller-Trumbore over all triangles), None when the ray meets none."""
    t, _ = _hits(mesh, origin, direction)
    return float(t.min()) if len(t) else None


def _roofed(mesh: trimesh.Trimesh, origin: np.ndarray, direction: np.ndarray) -> bool:
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


def _part_slice(part: CadPart, base: CadPart, axis: np.ndarray) -> tuple[float, Loop] | None:
    """The level [m] (to 0.1 µm) in the middle of the part's depth inside the base along ``axis`` (the
    base's extent there taken over its vertices within the part's box across the axis, where
    at that level the base has an inner loop around the part: a switch's body in the slot of
    a hollow case's top, sliced in the top, not in the cavity under it; else over its
    vertices within that box grown by the box's larger side on each side: the walls of a
    hole with room around the part, while a pin of the base standing farther off is not
    around it) and the part's one outline there (a ring's, its bore inside); None when
    the part does not reach into the base or its slice there is not one outline. Where the
    base's slice at that level has no inner loop around the part (a boss of the base beside
    it stretches the base's extent: a bolt in a hub's disc next to its boss, sliced at the
    disc's face), the level of the base's hole around it that :func:`_hole_around` finds,
    if any."""
    across = np.abs(axis) < 0.5
    lower, upper = part.mesh.bounds[0][across], part.mesh.bounds[1][across]
    tight = _level_within(part, base, axis, lower, upper)
    if tight is not None and _holds(base, axis, *tight):
        return tight
    grown = float(np.max(upper - lower))
    found = _level_within(part, base, axis, lower - grown, upper + grown)
    if found is None:
        return None
    level, own = found
    if not _holds(base, axis, level, own):
        hit = _hole_around(base, part, axis)
        if hit is not None:
            return round(hit[0], 7), hit[3]
    return level, own


def _level_within(part: CadPart, base: CadPart, axis: np.ndarray, lower: np.ndarray, upper: np.ndarray
                  ) -> tuple[float, Loop] | None:
    """The level [m] (to 0.1 µm) in the middle of the part's depth inside the base along
    ``axis``, the base's extent taken over its vertices between ``lower`` and ``upper``
    across the axis [m], and the part's one outline there; None when no vertex of the base
    lies there, the part does not reach into that extent or its slice there is not one
    outline."""
    across = np.abs(axis) < 0.5
    inside = np.all((base.mesh.vertices[:, across] >= lower) & (base.mesh.vertices[:, across] <= upper), axis=1)
    if not np.any(inside):
        return None
    along, base_along = part.mesh.vertices @ axis, base.mesh.vertices[inside] @ axis
    low, high = max(along.min(), base_along.min()), min(along.max(), base_along.max())
    if high - low <= 1e-6:
        return None
    level = round(float(low + high) / 2, 7)
    cut = slice_loops(part.mesh, axis, level)
    own = [loop for loop in cut if _outer(loop, cut)]
    return (level, own[0]) if len(own) == 1 else None


def _holds(base: CadPart, axis: np.ndarray, level: float, own: Loop) -> bool:
    """Whether the base's slice at ``level`` [m] across ``axis`` has an inner loop around
    the centre of the part's outline ``own``."""
    loops = slice_loops(base.mesh, axis, level)
    return any(loop.contains(own.centre) and not _outer(loop, loops) for loop in loops)


def _holes(base: CadPart, parts: list[CadPart], axes: dict[str, str], before: dict[str, list[CadPart]]
           ) -> list[HoleFit]:
    """Every inner loop of the base's slices (at the levels of the parts in it, or at its
    middle along +z), with the part in it where one is, in order of position. A part is in
    none when, at its level, its bore holds an outline of the base or of one of the parts
    ``before`` it (a gland on a shaft: it goes onto a pin, :func:`pins`), or when it lies
    in the bore of another part standing in the base along its axis (a shaft in a bearing
    ring that stands in a housing's bore: the ring's hole, :func:`part_holes`), in along
    the same way or, that part ``before`` it, the other way (the shaft sent in from the
    ring's far end, through the housing's other opening: still in the ring, not in the
    housing's bore, where it would be a peg standing in a hole of the base, and the glands
    going in after it along its axis covers over it, on no pin)."""
    def sliced(part: CadPart) -> tuple[float, Loop] | None:
        axis = np.array(DIRECTIONS[axes[part.id]])
        found = _part_slice(part, base, axis)
        if found is not None and not any(_bore_around(part.mesh, other.mesh, axis, found[0]) is not None
                                         for other in [base, *before.get(part.id, [])]):
            return found
        return None

    workers = processes([base.mesh, *(part.mesh for part in parts)])
    cut = {part.id: found for part, found in zip(parts, forked_map(sliced, parts, workers,
                                                                   cost=lambda part: len(part.mesh.faces)))
           if found is not None}
    by_id = {part.id: part for part in parts}
    slices: dict[tuple[str, float], list[tuple[CadPart, Loop]]] = {}

    def in_another(pid: str) -> bool:
        axis = np.array(DIRECTIONS[axes[pid]])
        earlier = {part.id for part in before.get(pid, [])}
        return any(other != pid and (axes[other] == axes[pid] or (axes[other] == opposite(axes[pid])
                                                                   and other in earlier))
                   and _hole_around(by_id[other], by_id[pid], axis) for other in cut)

    for (pid, (level, own)), inside in zip(cut.items(), forked_map(in_another, list(cut), workers)):
        if not inside:
            slices.setdefault((axes[pid], round(level, 7)), []).append((by_id[pid], own))
    if not slices:
        z = base.mesh.vertices[:, 2]
        slices[("+z", round(float(z.min() + z.max()) / 2, 7))] = []
    fits: list[tuple[HoleFit, np.ndarray, np.ndarray]] = []  # each with its centre at the level sliced, its axis
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
            same = [k for k, (f, _, _) in enumerate(fits) if f.axis == name and np.linalg.norm(
                np.array(f.centre) - centre - axis * np.dot(np.array(f.centre) - centre, axis)) < _SAME_HOLE]
            if same and (occupant is None or fits[same[0]][0].part is not None):
                continue
            if occupant is None and _roofed(base.mesh, centre, axis):
                continue  # empty and roofed along its axis: a cavity open the other way (a brick's underside)
            # a hole met empty at another part's level (a shallower one beside a deeper) is its occupant's
            fit = (_measure(base, name, loop, level, around[0] if around else None, occupant, workers), centre, axis)
            if same:
                fits[same[0]] = fit
            else:
                fits.append(fit)
    found = _without_cavities(base.mesh, fits)
    found.sort(key=lambda f: (round(f.centre[0], 6), round(f.centre[1], 6), round(f.centre[2], 6)))
    return found


def _without_cavities(base: trimesh.Trimesh, fits: list[tuple[HoleFit, np.ndarray, np.ndarray]]) -> list[HoleFit]:
    """The holes of ``fits`` (each with its centre at the level sliced and its axis) that
    are no open box's cavity in ``base`` (:func:`_open_box`): a part in a cavity is in no
    hole, and an empty cavity, or one so emptied, is no hole when it is one for the widest
    part left in a hole (every empty floored loop wider than :data:`CAVITY_ROOM` when none is)."""
    emptied = [(replace(fit, part=None, section=None)
                if fit.section is not None and _open_box(fit.hole.b, fit.section.a, base, centre, axis) else fit,
                centre, axis) for fit, centre, axis in fits]
    widest = max((fit.section.a for fit, _, _ in emptied if fit.section is not None), default=0.0)
    return [fit for fit, centre, axis in emptied
            if fit.part is not None or not _open_box(fit.hole.b, widest, base, centre, axis)]


def _open_box(narrowest: float, widest: float, mesh: trimesh.Trimesh, centre: np.ndarray, axis: np.ndarray) -> bool:
    """Whether a loop of ``mesh`` ``narrowest`` [m] across (its section's short side) is an
    open box's cavity for a part ``widest`` [m] at its widest (its section's long side): it
    leaves it more than :data:`CAVITY_ROOM` of room, so it locates nothing of that size, and
    it has a floor (the ray from its ``centre`` [m] down the unit ``axis`` goes into the
    solid: no opening through)."""
    return narrowest - widest > CAVITY_ROOM and _roofed(mesh, centre, -axis)


def _roomy(hole: Loop, part: Loop) -> bool:
    """Whether the ``hole`` loop may leave the ``part``'s loop in it more than
    :data:`CAVITY_ROOM` across (:func:`_open_box`), by bounds that need no minimum-area
    rectangle (whose sides cost a turn per hull edge, a second on a fine round loop): the
    hole's short side is at most the square root of its axis-aligned box's area, the
    part's long side at least the square root of its own area. False: it does not."""
    box = np.ptp(hole.points, axis=0)
    return math.sqrt(float(box[0] * box[1])) - math.sqrt(part.area) > CAVITY_ROOM


def _outer(loop: Loop, loops: list[Loop]) -> bool:
    """Whether ``loop`` is an outline of its slice (inside an even number of the others)."""
    return sum(1 for o in loops if o is not loop and o.area > loop.area and o.contains(loop.centre)) % 2 == 0


def pins(derived: Derived) -> tuple[dict[str, PinFit], dict[str, Shape2D], dict[tuple[str, str], Shape2D]]:
    """The pins moving parts go onto and each such part's bore section (module docstring,
    :func:`_pin_of`): a part with a bore around one outline of another part, that part the
    base or one the geometric precedence puts before it (a part that goes in after, into
    the bore, is no pin: a head in a cover's socket). A bore around no such outline is no
    fit; nor is one around a peg standing in a hole of the base that goes in along the
    part's own axis (that part is a cover, :mod:`executor.cad.covers`), unless the part
    rests on such pegs alone (:attr:`Derived.supports`: it goes onto their ends). Parts on one pin
    share its section, the one measured over the longest stretch of it (from the part
    farthest from its end). A part goes onto every pin of each such owner (in order of their
    names) that stands in a bore of its own around no pin it is on already: a plate onto
    both dowel pins of the base, asm4_disk_arm's arm onto the base's pivot pin through its
    bore and onto the disk's nipple through its slot; but not onto a further pin that
    another part is around (:func:`_within_another`: a washer over a sleeve over a pin).
    Its first bore is its section against every pin (:attr:`Derived.bores`), each
    further one against its own pin (:attr:`Derived.further_bores`): also the (part,
    pin) -> bore pairs returned third."""
    found: list[tuple[str, str, Shape2D, np.ndarray, str | None, float]] = []  # owner, axis, pin, centre, part, level
    further: dict[int, Shape2D] = {}  # index in found -> the part's bore there, on a pin other than its first
    order = nx.DiGraph(list(derived.edges))
    bores: dict[str, Shape2D] = {}
    levels: dict[str, float] = {}
    for pid in sorted(derived.axis):
        if pid not in derived.hole_of:
            along = derived.parts[pid].mesh.vertices @ np.array(derived.directions[derived.axis[pid]])
            levels[pid] = float(along.min() + along.max()) / 2
    onto = forked_map(lambda pid: _pins_of(derived, order, pid, levels[pid]), list(levels),
                      processes(p.mesh for p in derived.parts.values()),
                      cost=lambda pid: len(derived.parts[pid].mesh.faces))
    for pid, hits in zip(levels, onto):
        for k, (other, pin, centre, level, bore) in enumerate(hits):
            if k:
                further[len(found)] = bore
            else:
                bores[pid] = bore
            found.append((other, derived.axis[pid], pin, centre, pid, level))
    found += [(derived.base, derived.axis[pid], pin, centre, None, math.inf) for pid in sorted(bores)
              for pin, centre in _standing_pins(derived, derived.axis[pid], levels[pid], bores.values())]
    merged: list[tuple[str, str, Shape2D, np.ndarray, list[str], float]] = []
    held: list[list[tuple[Shape2D, Shape2D]]] = []  # index in merged -> each part's own pin section and bore
    into: list[int] = []  # index in found -> index in merged
    for k, (owner, name, pin, centre, on, level) in enumerate(found):
        axis = np.array(derived.directions[name])
        mine = [] if on is None else [(pin, further[k] if k in further else bores[on])]
        same = None
        for k_merged, m in enumerate(merged):
            # coaxial, and the section kept passes every bore on it that passes its own: a
            # pin's wider step farther from its end (a pot's thread under its shaft) is a pin
            # of its own, not the section of the knob on the shaft; a standing pin whose
            # outline holds the pin's centre is that pin (a D-shaft's centroid lies off its axis)
            across = float(np.linalg.norm((m[3] - centre) - axis * np.dot(m[3] - centre, axis)))
            kept = pin if level < m[5] else m[2]
            if m[:2] == (owner, name) and (
                    across < _SAME_HOLE and all(passes(kept, bore) or not passes(own, bore)
                                                for own, bore in held[k_merged] + mine)
                    if on is not None else across < _SAME_HOLE or shapely.Polygon(pin.outline + pin.centre)
                    .contains(shapely.Point(frame_of(axis) @ m[3]))):
                same = k_merged
                break
        into.append(len(merged) if same is None else same)
        if same is None:
            merged.append((owner, name, pin, centre, [] if on is None else [on], level))
            held.append(mine)
            continue
        held[same] += mine
        parts = merged[same][4] + ([] if on is None else [on])
        merged[same] = (owner, name, pin, centre, parts, level) if level < merged[same][5] else (
            *merged[same][:4], parts, merged[same][5])
    ids: dict[int, str] = {}
    counts: dict[str, int] = {}
    result: dict[str, PinFit] = {}
    for k in sorted(range(len(merged)), key=lambda k: (merged[k][0], *(round(float(v), 6) for v in merged[k][3]))):
        owner, name, pin, centre, parts, _ = merged[k]
        counts[owner] = counts.get(owner, 0) + 1
        ids[k] = pin_id = f"{owner}_pin{counts[owner]}"
        result[pin_id] = PinFit(pin_id, owner, name, pin, (float(centre[0]), float(centre[1]), float(centre[2])),
                                tuple(parts))
    return result, bores, {(str(found[k][4]), ids[into[k]]): bore for k, bore in further.items()}


def _pins_of(derived: Derived, order: nx.DiGraph, pid: str, middle: float
             ) -> list[tuple[str, Shape2D, np.ndarray, float, Shape2D]]:
    """The pins part ``pid`` goes onto (:func:`pins`), in order: each one's owner, section,
    centre [m], the level [m] it was measured at and the part's bore there; ``order`` the
    geometric precedence, ``middle`` [m] the middle of the part's extent along its removal
    direction."""
    name = derived.axis[pid]
    before = nx.ancestors(order, pid) if pid in order else set()
    covered = {peg for peg in derived.hole_of if derived.axis[peg] == name}  # over it: a cover
    resting = {y for y, x in derived.supports if x == pid}
    if resting and resting <= covered:  # on those pegs alone: onto their ends, as no cover rests
        covered -= resting
    taken: list[np.ndarray] = []  # the centres of the pins the part is on so far, across the axis
    hits = []
    for other in sorted(({derived.base} | before) - covered):
        while (hit := _pin_of(derived, pid, name, other, taken)) is not None:
            pin, bore, centre, level = hit
            if any(np.linalg.norm(pin.centre - point) < _SAME_HOLE for point in taken):
                break  # its bore is around a pin the part is on already
            taken.append(pin.centre)
            if len(taken) > 1 and _within_another(derived, pid, other, name, pin.centre, middle):
                continue  # a washer over a sleeve over a pin: the pin is the sleeve's to go into
            hits.append((other, pin, centre, level, bore))
    return hits


def _within_another(derived: Derived, pid: str, owner: str, name: str, centre: np.ndarray, level: float) -> bool:
    """Whether a part other than ``pid`` and ``owner`` is around the point ``centre`` (2,) [m]
    across removal direction ``name`` (an outline of its slice at ``level`` [m] along it
    holds the point): a pin of ``owner`` there stands in that part's bore (or under it),
    so ``pid``'s bore around both goes over that part, not onto the pin."""
    axis = np.array(derived.directions[name])
    frame = frame_of(axis)
    for other in sorted(set(derived.parts) - {pid, owner}):
        mesh = derived.parts[other].mesh
        along, across = mesh.vertices @ axis, mesh.vertices @ frame.T
        if not (along.min() < level < along.max()) or not np.all(
                (across.min(axis=0) <= centre) & (centre <= across.max(axis=0))):
            continue  # it does not reach the level, or no outline of it can hold the point
        loops = slice_loops(mesh, axis, level)
        if any(_outer(loop, loops) and loop.contains(centre) for loop in loops):
            return True
    return False


def _pin_of(derived: Derived, pid: str, name: str, owner: str, taken: Iterable[np.ndarray] = ()
            ) -> tuple[Shape2D, Shape2D, np.ndarray, float] | None:
    """Part ``pid`` on a pin of ``owner`` along removal direction ``name``: the pin's
    section, the bore's, the pin's centre [m] and the level [m] along the direction they
    were measured at; None when no level tried has one of ``pid``'s inner loops (its bore)
    around exactly one outline of ``owner`` lying in it (within the bore's sagitta and
    :data:`executor.cad.fits.faces.TOUCH`, as a nominal zero-clearance fit lies), no bore around
    a point of ``taken`` (the centres [m] across the axis of pins the part is on already: it
    goes onto another pin only through another bore of its own). The pin is the owner's
    within the part's reach across the axis, short of the owner's outlines in the part's
    other bores by twice :data:`_SAME_HOLE` (a plate's other dowel pin is not this one). The levels
    tried: the middle of the part's extent along the direction, then
    :data:`_HOLE_LEVELS` middles of the spans between the owner's vertex levels where both
    reach, longest first (a pulley whose middle lies behind the hub's disc has its bore
    around the boss in front of it).

    The part leaves over the pin's stretch from its own trailing end to the pin's free end
    (the owner's farthest vertex along the direction near the line): its bore at each level
    passes every section of the pin beyond that level. The sections kept are those of the
    narrowest such passage (the least room, :func:`executor.cad.sections.section_room`): the
    bore over one span and the union of the pin's outlines beyond it, over spans end to end
    split at the vertex levels of both (:func:`_intervals`), each measured over its whole
    length (:func:`executor.cad.sections.over_span`: the bore free at every level of it,
    the pin covering at some level), so a bore narrowest at a vertex level is measured
    there (Meta-World's torus ring, d 74.569 mm at its middle, d 74.980 at the nearest
    span's middle); a gland's d 17 lips, not the d 28 recess between them; a pulley's
    d 26 web over the boss's d 26 collar, not the d 22 it sits on. Of the passages within
    :data:`executor.cad.sections.OUTLINE_TOUCH` of the narrowest (one nominal room), the
    one nearest the pin's free end: a taper passes at zero clearance at every level,
    and alike parts on alike pins are then measured at the same level (asap_beam's feet on
    their tapered tenons: at levels 0.7 mm apart their sections differed by 63 µm)."""
    axis = np.array(derived.directions[name])
    part, other = derived.parts[pid].mesh, derived.parts[owner].mesh
    along, other_along = part.vertices @ axis, other.vertices @ axis
    low, high = max(along.min(), other_along.min()), min(along.max(), other_along.max())
    if high - low <= 1e-6:
        return None
    middle = float(along.min() + along.max()) / 2
    hit = next((found for level in ([middle] if low < middle < high else [])
                + _spans(other_along, low, high)[:_HOLE_LEVELS]
                if (found := _bore_around(part, other, axis, level, taken)) is not None), None)
    if hit is None:
        return None
    line, apart = hit
    frame = frame_of(axis)
    reach = min(float(np.linalg.norm(part.vertices @ frame.T - line, axis=1).max()), apart - 2 * _SAME_HOLE)
    near = other_along[np.linalg.norm(other.vertices @ frame.T - line, axis=1) <= reach + _SAME_HOLE]
    start, end = float(along.min()), float(near.max())
    stretch: list[tuple[float, Loop | None, shapely.Polygon | None]] = []
    for low, high in _intervals(np.concatenate([along, near]), start, end, _PIN_LEVELS):
        level = (low + high) / 2
        own, theirs = slice_loops(part, axis, level), slice_loops(other, axis, level)
        bores = [o for o in own if o.contains(line) and not _outer(o, own)]
        pins = [o for o in theirs if o.contains(line) and float(np.linalg.norm(o.points - line, axis=1).max()) <= reach
                and _outer(o, theirs)]  # the base's plate is no pin
        narrowest = over_span(min(bores, key=lambda o: o.area), part, axis, low, high, hole=True) if bores else None
        widest = over_span(min(pins, key=lambda o: o.area), other, axis, low, high, hole=False,
                           reach=reach) if pins else None
        stretch.append((level, narrowest if narrowest is not None and len(narrowest.points) >= 3 else None,
                        None if widest is None else shapely.Polygon(widest.points)))
    beyond: shapely.Polygon | None = None
    passages: list[tuple[float, Shape2D, Shape2D, float]] = []
    rooms: dict[tuple[bytes, bytes], float] = {}
    for level, bore, pin in reversed(stretch):
        if pin is not None:
            beyond = _joined(beyond, pin)
        if bore is None or beyond is None:
            continue
        outline = _outline(beyond)
        union, hole = classify(outline, hole=False), classify(bore, hole=True)
        hole = faceted(hole, bore, union, hole=True)  # a tessellated round one against no round: its polygon
        union = faceted(union, outline, hole, hole=False)
        key = (np.round(union.outline + union.centre, 8).tobytes(), np.round(bore.points, 8).tobytes())
        if key not in rooms:
            try:
                rooms[key] = section_room(union, hole, "pin", "bore").margin
            except OutlineError:
                continue
        passages.append((rooms[key], union, hole, level))
    if not passages:
        return None
    least = min(room for room, *_ in passages)
    _, pin, hole, level = max((p for p in passages if p[0] <= least + OUTLINE_TOUCH), key=lambda p: p[3])
    return pin, hole, frame.T @ pin.centre + axis * level, level


def swept_fits(derived: Derived) -> dict[tuple[str, str], tuple[Shape2D, Shape2D, float]]:
    """The pairs the sweep admits (:func:`executor.cad.sections.passage`) though the peg's
    section over its whole stretch does not pass the hole's (a taper in its own taper, a
    stepped peg in its stepped hole): a part in a hole (of the base or of a moving part)
    in the pose the product has it, leaving along the hole's axis from its tip to the entry,
    and a pin in the bore of a part on it, the pin leaving the bore; each with the sections
    at the levels of least room and that room (diametral). A peg the sweep admits into its
    own feature is tried the same way in every other feature of its owner along that axis
    (moved onto that feature's centre line and as deep past its entry; a pin under the bore
    as far past its tip), where the sections do not pass. A pair is admitted when its room
    is positive or it is a nominal zero-clearance fit (:func:`executor.cad.sections.zero_clearance`).
    A screwed pair (a modelled thread, :meth:`Derived.screwed`) is not swept: its part fits
    its feature by screwing, written with the feature's section for both and room 0."""
    found: dict[tuple[str, str], tuple[Shape2D, Shape2D, float]] = {}
    slicers: dict[tuple[str, str], Slicer] = {}

    def slicer(pid: str, name: str, out: np.ndarray) -> Slicer:
        if (pid, name) not in slicers:
            slicers[(pid, name)] = Slicer(derived.parts[pid].mesh, out)
        return slicers[(pid, name)]

    def admitted(way: Passage | None) -> tuple[Shape2D, Shape2D, float] | None:
        if way is None:
            return None
        peg, hole = classify(way.peg, hole=False), classify(way.hole, hole=True)
        return (peg, hole, way.room) if way.room > 0 or zero_clearance(peg, hole, way.room) is not None else None

    def extent(pid: str, out: np.ndarray, line: np.ndarray, reach: float) -> tuple[float, float]:
        """The least and the greatest level [m] along ``out`` of ``pid``'s vertices within
        ``reach`` [m] of the point ``line`` across it."""
        along = derived.parts[pid].mesh.vertices
        near = along[np.linalg.norm(along @ frame_of(out).T - line, axis=1) <= reach] @ out
        return (float(near.min()), float(near.max())) if len(near) else (math.inf, -math.inf)

    holes = {**derived.holes, **derived.part_holes}
    for hid, fit in holes.items():
        if fit.part is None or fit.section is None or passes(fit.section, fit.hole):
            continue
        if derived.screwed(fit.part, fit.owner or derived.base):
            found[(fit.part, hid)] = (fit.hole, fit.hole, 0.0)
            continue
        out = np.array(DIRECTIONS[fit.axis])
        owner = fit.owner or derived.base
        peg, walls = slicer(fit.part, fit.axis, out), slicer(owner, fit.axis, out)
        tip = float((derived.parts[fit.part].mesh.vertices @ out).min())
        for other, there in [(hid, fit), *((k, h) for k, h in holes.items() if k != hid)]:
            if other != hid and (there.axis != fit.axis or (there.owner or derived.base) != owner
                                 or passes(fit.section, there.hole)):
                continue
            floor = extent(owner, out, there.hole.centre, max(there.hole.a, there.hole.b))[0]
            offset = frame_of(out).T @ (there.hole.centre - fit.hole.centre) + out * (there.entry - fit.entry)
            way = admitted(passage(peg, walls, there.hole.centre, max(tip + there.entry - fit.entry, floor),
                                   there.entry, offset))
            if way is None and other == hid:
                break
            if way is not None:
                found[(fit.part, other)] = way
    for pin_id, pin in derived.pins.items():
        out = -np.array(derived.directions[pin.axis])
        name = f"against {pin.axis}"  # the slicers across the pin's way out of the bore
        line = frame_of(out) @ np.array(pin.centre)
        reach = max(pin.section.a, pin.section.b)
        for pid in pin.parts:
            own = derived.bore_on(pid, pin_id)
            if passes(pin.section, own):
                continue
            if derived.screwed(pid, pin.owner):
                found[(pid, pin_id)] = (own, own, 0.0)
                continue
            bore = slicer(pid, name, out)
            low, entry = extent(pid, out, line, reach)
            tip = extent(pin.owner, out, line, reach)[0]
            for other_id, under in [(pin_id, pin), *((k, p) for k, p in derived.pins.items() if k != pin_id)]:
                if other_id != pin_id and (under.axis != pin.axis or passes(under.section, own)):
                    continue
                centre = frame_of(out) @ np.array(under.centre)
                offset = frame_of(out).T @ (line - centre) + out * (tip - extent(under.owner, out, centre, reach)[0])
                way = admitted(passage(slicer(under.owner, name, out), bore, line, max(low, tip), entry, offset))
                if way is None and other_id == pin_id:
                    break
                if way is not None:
                    found[(pid, other_id)] = way
    return found


def _joined(beyond: shapely.Polygon | None, pin: shapely.Polygon) -> shapely.Polygon:
    """The union of a pin's sections ``beyond`` a level (None: none yet) and ``pin``, its
    section at the level, its vertices on a grid of :data:`_GRID` [m]: the sections of a
    straight pin differ by the mesh's noise (under 1 µm), and GEOS takes seconds over the
    slivers between two alike many-sided outlines unless their vertices snap together.
    A union with more than 4 times the section's vertices has gathered the sections' noise
    (25 000 vertices over 64 levels of a 300-sided pin, each union slower than the last):
    its vertices within the grid of the line through their neighbours are left out
    (Douglas-Peucker, topology kept), which moves it less than the grid (64 noisy sections
    of a round pin: within 3 grid steps of their union taken at once, about one section's
    vertices). A union that stays smaller is kept as it is. On ldraw_axles' cross axle
    (45 vertices a section, its union 239) the simplified union gives the bush and the
    gear on it 0.1 µm more room than the union kept whole (+0.0 µm, not -0.1 µm: the same
    nominal fits)."""
    if beyond is None:
        return pin
    union = shapely.union(beyond, pin, grid_size=_GRID)
    if not isinstance(union, shapely.Polygon):  # snapped apart, or with lines of no area: what holds them all
        polygons = [part for part in shapely.get_parts(union) if isinstance(part, shapely.Polygon)]
        union = polygons[0] if len(polygons) == 1 else shapely.union_all(polygons).convex_hull
    if len(union.exterior.coords) > 4 * len(pin.exterior.coords):
        return shapely.simplify(union, _GRID)
    return union


def _outline(union: shapely.Polygon) -> Loop:
    """The outer loop of the ``union`` of a pin's sections (:func:`_joined`) without its
    jitter: its vertices within :data:`_JITTER` of the line through their neighbours
    dropped (Douglas-Peucker). Where two alike outlines cross at a small angle the union
    alternates between them in edges of a few tens of nm, which the cell's chamfer
    offsets into spikes (``ldraw_axles``' cross axle: 630 vertices for its 16 corners)."""
    return Loop(np.asarray(shapely.simplify(shapely.Polygon(union.exterior), _JITTER).exterior.coords)[:-1])


def _bore_around(part: trimesh.Trimesh, other: trimesh.Trimesh, axis: np.ndarray, level: float,
                 taken: Iterable[np.ndarray] = ()) -> tuple[np.ndarray, float] | None:
    """The centre (2,) [m] of the one outline of ``other`` that lies in an inner loop (a
    bore) of ``part`` on their slices at ``level`` [m] along ``axis`` (:func:`_in_loop`),
    of the bores around none of the points ``taken`` (2,) [m], and how far [m] from it the
    nearest outline of ``other`` in another inner loop of ``part`` lies (a plate's other
    dowel pin: inf when there is none); None when no bore holds exactly one."""
    own = slice_loops(part, axis, level)
    bores = [o for o in own if not _outer(o, own) and not any(o.contains(point) for point in taken)]
    if not bores:
        return None
    across = other.vertices @ frame_of(axis).T
    if not any(np.all((across >= bore.points.min(axis=0)) & (across <= bore.points.max(axis=0)), axis=1).any()
               for bore in bores):
        return None  # nothing of the other part in a bore's box across the axis, at any level: no slice needed
    theirs = slice_loops(other, axis, level)
    outlines = [o for o in theirs if _outer(o, theirs)]
    for bore in bores:
        inside = [o for o in outlines if bore.contains(o.centre) and _in_loop(o, bore)]
        if len(inside) == 1:
            centre = inside[0].centre
            apart = [float(np.linalg.norm(o.points - centre, axis=1).min()) for o in outlines
                     if o is not inside[0] and any(h is not bore and h.contains(o.centre) for h in own
                                                   if not _outer(h, own))]
            return centre, min(apart, default=math.inf)
    return None


def _spans(levels: np.ndarray, low: float, high: float) -> list[float]:
    """The middles [m] of the spans between the distinct ``levels`` [m] clipped to
    [``low``, ``high``], longest first, spans of 1 µm or less left out: a slice changes only
    at its mesh's vertex levels."""
    bounds = np.unique(np.concatenate([[low, high], np.unique(np.round(np.clip(levels, low, high), 9))]))
    spans = sorted(zip(bounds[:-1], bounds[1:], strict=True), key=lambda span: span[0] - span[1])
    return [float(a + b) / 2 for a, b in spans if b - a > 1e-6]


def _intervals(levels: np.ndarray, low: float, high: float, count: int) -> list[tuple[float, float]]:
    """Spans [m] that cover [``low``, ``high``] end to end, split at the distinct
    ``levels`` [m] within it (a slice changes only at its mesh's vertex levels, so within
    a span each section's corners move in straight lines), spans of 1 µm or less joined to
    the next; where that makes more than ``count`` spans, split only at the ends of the
    ``count`` longest (a joined span is measured over its whole length: never less
    narrow, only coarser)."""
    bounds = [low]
    for level in np.unique(np.round(np.clip(levels, low, high), 9)):
        if level - bounds[-1] > 1e-6 and high - level > 1e-6:
            bounds.append(float(level))
    bounds.append(high)
    spans = list(zip(bounds[:-1], bounds[1:], strict=True))
    if len(spans) > count:
        kept = sorted({low, high} | {end for span in sorted(spans, key=lambda s: s[0] - s[1])[:count] for end in span})
        spans = list(zip(kept[:-1], kept[1:], strict=True))
    return spans


def _standing_pins(derived: Derived, name: str, level: float,
                   bores: Iterable[Shape2D]) -> list[tuple[Shape2D, np.ndarray]]:
    """The pins of the base that stand out along ``name`` through ``level`` [m] and that
    some of ``bores`` passes over, each with its centre [m] on that level: the outlines
    of the base's slice there with no outline inside them (a pin, solid or hollow) and
    nothing of the base beyond the level within their circumscribed circle but the pin
    itself (its free end: a part comes down onto it), whose section passes a bore
    (:func:`executor.cad.sections.passes`, as ``sizes.lp`` decides)."""
    axis = np.array(derived.directions[name])
    frame = frame_of(axis)
    vertices = derived.parts[derived.base].mesh.vertices
    beyond = vertices[vertices @ axis > level] @ frame.T
    loops = slice_loops(derived.parts[derived.base].mesh, axis, level)
    standing = []
    for loop in loops:
        if not _outer(loop, loops) or any(o is not loop and _outer(o, loops) and loop.contains(o.centre)
                                          for o in loops):
            continue
        reach = float(np.linalg.norm(loop.points - loop.centre, axis=1).max()) + _SAME_HOLE
        over = beyond[np.linalg.norm(beyond - loop.centre, axis=1) <= reach]
        outline = shapely.Polygon(loop.points).buffer(_ON_PIN)
        if not shapely.contains_xy(outline, over[:, 0], over[:, 1]).all():
            continue
        pin = classify(loop, hole=False)
        if any(passes(pin, bore) for bore in bores):
            standing.append((pin, frame.T @ pin.centre + axis * level))
    return standing


def part_holes(derived: Derived) -> dict[str, HoleFit]:
    """The holes of moving parts (``<owner>_hole1``, ... by position) and the parts in
    each (module docstring): a moving part in no hole of the base and onto no pin, whose
    outline across its insertion axis (one of the six) lies in an inner loop of a part the
    geometric precedence puts before it (not the base, not of its own body) at a level both
    reach: a rod through a bracket's bore, a shaft into a bearing placed before it; and a
    part onto a pin whose outline (its outside) lies so in an inner loop of a part the
    precedence does not put after it: a clutch plate on its shaft, its splined outside in
    the outer holder's splined hole. The parts in one hole (within :data:`_SAME_HOLE` of
    each other across its axis) are its occupants, the deepest first (the hole measured
    over its stretch)."""
    order = nx.DiGraph(list(derived.edges))
    pairs = []  # (part, owner): each part's, owners in order of their names
    for pid in sorted(derived.axis):
        if pid in derived.hole_of or derived.axis[pid] not in DIRECTIONS or pid not in order:
            continue
        body = next(members for members in derived.bodies.values() if pid in members)
        if pid in derived.bores:  # onto a pin: owners around it (their box across the axis holds its box)
            owners = {other for other in set(derived.parts) - nx.descendants(order, pid)
                      if _around(derived.parts[other].mesh, derived.parts[pid].mesh, derived.axis[pid])}
        else:
            owners = nx.ancestors(order, pid)
        pairs += [(pid, owner) for owner in sorted(owners - {derived.base} - body)]
    found = [fit for fit in forked_map(lambda pair: _hole_of(derived, *pair), pairs,
                                       processes(p.mesh for p in derived.parts.values()),
                                       cost=lambda pair: len(derived.parts[pair[1]].mesh.faces)) if fit is not None]
    found.sort(key=lambda f: (f.owner or "", round(f.centre[0], 6), round(f.centre[1], 6), round(f.centre[2], 6)))
    holes: list[list[HoleFit]] = []
    for fit in found:
        same = next((hole for hole in holes if hole[0].owner == fit.owner and hole[0].axis == fit.axis
                     and np.linalg.norm(hole[0].hole.centre - fit.hole.centre) < _SAME_HOLE), None)
        if same is None:
            holes.append([fit])
        else:
            same.append(fit)
    counts: dict[str, int] = {}
    result: dict[str, HoleFit] = {}
    for group in holes:
        deepest, *rest = sorted(group, key=lambda f: (_tip(derived, str(f.part), f.axis), str(f.part)))
        owner = deepest.owner or ""
        counts[owner] = counts.get(owner, 0) + 1
        hid = f"{owner}_hole{counts[owner]}"
        result[hid] = replace(deepest, id=hid, more=tuple((str(f.part), f.section) for f in rest
                                                          if f.section is not None))
    return result


def _around(owner: trimesh.Trimesh, part: trimesh.Trimesh, name: str) -> bool:
    """Whether ``owner`` may have a hole around ``part`` across removal direction ``name``:
    its bounding box across the direction holds the part's, and along it the two overlap by
    more than 1 µm (as :func:`_hole_around` needs), a test of their vertices' extents alone."""
    axis = np.array(DIRECTIONS[name])
    frame = np.vstack([frame_of(axis), axis])
    low, high = (owner.vertices @ frame.T).min(axis=0), (owner.vertices @ frame.T).max(axis=0)
    inner_low, inner_high = (part.vertices @ frame.T).min(axis=0), (part.vertices @ frame.T).max(axis=0)
    return bool(np.all(low[:2] <= inner_low[:2]) and np.all(inner_high[:2] <= high[:2])
                and min(high[2], inner_high[2]) - max(low[2], inner_low[2]) > 1e-6)


def _tip(derived: Derived, pid: str, name: str) -> float:
    """How far [m] part ``pid`` reaches against removal direction ``name``: its lowest
    level along it (the deepest part in a hole has the least)."""
    return float((derived.parts[pid].mesh.vertices @ np.array(DIRECTIONS[name])).min())


def _hole_of(derived: Derived, pid: str, owner: str) -> HoleFit | None:
    """The hole of part ``owner`` that part ``pid`` goes through along its insertion axis
    (:func:`part_holes`), with its owner; None: none."""
    name = derived.axis[pid]
    hit = _hole_around(derived.parts[owner], derived.parts[pid], np.array(DIRECTIONS[name]))
    if hit is None:
        return None
    level, loop, outer, own = hit
    return replace(_measure(derived.parts[owner], name, loop, level, outer, (derived.parts[pid], own)), owner=owner)


def _hole_around(owner: CadPart, part: CadPart, axis: np.ndarray) -> tuple[float, Loop, Loop | None, Loop] | None:
    """Where ``owner`` has a hole around ``part`` across ``axis``: the level [m], the
    hole's loop, the loop around it (None: none) and the part's loop in it; None when no
    level tried has one. The levels tried are the middles of the spans between the owner's
    vertices near the part's centre line (within twice the part's reach across it) along
    the axis, where both reach, :data:`_HOLE_LEVELS` longest first: an owner's slice changes
    only at its vertices' levels."""
    along, owner_along = part.mesh.vertices @ axis, owner.mesh.vertices @ axis
    low, high = max(along.min(), owner_along.min()), min(along.max(), owner_along.max())
    if high - low <= 1e-6:
        return None
    frame = frame_of(axis)
    middle = slice_loops(part.mesh, axis, float(along.min() + along.max()) / 2)
    outlines = [loop for loop in middle if _outer(loop, middle)]
    if len(outlines) != 1:
        return None
    line = outlines[0].centre
    reach = 2 * float(np.linalg.norm(part.mesh.vertices @ frame.T - line, axis=1).max())
    near = np.linalg.norm(owner.mesh.vertices @ frame.T - line, axis=1) <= reach
    if not near.any():  # nothing of the owner around the part: no slice needed
        return None
    for level in _spans(owner_along[near], low, high)[:_HOLE_LEVELS]:
        loops = slice_loops(owner.mesh, axis, level)
        cut = slice_loops(part.mesh, axis, level)
        own = [o for o in cut if _outer(o, cut)]
        for loop in (o for o in loops if not _outer(o, loops)):
            inside = [o for o in own if loop.contains(o.centre) and _in_loop(o, loop)]
            if len(inside) == 1 and not (_roomy(loop, inside[0]) and _open_box(
                    loop.extent[1], inside[0].extent[0], owner.mesh, frame.T @ loop.centre + axis * level, axis)):
                around = sorted((o for o in loops if o is not loop and o.area > loop.area
                                 and o.contains(loop.centre)), key=lambda o: o.area)
                return level, loop, around[0] if around else None, inside[0]
    return None


def _in_loop(outline: Loop, hole: Loop) -> bool:
    """Whether a part's ``outline`` lies in the ``hole`` loop of another part's slice: at
    most the hole's sagitta (a round one's) plus :data:`executor.cad.fits.faces.TOUCH` beyond
    it, as a shaft tessellated at a nominal zero-clearance fit is (its vertices on the
    circle the bore's chords cut inside); a ring around a tube is not in the tube's bore."""
    margin = classify(hole, hole=True).deflection + TOUCH
    return bool(shapely.Polygon(hole.points).buffer(margin).covers(shapely.Polygon(outline.points)))


def _fields(fit: HoleFit) -> tuple:
    return (fit.axis, fit.hole, fit.centre, fit.entry, fit.depth, fit.chamfer, fit.outer, fit.part, fit.section)


def _measure(base: CadPart, name: str, loop: Loop, level: float, outer: Loop | None,
             occupant: tuple[CadPart, Loop] | None, workers: int = 1) -> HoleFit:
    """Section, entry, depth (to the first face of ``base``, the part the hole is in, down
    the hole's centre line; through it, to its lowest point around the hole, when there is
    none) and chamfer of the hole ``loop`` sliced at ``level`` [m], and the section of the
    ``occupant`` (its part, its loop there). The sections are over the stretch from the
    occupant's end (or the hole's lowest point around it, if higher) to the entry
    (:func:`executor.cad.sections.over_span`, made in ``workers`` processes:
    :func:`executor.cad.sweep.forked_map`; 1 in a forked one); without an occupant, from the
    floor (the first face of ``base`` down the centre line of the loop) or, with none, from
    the hole's lowest point around it: as deep as a part goes in. Where nothing of the hole
    is free down to that floor, it is no face across the axis (a drill point's cone) and the
    stretch starts at ``level``. ExecutorError when nothing of the hole is free all along the
    stretch."""
    axis = np.array(DIRECTIONS[name])
    frame = frame_of(axis)
    sliced = classify(loop, hole=True)
    radial = base.mesh.vertices @ frame.T - sliced.centre
    around = (base.mesh.vertices @ axis)[np.linalg.norm(radial, axis=1) <= max(sliced.a, sliced.b)]
    entry = float(around.max())
    if occupant is None:  # as deep as a part can go in: to the floor down its centre line, or through
        floor = first_hit(base.mesh, frame.T @ sliced.centre + axis * level, -axis)
        tip = float(around.min()) if floor is None else level - floor
    else:
        tip = float((occupant[0].mesh.vertices @ axis).min())
    low = max(tip, float(around.min()))
    spans: list[tuple[Loop, trimesh.Trimesh, float, bool]] = [(loop, base.mesh, low, True)]
    if occupant is not None:
        spans.append((occupant[1], occupant[0].mesh, tip, False))
    narrowest, *occupied = forked_map(lambda span: over_span(span[0], span[1], axis, span[2], entry, hole=span[3]),
                                      spans, workers)
    if occupant is None and len(narrowest.points) < 3:  # a floor not across the axis (a drill point's cone)
        low = level
        narrowest = over_span(loop, base.mesh, axis, low, entry, hole=True)
    if len(narrowest.points) < 3:
        x, y, z = 1e3 * (frame.T @ sliced.centre + axis * level)
        raise ExecutorError(f"the hole of part {base.id} at ({x:.3f}, {y:.3f}, {z:.3f}) mm is closed between "
                            f"{1e3 * (entry - low):.3f} mm below its entry and its entry along {name[1:]} "
                            "(expected an opening all the way in)")
    hole = exact_round(classify(narrowest, hole=True), base.cylinders, axis, level, STEP_DEFLECTION)
    part, section = (None, None) if occupant is None else (
        occupant[0].id, exact_round(classify(occupied[0], hole=False), occupant[0].cylinders, axis, level,
                                    STEP_DEFLECTION))
    if section is not None:  # a tessellated round section against a section that is no round: its polygon
        hole = faceted(hole, narrowest, section, hole=True)
        section = faceted(section, occupied[0], hole, hole=False)
    centre = frame.T @ hole.centre + axis * level
    bottom = first_hit(base.mesh, centre, -axis)
    depth = entry - (level - bottom if bottom is not None else float(around.min()))
    probe = [o for o in slice_loops(base.mesh, axis, entry - _ENTRY_PROBE) if o.contains(hole.centre)]
    chamfer = 0.0
    if probe:
        top = classify(min(probe, key=lambda o: o.area), hole=True)
        chamfer = max(0.0, (top.b - hole.b) / 2 + _ENTRY_PROBE) if top.b > hole.b + 1e-7 else 0.0
    return HoleFit("", name, hole, (float(centre[0]), float(centre[1]), float(entry)), entry, depth, chamfer,
                   None if outer is None else classify(outer, hole=False), part, section)
