"""An assembly folder: parts, holes, ground truths and demonstrations.

An assembly is a folder (a name under ``data/`` or a path) holding:

- ``assembly.toml``: ``[parts.<id>]`` with ``name``, ``role``, optional ``start``
  ``[x, y]`` [m] (where the part waits in the cell), optional ``shape`` (its cross-section
  kind, :data:`SHAPES`; default the kind ``geometry.toml`` gives it) and, for a rect part,
  optional ``section`` (a label: parts of one section are scaled copies of one
  cross-section; default the shape for round and square, the part's own id for rect);
  ``[holes.<id>]`` with ``name``, ``shape`` (default the kind ``geometry.toml`` gives it,
  else round), ``position`` ``[x, y]`` [m] on the base plate and ``capacity`` (the number
  of parts stacked in it or onto it along its axis, default 1), and for a hole of a part
  that parts go through into another hole (on its line), ``on_line`` (that hole) and
  ``owner`` (the part); an optional ``[sizes]``
  table with ``model`` (the size model the product declares: ``line``, ``sections`` or
  ``pairs``, docs/sizes.md);
- ``precedence.lp`` (optional): the true precedence constraints (``part/1``,
  ``precedence_edge/2`` or ``must_precede/2``);
- ``sizes.lp`` (optional): which part fits which hole (``part/1``, ``hole/1``,
  ``fits/2``; closed world);
- ``demos.txt`` (optional): demonstrated feasible sequences;
- ``geometry.toml`` (optional): the cell's dimensions and cross-sections (the simulated
  and the ``truth`` cells need it; the planner alone does not).

``assembly.toml`` and ``geometry.toml`` are decoded and checked as a whole by
:mod:`bridge.product`; :func:`load_assembly` gives the planner's view of the result.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from bridge import BridgeError
from bridge.product import (
    ID_PATTERN,
    MAX_COORDINATE,
    SHAPES,
    SIZE_MODELS,
    ProductDescription,
    hole_kinds,
    is_id,
    load_product_description,
    part_kinds,
    section_label,
)
from bridge.product.nominal import models_nominal_fits, stated_nominal_fits, widened_fits

__all__ = ["DATA_DIR", "ID_PATTERN", "MAX_COORDINATE", "NEAR_MISS_BACKENDS", "SHAPES", "SIZE_MODELS", "Assembly",
           "Hole", "Item", "Part", "is_id", "load_assembly", "resolve_assembly_folder"]

_INSTALLED_ASSEMBLIES = Path(__file__).resolve().parent / "assemblies"
DATA_DIR = (_INSTALLED_ASSEMBLIES if _INSTALLED_ASSEMBLIES.is_dir()
            else Path(__file__).resolve().parent.parent / "data")
"""The shipped assemblies: the repository's ``data/``, or in an installed copy its package
data ``bridge/assemblies`` (``setup.py``), so ``--assembly cranfield`` works from any folder."""
NEAR_MISS_BACKENDS = frozenset({"sim"})
"""The backends whose physics cannot tell a near miss (``near_miss`` of ``geometry.toml``)
from a fit: the PyBullet cell's (``sim``), whose pegs built from sections lack their
corners by its 1 mm hull margin (docs/cell.md#what-the-physics-resolves). The ``truth``
backend answers from the CAD, the arm (``franka``, real or franky-sim) inserts the real
part and a plugin's physics is its own: they try such a pair."""


@dataclass(frozen=True)
class Item:
    """A part or a hole: its id (an ASP constant) and a readable name."""

    id: str
    name: str


@dataclass(frozen=True)
class Part(Item):
    """One part of an assembly; ``start`` is its waiting position [m] or None; ``shape``
    its cross-section kind (one of :data:`SHAPES`, None when the file gives none) and
    ``section`` the label of its cross-section (None without a shape)."""

    role: str = "part"
    start: tuple[float, float] | None = None
    shape: str | None = None
    section: str | None = None


@dataclass(frozen=True)
class Hole(Item):
    """One hole of the base plate; ``position`` [m] or None; ``capacity``: how many parts
    go in it or onto it, one above the other; ``line``: (the hole whose line it lies on, the
    part it is in) for a hole parts go through into that one (``on_line``, ``owner``), else None."""

    shape: str = "round"
    position: tuple[float, float] | None = None
    capacity: int = 1
    line: tuple[str, str] | None = None


@dataclass(frozen=True)
class Assembly:
    """An assembly folder loaded from disk."""

    folder: Path
    name: str
    parts: tuple[Part, ...]
    holes: tuple[Hole, ...] = field(default_factory=tuple)
    size_model: str | None = None
    """The size model the product declares (``[sizes] model``), None when it declares none."""
    manual: dict[str, str] = field(default_factory=dict)
    """The parts the cell places by hand (``[manual.<id>]`` of ``geometry.toml``): id -> why."""
    cad_holes: dict[str, frozenset[str]] = field(default_factory=dict)
    """Part -> the holes it is in or on where the CAD has it, for each part whose step must
    put it there: a part placed by hand goes to its goal in the CAD (``on`` of its
    ``[manual.<id>]``), and a part the cell places that carries its feature must be where
    the CAD has it (``held_by``)."""
    pressed: frozenset[str] = frozenset()
    """Of the parts placed by hand, those pressed into where the CAD has them (``pressed``
    of their ``[manual.<id>]``): no fit as the cell slides parts, they need no hole."""
    cell_holes: frozenset[str] | None = None
    """The holes the simulated cell models (``[hole_shapes.*]`` of ``geometry.toml``), None
    without a ``geometry.toml``."""
    pins: frozenset[str] = frozenset()
    """Of those, the pins parts with a bore go onto (``pin = true``)."""
    bores: frozenset[str] = frozenset()
    """The parts with a bore the cell puts onto pins (``bore = true`` of ``[part_shapes.*]``)."""
    nominal_fits: frozenset[tuple[str, str]] = frozenset()
    """The (part, hole) pairs ``geometry.toml`` states as nominal zero-clearance fits (``zero_clearance``)."""
    near_misses: frozenset[tuple[str, str]] = frozenset()
    """The (part, hole) pairs ``geometry.toml`` states the PyBullet cell cannot tell from a
    fit (``near_miss``: the part misses the hole by less than the cell's peg lacks at its
    corners, or stops on it as near its goal as in or on it); a near miss only with a
    backend of :data:`NEAR_MISS_BACKENDS`."""
    base_center: tuple[float, float] | None = None
    """Where the cell's fixture holds the base's centre [m] (``base_center`` of ``[plate]`` in
    ``geometry.toml``), None without a ``geometry.toml``."""
    nominal_modelled: bool = False
    """Whether the simulated cell builds those fits in holes with
    :data:`bridge.product.nominal.NOMINAL_FIT_ROOM` per side (its holes are primitives); else
    it cannot resolve them and they are no experiment. Those on pins it builds so where it
    widens the part's bore, and in holes of a base with its own mesh where it narrows the peg
    (:attr:`widened`)."""
    widened: dict[tuple[str, str], float] = field(default_factory=dict)
    """The (part, feature) pairs whose room the simulated cell does not resolve, room 0 or
    positive, built with :data:`bridge.product.nominal.NOMINAL_FIT_ROOM` more room per side
    (the part's round bore wider on a pin, the round peg narrower in a hole of a base with
    its own mesh; ``widened`` of the feature: :func:`bridge.product.nominal.widened_fits`):
    pair -> the CAD's room per side [m]."""

    hole_owners: dict[str, str] = field(default_factory=dict)
    """Hole -> the part whose pin it is (``owner`` of its ``[hole_shapes.*]``): a pin not on the base."""
    pins_of: dict[str, frozenset[str]] = field(default_factory=dict)
    """Part -> the parts placed by hand whose pins it goes onto besides (``pins_of`` of its ``[part_shapes.*]``)."""

    def in_trial(self, part: str, hole: str) -> frozenset[str]:
        """The parts other than the base that stand at their goals in the scene of a trial of
        ``part`` into ``hole`` (:meth:`executor.world.scene.Scene.feature`): the hole's owner
        and the parts whose pins ``part`` goes onto besides; the cell puts ``part`` in after them."""
        owner = self.hole_owners.get(hole)
        return self.pins_of.get(part, frozenset()) | (frozenset() if owner is None else frozenset({owner}))

    def tried_by_hand(self, part: str, hole: str, backend: str) -> bool:
        """Whether no cell of ``backend`` (``sim``, ``truth``, ``franka`` or a plugin's
        ``MODULE:CLASS``) can try ``part`` in ``hole``: the part is placed by hand, the
        hole is one the cell does not model (a pin an imported part goes onto, a hole of a
        section the cell inserts no part in), a peg and a pin, a part with a bore and a
        hole (the cell puts parts with a bore onto pins only, pegs into holes only), a
        nominal zero-clearance fit the cell cannot build with room (:attr:`nominal_modelled`),
        or, with a backend of :data:`NEAR_MISS_BACKENDS`, a near miss its physics cannot
        tell from a fit (:attr:`near_misses`)."""
        return (part in self.manual or self.cell_cannot_insert(part, hole)
                or (backend in NEAR_MISS_BACKENDS and (part, hole) in self.near_misses)
                or ((part, hole) in self.nominal_fits
                    and not ((self.nominal_modelled and hole not in self.pins) or (part, hole) in self.widened)))

    def cell_cannot_insert(self, part: str, hole: str) -> bool:
        """Whether the simulated cell refuses to put ``part`` into ``hole`` even were the
        part one it inserts: the hole is not one it models (a hole of a part placed by
        hand, a hole of a section it inserts nothing in), or a peg and a pin, a part with
        a bore and a hole. False without a ``geometry.toml`` (every hole is the plate's)."""
        return self.cell_holes is not None and (hole not in self.cell_holes
                                                or (part in self.bores) != (hole in self.pins))

    def step_text(self, part: str, hole: str | None) -> str:
        """A plan step as the commands print it: ``p->h``, ``p``, a part placed by hand ``p (manual)``."""
        return part + (f"->{hole}" if hole else "") + (" (manual)" if part in self.manual else "")

    def sections(self) -> dict[str, str]:
        """Part id -> section, for the parts whose cross-section is stated."""
        return {p.id: p.section for p in self.parts if p.section is not None}

    @property
    def part_ids(self) -> list[str]:
        return [p.id for p in self.parts]

    @property
    def hole_ids(self) -> list[str]:
        return [h.id for h in self.holes]

    def file(self, name: str) -> Path:
        """Path of a file of the folder; BridgeError if it does not exist."""
        path = self.folder / name
        if not path.is_file():
            raise BridgeError(f"{path}: no such file (assembly '{self.name}' has no {name})")
        return path

    def has_file(self, name: str) -> bool:
        return (self.folder / name).is_file()


def resolve_assembly_folder(name_or_path: str) -> Path:
    """A folder holding ``assembly.toml`` (relative to the working folder) or the name of a
    shipped assembly (a folder of :data:`DATA_DIR`), in this order."""
    candidates = [Path(name_or_path), DATA_DIR / name_or_path]
    for folder in candidates:
        if (folder / "assembly.toml").is_file():
            return folder.resolve()
    known = sorted(p.parent.name for p in DATA_DIR.glob("*/assembly.toml"))
    raise BridgeError(
        f"assembly '{name_or_path}': expected a shipped assembly ({', '.join(known)}) "
        "or a folder holding assembly.toml"
    )


def assembly_of(product: ProductDescription) -> Assembly:
    """The planner's view of a decoded product: its parts and holes in file order, each
    with the kind every statement of the product gives it (``shape`` in ``assembly.toml``,
    the kind of its table in ``geometry.toml``: :func:`bridge.product.part_kinds`),
    a rect or polygon part's section defaulting to its id, a round or square part's to its kind."""
    layout = product.assembly
    kinds, hole_kind = part_kinds(layout, product.geometry), hole_kinds(layout, product.geometry)
    parts = tuple(
        Part(pid, part.name or pid, part.role, None if part.start is None else (part.start[0], part.start[1]),
             kinds.get(pid), None if pid not in kinds else section_label(pid, kinds[pid], part.section))
        for pid, part in layout.parts.items())
    holes = tuple(Hole(hid, hole.name or hid, hole_kind[hid],
                       None if hole.position is None else (hole.position[0], hole.position[1]), hole.capacity,
                       None if hole.on_line is None or hole.owner is None else (hole.on_line, hole.owner))
                  for hid, hole in layout.holes.items())
    geometry = product.geometry
    manual = {} if geometry is None else {mid: m.reason for mid, m in geometry.manual.items()}
    cad_holes: dict[str, frozenset[str]] = {} if geometry is None else {
        mid: frozenset(m.on) for mid, m in geometry.manual.items() if m.on is not None}
    if geometry is not None:
        cad_holes |= {pid: frozenset(holes) for m in geometry.manual.values() for pid, holes in m.held_by.items()}
    cell_holes = (None if geometry is None
                  else frozenset(h for shape in geometry.hole_shapes.values() for h in shape.holes))
    pins = frozenset() if geometry is None else frozenset(
        h for shape in geometry.hole_shapes.values() if shape.pin for h in shape.holes)
    bores = frozenset() if geometry is None else frozenset(
        p for shape in geometry.part_shapes.values() if shape.bore for p in shape.parts)
    return Assembly(folder=product.folder, name=layout.name or product.folder.name, parts=parts, holes=holes,
                    size_model=None if layout.sizes is None else layout.sizes.model, manual=manual,
                    cad_holes=cad_holes, cell_holes=cell_holes, pins=pins, bores=bores,
                    pressed=frozenset() if geometry is None else frozenset(
                        mid for mid, m in geometry.manual.items() if m.pressed),
                    nominal_fits=frozenset() if geometry is None else frozenset(stated_nominal_fits(geometry)),
                    near_misses=frozenset() if geometry is None else frozenset(
                        (pid, hid) for shape in geometry.hole_shapes.values() for hid in shape.holes
                        for pid in shape.near_miss or ()),
                    base_center=None if geometry is None else (geometry.plate.base_center[0],
                                                               geometry.plate.base_center[1]),
                    nominal_modelled=geometry is not None and models_nominal_fits(geometry),
                    widened={} if geometry is None else widened_fits(geometry),
                    hole_owners={} if geometry is None else {
                        hid: shape.owner for shape in geometry.hole_shapes.values() if shape.owner is not None
                        for hid in shape.holes},
                    pins_of={} if geometry is None else {
                        pid: frozenset(shape.pins_of) for shape in geometry.part_shapes.values() if shape.pins_of
                        for pid in shape.parts})


def load_assembly(name_or_path: str) -> Assembly:
    """Load an assembly folder (its whole product description is checked:
    :func:`bridge.product.load_product_description`); BridgeError naming the file and
    field on bad input."""
    return assembly_of(load_product_description(resolve_assembly_folder(name_or_path)))
