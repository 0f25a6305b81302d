"""``import SOURCE --out DIR``: a product from its CAD as an assembly folder.

SOURCE is a STEP assembly or a folder of ``*.stl``/``*.obj`` meshes in the assembled pose
(``--units``). ``--config FILE`` is an optional TOML file::

    base = "plate"            # the fixture part (default: the part of largest volume, the lowest of alike ones)
    up = "+y"                 # the CAD's axis pointing up (default +z): +x, -x, +y, -y, +z or -z
    pieces_cpu_s = 60         # CoACD's CPU time per part's convex pieces [s] (default 60): then placed by hand
    [parts.peg1]
    tray = [0.25, 0.40]       # where the part waits in the cell [m] (default: laid out by footprints)
    name = "round peg"
    fixed_to = "lever"        # moves with that part (screwed, glued): neither blocks the other
    place = [0.56, 0.0]       # where the base's centre stands on the cell's table [m]; a third value:
                              # the height of the product's lowest point (default 0, the cell's floor)
    turn = 90                 # the product turned about z on the table [deg]: 0, 90, 180 or 270

``--up AXIS`` overrides ``up``: every part is turned right after reading by the rotation
taking that axis to +z (:func:`executor.cad.parts.turned`). Without either, a product that
looks drawn with another axis up (lying on its side, upside down, unable to rest on the
floor as read, or holding its parts less well than another up) is refused
(:func:`drawn_up`). ``--place X,Y[,Z]`` overrides ``place``, ``--turn DEG`` ``turn``.
Without either, a product whose base's centre lies
outside the arm's reach (:data:`REACH`) is placed at :data:`WORK_POSITION`, and the import
says so; without a z, the product's lowest point (of all its parts) goes to the cell's floor,
z = 0 (:func:`placement`). Where the user sets no turn or no place, the import chooses
them so that the arm reaches the most horizontal insertions (:func:`_chosen_pose`); every
part is turned and moved right after reading, so every file written is in the cell frame.

It prints what it assumes, each part's insertion axis and free directions, each hole
with both cross-sections and the clearance, the disassembly stages, the geometric
precedence with each pair's reason (``--locating-reach R``: the locating rule's reach [m],
:mod:`executor.cad.locating`; 0: off) and the collision queries; bad
CAD or a bad file: one line, exit code 2. ``--max-triangles N`` bounds the parts'
triangles together; the folder's ``.import-manifest.json`` lists the files an import
wrote, the only ones a later import replaces or removes (``--replace``: also a product it
did not write, :func:`executor.cad.write.manifest.claim_folder`).
"""

from __future__ import annotations

import argparse
import functools
import math
import time
import tomllib
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

from bridge.cli_types import ArgumentParser, finite_float, int_in, nonempty_path, number_in
from bridge.inputs import read_text, shorten
from executor import ExecutorError
from executor.cad.convex import MESH_FOLDER, PIECES_CPU, budget_assumption, overlap_assumption, pieces_budget
from executor.cad.covers import Mapped
from executor.cad.derive import Derived, derive
from executor.cad.locating import LOCATING_REACH, MAX_REACH
from executor.cad.operations.arm import QUARTERS, best_pose
from executor.cad.operations.fingers import finger_assumption
from executor.cad.operations.frames import entry_point, pin_entry
from executor.cad.operations.screwed import screwed_fits
from executor.cad.operations.tools import finger_order_text, finger_orders, tool_of
from executor.cad.operations.view import reaches_asked
from executor.cad.parts import (
    MAX_TRIANGLES,
    STEP_SUFFIXES,
    UNITS,
    UP_AXES,
    CadPart,
    check_solids,
    left_out,
    load_meshes,
    matching,
    overlaps_checked,
    quarter_turned,
    translated,
    turn_text,
    turned,
)
from executor.cad.sections import Shape2D, section_room, slices_kept, zero_clearance
from executor.cad.step import coarse_assumption, load_step
from executor.cad.sweep import opposite, processes
from executor.cad.upright import drawn_tilted, drawn_up
from executor.cad.upright.gravity import mm as _mm
from executor.cad.write.assembly import Settings
from executor.cad.write.facts import nominal_assumption
from executor.cad.write.folder import map_product, write_folder
from executor.cad.write.manifest import MANIFEST, claim_folder
from executor.cad.write.meshes import mesh_pieces
from executor.cad.write.near_misses import near_miss_assumption
from executor.cad.write.trays import REACH, TRAY_GAP, TRAY_START
from executor.cad.write.widened import widened_fits_assumption

WORK_POSITION = (0.56, 0.0)
"""Where a product out of the arm's reach is placed by default: its base's centre [m] in the
cell (the arm's base at the origin); the tests' products stand at x = 0.55 to 0.63 m."""
PLACE_BOUND = 1.0
"""``place`` coordinates lie in [-PLACE_BOUND, PLACE_BOUND] [m] (the cell's table)."""
_UP_EXPECTED = f"one of {', '.join(UP_AXES)} (the CAD's axis pointing up)"


def up_axis(text: str) -> str:
    """An argparse type: one of :data:`executor.cad.parts.UP_AXES`."""
    if text not in UP_AXES:
        raise argparse.ArgumentTypeError(f"{shorten(text)!r}: expected {_UP_EXPECTED}")
    return text


def _up_setting(path: Path | None, value: object) -> str | None:
    """``up`` of ``--config`` (None: not set); ExecutorError naming the file otherwise."""
    if value is None:
        return None
    if value not in UP_AXES:
        raise ExecutorError(f"{path}: up: expected {_UP_EXPECTED}, got {shorten(repr(value))}")
    return str(value)


def _budget_setting(path: Path | None, value: object) -> float:
    """``pieces_cpu_s`` of ``--config``, the CPU time [s] CoACD may spend on one part's
    pieces (:data:`executor.cad.convex.PIECES_CPU` when not set); ExecutorError naming the
    file when it is no positive number."""
    if value is None:
        return PIECES_CPU
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
        raise ExecutorError(f"{path}: pieces_cpu_s: expected a positive number of seconds, got {shorten(repr(value))}")
    return float(value)


def part_names(text: str) -> tuple[str, ...]:
    """An argparse type: part ids or ``fnmatch`` patterns on ids, separated by commas."""
    names = tuple(name.strip() for name in text.split(","))
    if not all(names):
        raise argparse.ArgumentTypeError(f"{shorten(text)!r}: expected part ids or patterns separated by commas "
                                         "(hopper,screw_*)")
    return names


def _names_setting(path: Path | None, key: str, value: object, example: str = "part ids or patterns "
                   "([\"hopper\", \"screw_*\"])") -> tuple[str, ...]:
    """``key`` of ``--config``, ids or patterns (``leave_out``, ``one_part``; none when not
    set); ExecutorError naming the file and ``key`` when it is no list of non-empty strings
    (``example``: what is expected)."""
    if value is None:
        return ()
    if not (isinstance(value, list) and all(isinstance(v, str) and v.strip() for v in value)):
        raise ExecutorError(f"{path}: {key}: expected a list of {example}, got {shorten(repr(value))}")
    return tuple(value)


@dataclass(frozen=True)
class LeaveOut:
    """The parts to leave out: part ids or ``fnmatch`` patterns (:func:`executor.cad.parts.left_out`),
    the ``setting`` that names them as errors name it (``--leave-out``, or ``<file>: leave_out``),
    as the assumption names it (``label``) and the ``base`` set (None: none), which none may leave out."""

    names: tuple[str, ...] = ()
    setting: str = "--leave-out"
    label: str = "--leave-out"
    base: object = None

    def kept(self, ids: list[str], dropped: list[str]) -> set[str]:
        """Of ``ids``, those kept; those left out added to ``dropped`` (sorted); ExecutorError
        naming the setting when a name matches none or the base is left out."""
        dropped.extend(sorted(left_out(ids, self.names, self.setting)))
        if self.base in dropped:
            raise ExecutorError(f"{self.setting}: the base {self.base!r} cannot be left out (set another base)")
        return set(ids) - set(dropped)

    def assumption(self, ids: list[str]) -> list[str]:
        """The assumption of the parts ``ids`` left out (none without one)."""
        if not ids:
            return []
        count = f"{len(ids)} part{'s' if len(ids) > 1 else ''}"
        return [f"parts left out as set ({self.label}): {', '.join(ids)} ({count}; dropped as read, before any "
                "check: their triangles, overlaps and fits do not count)"]


@dataclass(frozen=True)
class OnePart:
    """The STEP sub-assemblies each imported as one part (:func:`executor.cad.step.load_step`):
    their ids or ``fnmatch`` patterns on them (:func:`executor.cad.parts.matching`), the
    ``setting`` that names them as errors name it (``--one-part``, or ``<file>: one_part``)
    and as the assumption names it (``label``)."""

    names: tuple[str, ...] = ()
    setting: str = "--one-part"
    label: str = "--one-part"

    def chosen(self, solids: dict[str, int], joined: dict[str, int]) -> set[str]:
        """Of the sub-assemblies' ids (each with its solids), those the names match, these
        added to ``joined``; ExecutorError naming the setting when a name matches none."""
        hits = matching(sorted(solids), self.names, self.setting, "sub-assembly")
        joined.update({ident: solids[ident] for ident in sorted(hits)})
        return hits

    def assumption(self, joined: dict[str, int], ids: set[str]) -> list[str]:
        """The assumption of the sub-assemblies ``joined`` that are parts of ``ids`` (not
        within another joined, nor left out; none without one)."""
        listed = [f"{ident} ({count} solid{'s' if count > 1 else ''})" for ident, count in joined.items()
                  if ident in ids]
        if not listed:
            return []
        return [f"STEP sub-assemblies imported as one part as set ({self.label}): {', '.join(listed)} (each its "
                "solids' meshes joined into one, their cylinders kept)"]


def _up_assumption(up: str | None) -> str:
    """What ``import`` prints about the up axis: the turn of the ``up`` set, or the default."""
    if up is None:
        return ("the CAD's +z is up (set up = \"+y\" or --up +y for a CAD drawn y up, up = \"-z\" or --up=-z "
                "for one drawn upside down)")
    return f"the CAD's {up} is up (up): every part turned {turn_text(up)}, before it is placed"


Place = tuple[float, ...]
"""Where the product goes in the cell [m]: the base's centre (x, y), and (z) the height of its lowest point."""


def place_pair(text: str) -> Place:
    """An argparse type: ``"X,Y"`` or ``"X,Y,Z"`` [m], each finite in [-PLACE_BOUND, PLACE_BOUND]."""
    parse = finite_float(-PLACE_BOUND, PLACE_BOUND)
    values = text.split(",")
    if len(values) not in (2, 3):
        raise argparse.ArgumentTypeError(f"{shorten(text)!r}: expected X,Y or X,Y,Z in m, each a finite number in "
                                         f"[{-PLACE_BOUND:g}, {PLACE_BOUND:g}]")
    return tuple(parse(value.strip()) for value in values)


def _place_setting(path: Path | None, value: object) -> Place | None:
    """``place`` of ``--config`` (None: not set); ExecutorError naming the file otherwise."""
    if value is None:
        return None
    if not (isinstance(value, list) and len(value) in (2, 3) and all(
            isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
            and abs(v) <= PLACE_BOUND for v in value)):
        raise ExecutorError(f"{path}: place: expected [x, y] or [x, y, z] in m, each in [{-PLACE_BOUND:g}, "
                            f"{PLACE_BOUND:g}], got {shorten(repr(value))}")
    return tuple(float(v) for v in value)


def turn_degrees(text: str) -> int:
    """An argparse type: a turn about z [deg], one of :data:`QUARTERS`."""
    if text.strip() not in {str(q) for q in QUARTERS}:
        raise argparse.ArgumentTypeError(f"{shorten(text)!r}: expected one of {', '.join(map(str, QUARTERS))} (deg)")
    return int(text)


def _turn_setting(path: Path | None, value: object) -> int | None:
    """``turn`` of ``--config`` (None: not set); ExecutorError naming the file otherwise."""
    if value is None:
        return None
    if isinstance(value, bool) or value not in QUARTERS:
        raise ExecutorError(f"{path}: turn: expected one of {', '.join(map(str, QUARTERS))} (deg about z), "
                            f"got {shorten(repr(value))}")
    return int(value)


FLOOR_TOLERANCE = 1e-6
"""A product whose lowest point lies within this [m] of the height it goes to (the cell's
floor, z = 0, unless ``place`` gives z) is not moved along z: a CAD's rounding moves nothing."""


def placement(parts: list[CadPart], base: str, place: Place | None, chosen: str = "place"
              ) -> tuple[tuple[float, float, float], str]:
    """The offset [m] that puts the centre of ``base``'s box at ``place``'s x, y (None: at
    :data:`WORK_POSITION` when it lies out of :data:`REACH`, else no horizontal offset) and
    the lowest point of all the parts at ``place``'s z (default 0, the cell's floor; within
    :data:`FLOOR_TOLERANCE`: not moved), and the assumption to print (``chosen``: why the
    place is where it is)."""
    bounds = next(p.mesh.bounds for p in parts if p.id == base)
    centre = (float(bounds[0][0] + bounds[1][0]) / 2, float(bounds[0][1] + bounds[1][1]) / 2)
    distance = math.hypot(*centre)
    if place is None and REACH[0] <= distance <= REACH[1]:
        horizontal = (0.0, 0.0)
        where = (f"the base's centre where the CAD has it ({_mm(distance)} mm from the arm's base, within reach; "
                 "set place = [x, y] to move it)")
    else:
        target, why = ((place[0], place[1]), chosen) if place is not None else (WORK_POSITION, (
            f"the base's centre {_mm(distance)} mm from the arm's base is out of its reach "
            f"({_mm(REACH[0])} to {_mm(REACH[1])} mm); set place = [x, y] or --place X,Y"))
        horizontal = (target[0] - centre[0], target[1] - centre[1])
        where = f"the base's centre placed at ({_mm(target[0])}, {_mm(target[1])}) mm in the cell ({why})"
    lowest = min(float(p.mesh.bounds[0][2]) for p in parts)
    height, given = (place[2], True) if place is not None and len(place) == 3 else (0.0, False)
    rise = height - lowest if abs(height - lowest) > FLOOR_TOLERANCE else 0.0
    floor = (f"the product's lowest point (of all its parts) at z = {_mm(height)} mm (place)" if given else
             "the product's lowest point (of all its parts) on the cell's floor, z = 0 (set place = [x, y, z] "
             "or --place X,Y,Z for another height)")
    if rise:
        floor += f", from z = {_mm(lowest)} mm in the CAD"
    offset = (horizontal[0], horizontal[1], rise)
    moved = (f": every part moved by ({_mm(offset[0])}, {_mm(offset[1])}, {_mm(offset[2])}) mm from the CAD frame"
             if any(offset) else ": the CAD frame is the cell frame")
    return offset, f"{where}; {floor}{moved}"


def _settings_file(path: Path | None) -> dict:
    """The TOML of ``--config`` ({} without one); ExecutorError naming the file when it is not TOML."""
    if path is None:
        return {}
    try:
        return tomllib.loads(read_text(path, "import settings (TOML)", error=ExecutorError))
    except tomllib.TOMLDecodeError as exc:
        raise ExecutorError(f"{path}: not valid TOML ({exc})") from None


ALIKE_VOLUME = 1e-6
"""Parts whose volumes are within this fraction of the largest are alike (one part drawn
again: stacked bricks); the default base is the lowest of them (its bottom, up being +z)."""


def _config(path: Path | None, data: dict, parts: list[CadPart], up: str
            ) -> tuple[Settings, dict[str, str], list[str]]:
    """The settings of ``--config`` (``data``, read from ``path``; checked: one line
    naming the file and key; the trays it sets only), with the ``up`` in force, the
    fixed-to map and what was assumed for lack of them."""
    ids = {p.id for p in parts}
    assumed: list[str] = []
    base = data.get("base")
    if base is None:
        largest = max(p.mesh.volume for p in parts)
        alike = [p for p in parts if p.mesh.volume >= (1 - ALIKE_VOLUME) * largest]
        base = min(alike, key=lambda p: (float(p.mesh.bounds[0][2]), p.id)).id
        lowest = f", the lowest of {len(alike)} alike" if len(alike) > 1 else ""
        assumed.append(f"base {base} (the largest part{lowest}; set base = \"<id>\")")
    elif base not in ids:
        raise ExecutorError(f"{path}: base: expected a part id ({', '.join(sorted(ids))}), got {shorten(repr(base))}")
    tables = data.get("parts", {})
    if not isinstance(tables, dict):
        raise ExecutorError(f"{path}: [parts]: expected tables [parts.<id>]")
    trays: dict[str, tuple[float, float]] = {}
    names: dict[str, str] = {}
    fixed: dict[str, str] = {}
    for pid, table in tables.items():
        if pid not in ids or not isinstance(table, dict):
            raise ExecutorError(f"{path}: [parts.{pid}]: expected a table of a part of the CAD "
                                f"({', '.join(sorted(ids))})")
        tray = table.get("tray")
        if tray is not None:
            if not (isinstance(tray, list) and len(tray) == 2 and all(
                    isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in tray)):
                raise ExecutorError(f"{path}: [parts.{pid}] tray: expected [x, y] in m, got {shorten(repr(tray))}")
            trays[pid] = (float(tray[0]), float(tray[1]))
        if "name" in table:
            names[pid] = str(table["name"])
        host = table.get("fixed_to")
        if host is not None:
            if host not in ids or host in (pid, base):
                raise ExecutorError(f"{path}: [parts.{pid}] fixed_to: expected another part than it and the base, "
                                    f"got {shorten(repr(host))}")
            fixed[pid] = host
    return Settings(base, trays, names, up), fixed, assumed




def _around(islands: int) -> str:
    """A hole's islands as the report names them ("" for none)."""
    return "" if not islands else f" around {islands} island{'s' if islands > 1 else ''}"


def _describe(kind: str, a: float, b: float) -> str:
    return f"round d {_mm(a)}" if kind == "round" else f"{kind} {_mm(a)} x {_mm(b)}"


def _clearance(peg: Shape2D, hole: Shape2D, peg_name: str, hole_name: str) -> str:
    """How ``peg`` passes ``hole`` as the report says it: the clearance and room all round
    (:func:`executor.cad.sections.section_room`), preceded by ``no fit`` and the
    clearance [µm] where it is not positive, or a nominal zero-clearance fit
    (:func:`executor.cad.sections.zero_clearance`) with the measured difference: as
    ``sizes.lp`` writes it (:func:`executor.cad.sections.passes`)."""
    room = section_room(peg, hole, peg_name, hole_name)
    apart = zero_clearance(peg, hole, room.margin)
    if apart is not None:
        measured = "vertex circles" if peg.kind == hole.kind == "round" else "outlines"
        return (f"nominal zero-clearance fit, room 0 (measured {_mm(room.margin)} mm, {measured} "
                f"{round(1e6 * apart, 1) + 0.0:+.1f} µm apart)")
    # a pair that does not pass says so: an overlap under 0.5 µm prints as 0.000 mm
    verdict = "" if room.margin > 0 else f"no fit ({round(1e6 * room.margin, 1) + 0.0:+.1f} µm), "
    return f"{verdict}clearance {_mm(room.margin)} mm: {_mm(room.room)} mm all round at yaw {room.yaw:.3f} deg"


def _swept(derived: Derived, part: str, feature: str) -> str:
    """What the report adds where the sweep admits a pair the sections over the whole
    stretch do not (:func:`executor.cad.derive.swept_fits`): the sections at the levels of
    least room on the way in and that room, as ``sizes.lp`` takes it; "" elsewhere."""
    if (part, feature) not in derived.swept:
        return ""
    if (slide := screwed_fits(derived).get((part, feature))) is not None:
        return f"; screwed ({slide.thread}): it fits by screwing, room 0, placed by hand"
    peg, hole, room = derived.swept[(part, feature)]
    apart = zero_clearance(peg, hole, room)
    verdict = f"room {_mm(room)} mm" if apart is None else \
        f"nominal zero-clearance fit, room 0 (measured {_mm(room)} mm)"
    return (f"; the sweep admits it: {_describe(peg.kind, peg.a, peg.b)} mm in {_describe(hole.kind, hole.a, hole.b)}"
            f" mm at the levels of least room on the way in, {verdict}")


def report(derived: Derived) -> list[str]:
    """The lines ``import`` prints about what it derived."""
    lines = []
    for pid in sorted(derived.axis):
        way = derived.axis[pid]
        later = "" if way in derived.free(pid) else (
            f" with {' '.join(sorted(derived.blockers[(pid, way)]))} out, placed after it")
        lines.append(f"part {pid}: insertion axis {opposite(way)} (leaves along {way}{later}); free in the "
                     f"assembled product along {', '.join(derived.free(pid)) or 'none'}")
    for hid, fit in [*derived.holes.items(), *derived.part_holes.items()]:
        yaw = f", yaw {fit.hole.yaw:g} deg" if fit.hole.yaw else ""
        held = "empty"
        if fit.occupants:
            held = "holds " + "; ".join(
                f"{pid} ({_describe(section.kind, section.a, section.b)} mm, "
                f"{_clearance(section, fit.hole, pid, hid)}{_swept(derived, pid, hid)})"
                for pid, section in fit.occupants.items())
        owner = "" if fit.owner is None else f" of {fit.owner}"
        where = (f"at ({_mm(fit.position[0])}, {_mm(fit.position[1])}) mm" if fit.axis == "+z" else
                 "entry at ({}, {}, {}) mm".format(*map(_mm, entry_point(fit))))
        lines.append(f"hole {hid}{owner} {where}, entered along "
                     f"{opposite(fit.axis)}: {_describe(fit.hole.kind, fit.hole.a, fit.hole.b)} mm{yaw}"
                     f"{_around(len(fit.hole.inner))}, depth "
                     f"{_mm(fit.depth)} mm, chamfer {_mm(fit.chamfer)} mm; {held}")
    for pin_id, pin in derived.pins.items():
        onto = []
        for pid in pin.parts:
            bore = derived.bore_on(pid, pin_id)
            onto.append(f"{pid} onto it (bore {_describe(bore.kind, bore.a, bore.b)} mm, "
                        f"{_clearance(pin.section, bore, pin_id, pid)}{_swept(derived, pid, pin_id)})")
        where = (f"at ({_mm(pin.position[0])}, {_mm(pin.position[1])})" if pin.axis in ("+z", "-z") else
                 "end at ({}, {}, {})".format(*map(_mm, pin_entry(derived, pin))))  # standing out of a side
        lines.append(f"pin {pin_id} of {pin.owner} {where} mm, "
                     f"entered along {opposite(pin.axis)}: {_describe(pin.section.kind, pin.section.a, pin.section.b)}"
                     f" mm; {'; '.join(onto) or 'empty'}")
    for pocket in derived.pockets:
        lines.append(f"pocket at ({_mm(pocket.position[0])}, {_mm(pocket.position[1])}) mm, "
                     f"{_mm(pocket.hole.a)} x {_mm(pocket.hole.b)} mm{_around(len(pocket.hole.inner))}, depth "
                     f"{_mm(pocket.depth)} mm: " + ("empty around its islands" if len(pocket.hole.inner) else
                                                    "a polygon with no rotational symmetry about its centre")
                     + ", no hole")
    if not (derived.hole_of or any(fit.part for fit in derived.part_holes.values())
            or any(pin.parts for pin in derived.pins.values())):
        found = ("no part in a hole or on a pin: sizes.lp names no part" if derived.holes or derived.part_holes
                 or derived.pins else "no hole and no pin found: sizes.lp names no part and no hole")
        lines.append(f"{found}, nothing to learn; `plan` and `session` place every part without a hole, in the "
                     "order of geometric_precedence.lp")
    lines.append("disassembly stages: " + " | ".join(" ".join(stage) for stage in derived.stages))
    for pid, by_direction in sorted(derived.located.items()):
        lines.append(f"part {pid} moved {_mm(derived.reach)} mm: " + "; ".join(
            f"{name} {' '.join(sorted(found)) or 'free'}" for name, found in by_direction.items())
            + f" (its ways in: along {', '.join(opposite(way) for way in derived.ways(pid))}"
            + (f"; not counted, they go in after it: {' '.join(sorted(after))})" if (after := {
                p for found in by_direction.values() for p in found} & derived.later.get(pid, set())) else ")"))
    for locator, pid in sorted(derived.dropped):
        lines.append(f"locating pair {locator}->{pid} dropped: the blocking needs {pid} before {locator}")
    lines += derived.notes()
    lines.append("geometric precedence (A before B): " + (" ".join(
        f"{a}->{b} ({reason})" for (a, b), reason in sorted(derived.reasons.items())) or "none"))
    return lines


def mapped_report(mapped: Mapped) -> list[str]:
    """The lines ``import`` prints about the covers and heads it found and the parts placed by hand."""
    lines = []
    for cid, cover in sorted(mapped.covers.items()):
        x0, y0, x1, y1 = cover.outline
        socket = "" if cover.socket is None else (f", socket {_mm(cover.socket[2])} mm {_mm(cover.socket[3])} deep at "
                                                  f"({_mm(cover.socket[0])}, {_mm(cover.socket[1])}) mm")
        lines.append(f"cover {cid} over {' '.join(cover.over)} on {' '.join(cover.on)}: {_mm(x1 - x0)} x "
                     f"{_mm(y1 - y0)} x {_mm(cover.thickness)} mm, {_mm(cover.bottom)} mm above the plate top, "
                     f"openings {_mm(cover.clearance)} mm over their holes{socket}; grip ({_mm(cover.grip[0])}, "
                     f"{_mm(cover.grip[1])}) mm, skill {cover.skill}; "
                     + ("the cell's cover" if cover.primitive else "no cell's cover: its own mesh"))
    for hid, head in sorted(mapped.heads.items()):
        section = head.section
        lines.append(f"head {hid} into {head.into}: {_describe(section.kind, section.a, section.b)} x "
                     f"{_mm(head.length)} mm, skill {head.skill}; "
                     + ("a cylinder or box" if head.primitive else "no cylinder or box: its own mesh"))
    for pid, reason in sorted(mapped.manual.items()):
        lines.append(f"manual {pid}: the cell has no operation for it, a plan's step places it by hand ({reason})")
    return lines



def load_source(source: Path, units: str, max_triangles: int = MAX_TRIANGLES, leave: LeaveOut = LeaveOut(),
                one: OnePart = OnePart(), joined: dict[str, int] | None = None) -> tuple[list[CadPart], list[str]]:
    """The parts of a mesh folder or a STEP file (``units`` applies to meshes only), of at
    most ``max_triangles`` together, the STEP sub-assemblies ``one`` names each one part
    (their ids and solids added to ``joined``), but those ``leave`` leaves out, and the ids
    of these (sorted; ExecutorError naming its setting when a name matches none, or when
    ``one`` names any for a mesh folder)."""
    dropped: list[str] = []
    keep = functools.partial(leave.kept, dropped=dropped) if leave.names else None
    whole = functools.partial(one.chosen, joined={} if joined is None else joined) if one.names else None
    if source.is_dir():
        if whole is not None:
            raise ExecutorError(f"{one.setting}: {source} is a folder of meshes, each file one part already "
                                "(expected a STEP file, whose sub-assemblies it names)")
        return load_meshes(source, units, max_triangles, keep), dropped
    if source.suffix.lower() in STEP_SUFFIXES and source.is_file():
        return load_step(source, max_triangles, keep, whole), dropped
    raise ExecutorError(f"{source}: expected a folder of *.stl/*.obj meshes or a STEP file (*.step, *.stp)")


@dataclass(frozen=True)
class Imported:
    """What :func:`run_import` found: the ``derived`` geometry, the ``mapped`` covers and
    heads, what was ``assumed``, ``why`` there is no geometry.toml (None: there is), the
    files ``written``, the ``seconds`` taken, the ``offset`` (x, y, z) [m] by which every
    part was moved into the cell (:func:`placement`) after it was turned ``turn`` [deg] about z
    (:func:`executor.cad.parts.quarter_turned`; a point p of the CAD, its up turned up, is at
    turn(p) + offset in the cell), and the parts the cell holds on its suction cup, with why
    (:func:`executor.cad.operations.tools.tool_of`)."""

    derived: Derived
    mapped: Mapped
    assumed: list[str]
    why: str | None
    written: list[Path]
    seconds: float
    offset: tuple[float, float, float]
    suction: dict[str, str]
    turn: int = 0


@dataclass(frozen=True)
class ImportOptions:
    """The command line's choices of an import: ``reach`` [m], the locating rule's (0:
    off); ``max_triangles``, the bound on the product's triangles; ``replace``: also write
    over a product another import or a person wrote (:func:`executor.cad.write.manifest.claim_folder`);
    ``place`` [m]: where the base's centre goes in the cell (and the product's lowest point's height), over the config's
    (:func:`placement`); ``leave_out``: the parts to leave out, over the config's (None: the config's);
    ``one_part``: the STEP sub-assemblies each imported as one part, over the config's (None: the config's);
    ``turn`` [deg]: the product's turn about z, over the config's (None:
    the config's, else chosen, :func:`_chosen_pose`); ``up``: the CAD's axis pointing up, over the config's
    (:func:`executor.cad.parts.turned`; None: the config's, else +z and :func:`drawn_up` checked)."""

    reach: float = LOCATING_REACH
    max_triangles: int = MAX_TRIANGLES
    replace: bool = False
    place: Place | None = None
    up: str | None = None
    turn: int | None = None
    leave_out: tuple[str, ...] | None = None
    one_part: tuple[str, ...] | None = None


def run_import(source: Path, out: Path, units: str, config: Path | None,
               options: ImportOptions = ImportOptions()) -> Imported:
    """Read, turn the CAD's up to +z, check, claim ``out``, turn and move the parts into
    the cell (the pose :func:`_chosen_pose` chooses where the user sets none), derive, map
    the covers and heads, and write, as ``options`` say (:class:`ImportOptions`);
    ExecutorError naming ``source`` when no up is set and the product looks drawn with
    another (:func:`drawn_up`), before anything is written."""
    started = time.perf_counter()
    data = _settings_file(config)
    up = options.up or _up_setting(config, data.get("up"))
    seconds = _budget_setting(config, data.get("pieces_cpu_s"))
    place = options.place or _place_setting(config, data.get("place"))
    turn = options.turn if options.turn is not None else _turn_setting(config, data.get("turn"))
    leave = (LeaveOut(options.leave_out, base=data.get("base")) if options.leave_out is not None
             else LeaveOut(_names_setting(config, "leave_out", data.get("leave_out")), f"{config}: leave_out",
                           f"leave_out in {config}", data.get("base")))
    one = (OnePart(options.one_part) if options.one_part is not None
           else OnePart(_names_setting(config, "one_part", data.get("one_part"),
                                       "sub-assembly ids or patterns ([\"deep_groove_ball_bearing*\"])"),
                        f"{config}: one_part", f"one_part in {config}"))
    joined: dict[str, int] = {}
    read, dropped = load_source(source, units, options.max_triangles, leave, one, joined)
    parts = turned(read, up or "+z")
    check_solids(parts, units)
    with pieces_budget(seconds):
        # the overlap check runs beside the derivation where the sweeps would take two cores
        with overlaps_checked(parts, processes(p.mesh for p in parts) > 1) as start:
            found = _derived(parts, (source, out), (config, data, up), options, start, (turn or 0, place, "place"))
            # the up checked on the CAD's own axes (or as the user turned it), before any pose is chosen
            doubt = None if up is not None else drawn_up(found.derived)
            if doubt is not None:
                turned_by = f" (read turned {turn} deg about z as set: the axes named are the turned ones)" \
                    if turn else ""
                raise ExecutorError(f"{source}: {doubt}{turned_by}")
            found = _chosen_pose(parts, (source, out), (config, data, up), options, found, (turn, place))
        settings = replace(found.settings, left_out=(leave.label, tuple(dropped)))
        written, why, mapped, cell = write_folder(found.derived, found.cell, found.mapped, settings, source.stem,
                                                  out, found.removable)
    assumed, derived = found.assumed, found.derived
    assumed.append(budget_assumption(seconds))
    assumed[found.near:found.near] = near_miss_assumption(derived, mesh_pieces(out, written))
    # after the up and the placement
    assumed[2:2] = [*one.assumption(joined, {part.id for part in read}), *leave.assumption(dropped),
                    *coarse_assumption(parts, options.max_triangles)]
    tools = {pid: tool_of(cell, fit) for pid, fit in sorted(cell.hole_of.items())}
    suction = {pid: reason for pid, (tool, reason) in tools.items() if tool == "suction"}
    return Imported(derived, mapped, assumed, why, written, time.perf_counter() - started, found.settings.moved,
                    suction, found.settings.turn)


@dataclass(frozen=True)
class _Found:
    """What :func:`run_import` finds before it writes (:func:`_derived`)."""

    removable: set[str]
    settings: Settings
    derived: Derived
    cell: Derived
    assumed: list[str]
    mapped: Mapped
    near: int


def _chosen_pose(parts: list[CadPart], paths: tuple[Path, Path], config: tuple[Path | None, dict, str | None],
                 options: ImportOptions, found: _Found, given: tuple[int | None, Place | None]) -> _Found:
    """``found`` (the product as drawn, or in the turn and place the user ``given``) or,
    where the user leaves the turn or the place free, the product in the pose that makes
    the cell insert more parts: :func:`executor.cad.operations.arm.best_pose` over the
    reaches the cell's decisions rest on (:func:`reaches_asked`, evaluated for each pose
    on the features turned and moved: the derivation is not run again for each), the
    base's centre within :data:`REACH` of the arm's base; the product is derived again in
    that pose alone and taken where the cell places fewer parts by hand there, with the
    assumption that says so (the parts it now inserts, the settings that keep it as drawn)."""
    turn, place = given
    if turn is not None and place is not None:
        return found
    derived = found.derived
    bounds = derived.parts[derived.base].mesh.bounds
    centre = (float(bounds[0][0] + bounds[1][0]) / 2, float(bounds[0][1] + bounds[1][1]) / 2)
    inserted, reaches = reaches_asked(derived)
    pose = best_pose(reaches, inserted, centre, (None if turn is None else 0, None if place is None else centre),
                     lambda xy: REACH[0] <= math.hypot(*xy) <= REACH[1] and max(map(abs, xy)) <= PLACE_BOUND)
    if pose.turn == 0 and pose.place == centre:
        return found
    now = (turn or 0) + pose.turn
    where = place if place is not None else pose.place
    again = _derived(parts, paths, config, options, lambda: None, (now, where, "chosen for the arm's reach: below"))
    more, gained = sorted(set(found.mapped.manual) - set(again.mapped.manual)), len(found.mapped.manual) - len(
        again.mapped.manual)
    if gained <= 0:
        return found
    drawn = ", ".join(f"{v:g}" for v in (place or (round(centre[0], 4), round(centre[1], 4))))
    keep = " and ".join(([] if turn is not None else ["turn = 0"])
                        + ([] if place is not None else [f"place = [{drawn}]"]))
    again.assumed.insert(2, (f"the product turned {now} deg about z" if now else "the product as drawn")
                         + f" and its base's centre placed at ({_mm(pose.place[0])}, {_mm(pose.place[1])}) mm so the "
                         f"arm reaches {gained} more insertion(s) ({' '.join(more)}; the cell inserts "
                         f"{len(derived.parts) - 1 - len(again.mapped.manual)} of {len(derived.parts) - 1} moving "
                         f"parts); set {keep} to keep it as drawn")
    return replace(again, near=again.near + 1)


def _derived(parts: list[CadPart], paths: tuple[Path, Path], config: tuple[Path | None, dict, str | None],
             options: ImportOptions, beside: Callable[[], None], pose: tuple[int, Place | None, str]) -> _Found:
    """What :func:`run_import` finds before it writes (``paths``: the source and ``out``;
    ``config``: the settings file, its TOML and the up set, None: none; ``pose``: the turn
    [deg] about z, the place (None: :func:`placement`'s default) and why it is there;
    ExecutorError naming the source where no up is set and the base looks drawn tilted,
    :func:`drawn_tilted`): the files of ``out`` it may remove,
    the settings with every tray, the offset into the cell and the turn, the derived
    product and the product as the cell inserts
    it (:func:`executor.cad.operations.view.cell_view`), the assumptions, the mapped product
    and where in the assumptions the near misses go (they are known once the meshes'
    pieces are written); ``beside``: :func:`executor.cad.derive.derive`'s."""
    reach, (turn, place, chosen) = options.reach, pose
    source, out = paths
    removable = claim_folder(out, [p.id for p in parts], options.replace)
    path, data, up = config
    settings, fixed, assumed = _config(path, data, parts, up or "+z")
    base = next(p.mesh for p in parts if p.id == settings.base)
    tilt = None if up is not None else drawn_tilted(base, settings.base)
    if tilt is not None:
        raise ExecutorError(f"{source}: {tilt}")
    parts = quarter_turned(parts, turn)
    offset, where = placement(parts, settings.base, place, chosen)
    parts = translated(parts, offset)
    settings = replace(settings, moved=offset, turn=turn)
    assumed[:0] = [_up_assumption(up), where]
    assumed.append(f"the locating rule: a part that one other part alone keeps from moving {_mm(reach)} mm sideways "
                   "goes after it (--locating-reach 0: off)" if reach > 0 else "no locating rule")
    with slices_kept():  # the parts' meshes stay as they are until written
        derived = derive(parts, settings.base, fixed, reach, beside)
        assumed += [*derived.assumptions(), *nominal_assumption(derived)]
        near = len(assumed)  # the near misses' place: they are known once the pieces of the meshes are
        assumed += overlap_assumption(derived)
        mapped, laid, cell = map_product(derived, settings)
        assumed += widened_fits_assumption(cell)
    assumed += [finger_assumption(), *map(finger_order_text, finger_orders(cell))]
    assumed += [mapped.tool] if mapped.tool else []
    missing = sorted(set(laid.trays) - set(settings.trays))
    if missing:
        assumed.append(f"trays of {', '.join(missing)} laid out by their footprints, "
                       f"{_mm(TRAY_GAP)} mm apart and clear of the product, in rows from "
                       f"({_mm(TRAY_START[0])}, {_mm(TRAY_START[1])}) mm (set [parts.<id>] tray)")
    return _Found(removable, laid, derived, cell, assumed, mapped, near)


def main(argv: list[str]) -> int:
    parser = ArgumentParser(prog="import", description="A product from its CAD (STEP, or STL/OBJ meshes in the "
                            "assembled pose) as an assembly folder: assembly.toml, sizes.lp, "
                            "geometric_precedence.lp, geometry.toml where the product is made of primitives.",
                            formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("source", type=Path, metavar="SOURCE", help="a STEP file or a folder of *.stl/*.obj meshes")
    parser.add_argument("--out", type=nonempty_path, required=True, metavar="DIR", help="the assembly folder to write")
    parser.add_argument("--units", choices=list(UNITS), default="mm",
                        help="length unit of mesh files (default mm; a STEP file states its own)")
    parser.add_argument("--config", type=Path, metavar="FILE",
                        help="TOML: base part, up, trays, names, fixed_to, place, turn, leave_out, one_part")
    parser.add_argument("--up", type=up_axis, metavar="AXIS",
                        help=f"the CAD's axis pointing up, {', '.join(UP_AXES)} (over the config's up; default +z, "
                             "and a product whose base looks drawn with another axis up is refused); a negative "
                             "one as --up=-y")
    parser.add_argument("--place", type=place_pair, metavar="X,Y[,Z]",
                        help="where the base's centre stands in the cell [m] (over the config's place; default: "
                             f"where the CAD has it, or ({WORK_POSITION[0]:g}, {WORK_POSITION[1]:g}) when that is "
                             "out of the arm's reach); Z: the height of the product's lowest point (default 0, "
                             "the cell's floor)")
    parser.add_argument("--turn", type=turn_degrees, metavar="DEG",
                        help="the product turned about z on the table, 0, 90, 180 or 270 [deg] (over the config's "
                             "turn; default: as drawn, or a turn and place where the arm reaches more insertions)")
    parser.add_argument("--leave-out", type=part_names, metavar="NAME[,NAME...]",
                        help="parts of the CAD to leave out, by id or fnmatch pattern on ids (screw_*), over the "
                             "config's leave_out; dropped as read, before the triangle bound and every check")
    parser.add_argument("--one-part", type=part_names, metavar="NAME[,NAME...]",
                        help="STEP sub-assemblies each imported as one part (a bearing, a motor), by id or fnmatch "
                             "pattern on ids, over the config's one_part; its solids' meshes joined into one")
    parser.add_argument("--locating-reach", type=number_in(float, 0.0, MAX_REACH), default=LOCATING_REACH,
                        metavar="R", help="the locating rule: a part that one other part alone keeps from moving "
                                          f"R [m] sideways goes after it (default {LOCATING_REACH:g}; 0: off)")
    parser.add_argument("--max-triangles", type=int_in(1), default=MAX_TRIANGLES, metavar="N",
                        help=f"the most triangles the parts may have together (default {MAX_TRIANGLES}: about 1.9 kB "
                             "of memory each)")
    parser.add_argument("--replace", action="store_true",
                        help=f"replace the product in DIR even where import did not write it (DIR/{MANIFEST} lists "
                             "the files import wrote; without --replace any other file it would write is refused)")
    args = parser.parse_args(argv)
    if not args.source.exists():
        raise ExecutorError(f"{args.source}: no such file or folder (expected a STEP file or a mesh folder)")
    done = run_import(args.source, args.out, args.units, args.config,
                      ImportOptions(args.locating_reach, args.max_triangles, args.replace, args.place, args.up,
                                    args.turn, args.leave_out, args.one_part))
    derived, why = done.derived, done.why
    units = "the STEP file's" if args.source.is_file() else args.units
    print(f"assumes: units {units}; " + "; ".join(done.assumed))
    for line in report(derived) + mapped_report(done.mapped):
        print(line)
    for pid, reason in done.suction.items():
        print(f"tool {pid}: the suction cup on its top, not the fingers ({reason})")
    meshes = sorted(p.name.removesuffix(".obj") for p in done.written
                    if p.parent.name == MESH_FOLDER and not p.name.endswith(".convex.obj"))
    print(f"wrote {args.out}: assembly.toml, sizes.lp, nominal_sizes.lp, geometric_precedence.lp"
          + (", geometry.toml" if why is None else f" (no geometry.toml: {why})")
          + (f"; simulated from their own meshes ({MESH_FOLDER}/): {', '.join(meshes)}" if meshes else "")
          + f"; the files it wrote listed in {MANIFEST}")
    print(f"{len(derived.parts)} parts, {derived.queries} collision queries, {done.seconds:.2f} s")
    return 0
