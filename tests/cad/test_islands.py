"""A pocket of the base with an island standing in it (PEARL's digits 0 and 4 over their
counters, corpus ``pearl_peg_board``) is a hole whose opening has a hole: a ring sunk in
it goes into it (not onto the island as onto a pin), and the fit relation decides every
part against the opening around the island."""

from __future__ import annotations

from pathlib import Path

import pytest
import trimesh

from executor.cad.cli import run_import
from tests.cad.test_mesh_import import _box

X_MM = 560.0
"""Where the block stands along x [mm]: within the simulated arm's reach."""


def _difference(*meshes: trimesh.Trimesh) -> trimesh.Trimesh:
    return trimesh.boolean.difference(list(meshes), engine="manifold")


def _block(folder: Path) -> None:
    """A 120 x 80 x 30 mm block with two 32 mm square pockets 20 deep, around a 12 mm and a
    16 mm square island flush with its top, and a 6 x 22 mm slot 20 deep; in them, flush,
    30 mm square rings of bore 14 and 18 mm (1 mm all round) and a 4 x 20 mm bar."""
    block = _difference(_box((120, 80, 30), (X_MM, 0, 15)), _box((32, 32, 22), (X_MM - 35, 0, 21)),
                        _box((32, 32, 22), (X_MM + 5, 0, 21)), _box((6, 22, 22), (X_MM + 40, 0, 21)))
    islands = [_box((12, 12, 20), (X_MM - 35, 0, 20)), _box((16, 16, 20), (X_MM + 5, 0, 20))]
    trimesh.boolean.union([block, *islands], engine="manifold").export(folder / "block.stl")
    for name, x, bore in (("narrow", X_MM - 35, 14.0), ("wide", X_MM + 5, 18.0)):
        _difference(_box((30, 30, 20), (x, 0, 20)), _box((bore, bore, 22), (x, 0, 20))).export(folder / f"{name}.stl")
    _box((4, 20, 20), (X_MM + 40, 0, 20)).export(folder / "bar.stl")


@pytest.mark.slow  # an import whose closed world measures 9 polygon pairs around islands (10 s of CPU)
def test_rings_sunk_in_pockets_around_islands_go_into_them_each_as_its_bore_passes_the_island(
        tmp_path: Path) -> None:
    # The import took each island for a pin and the ring onto it (the pocket around it no
    # hole: the bar's fits there unknown, and PEARL's digit 0 then fitted the digit 4's
    # island, not its pocket).
    folder = tmp_path / "cad"
    folder.mkdir()
    _block(folder)
    derived = run_import(folder, tmp_path / "out", "mm", None).derived
    assert not derived.pins
    found = {hole.part: (hid, hole) for hid, hole in derived.holes.items()}
    assert set(found) == {"narrow", "wide", "bar"}
    for ring in ("narrow", "wide"):
        _, hole = found[ring]
        assert hole.hole.kind == "polygon" and len(hole.hole.inner) == 1  # the island, cut out of its opening
        assert hole.section is not None and len(hole.section.inner) == 1  # the ring's bore
    ids = {part: hid for part, (hid, _) in found.items()}
    fits = set((tmp_path / "out" / "sizes.lp").read_text().replace(" ", "\n").splitlines())
    expected = {("narrow", "narrow"), ("wide", "wide"), ("bar", "bar"),
                ("wide", "narrow"),  # its 18 mm bore over the 12 mm island
                ("bar", "narrow"), ("bar", "wide")}  # beside the islands (10 and 8 mm for its 4)
    assert {line for line in fits if line.startswith("fits(")} == {
        f"fits({part},{ids[feature]})." for part, feature in expected}  # not the narrow ring over the 16 mm island
