"""Alike holes of a corpus product are measured alike, whether a part stands in them or not:
``gridfinity_bases``' three rounded-square through pockets (two holding a bin's base) and
``asap_beam``'s four tapered through mortises (two holding an upright), each product's
truth calling its holes one shape."""

from __future__ import annotations

from pathlib import Path

import pytest

from executor.cad.cli import run_import

CORPUS = Path(__file__).parent / "corpus"


@pytest.mark.slow  # two imports: 10 to 40 s under load
@pytest.mark.parametrize(("name", "count"), [("gridfinity_bases", 3), ("asap_beam", 4)])
def test_alike_holes_occupied_or_empty_are_measured_alike(tmp_path: Path, name: str, count: int) -> None:
    # Each hole's section is the narrowest over the stretch a part goes in: through the
    # base, for an empty hole as for one whose part stands on the floor the base stands
    # on (gridfinity_bases: the 36.3 mm bottom opening; asap_beam: the mortise's narrow
    # end, 9.120 x 5.310 mm). Measured only from the level it is sliced at up, an empty
    # pocket was its 37.7 mm walls, an empty mortise 9.605 x 5.795 mm.
    folder = CORPUS / name
    holes = run_import(folder / "meshes", tmp_path / "out", "mm", folder / "import.toml").derived.holes
    assert len(holes) == count and 0 < sum(fit.part is None for fit in holes.values()) < count
    first, *others = holes.values()
    for fit in others:
        assert fit.hole.kind == first.hole.kind
        assert (fit.hole.a, fit.hole.b, fit.hole.corner, fit.chamfer, fit.depth) == pytest.approx(
            (first.hole.a, first.hole.b, first.hole.corner, first.chamfer, first.depth), abs=1e-7)
