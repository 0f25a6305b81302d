"""``precedence learn --prior``: the geometric precedence as the prior Algorithm 1 refines."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from assembly_constraints.cli import main

PRIOR = "part(base). part(a). part(b). part(c).\nmust_precede(base,a). must_precede(base,b). must_precede(a,c).\n"


def _learn(capsys: pytest.CaptureFixture[str], *argv: str) -> dict:
    assert main(["precedence", "learn", *argv, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_the_prior_alone_and_refined(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    prior = tmp_path / "geometric_precedence.lp"
    prior.write_text(PRIOR)
    (tmp_path / "assembly.toml").write_text("name = 't'\n" + "".join(
        f"[parts.{p}]\nname = '{p}'\n" for p in ("base", "a", "b", "c")))
    alone = _learn(capsys, "--assembly", str(tmp_path), "--prior", str(prior))
    assert sorted(map(tuple, alone["must_precede"])) == [("a", "c"), ("base", "a"), ("base", "b"), ("base", "c")]
    demos = tmp_path / "demos.txt"
    demos.write_text("base a b c\nbase b a c\n")
    refined = _learn(capsys, str(demos), "--assembly", str(tmp_path), "--prior", str(prior))
    assert {tuple(p) for p in alone["must_precede"]} <= {tuple(p) for p in refined["must_precede"]}
    assert ("b", "c") in {tuple(p) for p in refined["must_precede"]}  # both demonstrations place b before c
    assert refined["admitted"] == 2


def test_a_demonstration_breaking_the_prior_is_wrong(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    prior = tmp_path / "geometric_precedence.lp"
    prior.write_text(PRIOR)
    demos = tmp_path / "demos.txt"
    demos.write_text("base a b c\nbase c a b\n")
    assert main(["precedence", "learn", str(demos), "--prior", str(prior)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"error: {demos}:2: a wrong demonstration: it breaks the geometric precedence a<c of {prior} "
                   "(the CAD admits no such order)"]


def _sizes_folder(tmp_path: Path) -> Path:
    """Two round pegs (d 10, 12 mm) and two round holes (d 10.3, 12.05 mm), as import writes them."""
    (tmp_path / "assembly.toml").write_text(
        "name = 't'\n[parts.a]\nname = 'a'\nshape = 'round'\n[parts.b]\nname = 'b'\nshape = 'round'\n"
        "[holes.h1]\nname = 'h1'\n[holes.h2]\nname = 'h2'\n")
    (tmp_path / "sizes.lp").write_text("part(a;b). hole(h1;h2). fits(a,h1). fits(a,h2). fits(b,h2).\n")
    (tmp_path / "nominal_sizes.lp").write_text(
        "nominal_margin(a,h1,300). nominal_margin(a,h2,2050). nominal_margin(b,h1,-1700). nominal_margin(b,h2,50).\n")
    return tmp_path


def test_the_cad_prior_leaves_the_pairs_within_the_tolerance(tmp_path: Path, capsys: pytest.CaptureFixture[str]
                                                              ) -> None:
    folder = _sizes_folder(tmp_path)
    without = _sizes(capsys, "--assembly", str(folder), "--model", "pairs")
    prior = _sizes(capsys, "--assembly", str(folder), "--model", "pairs", "--prior", "cad", "--tolerance", "0.0001")
    assert sorted(map(tuple, prior["prior"])) == [("a", "h1", "fit"), ("a", "h2", "fit"), ("b", "h1", "no_fit")]
    assert [(e["part"], e["hole"]) for e in prior["experiments"]] == [("b", "h2")]  # 50 µm: within 0.1 mm
    assert without["count"] == 4 and prior["count"] == 1 and prior["saved"] == 3
    assert sorted(map(tuple, prior["fits"])) == sorted(map(tuple, without["fits"])) == [
        ("a", "h1"), ("a", "h2"), ("b", "h2")]


def _sizes(capsys: pytest.CaptureFixture[str], *argv: str) -> dict:
    assert main(["sizes", "learn", *argv, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_the_cad_prior_needs_its_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    folder = _sizes_folder(tmp_path)
    (folder / "nominal_sizes.lp").write_text("nominal_margin(a,h1,wide).\n")
    assert main(["sizes", "learn", "--assembly", str(folder), "--prior", "cad"]) == 2
    assert "expected nominal_margin(Part,Hole,Micrometres) facts only" in capsys.readouterr().err
    assert main(["sizes", "learn", "--assembly", str(folder), "--tolerance", "0.001"]) == 2
    assert "--tolerance applies to --prior cad only" in capsys.readouterr().err


def test_an_assembly_folder_s_own_geometric_precedence_is_the_session_s_prior(tmp_path: Path) -> None:
    """:func:`learn_for_assembly` (what a session learns its precedence with): the folder's
    ``geometric_precedence.lp`` alone without demonstrations, refined by its ``demos.txt``,
    and a demonstration that breaks it refused naming its line."""
    from asp import PlannerError
    from asp.precedence.learn import GEOMETRIC_PRIOR, learn_for_assembly
    from bridge.assembly import load_assembly

    (tmp_path / GEOMETRIC_PRIOR).write_text(PRIOR)
    (tmp_path / "assembly.toml").write_text("name = 't'\n" + "".join(
        f"[parts.{p}]\nname = '{p}'\n" for p in ("base", "a", "b", "c")))
    demos, alone, prior = learn_for_assembly(load_assembly(str(tmp_path)))
    assert prior == tmp_path / GEOMETRIC_PRIOR and demos.sequences == ()
    assert set(alone.pairs()) == {("base", "a"), ("base", "b"), ("base", "c"), ("a", "c")}
    (tmp_path / "demos.txt").write_text("base a b c\nbase b a c\n")
    _, refined, _ = learn_for_assembly(load_assembly(str(tmp_path)))
    assert set(alone.pairs()) < set(refined.pairs()) and ("b", "c") in set(refined.pairs())
    (tmp_path / "demos.txt").write_text("base a b c\nbase c a b\n")
    with pytest.raises(PlannerError, match="demos.txt:2"):
        learn_for_assembly(load_assembly(str(tmp_path)))


@pytest.mark.slow  # the first session command of a process imports the session's stack (zenoh, rerun)
def test_a_session_refuses_a_tolerance_without_the_prior(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    folder = _sizes_folder(tmp_path)
    argv = ["session", "--backend", "truth", "--assembly", str(folder), "--out", str(tmp_path / "runs")]
    assert main([*argv, "--tolerance", "0.001"]) == 2
    assert capsys.readouterr().err.strip().splitlines() == ["error: --tolerance applies to --prior cad only"]
    (folder / "nominal_sizes.lp").unlink()
    assert main([*argv, "--prior", "cad"]) == 2
    assert capsys.readouterr().err.strip().splitlines() == [
        f"error: --prior cad: {folder}: no nominal_sizes.lp (expected an assembly folder ./run.sh import wrote)"]
    assert not (tmp_path / "runs").exists()
