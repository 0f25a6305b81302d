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
