"""The assembly folder of an imported product, in the vocabulary every command reads.

- ``assembly.toml``: every part (the base with role ``base``, a part in a hole with role
  ``peg`` and its section's kind as ``shape``, ``cover``, ``head``, any other ``part``) with its tray ``start``,
  every hole (``h1``, ``h2``, ... by position, empty ones too) with its kind and position,
  every hole of a moving part a part passes (``<owner>_hole1``, ...
  :func:`executor.cad.derive.part_holes`), and every pin a part goes onto or no part is on
  (``<owner>_pin1``, ... :func:`executor.cad.derive.pins`) as a hole at the pin's
  position with the pin's section kind;
- ``sizes.lp``: ``fits(P,H)`` for every peg and hole whose nominal sections pass, and for
  every part with a bore and pin when the pin's section passes the bore's
  (:func:`executor.cad.sections.passes`: the exact rules of round sections, the loops'
  room of two rect or square ones, the polygon relation where one is a polygon) or when they
  are a nominal zero-clearance fit (:func:`executor.cad.operations.nominal_fits`, named in a comment), or when
  the sweep admits them (:func:`executor.cad.derive.swept_fits`: a taper in its taper), closed world;
- ``nominal_sizes.lp``: ``nominal_margin(P,H,M)``, the room M [µm] of each peg's nominal
  section in each hole's (0: a nominal zero-clearance fit), the input of ``sizes learn --prior cad``;
- ``geometric_precedence.lp``: ``part/1`` and ``must_precede/2`` (transitively closed)
  from the disassembly, the features and the rules of placing, each direct pair's reason
  in a comment (``blocks``, ``base``, ``feature``, ``supports``, ``locates``), the input
  of ``precedence learn --prior`` and ``precedence count``;
- ``geometry.toml``: the simulated cell's product unless two parts overlap where they
  wait or parts without a tray find none in the arm's reach (:func:`default_trays`), and
  when the cell's loader accepts it and its sections answer every pair as ``sizes.lp``
  (:func:`_cell_disagrees`; left out otherwise, and the report says why; a hole or bore
  with nominal zero-clearance fits at its nominal diameter, naming them,
  :func:`nominal_section`): pegs standing in holes entered along +z with a round, square
  or rect section or the prism of a polygon (built by the cell from its outline), parts
  with a bore onto pins of the base (a part on several pins down its first, the only
  one of them written: :func:`executor.cad.operations._onto_pins`), covers and heads
  (:mod:`executor.cad.covers`), every other part placed by hand (``[manual.<id>]``,
  :func:`executor.cad.operations.cell_view`); the plate at the entry height and depth most holes share, a hole
  at another one with its own ``top_z`` and ``depth``, the
  plate, pegs, covers and heads as primitives where they are ones, else as their own
  meshes with convex pieces (``meshes/``, :mod:`executor.cad.convex`;
  a STEP base tessellated again to :data:`CELL_DEFLECTION` for the cell), a part placed by
  hand as its own mesh (static, no pieces), a base without such holes as its own mesh.
- ``cell_order.lp``: with ``geometry.toml``, ``cell_before(P,Q)`` where the fingers' grip
  of peg P needs it in before part Q (:func:`cell_order_text`), the cell's own orders
  every plan of the product honours;
- ``.import-manifest.json`` (:data:`MANIFEST`): the files this import wrote with their
  SHA-256. A later import into the folder replaces or removes only those of them that
  are still as written (:func:`claim_folder`), and refuses a folder holding any other file
  it would write (a product it did not write, a mesh at its name) unless told to replace
  it; nothing else in the folder is ever removed.
"""

from __future__ import annotations

import hashlib
import json
import math
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import clingo
import networkx as nx
import numpy as np
import shapely
import trimesh

from bridge.errors import ToolError
from bridge.files import make_folder, os_reason, write_atomic
from bridge.inputs import read_text, shorten
from bridge.product import Mesh
from bridge.product.checks import overlapping_bosses
from bridge.product.nominal import NOMINAL_FIT_ROOM
from executor import ExecutorError
from executor.cad.convex import (
    MESH_FOLDER,
    NEAR,
    fitted,
    peg_frame,
    peg_is_primitive,
    write_mesh,
)
from executor.cad.covers import Mapped, map_parts
from executor.cad.derive import Derived, HoleFit, PinFit
from executor.cad.operations import (
    GRIPPER,
    LEVEL,
    MAX_PLATE_DEPTH,
    along_axis,
    bore_frame,
    bore_pieces,
    builds_plate,
    cell_view,
    entry_point,
    feature_turn,
    fine_fits,
    finger_grip,
    finger_order_text,
    finger_orders,
    margins,
    narrows_peg,
    nominal_fits,
    order,
    pin_entry,
    pin_level,
    plate_level,
    plate_top,
    pressed,
    section_kind,
    section_pairs,
    tool_length,
    tool_of,
    upright,
    widens_bore,
)
from executor.cad.parts import turn_text
from executor.cad.sections import Shape2D, section, slice_loops
from executor.cad.sections import rounded as _q
from executor.cad.sweep import DIRECTIONS, opposite
from executor.control.detector import Thresholds
from executor.world import SIZE_RESOLUTION
from executor.world.geometry import CellGeometry, feature_passes, load_geometry, plate_obj_text
from executor.world.meshes import read_objects
from executor.world.near_miss import mesh_near_miss, near_miss

DENSITY = 2700.0
"""Mass of a peg in the simulated cell: its volume times this [kg/m³] (aluminium)."""
TRAY_START = (0.25, 0.40)
"""The first default tray [m] (the shipped products' trays lie 0.47 to 0.50 m from the arm's base)."""
TRAY_PITCH = 0.05
"""The least distance [m] along its row from a default tray to the one before."""
TRAY_GAP = 0.02
"""The least room [m] between a part's footprint on a default tray and any other part's
footprint on its tray or the product's where it stands."""
BASE_TRAY = (0.30, -0.40)
"""Default tray of the base [m]."""
REACH = (0.35, 0.70)
"""A base whose centre, or a default tray, lies this far [m] from the arm's base
horizontally (inclusive) is within the arm's reach: the span of the shipped products'
holes (Cranfield's at 0.55 to 0.63 m) and trays (0.47 to 0.50 m), widened; nearer or
farther is taken as out of reach (a product at x = 0 failed its fits in the sim cell)."""
MIN_CHAMFER = 1e-4
"""The simulated plate's chamfer when the CAD has a smaller one or none [m] (the cell needs one)."""
MAX_REASON = 200
"""The longest ``reason`` of a ``[manual.<id>]`` table (characters)."""
MANIFEST = ".import-manifest.json"
"""The files the last import into a folder wrote: ``{"written_by": "./run.sh import",
"title": the product's name, "files": {path relative to the folder: SHA-256 of its content}}``."""
PRODUCT_FILES = ("assembly.toml", "sizes.lp", "nominal_sizes.lp", "geometric_precedence.lp", "geometry.toml",
                 "cell_order.lp")
"""The product's files an import writes (``geometry.toml`` only where the cell builds the product,
``cell_order.lp`` only where it does and its fingers' grip orders parts)."""
_MESH_NAME = re.compile(rf"{MESH_FOLDER}/[a-z][a-z0-9_]*(\.convex)?\.obj")
"""The name of a mesh file an import writes, relative to the folder (a part id is an ASP constant)."""
CELL_DEFLECTION = 1e-5
"""The largest distance [m] of a STEP base's faces from the triangles the cell collides
with (its own mesh is measured at :data:`executor.cad.parts.STEP_DEFLECTION`)."""


@dataclass(frozen=True)
class Settings:
    """What the import file states: the ``base`` part, the ``trays`` [m], part ``names``,
    the CAD's axis pointing ``up`` (:func:`executor.cad.parts.turned`) and the offset (x, y, z)
    [m] every part was ``moved`` by from the CAD frame into the cell (:func:`executor.cad.cli.placement`)."""

    base: str
    trays: dict[str, tuple[float, float]]
    names: dict[str, str]
    up: str = "+z"
    moved: tuple[float, float, float] = (0.0, 0.0, 0.0)


def _section_lines(shape: Shape2D) -> list[str]:
    """``kind``, ``size`` and a rounded square's or rect's ``corner`` radius of a section
    table; a polygon's ``size`` the extents of its ``outline`` along x and y, which follows
    (about its centre, in the cell's axes)."""
    if shape.kind != "polygon":
        size = f"[{_q(shape.a)}, {_q(shape.b)}]" if shape.kind == "rect" else f"{_q(shape.a)}"
        return [f'kind = "{shape.kind}"', f"size = {size}", *([f"corner = {_q(shape.corner)}"] if shape.corner else [])]
    points = section("", shape).outline
    extents = np.ptp(np.array(points), axis=0)
    return ['kind = "polygon"', f"size = [{_q(float(extents[0]))}, {_q(float(extents[1]))}]",
            "outline = [" + ", ".join(f"[{x}, {y}]" for x, y in points) + "]"]


def _symbols(symbols: list[clingo.Symbol]) -> str:
    return " ".join(f"{symbol}." for symbol in symbols)


def assembly_text(derived: Derived, settings: Settings, title: str, roles: dict[str, str]) -> str:
    """``assembly.toml``: the parts with their ``roles`` (base, peg, else the given one or
    ``part``) and trays, the holes (a pin several parts go onto, or a hole of the base
    several parts stand in, with their number as its ``capacity``)."""
    pegs = derived.hole_of
    frame = "the CAD frame (the cell frame)" if settings.up == "+z" and not any(settings.moved) else "the cell frame"
    if settings.up != "+z":
        frame += f", the CAD's {settings.up} turned up ({turn_text(settings.up)})"
    if any(settings.moved):
        frame += (", moved by ({}, {}, {}) mm from the CAD frame (the base's centre to place, the product's lowest "
                  "point to the floor, z = 0, or place's z)").format(*(f"{1000 * v:.3f}" for v in settings.moved))
    lines = [f"# Imported from {title} by ./run.sh import: parts in {frame} [m].",
             f"name = {json.dumps(title)}", ""]
    for pid in sorted(derived.parts):
        role = "base" if pid == derived.base else "peg" if pid in pegs else roles.get(pid, "part")
        lines += [f"[parts.{pid}]", f"name = {json.dumps(settings.names.get(pid, derived.parts[pid].name))}",
                  f'role = "{role}"']
        x, y = settings.trays[pid]
        lines.append(f"start = [{_q(x)}, {_q(y)}]")
        if section_kind(pegs.get(pid)) is not None:
            lines.append(f'shape = "{section_kind(pegs.get(pid))}"')
        lines.append("")
    for hid, fit in [*derived.holes.items(), *derived.part_holes.items()]:
        name = f"hole of {fit.part}" if fit.part else f"hole {hid}"
        x, y, _ = entry_point(fit)
        if fit.owner is not None:
            name = f"hole of {fit.owner} ({' '.join(fit.occupants)} in it)"
        lines += [f"[holes.{hid}]", f'name = "{name}"', f'shape = "{fit.hole.kind}"',
                  f"position = [{_q(x)}, {_q(y)}]"]
        # a stack in a hole of the base (bearings and a spacer in a housing's bore)
        lines += [f"capacity = {len(fit.occupants)}"] if fit.owner is None and len(fit.occupants) > 1 else []
        lines.append("")
    for pin_id, pin in derived.pins.items():
        onto = f" ({' '.join(pin.parts)} onto it)" if pin.parts else ""
        x, y, _ = pin_entry(derived, pin)
        lines += [f"[holes.{pin_id}]", f'name = "pin of {pin.owner}{onto}"',
                  f'shape = "{pin.section.kind}"', f"position = [{_q(x)}, {_q(y)}]"]
        lines += [f"capacity = {len(pin.parts)}"] if len(pin.parts) > 1 else []
        lines.append("")
    return "\n".join(lines)


def sideways_depth(derived: Derived, fit: HoleFit) -> float:
    """The ``depth`` [m] of a hole entered sideways (or from below): from its entry along
    its axis to where its part's tip is in the CAD (the taught goal: nothing stops a part
    in a through hole), or the measured depth of an empty one."""
    if fit.part is None:
        return fit.depth
    return fit.entry - float((derived.parts[fit.part].mesh.vertices @ np.array(DIRECTIONS[fit.axis])).min())


STOP_PROBE = 1e-4
"""How far [m] under a part's tip the base is cut to see whether the hole narrows there (and
above and under a hole's entry, and how far beyond the hole a part resting on it reaches)."""


def down_depth(derived: Derived, fit: HoleFit) -> float:
    """The ``depth`` [m] of a hole entered down: to where its part's tip is in the CAD where
    the part rests on the hole's entry (its outline just above the entry reaches more than
    :data:`STOP_PROBE` beyond the base's loop around the hole just under it, so not at a
    nominal zero-clearance fit: a switch hanging by its flange through a slot
    of a case's 2 mm top, its tip 19.4 mm down where the measured depth says 2 mm, through
    the top, or 42 mm, to the case's rim) or where the base's opening just under the tip
    does not hold the part's section at the middle of its stretch in the hole (a plate on
    the ledge of a recess: the cell's goal, where the part rests, is the CAD's, not the floor
    down the hole's centre line); else the measured depth (to that floor, or through)."""
    if fit.part is None:
        return fit.depth
    mesh = derived.parts[fit.part].mesh
    (_, _, tip), (_, _, top) = mesh.bounds
    up = np.array([0.0, 0.0, 1.0])
    base = derived.parts[derived.base].mesh
    if abs(fit.entry - tip - fit.depth) > LEVEL:
        rim = [shapely.Polygon(loop.points) for loop in slice_loops(base, up, fit.entry - STOP_PROBE)
               if loop.contains(fit.hole.centre)]
        above = shapely.union_all([shapely.Polygon(loop.points)
                                   for loop in slice_loops(mesh, up, fit.entry + STOP_PROBE)])
        if rim and not above.is_empty and not above.within(min(rim, key=lambda loop: loop.area).buffer(STOP_PROBE)):
            return fit.entry - float(tip)
    if fit.entry - tip >= fit.depth - LEVEL:  # on the floor, or below the entry
        return fit.depth
    below = [shapely.Polygon(loop.points) for loop in slice_loops(base, up, tip - STOP_PROBE)
             if loop.contains(fit.hole.centre)]
    outline = shapely.union_all([shapely.Polygon(loop.points)
                                 for loop in slice_loops(mesh, up, (tip + min(top, fit.entry)) / 2)])
    passes = bool(below) and outline.within(min(below, key=lambda loop: loop.area))
    return fit.depth if passes else fit.entry - float(tip)


def sizes_text(derived: Derived) -> str:
    """``sizes.lp``: ``fits(P,H)`` for every peg whose nominal section passes a hole's
    (:func:`executor.cad.operations.margins`) or is a nominal zero-clearance fit in it
    (:func:`executor.cad.operations.nominal_fits`, named in a comment as the assumption it is)."""
    rooms, nominal = margins(derived), nominal_fits(derived)
    lines = ["% Which part fits which hole from the nominal cross-sections (closed world), by ./run.sh import.",
             *_nominal_comments(nominal),
             _symbols([clingo.Function("part", [clingo.Function(p)]) for p in rooms]),
             _symbols([clingo.Function("hole", [clingo.Function(h)])
                       for h in [*derived.holes, *derived.part_holes, *derived.pins]])]
    for pid, holes in rooms.items():
        fits = [clingo.Function("fits", [clingo.Function(pid), clingo.Function(hid)]) for hid, room in holes.items()
                if room > 0 or (pid, hid) in nominal]
        if fits:
            lines.append(_symbols(fits))
    return "\n".join(lines) + "\n"


RULE = ("a round peg at least as wide as a round hole's inscribed circle, their vertex circles' radii within 10 {um}, "
        "or a peg and hole of a polygon section (or both rect or square) that pass with an overlap of at most "
        "0.5 {um} all round, "
        "is taken for one nominal section: a fit, room 0")
"""The stated assumption of nominal zero-clearance fits ({um}: the micrometre's symbol)."""


def nominal_assumption(derived: Derived) -> list[str]:
    """The assumption of the nominal zero-clearance fits, as ``import`` prints it (none without one)."""
    nominal = nominal_fits(derived)
    return [f"nominal zero-clearance fits: {RULE.format(um='µm')} ({len(nominal)} pairs, vertex circles up to "
            f"{1e6 * max(map(abs, nominal.values())):.1f} µm apart)"] if nominal else []


def widened_fits(cell: Derived) -> dict[tuple[str, str], float]:
    """The fits of the product as the cell inserts it (``cell``:
    :func:`executor.cad.operations.cell_view`) whose room the simulated cell builds
    :data:`bridge.product.nominal.NOMINAL_FIT_ROOM` wider per side, sorted: on a pin with
    the part's round bore wider (:func:`executor.cad.operations.widens_bore`), in a hole of
    a base that is its own mesh with the round peg narrower
    (:func:`executor.cad.operations.narrows_peg`); (part, feature) to the CAD's room per
    side [m] (0.0 for a nominal zero-clearance fit); a feature's ``widened`` in ``geometry.toml``."""
    rooms, nominal = margins(cell), nominal_fits(cell)
    resized: list[tuple[str, list[str]]] = [
        *((pid, list(cell.pins)) for pid in cell.bores if widens_bore(cell, pid, nominal)),
        *((pid, list(cell.holes)) for pid in cell.hole_of if narrows_peg(cell, pid, nominal))]
    found = {(pid, fid): 0.0 if (pid, fid) in nominal else rooms[pid][fid] / 2
             for pid, features in resized for fid in fine_fits(cell, pid, features, nominal)}
    return dict(sorted(found.items()))


def widened_fits_assumption(cell: Derived) -> list[str]:
    """What the simulated cell assumes of the fits whose room it does not resolve
    (:func:`widened_fits`), as ``import`` prints it; none without one."""
    pairs = widened_fits(cell)
    return [f"fits with room under the {1e3 * SIZE_RESOLUTION:g} mm per side the simulated cell resolves: it builds "
            f"each with {1e3 * NOMINAL_FIT_ROOM:g} mm more room per side, on a pin with the part's round bore that "
            "much wider (its pieces' bores regular polygons about the bore's inscribed circle grown by that), in a "
            "hole of a base that is its own mesh with the round peg that much narrower (its pieces narrowed about its "
            "axis), so they are observed in that model, not at the CAD's room: "
            + " ".join(f"{pid}->{fid} ({'room 0' if not room else f'{1e3 * room:+.4f} mm'})"
                       for (pid, fid), room in pairs.items())] if pairs else []


def _nominal_comments(nominal: dict[tuple[str, str], float]) -> list[str]:
    """``sizes.lp``'s and ``nominal_sizes.lp``'s comment naming the nominal zero-clearance fits."""
    if not nominal:
        return []
    return [f"% Assumed: {RULE.format(um='um')}: "
            + ", ".join(f"{p}->{h} ({round(1e6 * t, 1) + 0.0:+.1f} um)" for (p, h), t in nominal.items()) + "."]


def zero_clearance_parts(derived: Derived) -> dict[str, list[str]]:
    """Feature (a hole or a pin) -> the parts that are a nominal zero-clearance fit in or on
    it (:func:`executor.cad.operations.nominal_fits`), sorted: a hole's ``zero_clearance`` in ``geometry.toml``."""
    found: dict[str, list[str]] = {}
    for pid, hid in sorted(nominal_fits(derived)):
        found.setdefault(hid, []).append(pid)
    return found


RIM_PRESS = 2e-4
"""How far [m] a part blocked on a hole's rim may end below the rim, pressed into it by the
insertion (0.05-0.18 mm measured: docs/cell.md, "What the physics resolves")."""


def near_misses(derived: Derived, pieces: Mapping[str, Sequence[np.ndarray]] | None = None
                ) -> dict[tuple[str, str], str]:
    """(peg, hole of the base) -> why the simulated cell cannot tell the pair's outcome:
    every peg in a hole no deeper than the cell's goal tolerance plus :data:`RIM_PRESS` (a
    part blocked on its rim ends as near its goal as one inside it), and each no-fit it
    cannot resolve (:func:`near_miss_reason`, how deep [m] the cell's peg lacks its
    section, plus the cell's resolution): for a peg the
    cell builds from its section (a cylinder, a box, a polygon's prism),
    :func:`executor.world.near_miss.near_miss` (its section eroded by what its collision
    shape may lack passes the hole); for a peg simulated from its mesh, whose convex
    pieces (vertices in its part frame) are in ``pieces``,
    :func:`executor.world.near_miss.mesh_near_miss` (what its pieces cover over the
    stretch that enters the hole passes it). A hole's ``near_miss`` in ``geometry.toml``."""
    rooms, pairs, found, tried = margins(derived), section_pairs(derived), {}, []
    for pid, fit in sorted(derived.hole_of.items()):
        if fit.section is None:
            continue
        primitive = peg_is_primitive(fit, upright(derived, fit))
        if not primitive and (pieces is None or pid not in pieces):
            continue
        tried.append(pid)
        tip = float((derived.parts[pid].mesh.vertices @ np.array(DIRECTIONS[fit.axis])).min())
        for hid in derived.holes:
            peg, hole = pairs[pid][hid]
            part, cell_hole = section(f"part {pid}", peg), section(f"hole {hid}", hole)
            depth = (near_miss(part, cell_hole, rooms[pid][hid]) if primitive else
                     mesh_near_miss(part, (pieces or {})[pid], fit.entry - tip, cell_hole, rooms[pid][hid]))
            if depth is not None:
                found[(pid, hid)] = near_miss_reason(pid, hid, depth)
    tolerance = Thresholds().goal_tolerance
    for hid, fit in derived.holes.items():
        deep = down_depth(derived, fit) if fit.axis == "+z" else sideways_depth(derived, fit)
        if deep <= tolerance + RIM_PRESS:
            for pid in tried:
                found.setdefault((pid, hid), (
                    f"{pid} in {hid}: the hole is {1e3 * deep:.3f} mm deep, no deeper than the cell's goal tolerance "
                    f"({1e3 * tolerance:g} mm) plus {1e3 * RIM_PRESS:g} mm: a part blocked on its rim would end as "
                    "near its goal as one inside it, decided from the CAD"))
    return found


def pin_near_misses(derived: Derived) -> dict[tuple[str, str], str]:
    """(part with a bore, pin) -> why the simulated cell cannot tell the pair's outcome: the
    part does not pass the pin (its room below 0) and would stop on the pin's end no farther
    than the cell's goal tolerance plus :data:`RIM_PRESS` from its goal there (the cell
    compares the part's origin, the centre of its bore at its end nearest the pin's root,
    with the pin's written bottom, where the first of the pin's parts rests in the CAD:
    :func:`executor.world.geometry.seat`, nothing stacked on it), so a part blocked on it
    ends as near its goal as one on it: a pin's ``near_miss`` in ``geometry.toml``. Where it
    stops (:func:`_pin_stop`) is a lower bound: the pair is listed whenever it may be that close."""
    rooms, found = margins(derived), {}
    tolerance = Thresholds().goal_tolerance
    for pin_id, pin in derived.pins.items():
        if not pin.parts:  # an empty pin: the cell has no goal on it (geometry_text leaves it out)
            continue
        top, height = pin_level(derived, pin)
        for pid in sorted(derived.bores):
            if rooms[pid][pin_id] >= 0:
                continue
            travel = _pin_stop(derived, pid, pin) - (top - height)
            if travel <= tolerance + RIM_PRESS:
                found[(pid, pin_id)] = (
                    f"{pid} on {pin_id}: it does not pass the pin and would stop on its end {1e3 * travel:.3f} mm from "
                    f"its goal there, no farther than the cell's goal tolerance ({1e3 * tolerance:g} mm) plus "
                    f"{1e3 * RIM_PRESS:g} mm: a part blocked on it would end as near its goal as one on it, "
                    "decided from the CAD")
    return found


STOP_RINGS = (0.0, 0.3, 0.6, 0.8, 0.9, 0.97, 0.995)
"""The radii, as fractions of the circle a pin's section holds, of the rings of points at
which :func:`_pin_stop` finds a part's material over that circle (72 points a ring)."""


def _pin_stop(derived: Derived, pid: str, pin: PinFit) -> float:
    """The lowest level [m, along ``pin``'s axis, its frame] the end of part ``pid`` nearest
    the pin's root reaches going down the pin's axis, its bore centred on it: the pin's top
    (the highest vertex of its owner within its section's reach at least as far from its
    axis as the circle its section holds, assumed to hold that circle up to there) less the
    height above that end of the part's lowest material over that circle (its lowest vertex
    in it, or the lowest of its faces over the points of :data:`STOP_RINGS`: the part's
    material the pin cannot pass). The part may be stopped higher (on material between
    those points, on a wider step above), never lower, so the travel from here to its goal
    is at most the cell's; without material over the circle (the pin's corners stop it),
    -inf: a near miss whatever its goal."""
    outline = shapely.Polygon(pin.section.outline)
    inner = float(outline.exterior.distance(shapely.Point(0.0, 0.0)))
    reach = math.hypot(pin.section.a, pin.section.b) / 2
    owner = along_axis(derived.parts[pin.owner].mesh, pin)
    off = np.linalg.norm(owner[:, :2] - pin.section.centre, axis=1)
    wide = (off >= inner - LEVEL) & (off <= reach + LEVEL)
    mesh = derived.parts[pid].mesh
    frame = bore_frame(derived, pid)
    part = trimesh.transform_points(mesh.vertices, frame)
    inside = part[np.linalg.norm(part[:, :2], axis=1) < inner - LEVEL, 2]
    turns = np.linspace(0.0, 2 * math.pi, 72, endpoint=False)
    points = np.array([(r * inner * math.cos(t), r * inner * math.sin(t)) for r in STOP_RINGS for t in turns])
    over = _lowest_over(points, part[mesh.faces])
    low = min([*inside, over])
    if not wide.any() or not math.isfinite(low):
        return -math.inf
    return float(owner[wide, 2].max()) - low


def _lowest_over(points: np.ndarray, triangles: np.ndarray) -> float:
    """The lowest z [m] of the ``triangles`` (n, 3, 3) over any of ``points`` (k, 2) [m] (the
    first face a ray up from below each point meets), inf over none."""
    (ax, ay, az), (bx, by, bz), (cx, cy, cz) = (triangles[:, k, :].T for k in range(3))
    det = (by - cy) * (ax - cx) + (cx - bx) * (ay - cy)
    flat = np.abs(det) > 1e-18  # faces seen from below; walls along the axis hide nothing
    ax, ay, az, bx, by, bz, cx, cy, cz, det = (v[flat] for v in (ax, ay, az, bx, by, bz, cx, cy, cz, det))
    lowest = math.inf
    for chunk in np.array_split(points, max(1, len(points) // 32)):
        px, py = chunk[:, :1], chunk[:, 1:]
        u = ((by - cy) * (px - cx) + (cx - bx) * (py - cy)) / det
        v = ((cy - ay) * (px - cx) + (ax - cx) * (py - cy)) / det
        hit = (u >= 0) & (v >= 0) & (u + v <= 1)
        if hit.any():
            lowest = min(lowest, float(np.where(hit, u * az + v * bz + (1 - u - v) * cz, np.inf).min()))
    return lowest


def mesh_pieces(out: Path, written: Iterable[Path]) -> dict[str, list[np.ndarray]]:
    """Part -> the vertices [m] of each convex piece of its ``convex`` file among the files
    ``written`` into the assembly folder ``out`` (a part simulated from its mesh)."""
    return {path.name.removesuffix(".convex.obj"): read_objects(out / MESH_FOLDER / path.name)
            for path in written if path.name.endswith(".convex.obj")}


def near_miss_reason(pid: str, hid: str, depth: float) -> str:
    """Why the pair is no experiment of the PyBullet cell (:func:`near_misses`)."""
    return (f"{pid} in {hid}: misses by less than the cell's peg lacks at its corners (rounded by its 1 mm hull "
            f"margin) plus what the cell resolves ({1e3 * depth:.3f} mm), decided from the CAD")


def near_miss_assumption(derived: Derived, pieces: Mapping[str, Sequence[np.ndarray]] | None = None) -> list[str]:
    """The near misses the PyBullet cell does not observe (:func:`near_misses`), as
    ``import`` prints them (none without one), saying which backends try them
    (:data:`bridge.assembly.NEAR_MISS_BACKENDS`)."""
    return [f"no experiment of the PyBullet cell (backend sim; the truth and franka backends try it): {reason}"
            for reason in (near_misses(derived, pieces) | pin_near_misses(derived)).values()]


def nominal_section(inward: Shape2D, outward: Iterable[Shape2D]) -> Shape2D:
    """A hole's or bore's section (``inward``) at its nominal diameter when it is a nominal
    zero-clearance fit with the round ``outward`` sections (the pegs in it, the pins in the
    bore): its vertex circle's diameter, or the widest of theirs where that is wider, so
    that the cell simulates every such fit at room 0 or more, never an interference;
    ``inward`` unchanged with none."""
    widths = [shape.a for shape in outward]
    if not widths:
        return inward
    size = max(inward.a + 2 * inward.deflection, *widths)
    return replace(inward, a=size, b=size, deflection=0.0)


def nominal_text(derived: Derived) -> str:
    """``nominal_margin(P,H,M)``: the room [µm, rounded] of each peg in each hole
    (:func:`executor.cad.operations.margins`)."""
    lines = ["% The nominal room of every peg in every hole [um] (negative: it does not pass), by ./run.sh import;",
             "% the input of sizes learn --prior cad.", *_nominal_comments(nominal_fits(derived))]
    for pid, rooms in margins(derived).items():
        lines.append(_symbols([clingo.Function("nominal_margin", [
            clingo.Function(pid), clingo.Function(hid), clingo.Number(round(1e6 * room))])
            for hid, room in rooms.items()]))
    return "\n".join(lines) + "\n"


def cell_base(derived: Derived) -> tuple[trimesh.Trimesh, str]:
    """The base's mesh as the cell simulates it and a line saying how it was made: a STEP
    base tessellated again to :data:`CELL_DEFLECTION` (or a tenth of the least room of a
    peg that fits a hole, if that is less), else the mesh the import measured."""
    base = derived.parts[derived.base]
    rooms = [room for holes in margins(derived).values() for room in holes.values() if room > 0]
    deflection = min([CELL_DEFLECTION, *(room / 10 for room in rooms)])
    coarse = None if base.remesh is None else base.remesh(deflection)
    if coarse is None or not coarse.is_watertight:
        return base.mesh, "as measured"
    if coarse.volume < 0:
        coarse.invert()
    return coarse, (f"tessellated to {1e6 * deflection:.3g} um for the cell: a round hole's polygon has its corners on "
                    "the circle, its sides within that of it")


REASONS = {
    "blocks": "A cannot go in once B is there (B, or parts always placed before B, block each way the base leaves A)",
    "base": "A is the base and B touches it",
    "feature": "B goes into or onto a feature of A (a hole, a pin): the cell inserts it there, so A is in place "
               "first (the insertion's precondition, not the blocking's)",
    "supports": "B rests on A and not on the base (the support rule, an assumption of the import)",
    "locates": "A alone keeps B from moving sideways (the locating rule, an assumption of the import)",
}
"""Why a pair of ``geometric_precedence.lp`` holds, as its comments say."""


def precedence_text(derived: Derived) -> str:
    """``geometric_precedence.lp``: its pairs with their reasons (comments), ``part/1`` and
    the closed ``must_precede/2``."""
    closure = sorted(nx.transitive_closure_dag(order(derived)).edges)
    used = [reason for reason in REASONS if reason in derived.reasons.values()]
    lines = ["% Geometric precedence by disassembly (./run.sh import), transitively closed: must_precede(A,B) when",
             *(f"% {reason}: {REASONS[reason]}" + (";" if k + 1 < len(used) else ".") for k, reason in enumerate(used)),
             *(f"% {a}->{b}: {reason}" for (a, b), reason in sorted(derived.reasons.items())),
             _symbols([clingo.Function("part", [clingo.Function(p)]) for p in sorted(derived.parts)])]
    lines += [_symbols([clingo.Function("must_precede", [clingo.Function(a), clingo.Function(b)])])
              for a, b in closure]
    return "\n".join(lines) + "\n"


def cell_order_text(cell: Derived) -> str | None:
    """``cell_order.lp``: ``cell_before(P,Q)`` for each order the fingers' grip needs
    (:func:`executor.cad.operations.finger_orders`), each with its reason in a comment;
    None where there is none. The cell's own constraint, not the product's precedence."""
    orders = finger_orders(cell)
    if not orders:
        return None
    lines = ["% The cell's own orders (./run.sh import): cell_before(P,Q) when the fingers hold peg P so deep",
             "% that part Q, in place before it, would meet them (P must go in before Q). Not the product's",
             "% precedence: the plans of this product honour them (plan --assembly, session, assemble).",
             *(f"% {finger_order_text(order)}" for order in orders)]
    lines += [_symbols([clingo.Function("cell_before", [clingo.Function(p), clingo.Function(q)])])
              for p, q, _, _ in orders]
    return "\n".join(lines) + "\n"


def map_product(derived: Derived, settings: Settings, refused: Mapping[str, str] | None = None
                ) -> tuple[Mapped, Settings, Derived]:
    """The covers, heads and parts placed by hand of the product as the cell inserts it
    (:func:`executor.cad.operations.cell_view`: its other pegs, and those ``refused``
    (part -> why), are placed by hand), with ``why`` the cell builds
    none of it (two parts overlapping on the tray, or parts without a tray in ``settings``
    that cannot all wait within the arm's reach), its gripper's flange where the default's is
    too short (:func:`executor.cad.operations.tool_length`), the settings with every part's tray
    (:func:`default_trays` for those it lacks), and that product (for :func:`write_folder`)."""
    cell, by_hand = cell_view(derived, refused)
    flange, tool = tool_length(cell)
    mapped = replace(map_parts(cell, plate_top(cell), by_hand), flange=flange, tool=tool)
    boxes = _footprints(cell, mapped)
    trays, unreached = default_trays(boxes, settings.trays, derived.base, _product_box(derived))
    settings = replace(settings, trays=trays)
    why = _tray_overlap(boxes, trays) or (
        None if not unreached else f"parts {', '.join(unreached)} find no tray within the arm's reach "
        f"({1000 * REACH[0]:g} to {1000 * REACH[1]:g} mm) clear of the product and the other parts "
        "(set [parts.<id>] tray in the import settings)")
    return replace(mapped, why=why), settings, cell


def manual_origin(mesh: trimesh.Trimesh) -> tuple[float, float, float]:
    """The frame origin of a part placed by hand: the centre of its bounding box's bottom face [m]."""
    (x0, y0, z0), (x1, y1, _) = mesh.bounds
    return (float(x0 + x1) / 2, float(y0 + y1) / 2, float(z0))


def _frames(derived: Derived, mapped: Mapped) -> dict[str, np.ndarray]:
    """Each part's transform (4 × 4) from the cell frame to its part frame (the base's: its
    bounding box's centre at its plate's ``base_center``)."""
    frames = {pid: peg_frame(fit.section, upright(derived, fit)) @ feature_turn(fit)
              for pid, fit in derived.hole_of.items() if fit.section is not None}
    frames |= {pid: bore_frame(derived, pid) for pid in derived.bores}
    (x0, y0, _), (x1, y1, _) = derived.parts[derived.base].mesh.bounds
    origins = {pid: fit.origin for pid, fit in mapped.covers.items()} | {pid: fit.origin for pid, fit in
                                                                         mapped.heads.items()}
    origins |= {pid: manual_origin(derived.parts[pid].mesh) for pid in mapped.manual}
    origins[derived.base] = ((x0 + x1) / 2, (y0 + y1) / 2, 0.0)
    return frames | {pid: trimesh.transformations.translation_matrix(np.negative(origin))
                     for pid, origin in origins.items()}


Box = tuple[np.ndarray, np.ndarray]
"""A footprint: the lowest and highest (x, y) [m] of an axis-aligned rectangle."""


def _footprints(derived: Derived, mapped: Mapped) -> dict[str, Box]:
    """Each part's footprint about its tray: the bounding box of its mesh in its part frame
    (a part without one: about its bounding box's bottom centre, :func:`manual_origin`)."""
    frames = _frames(derived, mapped)
    boxes = {}
    for pid, part in derived.parts.items():
        frame = frames.get(pid, trimesh.transformations.translation_matrix(np.negative(manual_origin(part.mesh))))
        corners = trimesh.transform_points(trimesh.bounds.corners(part.mesh.bounds), frame)[:, :2]
        boxes[pid] = (corners.min(axis=0), corners.max(axis=0))
    return boxes


def _product_box(derived: Derived) -> Box:
    """The footprint of the assembled product where it stands in the cell [m]."""
    bounds = np.array([part.mesh.bounds for part in derived.parts.values()])
    return bounds[:, 0, :2].min(axis=0), bounds[:, 1, :2].max(axis=0)


def _at(box: Box, tray: tuple[float, float]) -> Box:
    return box[0] + tray, box[1] + tray


def _apart(a: Box, b: Box, gap: float) -> bool:
    """Whether footprints ``a`` and ``b`` leave more than ``gap`` [m] between them along x or y."""
    return bool(np.any(np.maximum(a[0], b[0]) - np.minimum(a[1], b[1]) > gap))


def default_trays(boxes: dict[str, Box], trays: dict[str, tuple[float, float]], base: str, product: Box
                  ) -> tuple[dict[str, tuple[float, float]], list[str]]:
    """Every part's tray [m]: those in ``trays``, the base's at :data:`BASE_TRAY`, the others
    by id in rows along +x from :data:`TRAY_START`, each row below (towards -y) the one
    before: a tray at least :data:`TRAY_PITCH` after the one before in its row, its
    footprint (``boxes``) :data:`TRAY_GAP` clear of every other part's at its tray and of
    the ``product`` where it stands, its point within :data:`REACH` of the arm's base; and
    the parts that find no such tray (they wait in a row beyond the others, out of reach)."""
    trays = dict(trays)
    trays.setdefault(base, BASE_TRAY)
    taken = [product, *(_at(boxes[pid], tray) for pid, tray in trays.items())]
    x, y = TRAY_START
    edge = math.inf  # the lowest y [m] of the row before's footprints
    low = math.inf  # the lowest y [m] of this row's footprints so far
    unreached = []
    for pid in sorted(set(boxes) - set(trays)):
        box = boxes[pid]
        while True:
            y = TRAY_START[1] if math.isinf(edge) else edge - TRAY_GAP - float(box[1][1])
            if y < -REACH[1]:
                break
            x = max(x, math.sqrt(max(0.0, REACH[0] ** 2 - y * y)))
            while (blocker := next((t for t in taken if not _apart(_at(box, (x, y)), t, TRAY_GAP)), None)) is not None:
                x = float(blocker[1][0]) + TRAY_GAP - float(box[0][0]) + 1e-9
            if math.hypot(x, y) <= REACH[1]:
                break
            edge, low, x = min(low, y + float(box[0][1])), math.inf, TRAY_START[0]
        if y < -REACH[1]:
            unreached.append(pid)
            continue
        trays[pid] = (x, y)
        taken.append(_at(box, (x, y)))
        low = min(low, y + float(box[0][1]))
        x += TRAY_PITCH
    top = max(float(t[1][1]) for t in taken)
    x = TRAY_START[0]
    for pid in unreached:
        trays[pid] = (x - float(boxes[pid][0][0]), top + TRAY_GAP - float(boxes[pid][0][1]))
        x = trays[pid][0] + float(boxes[pid][1][0]) + TRAY_GAP
    return trays, unreached


def _tray_overlap(boxes: dict[str, Box], trays: dict[str, tuple[float, float]]) -> str | None:
    """Why two parts overlap where they wait (their footprints ``boxes`` at their
    ``trays``), None when none do."""
    ids = sorted(boxes)
    for k, a in enumerate(ids):
        for b in ids[k + 1:]:
            box_a, box_b = _at(boxes[a], trays[a]), _at(boxes[b], trays[b])
            if np.all(np.minimum(box_a[1], box_b[1]) - np.maximum(box_a[0], box_b[0]) > LEVEL):
                return (f"parts '{a}' and '{b}' overlap where they wait on the tray (set [parts.<id>] tray in the "
                        "import settings)")
    return None


def _tool_lines(derived: Derived, fit: HoleFit) -> list[str]:
    """A peg's ``[part_shapes.*]`` lines of what holds it (:func:`executor.cad.operations.tool_of`):
    ``tool = "suction"``, or the fingers' ``grasp_depth`` where they hold it less deep than
    :data:`executor.cad.operations.GRIPPER`'s (:func:`executor.cad.operations.finger_grip`); none otherwise."""
    tool, why = tool_of(derived, fit)
    if tool == "suction":
        return ['tool = "suction"']
    grip = finger_grip(derived, fit)[0]
    return [f"grasp_depth = {_q(grip)}  # {why}"] if 0 < grip < GRIPPER["grasp_depth"] else []


def _mesh_entry(mesh: Mesh) -> str:
    convex = "" if mesh.convex is None else f', convex = "{mesh.convex}"'
    return f'mesh = {{ file = "{mesh.file}", sha256 = "{mesh.sha256}"{convex} }}'


def write_meshes(derived: Derived, mapped: Mapped, out: Path, written: list[Path]
                 ) -> tuple[dict[str, Mesh], dict[str, str]]:
    """The meshes of the parts of a mapped product that are no primitive, written into
    ``out`` (the base in the cell frame, the others in their part frames, the moving ones
    with their convex pieces; each file written is appended to ``written``); returns their
    ``mesh`` entries by part, and the moving parts that have no pieces that fit, each with
    why (:func:`executor.cad.convex.fitting_pieces`)."""
    meshes: dict[str, Mesh] = {}
    refused: dict[str, str] = {}
    if not builds_plate(derived):
        done = write_mesh(out, derived.base, *cell_base(derived), None, "the cell frame")
        assert not isinstance(done, str)  # the base has no pieces
        meshes[derived.base], files = done
        written += files
    frames = _frames(derived, mapped)
    for pid in sorted(mapped.manual):  # static where it is placed: no pieces
        done = write_mesh(out, pid, derived.parts[pid].mesh.copy().apply_transform(frames[pid]), "as measured", None)
        assert not isinstance(done, str)
        meshes[pid], files = done
        written += files
    moving = [pid for pid, fit in derived.hole_of.items() if not peg_is_primitive(fit, upright(derived, fit))]
    moving += [pid for pid, cover in mapped.covers.items() if not cover.primitive]
    moving += [pid for pid, head in mapped.heads.items() if not head.primitive]
    moving += list(derived.bores)
    for pid in sorted(moving):
        mesh = derived.parts[pid].mesh
        near = {other: part.mesh.copy().apply_transform(frames[pid]) for other, part in derived.parts.items()
                if other != pid and np.all(np.minimum(mesh.bounds[1], part.mesh.bounds[1])
                                           - np.maximum(mesh.bounds[0], part.mesh.bounds[0]) > -NEAR)}
        done = write_mesh(out, pid, mesh.copy().apply_transform(frames[pid]), "as measured", near,
                          exact=bore_pieces(derived, pid) if pid in derived.bores else None,
                          fits=frozenset(fitted(derived, pid)), prisms=pid in derived.hole_of,
                          narrow=NOMINAL_FIT_ROOM if narrows_peg(derived, pid) else 0.0)
        if isinstance(done, str):
            written.append(out / MESH_FOLDER / f"{pid}.obj")  # written before its pieces were sought
            refused[pid] = done
            continue
        meshes[pid], files = done
        written += files
    return meshes, refused


def manual_features(derived: Derived, mapped: Mapped) -> dict[str, tuple[list[str], dict[str, list[str]]]]:
    """Each part placed by hand that is in or on features in the CAD (``derived``, the whole
    product, not the cell's view) -> those features (``on``) and the parts the cell places
    that carry one of them, each with the features it is in (``held_by``): a nut at its
    goal is on the bolt's end only with that bolt in its hole of the CAD."""
    def features(pid: str) -> list[str]:
        return sorted([hid for hid, fit in (derived.holes | derived.part_holes).items() if pid in fit.occupants]
                      + [pin_id for pin_id, pin in derived.pins.items() if pid in pin.parts])

    owner = {hid: fit.owner for hid, fit in derived.part_holes.items() if fit.owner is not None} | {
        pin_id: pin.owner for pin_id, pin in derived.pins.items()}
    placed = {pid for pid in derived.parts if pid != derived.base} - set(mapped.manual) - set(mapped.covers) - set(
        mapped.heads)  # into a hole the plan chooses
    found: dict[str, tuple[list[str], dict[str, list[str]]]] = {}
    for mid in mapped.manual:
        on = features(mid)
        if on:
            carriers = sorted({owner[f] for f in on if f in owner} & placed)
            found[mid] = (on, {pid: features(pid) for pid in carriers if features(pid)})
    return found


def pins_of(derived: Derived) -> dict[str, list[str]]:
    """Part with a bore -> the other parts than the base owning its further pins (parts the
    cell places by hand where it puts the part onto them: :func:`executor.cad.operations.cell_view`),
    for the parts that have such pins (``pins_of`` of ``[part_shapes.*]``)."""
    owners: dict[str, set[str]] = {}
    for pid, pin_id in derived.further_bores:
        if derived.pins[pin_id].owner != derived.base:
            owners.setdefault(pid, set()).add(derived.pins[pin_id].owner)
    return {pid: sorted(found) for pid, found in owners.items()}


def geometry_text(derived: Derived, mapped: Mapped, settings: Settings, meshes: dict[str, Mesh],
                  features: dict[str, tuple[list[str], dict[str, list[str]]]],
                  pieces: Mapping[str, Sequence[np.ndarray]], further: Mapping[str, list[str]]) -> str:
    """``geometry.toml`` of a mapped product (:func:`map_product`), the parts in ``meshes``
    as their own meshes (``pieces``: the convex pieces of those that move, :func:`mesh_pieces`),
    the features of the parts placed by hand (:func:`manual_features`), the owners of the
    further pins of parts with a bore (:func:`pins_of`)."""
    fits = list(derived.holes.values())
    base = derived.parts[derived.base].mesh
    (x0, y0, z0), (x1, y1, _) = base.bounds
    top, depth = plate_level(derived)
    # a hole the cell states at the sweep's level of least room keeps its entry's width
    chamfer = max([MIN_CHAMFER, *(f.chamfer - max(0.0, _hole_section(derived, hid, f).b - f.hole.b) / 2
                                  for hid, f in derived.holes.items())])
    tile = _tile([fit for fit in fits if fit.axis == "+z"])  # the plate's bosses: none around a sideways hole
    own = _own_tiles(derived, tile, chamfer)
    lines = ["# The simulated cell's product measured from the CAD by ./run.sh import [m]: primitives, and the",
             "# parts that are none as their own meshes (meshes/, checked by their SHA-256).", "",
             "[plate]", f"top_z = {_q(top)}", f"tile_size = {_q(tile)}", f"tile_thickness = {_q(depth)}",
             f"chamfer = {_q(chamfer)}  # [m] at least MIN_CHAMFER",
             "polygon_sides = 24",
             f"base_size = [{_q(x1 - x0)}, {_q(y1 - y0)}]", f"base_center = [{_q((x0 + x1) / 2)}, {_q((y0 + y1) / 2)}]",
             f"base_thickness = {_q(min(max(top - depth - z0, 1e-3), MAX_PLATE_DEPTH))}", ""]
    nominal, pairs, missed = zero_clearance_parts(derived), section_pairs(derived), near_misses(derived, pieces)
    missed |= pin_near_misses(derived)
    widened = widened_fits(derived)
    for hid, fit in derived.holes.items():
        listed = nominal.get(hid, [])
        lines += [f"[hole_shapes.{hid}]", f'holes = ["{hid}"]',
                  *_section_lines(nominal_section(_hole_section(derived, hid, fit),
                                                  [pairs[pid][hid][0] for pid in listed])),
                  *_zero_clearance_line([pid for pid in listed if pid in derived.hole_of]),
                  *_widened_line([pid for pid, on in widened if on == hid], "pegs", "narrower")]
        close = [(pid, reason) for (pid, h), reason in missed.items() if h == hid]
        if close:
            lines.append(f"near_miss = {json.dumps([pid for pid, _ in close])}  # no experiment: "
                         + "; ".join(reason for _, reason in close))
        if fit.hole.yaw:
            lines.append(f"yaw = {fit.hole.yaw:.6g}")
        if hid in own:
            lines.append(f"tile = {_q(own[hid])}  # its own boss: the plate's would overlap its neighbours'")
        if fit.axis != "+z":  # entered sideways: its entry's height, its depth to its part's tip
            lines += [f'axis = "{opposite(fit.axis)}"', f"top_z = {_q(entry_point(fit)[2])}",
                      f"depth = {_q(sideways_depth(derived, fit))}"]
        else:
            if abs(fit.entry - top) > LEVEL:
                lines.append(f"top_z = {_q(fit.entry)}")
            deep = down_depth(derived, fit)  # slices the base and the part: once
            if abs(deep - depth) > LEVEL:
                lines.append(f"depth = {_q(deep)}")
        lines.append("")
    for pid, fit in sorted(derived.hole_of.items()):
        mesh, peg = upright(derived, fit), derived.swept.get((pid, fit.id), (fit.section,))[0]
        assert peg is not None
        lines += [f"[part_shapes.{pid}]", f'parts = ["{pid}"]', *_section_lines(peg),
                  f"length = {_q(float(mesh.extents[2]))}", f"mass = {_q(mesh.volume * DENSITY)}",
                  f'demo_hole = "{fit.id}"', *([_mesh_entry(meshes[pid])] if pid in meshes else []),
                  *_tool_lines(derived, fit), ""]
    for pin_id, pin in derived.pins.items():
        top, height = pin_level(derived, pin)
        lines += [f"[hole_shapes.{pin_id}]", f'holes = ["{pin_id}"]', "pin = true", *_section_lines(pin.section),
                  *_zero_clearance_line([pid for pid in nominal.get(pin_id, []) if pid in derived.bores]),
                  *_widened_line([pid for pid, on in widened if on == pin_id], "bores", "wider")]
        if pin.section.yaw and pin.section.kind != "round":
            lines.append(f"yaw = {pin.section.yaw:.6g}")
        if close := [(pid, reason) for (pid, h), reason in missed.items() if h == pin_id]:
            lines.append(f"near_miss = {json.dumps([pid for pid, _ in close])}  # no experiment: "
                         + "; ".join(reason for _, reason in close))
        if pin.owner != derived.base:  # standing up on a part placed by hand (cell_view)
            lines.append(f'owner = "{pin.owner}"')
        if pin.axis != "+z":  # along a horizontal axis: its free end's height, the depth along its axis
            lines += [f'axis = "{opposite(pin.axis)}"']
            top = pin_entry(derived, pin)[2]
        lines += [f"top_z = {_q(top)}", f"depth = {_q(height)}", ""]
    for pid, bore in sorted(derived.bores.items()):
        mesh, pin = derived.parts[pid].mesh, derived.pin_of(pid)
        onto = [pins[0] for pin_id, pins in pairs[pid].items() if pid in nominal.get(pin_id, [])]
        length = float(np.ptp(along_axis(mesh, pin)[:, 2]))
        lines += [f"[part_shapes.{pid}]", f'parts = ["{pid}"]', "bore = true",
                  *_section_lines(nominal_section(bore, onto)),
                  f"length = {_q(length)}", f"mass = {_q(mesh.volume * DENSITY)}",
                  f'demo_hole = "{pin.id}"', *([f"pins_of = {json.dumps(further[pid])}"] if pid in further else []),
                  _mesh_entry(meshes[pid]), ""]
    gripper = GRIPPER if mapped.flange is None else GRIPPER | {"flange_length": mapped.flange}
    lines += ["[gripper]", *(f"{key} = {value}" for key, value in gripper.items()), "",
              "[base]", f'part = "{derived.base}"', f"tray = {_numbers(settings.trays[derived.base])}",
              "grip = [0.0, 0.0]", f"mass = {_q(base.volume * DENSITY)}",
              *([_mesh_entry(meshes[derived.base])] if derived.base in meshes else []), ""]
    for cid, cover in sorted(mapped.covers.items()):
        lines += [f"[covers.{cid}]", f"name = {json.dumps(settings.names.get(cid, derived.parts[cid].name))}",
                  f"over = {json.dumps(list(cover.over))}", f"outline = {_numbers(cover.outline)}",
                  f"thickness = {_q(cover.thickness)}", f"bottom = {_q(max(cover.bottom, 0.0))}",
                  f"clearance = {_q(cover.clearance)}", f"mass = {_q(derived.parts[cid].mesh.volume * DENSITY)}",
                  f"grip = {_numbers(cover.grip)}", f"tray = {_numbers(settings.trays[cid])}",
                  f'skill = "{cover.skill}"',
                  *([f"socket = {_numbers(cover.socket)}"] if cover.socket else []),
                  *([_mesh_entry(meshes[cid])] if cid in meshes else []), ""]
    for hid, head in sorted(mapped.heads.items()):
        lines += [f"[heads.{hid}]", f"name = {json.dumps(settings.names.get(hid, derived.parts[hid].name))}",
                  f'into = "{head.into}"', f'kind = "{head.section.kind}"', f"size = {_q(head.section.a)}",
                  f"length = {_q(head.length)}", f"mass = {_q(derived.parts[hid].mesh.volume * DENSITY)}",
                  f'skill = "{head.skill}"', *([_mesh_entry(meshes[hid])] if hid in meshes else []), ""]
    pressed_in = pressed(derived)
    for mid, reason in sorted(mapped.manual.items()):
        lines += [f"[manual.{mid}]", f"name = {json.dumps(settings.names.get(mid, derived.parts[mid].name))}",
                  f"reason = {json.dumps(shorten(reason, MAX_REASON))}",
                  f"goal = {_numbers(manual_origin(derived.parts[mid].mesh))}",
                  f"tray = {_numbers(settings.trays[mid])}", f"mass = {_q(derived.parts[mid].mesh.volume * DENSITY)}",
                  _mesh_entry(meshes[mid])]
        on, held_by = features.get(mid, ([], {}))
        lines += [f"on = {json.dumps(on)}"] if on else []
        lines += [f"held_by = {{ {', '.join(f'{pid} = {json.dumps(holes)}' for pid, holes in held_by.items())} }}",
                  ] if held_by else []
        lines += ["pressed = true"] if mid in pressed_in else []
        lines.append("")
    return "\n".join(lines)


def _hole_section(derived: Derived, hid: str, fit: HoleFit) -> Shape2D:
    """The section of hole ``hid`` the cell's tables state: where the sweep admits a part
    into it (:func:`executor.cad.derive.swept_fits`, a taper in its taper), the hole's at
    the level of least room with its own part (else with the first such part), so that
    the cell's sections answer as ``sizes.lp`` (:func:`_cell_disagrees` checks it); else
    its measured section."""
    swept = sorted(((pid != fit.part, pid), hole) for (pid, h), (_, hole, _) in derived.swept.items() if h == hid)
    return swept[0][1] if swept else fit.hole


def _widened_line(parts: list[str], what: str, how: str) -> list[str]:
    """A feature's ``widened`` line naming ``parts`` (:func:`widened_fits`; none without
    one): ``what`` the cell builds (bores, pegs) ``how`` (wider, narrower)."""
    return [f"widened = {json.dumps(parts)}  # {what} the cell builds {1e3 * NOMINAL_FIT_ROOM:g} mm {how} per side: "
            "room under what it resolves"] if parts else []


def _zero_clearance_line(parts: list[str]) -> list[str]:
    """A feature's ``zero_clearance`` line naming ``parts`` (none without one)."""
    return [f"zero_clearance = {json.dumps(parts)}  # nominal zero-clearance fits: room 0"] if parts else []


def _numbers(values: tuple[float, ...]) -> str:
    """A TOML list of lengths [m] to 0.1 µm."""
    return f"[{', '.join(str(_q(v)) for v in values)}]"


_BOSS_WALL = 0.002
"""The wall a boss leaves beyond its hole's chamfered mouth on each side when the holes'
spacing does not set its side [m]."""


def _tile(fits: list[HoleFit]) -> float:
    """The side of the square boss around every hole [m]: the measured boss when the base
    has one around each hole, else the largest square the holes' spacing leaves room for."""
    bosses = [f.outer.b for f in fits if f.outer is not None and f.outer.kind in ("square", "rect")]
    spacing = min((max(abs(a.position[0] - b.position[0]), abs(a.position[1] - b.position[1]))
                   for i, a in enumerate(fits) for b in fits[i + 1:]), default=0.04)
    widest = max([max(f.hole.a, f.hole.b) + 2 * f.chamfer for f in fits], default=0.0)
    tile = min([*bosses, spacing, 0.04])
    return tile if tile > widest else widest + 2 * _BOSS_WALL


def _own_tiles(derived: Derived, tile: float, chamfer: float) -> dict[str, float]:
    """Each hole's own boss side [m] where bosses of side ``tile`` (:func:`_tile`) around
    every hole would overlap; none where they do not. A hole's boss is its section's
    widest side, or twice its outline's farthest reach from its centre, with the
    ``chamfer`` on each side (its need) and :data:`_BOSS_WALL` of wall
    beyond, at most ``tile``, and no wider than leaves each neighbour's boss half the room
    between the two needs: the distance of their centres (the larger of x and y, or
    straight for a turned hole) plus half the difference of the needs."""
    fits = {hid: fit for hid, fit in derived.holes.items() if fit.axis == "+z"}
    turned = {hid for hid, fit in fits.items() if fit.hole.yaw}
    if overlapping_bosses({hid: (*fit.position, tile) for hid, fit in fits.items()}, turned) is None:
        return {}
    need = {hid: max(fit.hole.a, fit.hole.b, 2 * float(np.abs(fit.hole.outline).max())) + 2 * chamfer
            for hid, fit in fits.items()}  # a polygon's outline may reach farther on one side

    def apart(a: str, b: str) -> float:
        (xa, ya), (xb, yb) = fits[a].position, fits[b].position
        return math.hypot(xa - xb, ya - yb) if {a, b} & turned else max(abs(xa - xb), abs(ya - yb))

    own = {hid: min([need[hid] + 2 * _BOSS_WALL, tile,
                     *(apart(hid, other) + (need[hid] - need[other]) / 2 for other in fits if other != hid)])
           for hid in fits}
    return {hid: side for hid, side in own.items() if side < tile}


def _digest(path: Path) -> str | None:
    """The SHA-256 of the file at ``path`` (hex), None when there is none."""
    try:
        return hashlib.sha256(path.read_bytes()).hexdigest()
    except FileNotFoundError:
        return None
    except OSError as exc:
        raise ExecutorError(f"{path}: cannot read ({os_reason(exc)})") from None


def _manifest(out: Path) -> dict[str, str]:
    """The files the last import into ``out`` wrote and their SHA-256 (none without a
    manifest); ExecutorError naming it when it is no import's manifest."""
    path = out / MANIFEST
    if not path.exists():
        return {}
    try:
        files = json.loads(read_text(path, "import manifest (JSON)", error=ExecutorError)).get("files")
    except (ValueError, AttributeError):  # not JSON, or not an object
        files = None
    if not isinstance(files, dict) or not all(isinstance(name, str) and (name in PRODUCT_FILES or _MESH_NAME.fullmatch(
            name)) and isinstance(digest, str) for name, digest in files.items()):
        raise ExecutorError(f"{path}: not an import manifest (expected JSON with \"files\": {{path: sha256}} of the "
                            "files import writes); --replace replaces it")
    return files


def claim_folder(out: Path, ids: Iterable[str], replace: bool) -> set[str]:
    """The files of the assembly folder ``out`` (paths relative to it) that an import of
    the parts ``ids`` may remove: those its manifest lists that are still as written,
    and with ``replace`` the product's files (:data:`PRODUCT_FILES`) whoever wrote them.
    ExecutorError naming the folder and the files when, without ``replace``, one it may
    write (the product's files, ``meshes/<id>.obj`` and ``meshes/<id>.convex.obj``)
    exists and was not written by the last import, or has changed since."""
    try:
        owned = _manifest(out)
    except ExecutorError:
        if not replace:
            raise
        owned = {}
    mine = {name for name, digest in owned.items() if _digest(out / name) == digest}
    targets = [*PRODUCT_FILES, *(f"{MESH_FOLDER}/{pid}{suffix}" for pid in sorted(ids)
                                 for suffix in (".obj", ".convex.obj"))]
    foreign = [name for name in targets if name not in mine and (out / name).exists()]
    if foreign and not replace:
        what = "a product" if "assembly.toml" in foreign else "files"
        raise ExecutorError(f"{out}: holds {what} that import did not write or that changed since "
                            f"({shorten(', '.join(foreign), 200)}); expected a new folder or one import wrote "
                            "(--replace replaces them)")
    return mine | {name for name in foreign if name in PRODUCT_FILES}


def _cell_disagrees(derived: Derived, geometry: CellGeometry) -> str | None:
    """Why the cell's ``geometry`` would answer a pair otherwise than ``sizes.lp``
    (:func:`executor.world.geometry.feature_passes` on its sections against
    :func:`executor.cad.operations.margins` and :func:`executor.cad.operations.nominal_fits`), naming
    the first such pair; None when it answers every pair alike."""
    rooms, nominal = margins(derived), nominal_fits(derived)
    for pid, part in sorted(geometry.parts.items()):
        for hid, hole in sorted(geometry.holes.items()):
            room = rooms.get(pid, {}).get(hid)
            stated = room is not None and (room > 0 or (pid, hid) in nominal)
            if feature_passes(part, hole) != stated:
                return (f"the cell's sections would decide {pid} in {hid} as {'no fit' if stated else 'a fit'}, "
                        f"sizes.lp as {'a fit' if stated else 'no fit'}")
    return None


def write_folder(derived: Derived, cell: Derived, mapped: Mapped, settings: Settings, title: str, out: Path,
                 removable: set[str]) -> tuple[list[Path], str | None, Mapped, Derived]:
    """Write the files of the module docstring into ``out`` (removing the ``removable``
    files, :func:`claim_folder`, that this import does not write again; the manifest last),
    ``cell`` the product as the cell inserts it (:func:`executor.cad.operations.cell_view`, :func:`map_product`'s);
    a moving part with no convex pieces that fit (:func:`write_meshes`) is placed by hand
    with why, the product mapped again without it; returns the files, why there is no
    ``geometry.toml`` (None when there is one, checked by the cell's loader), and the
    mapped product and its cell's view as written."""
    make_folder(out)
    geometry = out / "geometry.toml"
    geometry.unlink(missing_ok=True)  # the claim made it this import's, if there was one
    why = mapped.why
    mesh_files: list[Path] = []
    stale: list[Path] = []  # the meshes written before a part was refused
    meshes: dict[str, Mesh] | None = None
    refused: dict[str, str] = {}
    while why is None and meshes is None:
        meshes, more = write_meshes(cell, mapped, out, mesh_files)
        if more:
            refused |= more
            mapped, settings, cell = map_product(derived, settings, refused)
            why, meshes = mapped.why, None
            stale, mesh_files = stale + mesh_files, []
    roles = ({pid: "cover" for pid in mapped.covers} | {pid: "head" for pid in mapped.heads}
             | {pid: "manual" for pid in mapped.manual})
    written = [write_atomic(out / "assembly.toml", assembly_text(derived, settings, title, roles)),
               write_atomic(out / "sizes.lp", sizes_text(derived)),
               write_atomic(out / "nominal_sizes.lp", nominal_text(derived)),
               write_atomic(out / "geometric_precedence.lp", precedence_text(derived))]
    if meshes is not None:
        write_atomic(geometry, geometry_text(cell, mapped, settings, meshes, manual_features(derived, mapped),
                                             mesh_pieces(out, mesh_files), pins_of(derived)))
        try:
            loaded = load_geometry(str(out))
            plate_obj_text(loaded)  # the cell builds its plate's bosses from it
            why = _cell_disagrees(derived, loaded)
        except ToolError as exc:
            why = f"the cell refuses its geometry ({exc})"
        if why is None:
            written += [*mesh_files, geometry]
            orders = cell_order_text(cell)
            written += [write_atomic(out / "cell_order.lp", orders)] if orders is not None else []
        else:
            geometry.unlink()
    kept = {path.relative_to(out).as_posix(): _digest(path) for path in written}
    # an earlier import's files not written again, and this one's meshes of a geometry not kept
    for name in sorted((removable | {path.relative_to(out).as_posix() for path in stale + mesh_files}) - set(kept)):
        (out / name).unlink(missing_ok=True)
    write_atomic(out / MANIFEST, json.dumps({"written_by": "./run.sh import", "title": title, "files": kept},
                                            indent=1) + "\n")
    return written, why, mapped, cell
