"""``geometry.toml`` (:func:`geometry_text`): the simulated cell's product, pegs standing in
holes entered along +z with a round, square or rect section or the prism of a polygon (built
by the cell from its outline), parts with a bore onto pins of the base (a part on several
pins down its first, the only one of them written:
:func:`executor.cad.operations.pins.onto_pin`), covers and heads (:mod:`executor.cad.covers`),
every other part placed by hand (``[manual.<id>]``,
:func:`executor.cad.operations.view.cell_view`); the plate at the entry height and depth most
holes share, a hole at another one with its own ``top_z`` and ``depth``; the plate, pegs,
covers and heads as primitives where they are ones, else as their own meshes with convex
pieces, a part placed by hand as its own mesh (static, no pieces), a base without such
holes as its own mesh; a hole or bore with nominal zero-clearance fits at its nominal
diameter, naming them. Lengths in metres."""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence

import numpy as np

from bridge.inputs import shorten
from bridge.product import Mesh
from bridge.product.nominal import NOMINAL_FIT_ROOM
from executor.cad.covers import Mapped
from executor.cad.derive import Derived, HoleFit
from executor.cad.operations.fingers import GRIPPER, finger_grip
from executor.cad.operations.frames import along_axis, entry_point, pin_entry, pin_level, upright
from executor.cad.operations.plate import LEVEL, MAX_PLATE_DEPTH, plate_level
from executor.cad.operations.rooms import section_pairs
from executor.cad.operations.screwed import pressed
from executor.cad.operations.tools import tool_of
from executor.cad.sections import Shape2D, section
from executor.cad.sections import rounded as _q
from executor.cad.sweep import opposite
from executor.cad.write.assembly import Settings
from executor.cad.write.bosses import own_tiles, plate_tile
from executor.cad.write.depths import down_depth, sideways_depth
from executor.cad.write.meshes import manual_origin
from executor.cad.write.near_misses import near_misses, pin_near_misses
from executor.cad.write.widened import nominal_section, widened_fits, zero_clearance_parts

DENSITY = 2700.0
"""Mass of a peg in the simulated cell: its volume times this [kg/m³] (aluminium)."""


MIN_CHAMFER = 1e-4
"""The simulated plate's chamfer when the CAD has a smaller one or none [m] (the cell needs one)."""
MAX_REASON = 200
"""The longest ``reason`` of a ``[manual.<id>]`` table (characters)."""


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


def _tool_lines(derived: Derived, fit: HoleFit) -> list[str]:
    """A peg's ``[part_shapes.*]`` lines of what holds it (:func:`executor.cad.operations.tools.tool_of`):
    ``tool = "suction"``, or the fingers' ``grasp_depth`` where they hold it less deep than
    :data:`executor.cad.operations.fingers.GRIPPER`'s
    (:func:`executor.cad.operations.fingers.finger_grip`); none otherwise."""
    assert fit.part is not None
    tool, why = tool_of(derived, fit)
    if tool == "suction":
        return ['tool = "suction"']
    grip = finger_grip(derived, fit.part, fit)[0]
    return [f"grasp_depth = {_q(grip)}  # {why}"] if 0 < grip < GRIPPER["grasp_depth"] else []


def _bore_grip_lines(derived: Derived, pid: str, length: float) -> list[str]:
    """A part with a bore's ``[part_shapes.*]`` line of the fingers' ``grasp_depth`` where
    they hold it less deep (:func:`executor.cad.operations.fingers.finger_grip`) than the cell
    holds it (:data:`executor.cad.operations.fingers.GRIPPER`'s grasp depth, at most half
    its ``length`` [m]); none otherwise."""
    grip, why = finger_grip(derived, pid, derived.pin_of(pid))
    return [f"grasp_depth = {_q(grip)}  # held {1e3 * grip:g} mm deep by the fingers{why}"] if grip < min(
        GRIPPER["grasp_depth"], length / 2) else []


def _mesh_entry(mesh: Mesh) -> str:
    convex = "" if mesh.convex is None else f', convex = "{mesh.convex}"'
    return f'mesh = {{ file = "{mesh.file}", sha256 = "{mesh.sha256}"{convex} }}'


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
    cell places by hand where it puts the part onto them: :func:`executor.cad.operations.view.cell_view`),
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
    tile = plate_tile([fit for fit in fits if fit.axis == "+z"])  # the plate's bosses: none around a sideways hole
    own = own_tiles(derived, tile, chamfer)
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
        lines += _near_miss_line(missed, hid)
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
        lines += _near_miss_line(missed, pin_id)
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
                  *_bore_grip_lines(derived, pid, length), _mesh_entry(meshes[pid]), ""]
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


def _near_miss_line(missed: Mapping[tuple[str, str], str], fid: str) -> list[str]:
    """A feature's ``near_miss`` line naming the parts of the pairs of ``missed`` on or in
    feature ``fid`` (:func:`executor.cad.write.near_misses.near_misses`,
    :func:`executor.cad.write.near_misses.pin_near_misses`) with their reasons; none without one."""
    close = [(pid, reason) for (pid, f), reason in missed.items() if f == fid]
    return [f"near_miss = {json.dumps([pid for pid, _ in close])}  # no experiment: "
            + "; ".join(reason for _, reason in close)] if close else []


def _zero_clearance_line(parts: list[str]) -> list[str]:
    """A feature's ``zero_clearance`` line naming ``parts`` (none without one)."""
    return [f"zero_clearance = {json.dumps(parts)}  # nominal zero-clearance fits: room 0"] if parts else []


def _numbers(values: tuple[float, ...]) -> str:
    """A TOML list of lengths [m] to 0.1 µm."""
    return f"[{', '.join(str(_q(v)) for v in values)}]"
