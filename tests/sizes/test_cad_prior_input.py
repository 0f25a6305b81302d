"""``sizes learn --prior cad``: the prior's ``nominal_sizes.lp`` is data, read as ground
facts (never grounded as a program), one margin per pair, over the product's parts and
holes; anything else is one line naming the file and line, exit 2, before any experiment."""

from __future__ import annotations

from pathlib import Path

import pytest

from assembly_constraints.cli import main

MARGINS = ["nominal_margin(a,h1,300).", "nominal_margin(a,h2,2050).", "nominal_margin(b,h1,-1700).",
           "nominal_margin(b,h2,50)."]


def _folder(tmp_path: Path, margins: list[str]) -> Path:
    """Two round pegs and two round holes with the prior ``margins`` (one fact a line)."""
    (tmp_path / "assembly.toml").write_text(
        "name = 't'\n[parts.a]\nname = 'a'\nshape = 'round'\n[parts.b]\nname = 'b'\nshape = 'round'\n"
        "[holes.h1]\nname = 'h1'\n[holes.h2]\nname = 'h2'\n")
    (tmp_path / "sizes.lp").write_text("part(a;b). hole(h1;h2). fits(a,h1). fits(a,h2). fits(b,h2).\n")
    (tmp_path / "nominal_sizes.lp").write_text("\n".join(margins) + "\n")
    return tmp_path


def _refused(capsys: pytest.CaptureFixture[str], folder: Path) -> str:
    capsys.readouterr()
    assert main(["sizes", "learn", "--assembly", str(folder), "--prior", "cad", "--tolerance", "0.0001"]) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), captured.err
    assert "saved" not in captured.out and "->" not in captured.out  # no experiment ran
    return lines[0]


@pytest.mark.parametrize("program", [
    "nominal_margin(a,h1,1..50000000).",  # grounded, an interval is fifty million facts
    "n(1..50000000).",
    "nominal_margin(a,h1,300;400).",
    "nominal_margin(a,h1,X) :- X = 300.",
    "nominal_margin(a,h1,299+1).",
    "#const m = 300.",
    "nominal_margin(a,h1,300) :- part(a).",
])
def test_a_prior_that_is_a_program_rather_than_facts_is_one_line(tmp_path: Path, program: str,
                                                                   capsys: pytest.CaptureFixture[str]) -> None:
    folder = _folder(tmp_path, [*MARGINS[1:], program])
    error = _refused(capsys, folder)
    assert error.startswith(f"error: {folder / 'nominal_sizes.lp'}:4: ")
    assert "expected nominal_margin(Part,Hole,Micrometres) facts only" in error


def test_two_margins_for_one_pair_are_refused_naming_both_lines(tmp_path: Path,
                                                                capsys: pytest.CaptureFixture[str]) -> None:
    folder = _folder(tmp_path, [*MARGINS, "nominal_margin(b,h1,900)."])  # b passes h1 by 0.9 mm, and not
    error = _refused(capsys, folder)
    assert error == (f"error: {folder / 'nominal_sizes.lp'}:5: nominal_margin(b,h1,900) contradicts line 3: "
                     "nominal_margin(b,h1,-1700); expected one margin per part and hole")


def test_a_prior_naming_a_part_or_hole_the_product_lacks_is_refused(tmp_path: Path,
                                                                    capsys: pytest.CaptureFixture[str]) -> None:
    folder = _folder(tmp_path, [*MARGINS, "nominal_margin(c,h1,100)."])
    error = _refused(capsys, folder)
    assert error.startswith(f"error: {folder / 'nominal_sizes.lp'}:{len(MARGINS) + 1}: unknown part or hole c")
    assert "parts a b and holes h1 h2" in error
    error = _refused(capsys, _folder(tmp_path, [*MARGINS, "nominal_margin(a,h9,100)."]))
    assert "unknown part or hole h9" in error


def test_a_margin_stated_twice_alike_is_one_margin(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    folder = _folder(tmp_path, [*MARGINS, MARGINS[2], "% a comment", "nominal_margin( b , h2 , 50 )."])
    assert main(["sizes", "learn", "--assembly", str(folder), "--prior", "cad", "--tolerance", "0.0001"]) == 0
    assert "the CAD prior (tolerance 0.1 mm) decides 3 of 4 pairs" in capsys.readouterr().out
