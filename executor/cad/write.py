"""The assembly folder of an imported product, in the vocabulary every command reads.

- ``assembly.toml``: every part (the base with role ``base``, a part in a hole with role
  ``peg`` and its section's kind as ``shape``, any other ``part``) with its tray ``start``,
  every hole (``h1``, ``h2``, ... by position) with its kind and position;
- ``sizes.lp``: ``fits(P,H)`` for every peg and hole whose nominal sections pass
  (:func:`executor.world.geometry.passes`), closed world;
- ``geometric_precedence.lp``: ``part/1`` and ``must_precede/2`` (transitively closed)
  from the disassembly, the input of ``precedence learn --prior`` and ``precedence count``;
- ``geometry.toml``: the simulated cell's primitives (plate with bosses, pegs) when the
  product is one (every part but the base a peg standing in a hole along +z, the holes'
  entries at one height with one depth); left out otherwise, and the report says why.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import clingo
import networkx as nx

from bridge.files import make_folder, write_atomic
from executor.cad.derive import Derived, HoleFit
from executor.world.geometry import Section, passes

DENSITY = 2700.0
"""Mass of a peg in the simulated cell: its volume times this [kg/m³] (aluminium)."""
GRIPPER = {"flange_mass": 1.0, "flange_inertia": 0.004, "flange_length": 0.06, "grasp_depth": 0.02}
"""The simulated gripper of every imported product (Cranfield's)."""
_LEVEL = 1e-5  # holes whose entries or depths differ by more [m] are no one plate


@dataclass(frozen=True)
class Settings:
    """What the import file states: the ``base`` part, the ``trays`` [m], part ``names``."""

    base: str
    trays: dict[str, tuple[float, float]]
    names: dict[str, str]


def hole_ids(derived: Derived) -> dict[str, str]:
    """Part → its hole's id, ``h1``... in order of position (x, then y)."""
    ordered = sorted(derived.holes.values(), key=lambda fit: (round(fit.position[0], 6), round(fit.position[1], 6)))
    return {fit.part: f"h{k}" for k, fit in enumerate(ordered, start=1)}


def section(name: str, shape_kind: str, a: float, b: float) -> Section:
    return Section(name, shape_kind, a, width=b if shape_kind == "rect" else 0.0)


def _q(value: float) -> float:
    """Metres rounded to 0.1 µm (a printed tessellation is no finer)."""
    return round(value, 7)


def _size(kind: str, a: float, b: float) -> str:
    return f"[{_q(a)}, {_q(b)}]" if kind == "rect" else f"{_q(a)}"


def _symbols(symbols: list[clingo.Symbol]) -> str:
    return " ".join(f"{symbol}." for symbol in symbols)


def assembly_text(derived: Derived, settings: Settings, title: str) -> str:
    holes = hole_ids(derived)
    lines = [f"# Imported from {title} by ./run.sh import: parts in the CAD frame (the cell frame) [m].",
             f"name = {json.dumps(title)}", ""]
    for pid in sorted(derived.parts):
        role = "base" if pid == derived.base else "peg" if pid in derived.holes else "part"
        lines += [f"[parts.{pid}]", f"name = {json.dumps(settings.names.get(pid, derived.parts[pid].name))}",
                  f'role = "{role}"']
        x, y = settings.trays[pid]
        lines.append(f"start = [{_q(x)}, {_q(y)}]")
        if pid in derived.holes and derived.holes[pid].section.kind != "other":
            lines.append(f'shape = "{derived.holes[pid].section.kind}"')
        lines.append("")
    for pid, hid in sorted(holes.items(), key=lambda item: int(item[1][1:])):
        fit = derived.holes[pid]
        lines += [f"[holes.{hid}]", f'name = "hole of {pid}"', f'shape = "{_kind(fit.hole.kind)}"',
                  f"position = [{_q(fit.position[0])}, {_q(fit.position[1])}]", ""]
    return "\n".join(lines)


def _kind(kind: str) -> str:
    """An ``other`` hole is stated as round in assembly.toml (its shape is only a label there)."""
    return kind if kind != "other" else "round"


def sizes_text(derived: Derived) -> str:
    holes = hole_ids(derived)
    pegs = [pid for pid in sorted(derived.holes) if derived.holes[pid].section.kind != "other"]
    ordered = sorted(holes.items(), key=lambda item: int(item[1][1:]))
    lines = ["% Which part fits which hole from the nominal cross-sections (closed world), by ./run.sh import.",
             _symbols([clingo.Function("part", [clingo.Function(p)]) for p in pegs]),
             _symbols([clingo.Function("hole", [clingo.Function(h)]) for _, h in ordered])]
    for pid in pegs:
        peg = derived.holes[pid].section
        fits = [clingo.Function("fits", [clingo.Function(pid), clingo.Function(hid)]) for owner, hid in ordered
                if derived.holes[owner].hole.kind != "other" and passes(
                    section(pid, peg.kind, peg.a, peg.b),
                    section(hid, derived.holes[owner].hole.kind, derived.holes[owner].hole.a,
                            derived.holes[owner].hole.b))]
        if fits:
            lines.append(_symbols(fits))
    return "\n".join(lines) + "\n"


def precedence_text(derived: Derived) -> str:
    graph = nx.DiGraph()
    graph.add_nodes_from(derived.parts)
    graph.add_edges_from(derived.edges)
    closure = sorted(nx.transitive_closure_dag(graph).edges)
    lines = ["% Geometric precedence by disassembly (./run.sh import): must_precede(A,B) when B blocks A's",
             "% straight way out along A's insertion axis, or A is the base and B touches it; transitively closed.",
             _symbols([clingo.Function("part", [clingo.Function(p)]) for p in sorted(derived.parts)])]
    lines += [_symbols([clingo.Function("must_precede", [clingo.Function(a), clingo.Function(b)])])
              for a, b in closure]
    return "\n".join(lines) + "\n"


def simulable(derived: Derived) -> str | None:
    """Why the product is not one the simulated cell builds from primitives, None when it is."""
    for pid in sorted(derived.parts):
        if pid == derived.base:
            continue
        fit = derived.holes.get(pid)
        if fit is None:
            return f"part '{pid}' stands in no hole of the base"
        if derived.axis[pid] != "+z":
            return f"part '{pid}' goes in along {derived.axis[pid]}, not from above"
        if "other" in (fit.section.kind, fit.hole.kind):
            return f"part '{pid}' or its hole has a cross-section other than round, square or rect"
    fits = list(derived.holes.values())
    if not fits:
        return "no part stands in a hole of the base"
    for what, values in (("entry", [f.entry for f in fits]), ("depth", [f.depth for f in fits])):
        if max(values) - min(values) > _LEVEL:
            return f"the holes' {what} differs by {1000 * (max(values) - min(values)):.3g} mm (one plate has one)"
    return None


def geometry_text(derived: Derived, settings: Settings) -> str:
    """``geometry.toml`` of a :func:`simulable` product."""
    fits = list(derived.holes.values())
    holes = hole_ids(derived)
    base = derived.parts[derived.base].mesh
    (x0, y0, z0), (x1, y1, _) = base.bounds
    top, depth = fits[0].entry, fits[0].depth
    tile = _tile(fits)
    lines = ["# The simulated cell's primitives measured from the CAD by ./run.sh import [m].", "",
             "[plate]", f"top_z = {_q(top)}", f"tile_size = {_q(tile)}", f"tile_thickness = {_q(depth)}",
             f"chamfer = {_q(max(f.chamfer for f in fits))}", "polygon_sides = 24",
             f"base_size = [{_q(x1 - x0)}, {_q(y1 - y0)}]", f"base_center = [{_q((x0 + x1) / 2)}, {_q((y0 + y1) / 2)}]",
             f"base_thickness = {_q(max(top - depth - z0, 1e-3))}", ""]
    for pid, fit in sorted(derived.holes.items()):
        hid = holes[pid]
        lines += [f"[hole_shapes.{hid}]", f'holes = ["{hid}"]', f'kind = "{fit.hole.kind}"',
                  f"size = {_size(fit.hole.kind, fit.hole.a, fit.hole.b)}"]
        if fit.hole.yaw:
            lines.append(f"yaw = {fit.hole.yaw:.6g}")
        lines.append("")
    for pid, fit in sorted(derived.holes.items()):
        mesh = derived.parts[pid].mesh
        lines += [f"[part_shapes.{pid}]", f'parts = ["{pid}"]', f'kind = "{fit.section.kind}"',
                  f"size = {_size(fit.section.kind, fit.section.a, fit.section.b)}",
                  f"length = {_q(float(mesh.extents[2]))}", f"mass = {_q(mesh.volume * DENSITY)}",
                  f'demo_hole = "{holes[pid]}"', ""]
    lines += ["[gripper]", *(f"{key} = {value}" for key, value in GRIPPER.items()), "",
              "[base]", f'part = "{derived.base}"',
              f"tray = [{_q(settings.trays[derived.base][0])}, {_q(settings.trays[derived.base][1])}]",
              "grip = [0.0, 0.0]", f"mass = {_q(base.volume * DENSITY)}", ""]
    return "\n".join(lines)


def _tile(fits: list[HoleFit]) -> float:
    """The side of the square boss around every hole [m]: the measured boss when the base
    has one around each hole, else the largest square the holes' spacing leaves room for."""
    bosses = [f.outer.b for f in fits if f.outer is not None and f.outer.kind in ("square", "rect")]
    spacing = min((max(abs(a.position[0] - b.position[0]), abs(a.position[1] - b.position[1]))
                   for i, a in enumerate(fits) for b in fits[i + 1:]), default=0.04)
    widest = max(max(f.hole.a, f.hole.b) + 2 * f.chamfer for f in fits)
    tile = min([*bosses, spacing, 0.04])
    return tile if tile > widest else widest + 0.004


def write_folder(derived: Derived, settings: Settings, title: str, out: Path) -> list[Path]:
    """Write the files of the module docstring into ``out``; returns them."""
    make_folder(out)
    written = [write_atomic(out / "assembly.toml", assembly_text(derived, settings, title)),
               write_atomic(out / "sizes.lp", sizes_text(derived)),
               write_atomic(out / "geometric_precedence.lp", precedence_text(derived))]
    geometry = out / "geometry.toml"
    if simulable(derived) is None:
        written.append(write_atomic(geometry, geometry_text(derived, settings)))
    elif geometry.exists():
        geometry.unlink()
    return written
