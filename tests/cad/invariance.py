"""The import's answers under changes of the CAD that cannot matter (metamorphic testing).

A corpus product (``tests/cad/corpus/<name>/``, meshes in mm) is written again changed in
one way that leaves the product the same, imported (``import``, one at a time, each in a
process of its own; the tests' in theirs: :func:`run_import`), and its written assembly
folder compared, parsed, with the same product written unchanged (``same``: the meshes
as ASCII STL of float64 coordinates, as every variant is written, so the comparison
measures the change, not the file format):

- ``turn90``, ``turn180``, ``turn270``: every vertex turned about z (an exact permutation
  of x and y with signs), and the trays the settings set turned as a whole with the parts
  on them (:func:`_turn_trays`); the cell frame's points and axes turned back about
  ``place``;
- ``shift``: every vertex moved by :data:`SHIFT` [mm] (taken off by the import's
  placement: x and y by ``place``, z by standing the product on the cell's floor);
- ``metres``: coordinates × 0.001, imported with ``--units m``;
- ``renamed``: each file's stem prefixed so that the ids sort in the reverse order;
- ``shuffled``: the triangles in another order, each triangle's corners turned cyclically
  (the same surface, the same winding).

Every import has ``--place`` :data:`PLACE` and ``--turn 0`` (the default placement
depends on where the CAD has the base, and the import would choose a turn and a place
where its arm reaches more). What is compared (:func:`answers`): ``sizes.lp``, ``nominal_sizes.lp``
(margins within :data:`MARGIN_UM`), ``geometric_precedence.lp`` (pairs and each pair's
reason), the insertion axes and free directions printed, ``assembly.toml`` and
``geometry.toml`` (lengths within :data:`LENGTH_M`, masses relative :data:`MASS_REL`),
the holes matched by position and their ids mapped. What is not, and why: the meshes'
digests (the files written are the meshes as read, in the cell frame); the trays laid
out by the import (``start``, ``tray``) where ids or footprints change (``renamed`` lays
them out in another id order, a turn turns the footprints); under a turn, a section's
orientation (``outline``, ``size``, ``yaw``): compared by what a turn keeps (its sorted
sides, its corners' distances from its centre), and a reason naming the arm's measured
reach (:data:`_REACH`: the reach is the cell frame's); a part free both ways along an
axis that goes in from the other side turned (a tie, :func:`_tied`): its axis, its
feature's entry and the sense of the axes its reason for going by hand names.
docs/import.md ("Invariances") lists what the comparison found.

``python -m tests.cad.invariance [--product NAME ...] [--transform T ...]`` prints one
line per product and transform (``same`` or the differences, each ``tie:`` too: a part
free both ways that goes in along the other way turned, :func:`_tied`) and exits 1 on
any difference but a tie.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import tomllib
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import shapely
import trimesh

from bridge.errors import ToolError
from executor.cad.cli import main as import_main
from executor.cad.sweep import opposite

ROOT = Path(__file__).resolve().parents[2]
CORPUS = Path(__file__).parent / "corpus"
PLACE = (0.56, 0.0)
"""``--place`` of every import [m]: where the base's box centre stands in the cell."""
SHIFT = (1234.5, -678.9, 50.0)
"""The ``shift`` transform [mm]."""
MARGIN_UM = 2
"""Tolerance on a ``nominal_margin`` [µm]."""
LENGTH_M = 2e-6
"""Tolerance on a length or position [m]."""
MASS_REL = 1e-5
"""Relative tolerance on a mass."""
TRANSFORMS = ("turn90", "turn180", "turn270", "shift", "metres", "renamed", "shuffled")
_TURN_KEYS = {"outline", "size", "yaw"}
"""A section's orientation: under a turn compared by :func:`_turn_invariant`."""
"""Heights in the cell [m]: the CAD's z is the cell's."""
_REACH = "out of the arm's reach measured in the cell"
"""A reason of the arm's measured reach, under a turn (:meth:`_Frame.word`)."""
_LAYOUT_KEYS = {"start", "tray"}
"""The trays the import lays out: by id order and footprint."""


@dataclass(frozen=True)
class Variant:
    """One change of a product's CAD: the ``points`` map on vertices [mm] into the file's
    unit, the import's ``units``, each file stem's new ``name``, ``quarter`` turns about z
    (+90° each) and whether triangles are ``shuffled``."""

    points: Callable[[np.ndarray], np.ndarray] = lambda v: v
    units: str = "mm"
    name: Callable[[str, list[str]], str] = lambda stem, stems: stem
    quarter: int = 0
    shuffled: bool = False


def _turn(quarter: int) -> Callable[[np.ndarray], np.ndarray]:
    """Vertices turned by ``quarter`` × 90° about z, exactly (a permutation with signs)."""
    def turn(v: np.ndarray) -> np.ndarray:
        out = v.copy()
        for _ in range(quarter):
            out = np.column_stack([-out[:, 1], out[:, 0], out[:, 2]])
        return out
    return turn


def _reverse_prefix(stem: str, stems: list[str]) -> str:
    """``stem`` prefixed by a letter that reverses the alphabetical order of ``stems``."""
    return f"{'zyxwvutsrqponmlkjihgfedcba'[sorted(stems).index(stem)]}_{stem}"


VARIANTS: dict[str, Variant] = {
    "same": Variant(),
    "turn90": Variant(points=_turn(1), quarter=1),
    "turn180": Variant(points=_turn(2), quarter=2),
    "turn270": Variant(points=_turn(3), quarter=3),
    "shift": Variant(points=lambda v: v + np.array(SHIFT)),
    "metres": Variant(points=lambda v: v * 0.001, units="m"),
    "renamed": Variant(name=_reverse_prefix),
    "shuffled": Variant(shuffled=True),
}


def _ascii_stl(path: Path, triangles: np.ndarray) -> None:
    """``triangles`` (n × 3 × 3) as an ASCII STL of 17 significant digits (float64 kept)."""
    lines = ["solid part"]
    for tri in triangles:
        lines += ["facet normal 0 0 0", "outer loop", *(f"vertex {x!r} {y!r} {z!r}" for x, y, z in tri.tolist()),
                  "endloop", "endfacet"]
    lines.append("endsolid part")
    path.write_text("\n".join(lines) + "\n")


def write_variant(product: Path, variant: Variant, out: Path, seed: int = 1) -> dict[str, str]:
    """``product``'s meshes written changed by ``variant`` into ``out/meshes`` with its
    ``import.toml`` (ids renamed); the renaming (old id → new id)."""
    stems = sorted(p.stem for p in (product / "meshes").iterdir())
    renamed = {stem: variant.name(stem, stems) for stem in stems}
    (out / "meshes").mkdir(parents=True)
    rng = np.random.default_rng(seed)
    for path in sorted((product / "meshes").iterdir()):
        mesh = trimesh.load(path, force="mesh", process=False)
        triangles = variant.points(np.asarray(mesh.vertices, dtype=np.float64))[np.asarray(mesh.faces)]
        if variant.shuffled:
            triangles = triangles[rng.permutation(len(triangles))]
            turns = rng.integers(0, 3, len(triangles))
            triangles = np.stack([np.roll(tri, k, axis=0) for tri, k in zip(triangles, turns, strict=True)])
        _ascii_stl(out / "meshes" / f"{renamed[path.stem]}.stl", triangles)
    config = tomllib.loads((product / "import.toml").read_text())
    config["base"] = renamed[config["base"]]
    config["parts"] = {renamed[pid]: table for pid, table in config.get("parts", {}).items()}
    _turn_trays(config["parts"], variant.points if variant.quarter else None)
    (out / "import.toml").write_text(_toml(config))
    return renamed


def _turn_trays(parts: dict[str, dict[str, Any]], turn: Callable[[np.ndarray], np.ndarray] | None) -> None:
    """The trays the settings set (positions in the cell [m], each part waiting on its tray
    as the CAD has it turned) turned by ``turn`` (None: as they are) about the centre of
    their box, in place: the parts turned with the product keep the room they had between
    them on their trays, as they would not on the trays set for the product unturned (the
    200 mm rod turned across them lies over another part's tray)."""
    set_trays = {pid: table["tray"] for pid, table in parts.items() if "tray" in table}
    if turn is None or not set_trays:
        return
    trays = np.array(list(set_trays.values()), dtype=float)
    centre = (trays.min(axis=0) + trays.max(axis=0)) / 2
    turned = turn(np.column_stack([trays - centre, np.zeros(len(trays))]))[:, :2] + centre
    for pid, tray in zip(set_trays, turned.tolist(), strict=True):
        parts[pid]["tray"] = tray


def _toml(config: dict[str, Any]) -> str:
    """The import settings ``config`` (a base, parts' tables of scalars and lists) as TOML."""
    def value(v: Any) -> str:
        return repr(v) if not isinstance(v, str) else f'"{v}"'
    lines = [f"{key} = {value(v)}" for key, v in config.items() if not isinstance(v, dict)]
    for pid, table in config.get("parts", {}).items():
        lines += [f"[parts.{pid}]", *(f"{key} = {value(v)}" for key, v in table.items())]
    return "\n".join(lines) + "\n"


def run_import(folder: Path, units: str, isolated: bool = True) -> tuple[Path, str]:
    """``import folder/meshes --config folder/import.toml --place PLACE`` into
    ``folder/out``, in a process of its own (``isolated``: nothing cached from an import
    before) or in this one: the folder and what it printed, kept in ``folder/printed.txt``
    (ImportFailed on a failure)."""
    out = folder / "out"
    args = ["import", str(folder / "meshes"), "--units", units, "--config", str(folder / "import.toml"),
            "--place", f"{PLACE[0]},{PLACE[1]}", "--turn", "0", "--out", str(out)]
    if isolated:
        done = subprocess.run([sys.executable, "-P", "-m", "assembly_constraints", *args], capture_output=True,
                              text=True, cwd=ROOT, env=os.environ | {"PYTHONPATH": str(ROOT)}, check=False)
        if done.returncode != 0:
            raise ImportFailed(done.stderr.strip().splitlines()[-1] if done.stderr.strip()
                               else f"exit {done.returncode}")
        printed = done.stdout
    else:
        buffer = io.StringIO()
        try:
            with contextlib.redirect_stdout(buffer):
                import_main(args[1:])
        except ToolError as exc:
            raise ImportFailed(str(exc)) from None
        printed = buffer.getvalue()
    (folder / "printed.txt").write_text(printed)
    return out, printed


class ImportFailed(Exception):
    """An import of a variant exited non-zero."""


def _lp(path: Path) -> dict[str, Any]:
    """A written ``.lp`` file's facts (predicate → sorted argument tuples) and its
    ``% a->b: reason`` comments (``reasons``)."""
    facts: dict[str, Any] = {}
    for line in path.read_text().splitlines():
        if line.startswith("%"):
            pair = re.match(r"% (\w+)->(\w+): (.*)$", line)
            if pair:
                facts.setdefault("reasons", {})[f"{pair[1]}->{pair[2]}"] = pair[3]
            continue
        for name, args in re.findall(r"(\w+)\(([^()]*)\)\.", line):
            facts.setdefault(name, []).append(args.split(","))
    return facts


def answers(out: Path, printed: str) -> dict[str, Any]:
    """An import's written answers, parsed: the files of ``out`` and the axes it ``printed``."""
    found: dict[str, Any] = {name: _lp(out / name) for name in
                             ("sizes.lp", "nominal_sizes.lp", "geometric_precedence.lp") if (out / name).is_file()}
    found["assembly.toml"] = tomllib.loads((out / "assembly.toml").read_text())
    if (out / "geometry.toml").is_file():
        found["geometry.toml"] = tomllib.loads((out / "geometry.toml").read_text())
    found["axes"] = {m[1]: {"insertion": m[2], "free": m[3].split(", ")} for m in re.finditer(
        r"^part (\w+): insertion axis (\S+) .*?free in the assembled product along (.*)$", printed, re.M)}
    return found


@dataclass
class _Frame:
    """How a variant's cell frame maps back onto the unchanged one's."""

    quarter: int
    ids: dict[str, str] = field(default_factory=dict)
    turned: bool = False
    """Whether the comparison is of a turned product (either side): a reason naming the
    arm's measured reach is its kind alone, the reach being the cell frame's."""

    def point(self, p: list[float]) -> list[float]:
        """A cell point [m] (x, y or x, y, z) of the variant in the unchanged product's frame."""
        x, y = p[0] - PLACE[0], p[1] - PLACE[1]
        for _ in range(self.quarter):  # turned back: -90° each
            x, y = y, -x
        return [x + PLACE[0], y + PLACE[1], *p[2:]]

    def axis(self, a: str) -> str:
        """A cell axis (``+x``, ``-z``) of the variant in the unchanged product's frame."""
        if a[1] == "z":
            return a
        vector = np.array([1.0 if a[1] == "x" else 0.0, 1.0 if a[1] == "y" else 0.0, 0.0]) * (1 if a[0] == "+" else -1)
        back = self.point([PLACE[0] + vector[0], PLACE[1] + vector[1]])
        x, y = round(back[0] - PLACE[0]), round(back[1] - PLACE[1])
        return ("+" if x + y > 0 else "-") + ("x" if x else "y")

    def word(self, text: str) -> str:
        """``text`` with every id of the variant named as in the unchanged product, every
        point ``(x, y[, z]) mm`` moved back, every axis turned back (:attr:`turned`: the
        arm's measured reach left out)."""
        text = re.sub(r"\b\w+\b", lambda m: self.ids.get(m[0], m[0]), text)
        text = re.sub(r"\((-?\d+\.\d+), (-?\d+\.\d+)(, -?\d+\.\d+)?\) mm", self._point_mm, text)
        if self.turned and ("measured to reach" in text or "out of the reach measured" in text):
            text = text.split(":")[0] + ": " + _REACH
        return re.sub(r"(?<![\w.])[+-][xyz]\b", lambda m: self.axis(m[0]), text) if self.quarter else text

    def _point_mm(self, match: re.Match[str]) -> str:
        """A point ``(x, y[, z]) mm`` of the variant's cell frame moved back, to 0.1 mm."""
        given = [float(v.strip(", ")) / 1000 for v in match.groups() if v is not None]
        return "(" + ", ".join(f"{1000 * v:.1f}" for v in self.point(given)) + ") mm"


def _holes(found: dict[str, Any]) -> dict[str, list[float]]:
    """Each hole's or pin's position [m] of ``assembly.toml``."""
    return {hid: hole["position"] for hid, hole in found["assembly.toml"].get("holes", {}).items()}


def hole_ids(base: dict[str, Any], other: dict[str, Any], frame: _Frame) -> dict[str, str]:
    """Each hole id of ``other`` mapped to the ``base`` hole at its position (turned back),
    of the same name once its part ids are mapped (:func:`_name_words`), or where none is
    there, the one hole of that name (a tied part's, :func:`_tied`, enters on the other
    side); one matched by none (or by several) gets its id and "?", not to be taken for
    the unchanged hole of its id."""
    mapped = {}
    named = {bid: _name_words(hole["name"], bid) for bid, hole in base["assembly.toml"].get("holes", {}).items()}
    for hid, position in _holes(other).items():
        back = frame.point(position)
        name = _name_words(frame.word(other["assembly.toml"]["holes"][hid]["name"]), frame.ids.get(hid, hid))
        alike = [bid for bid, words in named.items() if words == name]
        near = [bid for bid in alike if math.dist(_holes(base)[bid], back) <= 1e-5] or alike
        mapped[hid] = near[0] if len(near) == 1 else f"{hid}?"
    return mapped


def _name_words(name: str, hid: str) -> list[str]:
    """The words of hole ``hid``'s name, sorted (a pin's name lists its parts in id order),
    its own id as "#" (an empty hole is "hole h2", and holes are numbered by position)."""
    return sorted(re.findall(r"\w+|#", re.sub(rf"\b{hid}\b", "#", name)))


def _turn_invariant(section: dict[str, Any]) -> dict[str, Any]:
    """What a quarter turn keeps of a section: its sides sorted, its outline's corners'
    distances from the origin sorted."""
    kept = {key: v for key, v in section.items() if key not in _TURN_KEYS}
    size = section.get("size")
    if size is not None:
        kept["size"] = sorted(size) if isinstance(size, list) else size
    if "outline" in section:
        kept["outline_radii"] = sorted(math.hypot(x, y) for x, y in section["outline"])
    return kept


def canonical(found: dict[str, Any], frame: _Frame, layout: bool) -> Any:
    """``found`` in the unchanged product's frame and ids: points and axes turned back,
    ids mapped, the meshes' digests dropped, the laid-out trays dropped unless ``layout``,
    under a turn the sections' orientation replaced by :func:`_turn_invariant`."""
    def walk(value: Any, key: str) -> Any:
        if isinstance(value, dict):
            if frame.quarter and ("kind" in value or "outline" in value):
                value = _turn_invariant(value)
            return {frame.word(k): walk(v, k) for k, v in sorted(value.items())
                    if k != "sha256" and (layout or k not in _LAYOUT_KEYS)}
        if isinstance(value, list):
            if key in ("position", "goal", "base_center", "grip", "socket") and all(
                    isinstance(v, float | int) for v in value) and len(value) in (2, 3):
                return frame.point(value) if key != "grip" else value
            items = [walk(v, key) for v in value]
            return sorted(items, key=repr) if key not in ("size", "outline", "base_size") else items
        if isinstance(value, str):  # ids listed in id order: sorted
            text = re.sub(r"\((\w+(?:, \w+)+)\)", lambda m: f"({', '.join(sorted(m[1].split(', ')))})",
                          frame.word(value))
            return re.sub(r"\(([\w ]+) onto it\)", lambda m: f"({' '.join(sorted(m[1].split()))} onto it)",
                          text) if key == "name" else text
        return value
    tree = walk(found, "")
    if frame.quarter % 2:
        plate = tree.get("geometry.toml", {}).get("plate", {})
        if "base_size" in plate:
            plate["base_size"] = plate["base_size"][::-1]
    return tree


def differences(base: Any, other: Any, path: str = "") -> Iterator[str]:
    """Where ``other`` differs from ``base`` beyond the tolerances, one line each."""
    if isinstance(base, dict) and isinstance(other, dict):
        for key in sorted(set(base) | set(other)):
            if key not in other:
                yield f"{path}/{key}: only unchanged ({_short(base[key])})"
            elif key not in base:
                yield f"{path}/{key}: only changed ({_short(other[key])})"
            else:
                yield from differences(base[key], other[key], f"{path}/{key}")
    elif path.endswith("/outline") and isinstance(base, list) and isinstance(other, list):
        apart = shapely.Polygon(base).hausdorff_distance(shapely.Polygon(other))
        if apart > LENGTH_M:  # one polygon, however its corners are listed (noise adds or drops one)
            yield f"{path}: {apart * 1e6:.3f} um apart ({_short(base)} -> {_short(other)})"
    elif isinstance(base, list) and isinstance(other, list) and len(base) == len(other):
        for k, (a, b) in enumerate(zip(base, other, strict=True)):
            yield from differences(a, b, f"{path}[{k}]")
    elif isinstance(base, float | int) and isinstance(other, float | int) and not isinstance(base, bool):
        if not _close(float(base), float(other), path):
            yield f"{path}: {base} -> {other}"
    elif isinstance(base, str) and isinstance(other, str) and base != other:
        if base.endswith("\u2026") or other.endswith("\u2026"):  # shortened: where ids are longer, sooner
            base, other = base.rstrip("\u2026"), other.rstrip("\u2026")
            base, other = base[:min(len(base), len(other))].rstrip(), other[:min(len(base), len(other))].rstrip()
        numbers = re.compile(r"-?\d+\.\d+")
        if numbers.sub("#", base) != numbers.sub("#", other) or not all(
                abs(float(a) - float(b)) <= 2e-3 for a, b in zip(numbers.findall(base), numbers.findall(other),
                                                                 strict=True)):
            yield f"{path}: {_short(base)} -> {_short(other)}"
    elif base != other and not (isinstance(base, str) and isinstance(other, str)):
        yield f"{path}: {_short(base)} -> {_short(other)}"


def _close(a: float, b: float, path: str) -> bool:
    """Whether two numbers at ``path`` agree within the tolerance of their kind."""
    if "nominal_margin" in path:
        return abs(a - b) <= MARGIN_UM
    if path.endswith("/mass"):
        return abs(a - b) <= MASS_REL * max(abs(a), abs(b))
    return abs(a - b) <= LENGTH_M


def _short(value: Any) -> str:
    """``value`` in at most 160 characters."""
    text = repr(value)
    return text if len(text) <= 160 else text[:157] + "..."


def _mapped_lp(found: dict[str, Any]) -> dict[str, Any]:
    """``found`` with each ``.lp`` fact list as a sorted list of comma-joined atoms (numbers
    last, kept numeric for the tolerance)."""
    for name in ("sizes.lp", "nominal_sizes.lp", "geometric_precedence.lp"):
        facts = found.get(name, {})
        for pred, rows in list(facts.items()):
            if pred == "reasons":
                continue
            if pred == "nominal_margin":
                facts[pred] = {f"{p},{h}": int(m) for p, h, m in rows}
            else:
                facts[pred] = sorted(",".join(row) for row in rows)
    return found


def compare(product: Path, transform: str, work: Path, base: dict[str, Any] | None = None,
            isolated: bool = True) -> tuple[list[str], dict[str, Any]]:
    """The differences of ``product`` changed by ``transform`` from it unchanged (imported
    in ``work``, each import ``isolated`` or not: :func:`run_import`; ``base``: the
    unchanged import's answers, when already known), and those."""
    if base is None:
        folder = work / "same"
        write_variant(product, VARIANTS["same"], folder)
        base = answers(*run_import(folder, "mm", isolated))
    variant = VARIANTS[transform]
    folder = work / transform
    renamed = write_variant(product, variant, folder)
    other = answers(*run_import(folder, variant.units, isolated))
    frame = _Frame(variant.quarter, {new: old for old, new in renamed.items()}, bool(variant.quarter))
    frame.ids |= hole_ids(base, other, frame)
    layout = not (variant.quarter or transform == "renamed")
    mine = canonical(_mapped_lp(_deep(base)), _Frame(0, turned=bool(variant.quarter)), layout)
    if variant.quarter:
        mine = _unturned_sections(mine)
    theirs = canonical(_mapped_lp(other), frame, layout)
    tied = _tied(mine, theirs)
    if variant.quarter:
        _reach_either(mine, theirs)
    return [f"tie: {pid} goes in along {mine['axes'][pid]['insertion']} unchanged, "
            f"{theirs['axes'][pid]['insertion']} changed (free both ways)" for pid in sorted(tied)
            ] + list(differences(_untied(mine, tied), _untied(theirs, tied))), base


def _tied(mine: dict[str, Any], theirs: dict[str, Any]) -> set[str]:
    """The parts of a turned product that go in along another axis, both free in both
    imports: a tie the import breaks in the cell's terms, legitimate: the arm reaches some
    insertions sideways and not others (:data:`executor.cad.derive.PREFERRED`), and a
    product alike seen from either way goes by the order of the cell's axes
    (:data:`executor.cad.derive.LEAVING`); otherwise the product's geometry chooses, the
    same however it is turned (:func:`executor.cad.derive.ways._way_out`)."""
    def leaves(axes: dict[str, Any], pid: str) -> set[str]:
        return set(axes[pid]["free"]) | {opposite(axes[pid]["insertion"])}
    return {pid for pid, axes in mine["axes"].items() if pid in theirs["axes"]
            and axes["insertion"] != theirs["axes"][pid]["insertion"]
            and leaves(mine["axes"], pid) == leaves(theirs["axes"], pid)
            and opposite(theirs["axes"][pid]["insertion"]) in axes["free"]}


def _reach_either(mine: dict[str, Any], theirs: dict[str, Any]) -> None:
    """Under a turn, each part placed by hand in both for a reason, one of which is the
    arm's measured reach (the cell frame's): the other reason taken for it (the reach is
    checked first, so where it fails turned it is the reason given)."""
    mine_manual = mine.get("geometry.toml", {}).get("manual", {})
    theirs_manual = theirs.get("geometry.toml", {}).get("manual", {})
    for pid in set(mine_manual) & set(theirs_manual):
        reasons = (mine_manual[pid].get("reason", ""), theirs_manual[pid].get("reason", ""))
        if any(reason.endswith(_REACH) for reason in reasons):
            mine_manual[pid]["reason"] = theirs_manual[pid]["reason"] = _REACH


def _untied(tree: dict[str, Any], tied: set[str]) -> dict[str, Any]:
    """``tree`` without what follows from the insertion axis of each ``tied`` part: the
    axis itself, its feature's entry (position, axis, entry height, depth), and the sense
    of the axes its reason for going by hand names (``along -y`` as ``along y``)."""
    tree = _deep(tree)
    geometry = tree.get("geometry.toml", {})
    for pid in tied:
        del tree["axes"][pid]
        manual = geometry.get("manual", {}).get(pid, {})
        if "reason" in manual:
            manual["reason"] = re.sub(r"(?<![\w.])[+-]([xyz])\b", r"\1", manual["reason"])
        features = [geometry.get("part_shapes", {}).get(pid, {}).get("demo_hole"),
                    *geometry.get("manual", {}).get(pid, {}).get("on", [])]
        for hid in filter(None, features):
            tree["assembly.toml"].get("holes", {}).get(hid, {}).pop("position", None)
            for key in ("axis", "top_z", "depth"):
                geometry.get("hole_shapes", {}).get(hid, {}).pop(key, None)
    return tree


def _deep(value: Any) -> Any:
    """A deep copy of a tree of dicts, lists and scalars."""
    if isinstance(value, dict):
        return {k: _deep(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_deep(v) for v in value]
    return value


def _unturned_sections(tree: Any) -> Any:
    """``tree`` with each section's orientation replaced by :func:`_turn_invariant` (the
    unchanged import's side of a comparison under a turn)."""
    if isinstance(tree, dict):
        if "kind" in tree or "outline" in tree:
            tree = _turn_invariant(tree)
        return {k: _unturned_sections(v) for k, v in tree.items()}
    if isinstance(tree, list):
        return [_unturned_sections(v) for v in tree]
    return tree


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m tests.cad.invariance", description=__doc__.split("\n\n")[0])
    parser.add_argument("--product", action="append", help="a corpus product (default: all)")
    parser.add_argument("--transform", action="append", choices=TRANSFORMS, help="default: all")
    parser.add_argument("--keep", type=Path, help="write the variants and their imports here (default: a temp folder)")
    args = parser.parse_args(argv)
    products = args.product or sorted(p.name for p in CORPUS.iterdir() if (p / "truth.toml").is_file())
    failed = 0
    for name in products:
        work = Path(tempfile.mkdtemp(prefix=f"invariance_{name}_")) if args.keep is None else args.keep / name
        write_variant(CORPUS / name, VARIANTS["same"], work / "same")
        try:
            base = answers(*run_import(work / "same", "mm"))
        except ImportFailed as exc:
            print(f"{name}: the unchanged product's import failed: {exc}", flush=True)
            failed += 1
            continue
        for transform in args.transform or TRANSFORMS:
            try:
                found, _ = compare(CORPUS / name, transform, work, base)
            except ImportFailed as exc:
                found = [f"import failed: {exc}"]
            wrong = [line for line in found if not line.startswith("tie:")]
            failed += bool(wrong)
            print(f"{name} {transform}: {'same' if not wrong else f'{len(wrong)} difference(s)'}", flush=True)
            for line in found:
                print(f"  {line}", flush=True)
        if args.keep is None:
            shutil.rmtree(work)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
