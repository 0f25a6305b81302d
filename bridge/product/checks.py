"""The checks of a product description that one struct cannot make (:mod:`bridge.product`):
references between tables, a rect's ``[a, b]``, a chamfer inside its boss, every hole
deeper than its chamfer (a hole at its own level with its bottom above the floor), bosses
that do not overlap, a grasp shorter than the part, the shapes of ``assembly.toml``
against the kinds of ``geometry.toml``, the base, covers and heads against the parts, a
part's mesh against its file (by SHA-256) and its convex pieces against that mesh. Every
failure is one line ``<file>: [<table>] <key>: expected ..., got ...`` (a BridgeError)."""

from __future__ import annotations

import hashlib
import math
from collections.abc import Mapping
from pathlib import Path

import shapely

from bridge import BridgeError
from bridge.inputs import read_bytes, shorten
from bridge.product.kinds import section_label
from bridge.product.nominal import models_nominal_fits
from bridge.product.tables import (
    CONVEX_HEADER,
    TOUCH_TOLERANCE,
    AssemblyFile,
    GeometryFile,
    Gripper,
    HoleShape,
    Mesh,
    PartShape,
    Plate,
)

MAX_MESH_BYTES = 256 * 1024 * 1024
"""The largest mesh file read [bytes] (256 MiB: a base tessellated to 1 µm)."""


def where(table: str, key: str) -> str:
    """``[table] key``, ``[table]`` or ``key``."""
    return " ".join(([f"[{table}]"] if table else []) + ([key] if key else []))


def fail(path: Path, table: str, key: str, expected: str, value: object) -> BridgeError:
    """``<path>: [<table>] <key>: expected <expected>, got <value>`` (the value shortened)."""
    return BridgeError(f"{path}: {where(table, key)}: expected {expected}, got {shorten(repr(value))}")

# ---- the checks between tables ----

def _sides(size: float | list[float]) -> tuple[float, float]:
    """(a, b) [m] of a decoded section size: a rect's ``[a, b]``, else the size twice."""
    return (size[0], size[1]) if isinstance(size, list) else (size, size)


def check_assembly(path: Path, layout: AssemblyFile, kinds: Mapping[str, str]) -> None:
    """A ``section`` only for a rect part (``kinds``: part id -> kind, from every statement
    of the product, :func:`bridge.product.kinds.part_kinds`); no id both a part and a hole;
    a hole's ``on_line`` (a hole on no other's line) and ``owner`` (a part) given together."""
    for pid, part in layout.parts.items():
        kind = kinds.get(pid)
        if part.section is not None and kind != "rect":
            raise BridgeError(f"{path}: [parts.{pid}] section: only a part of shape \"rect\" has one "
                              f"(a {kind or 'part without a shape'} is its own section)")
    clash = set(layout.parts) & set(layout.holes)
    if clash:
        raise BridgeError(f"{path}: ids used for both a part and a hole: {sorted(clash)}")
    for hid, hole in layout.holes.items():
        if (hole.on_line is None) != (hole.owner is None):
            key = "owner" if hole.owner is None else "on_line"
            raise fail(path, f"holes.{hid}", key, f"{key} beside {'on_line' if key == 'owner' else 'owner'} "
                       "(a hole on another's line and the part it is in, or neither)", None)
        if hole.on_line is not None and (hole.on_line not in layout.holes or layout.holes[hole.on_line].on_line):
            raise fail(path, f"holes.{hid}", "on_line", "a hole of [holes.*] on no other's line", hole.on_line)
        if hole.owner is not None and hole.owner not in layout.parts:
            raise fail(path, f"holes.{hid}", "owner", "a part of [parts.*]", hole.owner)


def _members(path: Path, group: str, tables: Mapping[str, HoleShape] | Mapping[str, PartShape]) -> dict[str, str]:
    """Member id -> shape name; each id in one shape table once."""
    owner: dict[str, str] = {}
    for name, table in tables.items():
        members = table.holes if isinstance(table, HoleShape) else table.parts
        key = "holes" if isinstance(table, HoleShape) else "parts"
        for member in members:
            if member in owner:
                raise fail(path, f"{group}.{name}", key, f"ids not already in [{group}.{owner[member]}]", member)
            owner[member] = name
    return owner


def _check_sections(path: Path, group: str, tables: Mapping[str, HoleShape] | Mapping[str, PartShape]) -> None:
    """A rect's size is ``[a, b]`` with a >= b, a polygon's ``[a, b]`` the extents of its
    ``outline`` (a simple polygon; no other kind has one), any other kind's one number."""
    for name, table in tables.items():
        listed, size = table.kind in ("rect", "polygon"), table.size
        if listed != isinstance(size, list):
            expected = ("[a, b] in m with a >= b > 0 (the long side a along x) for a rect" if table.kind == "rect"
                        else "[a, b] in m (the outline's extents along x and y) for a polygon"
                        if table.kind == "polygon"
                        else f"one number (the {'diameter' if table.kind == 'round' else 'side'}) for a {table.kind}")
            raise fail(path, f"{group}.{name}", "size", expected, size)
        if table.kind == "rect" and isinstance(size, list) and size[0] < size[1]:
            raise fail(path, f"{group}.{name}", "size", "[a, b] with a >= b (the long side a along x)", size)
        if (table.kind == "polygon") != (table.outline is not None):
            raise fail(path, f"{group}.{name}", "outline", "an outline [[x, y], ...] for a polygon, none for a "
                       f"{table.kind}" if table.kind != "polygon" else "an outline [[x, y], ...] in m (a polygon's "
                       "section)", table.outline)
        if table.outline is not None and isinstance(size, list):
            _check_outline(path, f"{group}.{name}", table.outline, size)
        if table.corner and (table.kind not in ("square", "rect") or 2 * table.corner > min(_sides(size))):
            raise fail(path, f"{group}.{name}", "corner", "a corner radius of a square or rect at most half its "
                       f"short side ({min(_sides(size)) / 2:g} m)" if table.kind in ("square", "rect")
                       else f"no corner radius for a {table.kind}", table.corner)


OUTLINE_EXTENT_TOLERANCE = 1e-6
"""A polygon's ``size`` is its outline's extents within this [m]."""


def _check_outline(path: Path, table: str, outline: list[list[float]], size: list[float]) -> None:
    """A polygon's ``outline`` is a simple polygon of positive area whose extents along x
    and y are its ``size``."""
    ring = shapely.Polygon(outline)
    if not ring.is_valid or ring.area <= 0:
        raise fail(path, table, "outline", "a simple polygon (no crossing edges, positive area)",
                   f"{shapely.is_valid_reason(ring)} in {outline}")
    x0, y0, x1, y1 = ring.bounds
    if abs(x1 - x0 - size[0]) > OUTLINE_EXTENT_TOLERANCE or abs(y1 - y0 - size[1]) > OUTLINE_EXTENT_TOLERANCE:
        raise fail(path, table, "size", f"the outline's extents [{x1 - x0:.7g}, {y1 - y0:.7g}] m along x and y",
                   size)


def _check_polygons_simulated(path: Path, geo: GeometryFile) -> None:
    """A hole with a ``corner`` radius is in the ``[base]``'s mesh (the plate's bosses are
    round, square, sharp rect or polygon; a polygon peg without a mesh is the prism of its
    outline)."""
    for name, hole_shape in geo.hole_shapes.items():
        if hole_shape.corner and (geo.base is None or geo.base.mesh is None):
            raise BridgeError(f"{path}: [hole_shapes.{name}] corner: a hole with rounded corners needs a [base] with "
                              "its own mesh (the plate's bosses are round, square, sharp rect or polygon), got none")


def _check_sideways(path: Path, geo: GeometryFile) -> None:
    """A hole or pin entered sideways (``axis`` other than ``-z``) is in the ``[base]``'s
    own mesh and states its entry's ``top_z`` (a pin's: its free end's)."""
    for name, shape in geo.hole_shapes.items():
        if shape.axis == "-z":
            continue
        table = f"hole_shapes.{name}"
        if geo.base is None or geo.base.mesh is None:
            raise BridgeError(f"{path}: [{table}] axis: a hole entered along {shape.axis} needs a [base] with its own "
                              "mesh (the plate's bosses are entered from above), got none")
        if shape.top_z is None:
            raise BridgeError(f"{path}: [{table}] top_z: expected the height of the entry's centre [m] of a hole "
                              f"entered along {shape.axis}, got nothing")


def _check_pins(path: Path, geo: GeometryFile, holes: Mapping[str, str]) -> None:
    """Pins are in the ``[base]``'s own mesh and state their ``top_z`` and ``depth``; a part
    with a ``bore`` is taught on a pin and fits one at zero clearance, a peg a hole; a pin's
    ``owner`` is a part placed by hand or a peg inserted down into its ``demo_hole``."""
    demo_shapes = {pid: geo.hole_shapes.get(holes.get(part_shape.demo_hole, ""))
                   for part_shape in geo.part_shapes.values() if not part_shape.bore for pid in part_shape.parts}
    inserted = {pid for pid, demo in demo_shapes.items() if demo is not None and not demo.pin and demo.axis == "-z"}
    for name, shape in geo.hole_shapes.items():
        if not shape.pin:
            continue
        if geo.base is None or geo.base.mesh is None:
            raise BridgeError(f"{path}: [hole_shapes.{name}] pin: a pin needs a [base] with its own mesh (the pin is "
                              "part of it), got none")
        for key in ("top_z", "depth"):
            if getattr(shape, key) is None:
                raise BridgeError(f"{path}: [hole_shapes.{name}] {key}: expected the pin's "
                                  + ("top [m]" if key == "top_z" else "height above where a part rests on it [m]")
                                  + ", got nothing (a pin states both)")
        if shape.owner is not None and shape.owner not in geo.manual and shape.owner not in inserted:
            raise fail(path, f"hole_shapes.{name}", "owner", "a part placed by hand ([manual.<id>]) or a peg of "
                       "[part_shapes.*] whose demo_hole is a hole entered down, whose pin it is", shape.owner)
        if shape.owner is not None and shape.axis != "-z":
            raise fail(path, f"hole_shapes.{name}", "axis", "-z for a pin of another part than the base (it stands up)",
                       shape.axis)
    for name, shape in geo.hole_shapes.items():
        if shape.owner is not None and not shape.pin:
            raise fail(path, f"hole_shapes.{name}", "owner", "no owner: only a pin has one", shape.owner)
    for name, part_shape in geo.part_shapes.items():
        for pid in part_shape.pins_of or []:
            if pid not in geo.manual or not part_shape.bore:
                raise fail(path, f"part_shapes.{name}", "pins_of", "parts placed by hand ([manual.<id>]) whose "
                           "pins parts with a bore go onto", pid)
    bores = {pid: shape.bore for shape in geo.part_shapes.values() for pid in shape.parts}
    round_bores = {pid: shape.kind == "round" for shape in geo.part_shapes.values() for pid in shape.parts}
    for name, shape in geo.hole_shapes.items():
        for pid in shape.zero_clearance or []:
            if bores.get(pid) != shape.pin:
                raise fail(path, f"hole_shapes.{name}", "zero_clearance", "parts with a bore of [part_shapes.*] "
                           "for a pin, pegs of [part_shapes.*] for a hole", pid)
        for pid in shape.widened or []:
            if not (shape.pin == bores.get(pid) and shape.kind == "round" and round_bores.get(pid)
                    and (shape.pin or not models_nominal_fits(geo))):
                raise fail(path, f"hole_shapes.{name}", "widened", "parts with a round bore of [part_shapes.*] "
                           "on a round pin, round pegs in a round hole of a [base] with its own mesh", pid)
        for pid in shape.near_miss or []:
            if bores.get(pid) != shape.pin:
                raise fail(path, f"hole_shapes.{name}", "near_miss", "parts with a bore of [part_shapes.*] "
                           "for a pin, pegs of [part_shapes.*] for a hole", pid)
    for name, part_shape in geo.part_shapes.items():
        demo = geo.hole_shapes.get(holes.get(part_shape.demo_hole, ""))
        if demo is not None and demo.pin != part_shape.bore:
            raise fail(path, f"part_shapes.{name}", "demo_hole", "a pin for parts with a bore, a hole for pegs"
                       f" ({part_shape.demo_hole} is {'a pin' if demo.pin else 'a hole'})", part_shape.demo_hole)


def hole_level(plate: Plate, shape: HoleShape) -> tuple[float, float]:
    """(entry height, depth) [m] of the holes of ``shape``: its own ``top_z`` and
    ``depth``, else the plate's ``top_z`` and ``tile_thickness``."""
    return (plate.top_z if shape.top_z is None else shape.top_z,
            plate.tile_thickness if shape.depth is None else shape.depth)


def _check_levels(path: Path, plate: Plate, shapes: Mapping[str, HoleShape]) -> None:
    """The holes at the plate's level and each shape with its own are deeper than the
    entry chamfer; a shape's own level has its bottom above the floor (z = 0)."""
    if plate.chamfer >= plate.tile_thickness:
        raise fail(path, "plate", "chamfer", f"less than tile_thickness ({plate.tile_thickness:g} m)", plate.chamfer)
    for name, shape in shapes.items():
        top, depth = hole_level(plate, shape)
        table = f"hole_shapes.{name}"
        if shape.depth is not None and plate.chamfer >= depth:
            raise fail(path, table, "depth", f"more than the [plate] chamfer ({plate.chamfer:g} m)", depth)
        if shape.axis != "-z":  # its bottom is no height: the entry's top_z is checked with the sideways holes
            continue
        if depth < top or (shape.top_z is None and shape.depth is None):
            continue
        if shape.depth is not None:
            raise fail(path, table, "depth", f"less than the entry height ({top:g} m: the bottom above the floor)",
                       depth)
        raise fail(path, table, "top_z", f"more than the depth ({depth:g} m, the [plate] tile_thickness: the "
                   "bottom above the floor)", top)


def check_grasp(path: Path, geometry: GeometryFile, gripper: Gripper) -> None:
    """Every peg the fingers hold is longer than the part of it inside ``gripper``'s fingers
    (a part with a bore is held at most half its length deep, as a head; the suction cup
    holds a part by its top face)."""
    for name, table in geometry.part_shapes.items():
        if not table.bore and table.tool == "fingers" and gripper.grasp_depth >= table.length:
            raise fail(path, f"part_shapes.{name}", "length",
                       f"longer than [gripper] grasp_depth ({gripper.grasp_depth:g} m)", table.length)
        if table.grasp_depth is not None and table.tool != "fingers":
            raise fail(path, f"part_shapes.{name}", "grasp_depth", "none: a part on the suction cup is not held by "
                       "the fingers' depth", table.grasp_depth)


def check_geometry(path: Path, geo: GeometryFile, layout: AssemblyFile) -> None:
    """``geometry.toml`` (decoded) against itself and ``layout``: shape members, sections,
    chamfer, bosses, the product's grasp (with its own gripper), references, kinds, the
    base, covers and heads, the meshes."""
    plate = geo.plate
    holes = _members(path, "hole_shapes", geo.hole_shapes)
    pegs = _members(path, "part_shapes", geo.part_shapes)
    _check_sections(path, "hole_shapes", geo.hole_shapes)
    _check_sections(path, "part_shapes", geo.part_shapes)
    _check_polygons_simulated(path, geo)
    _check_levels(path, plate, geo.hole_shapes)
    _check_pins(path, geo, holes)
    _check_sideways(path, geo)
    for name, hole_shape in geo.hole_shapes.items():
        bossed = not hole_shape.pin and hole_shape.axis == "-z"  # a boss of the plate
        tile = plate.tile_size if hole_shape.tile is None else hole_shape.tile
        if bossed and max(_sides(hole_shape.size)) + 2 * plate.chamfer >= tile:
            raise fail(path, f"hole_shapes.{name}", "size", f"a hole and its chamfer inside the {tile:g} "
                       "m boss (size + 2 chamfer < tile or the plate's tile_size)", hole_shape.size)
    for name, part_shape in geo.part_shapes.items():
        if part_shape.demo_hole not in holes:
            raise fail(path, f"part_shapes.{name}", "demo_hole",
                       f"a hole of [hole_shapes.*] ({', '.join(sorted(holes))})", part_shape.demo_hole)
    if geo.gripper is not None:
        check_grasp(path, geo, geo.gripper)
    for hid, name in holes.items():
        entry = layout.holes.get(hid)
        if entry is None or entry.position is None:
            why = "has no position there" if entry is not None else "is not a hole there"
            raise fail(path, f"hole_shapes.{name}", "holes", f"holes of assembly.toml with a position ({hid} {why})",
                       hid)
    for pid in geo.extra_parts:
        if pid in layout.parts:
            raise fail(path, f"extra_parts.{pid}", "start", "a part that is not in assembly.toml (this one is)",
                       pid)
    starts = {pid for pid, part in layout.parts.items() if part.start is not None} | set(geo.extra_parts)
    for pid, name in pegs.items():
        if pid not in starts:
            raise fail(path, f"part_shapes.{name}", "parts", "parts of assembly.toml with a start, or of "
                       f"[extra_parts] ({pid} is neither)", pid)
    positions = {hid: layout.holes[hid].position for hid in holes}
    turned = {hid for hole_shape in geo.hole_shapes.values() if hole_shape.yaw for hid in hole_shape.holes}
    pins = {hid for hole_shape in geo.hole_shapes.values() if hole_shape.pin or hole_shape.axis != "-z"
            for hid in hole_shape.holes}  # no boss on the plate
    tiles = {hid: plate.tile_size if hole_shape.tile is None else hole_shape.tile
             for hole_shape in geo.hole_shapes.values() for hid in hole_shape.holes}
    _check_bosses(path, {h: (p[0], p[1], tiles[h]) for h, p in positions.items()
                         if p is not None and h not in pins}, turned)
    _check_kinds(path, geo, layout)
    _check_product(path, geo, layout, holes)
    meshes = [(f"part_shapes.{name}", shape.mesh, True) for name, shape in geo.part_shapes.items()]
    meshes += [(f"covers.{cid}", cover.mesh, True) for cid, cover in geo.covers.items()]
    meshes += [(f"heads.{hid}", head.mesh, True) for hid, head in geo.heads.items()]
    meshes += [(f"manual.{mid}", manual.mesh, False) for mid, manual in geo.manual.items()]
    meshes.append(("base", None if geo.base is None else geo.base.mesh, False))
    for table, mesh, moving in meshes:
        if mesh is not None:
            _check_mesh(path, table, mesh, moving)


def _check_mesh(path: Path, table: str, mesh: Mesh, moving: bool) -> None:
    """A part's ``mesh``: its ``file`` is there and has the stated ``sha256``; a moving
    part has ``convex`` pieces made from that file as it is (their header names its
    digest), the base and a part placed by hand none (static concave meshes)."""
    folder = path.parent
    try:
        data = read_bytes(folder / mesh.file, "mesh file (OBJ)", limit=MAX_MESH_BYTES)
    except BridgeError as exc:
        raise BridgeError(f"{path}: [{table}] mesh.file: {exc}") from None
    digest = hashlib.sha256(data).hexdigest()
    if digest != mesh.sha256:
        raise fail(path, table, "mesh.sha256", f"the SHA-256 of {mesh.file} ({digest}: the file changed since "
                   "geometry.toml was written; import the product again)", mesh.sha256)
    if not moving:
        if mesh.convex is not None:
            raise fail(path, table, "mesh.convex", "no convex pieces (the base and a part placed by hand are "
                       "simulated as their static concave meshes)", mesh.convex)
        _check_vertices(path, table, "mesh.file", folder / mesh.file, data,
                        MAX_BASE_REACH if table == "base" else MAX_PART_REACH)
        return
    if mesh.convex is None:
        raise BridgeError(f"{path}: [{table}] mesh.convex: expected the convex pieces of {mesh.file} (an .obj file "
                          "in the folder; a moving part collides as them), got nothing (a required key)")
    try:
        text = read_bytes(folder / mesh.convex, "convex pieces file (OBJ)", limit=MAX_MESH_BYTES)
    except BridgeError as exc:
        raise BridgeError(f"{path}: [{table}] mesh.convex: {exc}") from None
    first = text.split(b"\n", 1)[0].decode("utf-8", "replace").strip()
    expected = CONVEX_HEADER.format(file=mesh.file, sha256=digest)
    if first != expected:
        raise fail(path, table, "mesh.convex", f"pieces made from {mesh.file} as it is (first line of "
                   f"{mesh.convex} {expected!r}; stale pieces: import the product again)", first)
    for key, name, content in (("mesh.file", mesh.file, data), ("mesh.convex", mesh.convex, text)):
        _check_vertices(path, table, key, folder / name, content, MAX_PART_REACH)


MAX_PART_REACH = 0.5
"""A part's mesh and convex pieces (moving, or placed by hand) lie within this of its
frame's origin on every axis [m]: a part the arm carries, not one metres away or the size
of a room (millimetres written as metres)."""

MAX_BASE_REACH = 2.0
"""The base's mesh lies within this of its frame's origin on every axis [m]: a plate or
table in the cell's workspace, not metres of millimetres."""


def _check_vertices(path: Path, table: str, key: str, obj: Path, data: bytes, reach: float) -> None:
    """Every vertex ``v x y z`` of the OBJ ``data`` (the file ``obj``) is three finite
    coordinates within ``reach`` [m]; BridgeError naming ``obj``'s line otherwise."""
    for number, line in enumerate(data.splitlines(), 1):
        if line[:1] != b"v" and not line[:1].isspace():
            continue  # its first word is no "v" (a face, a comment): not split
        words = line.split()
        if words[:1] != [b"v"]:
            continue
        try:
            x, y, z = map(float, words[1:4])
        except ValueError:  # not three numbers
            x = y = z = math.nan
        if not (-reach <= x <= reach and -reach <= y <= reach and -reach <= z <= reach):  # NaN compares False
            raise BridgeError(f"{path}: [{table}] {key}: {obj}:{number}: expected a vertex 'v x y z' of finite "
                              f"coordinates within [-{reach:g}, {reach:g}] m of its frame's origin, got "
                              f"{shorten(line.decode('utf-8', 'replace'))!r}")


def _check_bosses(path: Path, bosses: Mapping[str, tuple[float, float, float]], turned: set[str]) -> None:
    """No two square bosses overlap (:func:`overlapping_bosses`)."""
    found = overlapping_bosses(bosses, turned)
    if found is not None:
        (a, (xa, ya, ta)), (b, (xb, yb, tb)) = ((hid, bosses[hid]) for hid in found)
        raise BridgeError(f"{path}: [plate] tile_size: expected bosses that do not overlap, got holes "
                          f"{a} at ({xa:g}, {ya:g}) and {b} at ({xb:g}, {yb:g}) m closer than their "
                          f"bosses' half sides together ({(ta + tb) / 2:g} m)")


def overlapping_bosses(bosses: Mapping[str, tuple[float, float, float]], turned: set[str]) -> tuple[str, str] | None:
    """The first two holes (by id) whose square bosses overlap, each ``(x, y, side)`` [m]
    around the hole it is named for; None when none do. A boss of a ``turned`` hole is
    turned with it: two bosses whose centres are closer than half their sides together
    overlap whatever their yaws (their inscribed circles do)."""
    ordered = sorted(bosses.items())
    for k, (a, (xa, ya, ta)) in enumerate(ordered):
        for b, (xb, yb, tb) in ordered[k + 1:]:
            reach = (ta + tb) / 2 - TOUCH_TOLERANCE
            if a in turned or b in turned:
                overlap = math.hypot(xa - xb, ya - yb) < reach
            else:
                overlap = abs(xa - xb) < reach and abs(ya - yb) < reach
            if overlap:
                return a, b
    return None


def _describe(kind: str, size: float | list[float]) -> str:
    """``round d 12 mm``, ``square 4 mm``, ``rect 16 x 10 mm``."""
    a, b = (1000 * side for side in _sides(size))
    return {"round": f"round d {a:g} mm", "square": f"square {a:g} mm"}.get(kind, f"rect {a:g} x {b:g} mm")


def _check_kinds(path: Path, geo: GeometryFile, layout: AssemblyFile) -> None:
    """The ``shape`` of each part and hole in ``assembly.toml`` (where given) is the
    ``kind`` of its cross-section in ``geometry.toml``, and the parts of one ``section``
    are scaled copies of one cross-section (one aspect ratio b/a, all round or none)."""
    source = path.parent / "assembly.toml"
    part_shape = {pid: shape for shape in geo.part_shapes.values() for pid in shape.parts}
    hole_shape = {hid: shape for shape in geo.hole_shapes.values() for hid in shape.holes}
    declared: list[tuple[str, str, str | None, HoleShape | PartShape | None]]
    declared = [(pid, "part", part.shape, part_shape.get(pid)) for pid, part in layout.parts.items()]
    declared += [(hid, "hole", hole.shape, hole_shape.get(hid)) for hid, hole in layout.holes.items()]
    for item, what, shape, spec in declared:
        if shape is not None and spec is not None and spec.kind != shape:
            raise BridgeError(f"{source}: {what} '{item}' has shape \"{shape}\" but geometry.toml gives it kind "
                              f"\"{spec.kind}\"")
    first: dict[str, tuple[str, PartShape]] = {}
    for pid, part in layout.parts.items():
        spec = part_shape.get(pid)
        if spec is None:
            continue
        section = section_label(pid, spec.kind, part.section)
        other_id, other = first.setdefault(section, (pid, spec))
        (a, b), (oa, ob) = _sides(spec.size), _sides(other.size)
        if (other.kind == "round") != (spec.kind == "round") or not math.isclose(b / a, ob / oa, rel_tol=1e-9):
            raise BridgeError(f"{source}: parts '{other_id}' and '{pid}' share section \"{section}\" but are no "
                              f"scaled copies of one cross-section ({_describe(other.kind, other.size)} and "
                              f"{_describe(spec.kind, spec.size)} in geometry.toml)")


def _check_manual_features(path: Path, geo: GeometryFile, layout: AssemblyFile) -> None:
    """A part placed by hand is ``on`` holes of ``assembly.toml``, and ``held_by`` parts the
    cell places (a peg of ``[part_shapes.*]``), each in holes of ``assembly.toml``, the same
    ones in every table naming it."""
    pegs = {pid for shape in geo.part_shapes.values() for pid in shape.parts}
    held: dict[str, set[str]] = {}
    for mid, manual in geo.manual.items():
        table = f"manual.{mid}"
        for hid in [*(manual.on or []), *(h for holes in manual.held_by.values() for h in holes)]:
            if hid not in layout.holes:
                raise fail(path, table, "on" if hid in (manual.on or []) else "held_by",
                           "holes of assembly.toml", hid)
        for pid in manual.held_by:
            if pid not in pegs:
                raise fail(path, table, "held_by", "parts the cell places (of [part_shapes.*])", pid)
            if held.setdefault(pid, set(manual.held_by[pid])) != set(manual.held_by[pid]):
                raise fail(path, table, f"held_by.{pid}",
                           f"the holes another [manual.*] gives it ({sorted(held[pid])})", manual.held_by[pid])


def _check_product(path: Path, geo: GeometryFile, layout: AssemblyFile, holes: Mapping[str, str]) -> None:
    """The base, covers and heads name parts of ``assembly.toml``, holes of the plate, part
    shapes (their skills) and covers with a socket; with a ``[base]``, every part of
    ``assembly.toml`` has exactly one geometry."""
    skills = sorted(geo.part_shapes)
    pegs = {pid for shape in geo.part_shapes.values() for pid in shape.parts}
    for cid, cover in geo.covers.items():
        table = f"covers.{cid}"
        for hid in cover.over:
            if hid not in holes:
                raise fail(path, table, "over", f"holes of [hole_shapes.*] ({', '.join(sorted(holes))})", hid)
        if len(set(cover.over)) != len(cover.over):
            raise fail(path, table, "over", "distinct holes", cover.over)
        xmin, ymin, xmax, ymax = cover.outline
        if not (xmin < xmax and ymin < ymax):
            raise fail(path, table, "outline", "[xmin, ymin, xmax, ymax] with xmin < xmax and ymin < ymax",
                       cover.outline)
        if cover.socket is not None and not (0 < cover.socket[2] and 0 < cover.socket[3] < cover.thickness):
            raise fail(path, table, "socket", f"[x, y, side, depth] with side > 0 and 0 < depth < thickness "
                       f"({cover.thickness:g} m)", cover.socket)
        if cover.skill not in geo.part_shapes:
            raise fail(path, table, "skill", f"a part shape of [part_shapes.*] ({', '.join(skills)})", cover.skill)
    for hid, head in geo.heads.items():
        table = f"heads.{hid}"
        cover_of = geo.covers.get(head.into)
        if cover_of is None or cover_of.socket is None:
            with_socket = sorted(c for c, t in geo.covers.items() if t.socket is not None)
            raise fail(path, table, "into", f"a cover with a socket ({', '.join(with_socket) or 'none'})",
                       head.into)
        if head.skill not in geo.part_shapes:
            raise fail(path, table, "skill", f"a part shape of [part_shapes.*] ({', '.join(skills)})", head.skill)
        part = layout.parts.get(hid)
        if part is None or part.start is None:
            raise fail(path, table, "", "a part of assembly.toml with a start", hid)
    for table_name, ids in (("covers", geo.covers), ("manual", geo.manual)):
        for pid in ids:
            if pid not in layout.parts:
                raise fail(path, f"{table_name}.{pid}", "", "a part of assembly.toml", pid)
    _check_manual_features(path, geo, layout)
    if geo.base is None:
        return
    if geo.base.part not in layout.parts:
        raise fail(path, "base", "part", f"a part of assembly.toml ({', '.join(layout.parts)})", geo.base.part)
    owners: dict[str, list[str]] = {pid: [] for pid in layout.parts}
    for pid in pegs:
        owners.get(pid, []).append("[part_shapes.*]")
    for pid in geo.covers:
        owners[pid].append("[covers.*]")
    for pid in geo.heads:
        owners[pid].append("[heads.*]")
    for pid in geo.manual:
        owners[pid].append("[manual.*]")
    owners[geo.base.part].append("[base]")
    missing = sorted(pid for pid, tables in owners.items() if not tables)
    if missing:
        raise BridgeError(f"{path}: part(s) {', '.join(missing)} of assembly.toml have no geometry "
                          "(expected a [part_shapes.*], [covers.*], [heads.*], [manual.*] or [base] entry)")
    twice = sorted(pid for pid, tables in owners.items() if len(tables) > 1)
    if twice:
        raise BridgeError(f"{path}: part {twice[0]} of assembly.toml has more than one geometry "
                          f"({' and '.join(owners[twice[0]])}); expected one")
