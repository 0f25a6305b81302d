"""Parts without a tray in the import settings wait on trays laid out by their footprints:
no two overlap, each within the arm's reach and clear of the product where it stands, so
``import`` writes ``geometry.toml``; parts that find no such tray are named in one line."""

from __future__ import annotations

import itertools
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

from assembly_constraints.cli import main
from executor.cad.write.trays import REACH, TRAY_GAP, default_trays
from tests.cad.test_covers import _pegs_and_plate
from tests.cad.test_mesh_import import _box

X_MM = 560.0
"""Where the product stands along x [mm]: within the simulated arm's reach."""


def test_parts_larger_than_the_old_row_get_trays_apart_and_a_geometry(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A 120 x 20 mm lid lying on the two 12 mm pegs of a 120 x 80 mm plate, no tray set:
    a row of trays 5 cm apart put the lid over peg1 (no geometry.toml)."""
    _pegs_and_plate(tmp_path / "cad", (X_MM, 0.0))
    _box((120, 20, 4), (X_MM, 0, 37)).export(tmp_path / "cad" / "lid.stl")
    assert main(["-q", "import", str(tmp_path / "cad"), "--out", str(tmp_path / "out")]) == 0
    printed = capsys.readouterr().out
    assert "trays of lid, peg1, peg2, plate laid out by their footprints, 20.000 mm apart" in printed
    assert ", geometry.toml;" in printed and "overlap" not in printed
    parts = tomllib.loads((tmp_path / "out" / "assembly.toml").read_text())["parts"]
    trays = {pid: np.array(part["start"]) for pid, part in parts.items()}
    half = {"lid": (0.06, 0.01), "peg1": (0.006, 0.006), "peg2": (0.006, 0.006), "plate": (0.06, 0.04)}
    boxes = {pid: (trays[pid] - half[pid], trays[pid] + half[pid]) for pid in half}
    for a, b in itertools.combinations(sorted(boxes), 2):  # apart along x or y by the gap
        assert np.max(np.maximum(boxes[a][0], boxes[b][0]) - np.minimum(boxes[a][1], boxes[b][1])) >= TRAY_GAP - 1e-6
    standing = (np.array([X_MM / 1000 - 0.06, -0.04]), np.array([X_MM / 1000 + 0.06, 0.04]))
    for pid in ("lid", "peg1", "peg2"):
        assert REACH[0] <= math.hypot(*trays[pid]) <= REACH[1]
        assert np.max(np.maximum(boxes[pid][0], standing[0]) - np.minimum(boxes[pid][1], standing[1])) >= TRAY_GAP


def test_parts_that_find_no_tray_in_reach_are_named() -> None:
    """Twelve 30 cm squares: the arm's reach holds a few; the others are named and wait
    beyond, still apart."""
    square = (np.array([-0.15, -0.15]), np.array([0.15, 0.15]))
    boxes = {f"p{k:02d}": square for k in range(12)} | {"base": square}
    product = (np.array([0.46, -0.1]), np.array([0.66, 0.1]))
    trays, unreached = default_trays(boxes, {}, "base", product)
    assert 0 < len(unreached) < 12 and unreached == sorted(unreached)
    for pid in sorted(set(boxes) - set(unreached) - {"base"}):
        assert REACH[0] <= math.hypot(*trays[pid]) <= REACH[1]
    placed = [(np.array(trays[pid]) + square[0], np.array(trays[pid]) + square[1]) for pid in sorted(boxes)]
    for a, b in itertools.combinations([*placed, product], 2):
        assert np.max(np.maximum(a[0], b[0]) - np.minimum(a[1], b[1])) >= TRAY_GAP - 1e-9
