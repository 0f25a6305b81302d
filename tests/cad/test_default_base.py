"""The default base: the part of largest volume; of alike ones (one part drawn again), the
lowest, the one the others stand on."""

from __future__ import annotations

from pathlib import Path

import trimesh

from executor.cad.cli import run_import


def test_of_alike_largest_parts_the_lowest_is_the_base(tmp_path: Path) -> None:
    # Three alike blocks stacked, staggered (a wall of bricks), their files named top to
    # bottom: the first of the largest by name (a_top) was the base, and the bottom block
    # went in from below it.
    folder = tmp_path / "meshes"
    folder.mkdir()
    for k, name in enumerate(["c_bottom", "b_middle", "a_top"]):
        block = trimesh.creation.box((30.0, 15.0, 10.0))
        block.apply_translation((15.0 * (k % 2), 0.0, 5.0 + 10.0 * k))
        block.export(folder / f"{name}.stl")
    done = run_import(folder, tmp_path / "out", "mm", None)
    assert done.derived.base == "c_bottom"
    assert any("base c_bottom (the largest part, the lowest of 3 alike" in line for line in done.assumed)
