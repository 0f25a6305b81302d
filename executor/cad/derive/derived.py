"""What :func:`executor.cad.derive.derive` finds, as data: the holes (:class:`HoleFit`),
the pins (:class:`PinFit`) and the whole derived product (:class:`Derived`: axes, stages,
precedence with its reasons, holes, pins, sweeps), with the lines ``import`` reports of it."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from executor.cad.fits.faces import COARSEST, PRESS_FIT, SMOOTH, CylinderFace, PrismFace, Slide
from executor.cad.parts import CadPart
from executor.cad.sections import Shape2D
from executor.cad.sweep import DIRECTIONS, axis_name


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
    """The moving part the hole is in (:func:`executor.cad.derive.part_holes`), None for a hole of the base."""
    more: tuple[tuple[str, Shape2D], ...] = ()
    """The further parts in a moving part's hole with their sections, after ``part`` (the
    deepest): plates stacked on a shaft whose outsides stand in a ring's hole."""
    line: str | None = None
    """The hole of the base on whose line this hole of a moving part lies, its occupants
    standing in that one (a bolt through a bracket's flange into the plate, a hinge's pin
    through the female leaf's knuckles into the male's): the cell inserts them through it
    into that hole, so it is no place of its own; None: a place (every other hole)."""

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
    """Everything :func:`executor.cad.derive.derive` finds; ``free`` the directions each part leaves the whole
    product along, ``axis`` its insertion axis (the name of the removal direction),
    ``stages`` the disassembly stages, ``edges`` the geometric must-precede pairs and
    ``reasons`` why each holds (``blocks``: :func:`executor.cad.derive.forced`, its blockers per direction in
    ``detail``; ``base``: the base precedes the parts touching it; ``feature``: the
    owner of a feature precedes the parts going into or onto it; ``supports`` and
    ``locates``: the rules of :mod:`executor.cad.locating`),
    ``located`` each moving body's locators per direction (of the six axes), ``dropped``
    the locating pairs and ``dropped_supports`` the supporting pairs the blocking
    contradicts, ``reach`` the locating reach [m] (0: the rule is off), ``bodies`` the
    moving bodies (:func:`executor.cad.derive.bodies`), ``directions`` those tried (name -> unit vector),
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
    nearer: dict[str, dict[str, list[set[str]]]] = field(default_factory=dict)
    """Where a body meets several parts along a direction: those met within shorter
    reaches, the nearest first (:func:`executor.cad.locating.locators`)."""
    later: dict[str, set[str]] = field(default_factory=dict)
    """Each moving body's parts that the placing pairs put after it (not counted among its locators)."""
    dropped: set[tuple[str, str]] = field(default_factory=set)
    reach: float = 0.0
    holes: dict[str, HoleFit] = field(default_factory=dict)
    pockets: list[HoleFit] = field(default_factory=list)
    """Empty inner loops of the base whose polygon section has no rotational symmetry
    (:func:`executor.cad.derive.receives`)."""
    pins: dict[str, PinFit] = field(default_factory=dict)
    bores: dict[str, Shape2D] = field(default_factory=dict)
    """Part -> the section of its bore around the first pin it is on
    (:func:`executor.cad.derive.pins`), the one it is compared with every pin by."""
    further_bores: dict[tuple[str, str], Shape2D] = field(default_factory=dict)
    """(part, pin) -> the section of another bore of the part, around a further pin it is on
    (a plate's second dowel pin, the arm's slot over the disk's nipple), the one its pair with that
    pin is measured by (:func:`executor.cad.derive.pins`)."""
    part_holes: dict[str, HoleFit] = field(default_factory=dict)
    """The holes of moving parts, each with the part through it (:func:`executor.cad.derive.part_holes`)."""
    supports: set[tuple[str, str]] = field(default_factory=set)
    """The supporting pairs (Y, X): X rests on Y and not on the base
    (:func:`executor.cad.locating.support_pairs`)."""
    swept: dict[tuple[str, str], tuple[Shape2D, Shape2D, float]] = field(default_factory=dict)
    """(peg, hole) and (part with a bore, pin) -> the sections of the peg (the pin) and the
    hole (the bore) at the levels of least room on the way in and that room [m] (diametral),
    for the pairs the sweep admits where the sections over the whole stretch do not
    (:func:`executor.cad.derive.swept_fits`)."""
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
        fits = [s for s in self.slides if not s.pitch and not s.interference]
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
                f"{sum(1 for s in self.slides if s.pitch)} pair(s) found)",
                "press fits: a shaft's cylinder coaxial with another part's bore and seated in it, its circle wider "
                f"than the bore's by more than 10 µm and at most {100 * PRESS_FIT:g} % of its radius, slides along its "
                "axis against it (the shaft's part taken in by the interference; placed by hand: the cell does not "
                f"press; {sum(1 for s in self.slides if s.interference)} pair(s) found)"]

    def notes(self) -> list[str]:
        """What the report says beyond the axes and holes: the zero-clearance fits, each
        blocking pair's blockers, the supporting pairs dropped."""
        lines = [f"screwed pair {s.shaft} in {s.bore} ({s.thread}): d {2000 * s.face.radius:.3f} mm in a minor "
                 f"d {2000 * s.hole.radius:.3f} mm along {axis_name(s.direction)[1:]}, pitch {1000 * s.pitch:.3f} mm, "
                 f"lead {1000 * abs(s.lead):.3f} mm, {'right' if s.lead > 0 else 'left'}-handed about "
                 f"{axis_name(s.direction)}; slides along the axis against each other, the cell does not screw"
                 for s in self.slides if s.pitch]
        lines += [f"press fit {s.shaft} in {s.bore}: {_face_size(s.face)} in {_face_size(s.hole)} along "
                  f"{axis_name(s.direction)[1:]} ({1000 * s.interference:.3f} mm per side); slides along the axis "
                  "against each other, the cell does not press" for s in self.slides if s.interference]
        lines += [(f"zero-clearance fit {s.shaft} in {s.bore}: " if s.seated else
                  f"zero-clearance passage {s.shaft} through {s.bore} (met only on a way along the axis): ")
                 + f"{_face_size(s.face)} along {axis_name(s.direction)[1:]}, "
                  f"overlap up to {1e6 * s.tolerance:.1f} µm across it taken as sliding"
                  for s in self.slides if not s.pitch and not s.interference]
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
        """Part → the hole of the base it stands in (each of a stack in one hole)."""
        return {pid: fit for fit in self.holes.values() for pid in fit.occupants}

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
