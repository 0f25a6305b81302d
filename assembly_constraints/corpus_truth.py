"""A corpus product (``tests/cad/corpus/<name>/``) imported and set against its truth.

A corpus folder holds the product's meshes in the assembled pose (``meshes/``, mm), the
import settings (``import.toml``) and ``truth.toml``, derived by hand from the source's
drawing, not from the import: the features that receive parts (holes, pins) with their
owner, kind and axis line [mm, CAD frame], and which part fits which feature
(``fits = [{part, feature, fits, room_mm}, ...]``, closed world), and each part's
feature (``in``) with the further ones it goes into at once (``also_in``: a clutch plate
onto its shaft, its splined outside into the outer holder's hole). The import names holes
its own way (``h1``, ``table_pin1``): :func:`feature_holes` finds the imported hole of
each truth feature by its owner, its kind and its axis, so a relation learned over the
import's ids (``fits(P,H)``) can be compared with the truth (:func:`compare_fits`).
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Collection, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from bridge.errors import ToolError
from bridge.inputs import read_text
from executor.cad.cli import run_import
from executor.cad.derive import HoleFit
from executor.cad.operations.arm import turned_axis, turned_xy
from executor.cad.sweep import opposite

FEATURE_REACH_MM = 2.0
"""An imported hole is a truth feature when its position lies this close to the feature's axis [mm]."""


class TruthError(ToolError):
    """A corpus folder's ``truth.toml`` or layout is not what this module reads."""


@dataclass(frozen=True)
class CorpusImport:
    """A corpus product as ``import`` wrote it: its ``truth``, the ``out`` folder, each
    moving part's insertion ``axes`` (the reverse of the direction it leaves along) in the
    CAD frame (its truth's), the ``offset`` (x, y, z) [m] the import moved it by into the
    cell after turning it ``turn`` [deg] about z, each imported hole's or pin's
    ``occupants`` (the parts in it or onto it) and ``owners`` (the part it is a feature
    of), the ids that are ``pins``, the product's ``parts`` (the base included), the
    import's wall time ``seconds``, the base's ``holes`` as the import measured them
    (their sections, chamfers and depths [m], in the cell frame) and each hole's or pin's
    axis ``lines``."""

    truth: dict[str, Any]
    out: Path
    axes: dict[str, str]
    offset: tuple[float, float, float]
    occupants: dict[str, set[str]]
    owners: dict[str, str]
    pins: frozenset[str] = frozenset()
    parts: int = 0
    seconds: float = 0.0
    holes: Mapping[str, HoleFit] = field(default_factory=dict)
    turn: int = 0
    lines: Mapping[str, str] = field(default_factory=dict)
    """Each imported hole's or pin's axis in the CAD frame, its letter (``x``, ``y``, ``z``)."""


def read_truth(folder: Path) -> dict[str, Any]:
    """``folder/truth.toml``; TruthError (one line, the file and what is missing) where it
    is no TOML or lacks the ``base``, ``features``, ``parts`` or ``fits`` the comparison reads."""
    path = folder / "truth.toml"
    try:
        truth = tomllib.loads(read_text(path, "corpus truth (TOML)", error=TruthError))
    except tomllib.TOMLDecodeError as exc:
        raise TruthError(f"{path}: {exc}") from None
    for key, kind in (("base", str), ("features", dict), ("parts", dict), ("fits", list)):
        if not isinstance(truth.get(key), kind):
            raise TruthError(f"{path}: expected {key} ({kind.__name__})")
    for number, row in enumerate(truth["fits"], 1):
        if not (isinstance(row, dict) and isinstance(row.get("part"), str) and row.get("feature") in truth["features"]
                and isinstance(row.get("fits"), bool)):
            raise TruthError(f"{path}: fits row {number}: expected {{part, feature (one of features), fits (bool)}}")
    for pid, part in truth["parts"].items():
        if not isinstance(part, dict):
            raise TruthError(f"{path}: parts.{pid}: expected a table")
        also = part.get("also_in", [])
        if not (isinstance(also, list) and all(fid in truth["features"] for fid in also)):
            raise TruthError(f"{path}: parts.{pid}.also_in: expected a list of features")
    return truth


def import_product(folder: Path, out: Path) -> CorpusImport:
    """Import ``folder/meshes`` (mm) with ``folder/import.toml`` into ``out`` (as
    ``import meshes/ --config import.toml --out OUT`` does) and read its truth."""
    truth = read_truth(folder)
    result = run_import(folder / "meshes", out, "mm", folder / "import.toml")
    derived = result.derived
    holes = derived.holes | derived.part_holes
    occupants = {hid: set(fit.occupants) for hid, fit in holes.items() if fit.occupants}
    occupants |= {pid: set(pin.parts) for pid, pin in derived.pins.items()}
    owners = {hid: fit.owner or derived.base for hid, fit in holes.items()}
    owners |= {pid: pin.owner for pid, pin in derived.pins.items()}
    axes = {hid: fit.axis for hid, fit in holes.items()} | {pid: pin.axis for pid, pin in derived.pins.items()}
    lines = {hid: turned_axis(axis, -result.turn)[1] for hid, axis in axes.items()}
    return CorpusImport(truth, out, {pid: turned_axis(opposite(leaves), -result.turn)
                                     for pid, leaves in derived.axis.items()},
                        result.offset, occupants, owners, frozenset(derived.pins), len(derived.parts), result.seconds,
                        derived.holes, result.turn, lines)


def distance_to_axis(position: list[float], feature: dict[str, Any], offset: tuple[float, float, float],
                     turn: int = 0) -> float:
    """How far an imported hole's ``position`` [m] (x, y, or x, y, z, in the cell, turned
    ``turn`` [deg] about z from the CAD frame, then moved by ``offset`` [m]) lies from a
    truth feature's axis line [mm]; with x, y only, from the line's projection on the xy plane."""
    point = [1000.0 * (v - offset[k]) for k, v in enumerate(position)]
    point[:2] = turned_xy(point[0], point[1], -turn % 360)
    origin = feature["axis_point"][:len(point)]
    direction = {"x": 0, "y": 1, "z": 2}[feature["axis"][1]]
    across = [point[k] - origin[k] for k in range(len(point)) if k != direction]
    return math.hypot(*across)


def features_of(part: dict[str, Any]) -> list[str]:
    """The truth features a part of ``truth.toml`` goes into or onto: its ``in`` (none: a
    part in no feature), then its ``also_in``."""
    return ([part["in"]] if "in" in part else []) + list(part.get("also_in", []))


def feature_holes(done: CorpusImport) -> dict[str, str]:
    """Each truth feature's imported hole id (absent: none found): the one of the
    feature's owner on its axis (along it: a bracket's flange hole under its horizontal
    bore, on the bore's line as seen from above, is not it) that is a pin where the
    feature is one (of a hollow shaft's bore and the shaft, the shaft); of several (the
    two ends of one rod), the one that is empty or holds a part the truth puts in that feature."""
    holes = tomllib.loads((done.out / "assembly.toml").read_text()).get("holes", {})
    found = {}
    for fid, feature in done.truth["features"].items():
        inside = {pid for pid, part in done.truth["parts"].items() if fid in features_of(part)}
        near = [hid for hid, hole in holes.items() if done.owners.get(hid) == feature["owner"]
                and distance_to_axis(hole["position"], feature, done.offset, done.turn) <= FEATURE_REACH_MM
                and done.lines.get(hid, feature["axis"][1]) == feature["axis"][1]
                and (hid in done.pins) == (feature["kind"] == "pin")]
        if len(near) > 1:
            near = [hid for hid in near if not done.occupants.get(hid) or done.occupants[hid] & inside]
        if len(near) == 1:
            found[fid] = near[0]
    return found


@dataclass
class FitCount:
    """A learned fit relation against the truth's rows: ``ok`` rows learned as the truth
    has them, ``wrong`` ones (part, imported hole), ``missing`` ones (``part->feature``:
    the feature not found by the import, or the pair not learned either way);
    ``pairs`` maps each compared row's (part, imported hole) to whether the truth has it fit."""

    ok: int = 0
    wrong: list[tuple[str, str]] = field(default_factory=list)
    missing: list[str] = field(default_factory=list)
    pairs: dict[tuple[str, str], bool] = field(default_factory=dict)

    @property
    def total(self) -> int:
        return self.ok + len(self.wrong) + len(self.missing)

    def describe(self, pair: tuple[str, str]) -> str:
        """A wrong pair in words: what was learned, what the truth has."""
        fits = self.pairs[pair]
        return f"{pair[0]}->{pair[1]} learned {'no_fit' if fits else 'fit'}, the truth {'fit' if fits else 'no_fit'}"

    def as_json(self) -> dict[str, Any]:
        return {"ok": self.ok, "total": self.total, "wrong": [self.describe(pair) for pair in self.wrong],
                "missing": self.missing}


def compare_fits(done: CorpusImport, holes: dict[str, str], fits: Collection[tuple[str, str]],
                 no_fits: Collection[tuple[str, str]]) -> FitCount:
    """A learned relation (``fits``, ``no_fits``: the pairs it decided) against each truth
    row, its feature taken as ``holes`` maps it (:func:`feature_holes`); a pair decided
    neither way (its part or hole outside what was learned) is missing."""
    count = FitCount()
    for row in done.truth["fits"]:
        part, hole = row["part"], holes.get(row["feature"])
        if hole is None or ((part, hole) not in fits and (part, hole) not in no_fits):
            count.missing.append(f"{part}->{row['feature']}" + ("" if hole is None else f" ({hole})"))
            continue
        count.pairs[part, hole] = row["fits"]
        if ((part, hole) in fits) == row["fits"]:
            count.ok += 1
        else:
            count.wrong.append((part, hole))
    return count
