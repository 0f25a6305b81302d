"""A part drawn as closed boxes whose faces touch (Blender objects) leaves cracks between
them where two faces meet not quite flat: a crack is no hole, while a slit wider than faces
that touch still is one."""

from __future__ import annotations

from pathlib import Path

import pytest
import trimesh

from executor.cad.cli import run_import

CORPUS = Path(__file__).parent / "corpus" / "pearl_peg_board" / "meshes"


def _as_the_source_has_it(text: str, keep: tuple[float, float] = (-1e9, 1e9)) -> str:
    """An OBJ of the corpus's ``pearl_peg_board`` (mm, z up) as its source draws it
    (metres, y up: (x, y, z) -> (x, z, -y) / 1000, back from SOURCE.md's change), the pegs
    stay turned over in their pockets; only the objects whose vertices lie within ``keep``
    [mm] along x, their faces renumbered."""
    kinds = ("v", "vt", "vn")
    records: list[list[str]] = [[]]
    for line in text.splitlines():
        if line.startswith("o "):
            records.append([])
        records[-1].append(line)
    seen = dict.fromkeys(kinds, 0)
    skipped = dict.fromkeys(kinds, 0)
    out: list[str] = []
    for record in records:
        xs = [float(line.split()[1]) for line in record if line.startswith("v ")]
        kept = bool(xs) and keep[0] <= min(xs) and max(xs) <= keep[1]
        for line in record:
            word, *rest = line.split()
            if word in kinds:
                seen[word] += 1
                skipped[word] += 0 if kept else 1
            if not kept:
                continue
            if word in ("v", "vn"):
                x, y, z = map(float, rest[:3])
                scale, digits = (1e-3, 6) if word == "v" else (1.0, 4)
                out.append(f"{word} {x * scale:.{digits}f} {z * scale:.{digits}f} {-y * scale:.{digits}f}")
            elif word == "f":
                out.append("f " + " ".join("/".join(str(int(index) - skipped[kind]) if index else ""
                                                    for index, kind in zip(corner.split("/"), kinds))
                                           for corner in rest))
            else:
                out.append(line)
    return "\n".join(out) + "\n"


@pytest.mark.slow
def test_the_crack_between_two_boxes_of_pearls_digit_2_block_is_no_hole(tmp_path: Path) -> None:
    # Two of the digit 2's block's objects meet along a slanted face, not quite flat in the
    # source's 6 decimals: their union keeps a crack of no width beside the pocket, a loop of
    # three points on a line at the peg's mid-depth. In metres with y up, as the source
    # draws it, the import took it for an empty hole closed all along and refused the board
    # ("the hole of part board at (582.376, -16.402, 100.000) mm is closed ...").
    folder = tmp_path / "meshes"
    folder.mkdir()
    (folder / "board.obj").write_text(_as_the_source_has_it((CORPUS / "board.obj").read_text(), (-50.0, 50.0)))
    (folder / "peg2.obj").write_text(_as_the_source_has_it((CORPUS / "peg2.obj").read_text()))
    config = tmp_path / "import.toml"
    config.write_text('base = "board"\nup = "+y"\n')
    derived = run_import(folder, tmp_path / "out", "m", config).derived
    holes = list(derived.holes.values())
    assert [hole.part for hole in holes] == ["peg2"]  # the pocket, the crack no hole
    assert holes[0].hole.kind == "polygon" and holes[0].hole.a == pytest.approx(0.057, abs=1e-5)


def test_a_slit_wider_than_a_touch_is_still_a_hole(tmp_path: Path) -> None:
    # A 20 x 0.05 mm slit through a block beside a peg's hole: too narrow for a part, but
    # wider than faces that touch (10 um), it is a hole the import measures (a pocket).
    folder = tmp_path / "meshes"
    folder.mkdir()
    block = trimesh.creation.box((60.0, 60.0, 20.0))
    bore = trimesh.creation.box((10.0, 10.0, 22.0))
    bore.apply_translation((-15.0, 0.0, 0.0))
    slit = trimesh.creation.box((20.0, 0.05, 22.0))
    slit.apply_translation((15.0, 0.0, 0.0))
    trimesh.boolean.difference([block, bore, slit], engine="manifold").export(folder / "block.stl")
    peg = trimesh.creation.box((9.0, 9.0, 20.0))
    peg.apply_translation((-15.0, 0.0, 5.0))
    peg.export(folder / "peg.stl")
    holes = sorted(run_import(folder, tmp_path / "out", "mm", None).derived.holes.values(), key=lambda h: h.centre)
    assert [hole.part for hole in holes] == ["peg", None]
    assert holes[1].hole.b == pytest.approx(5e-5, abs=2e-6)
