"""``precedence learn --prior FILE`` and an assembly folder's ``geometric_precedence.lp``:
the prior is data, read as ground facts, never grounded as a program."""

from __future__ import annotations

from pathlib import Path

import pytest

from asp import PlannerError
from asp.precedence.learn import GEOMETRIC_PRIOR, learn_for_assembly
from assembly_constraints.cli import main
from bridge.assembly import load_assembly

PRIOR = "part(base). part(a). part(b).\nmust_precede(base,a). must_precede(base,b).\n"


@pytest.mark.parametrize("line", ["part(1..50000000).", "must_precede(base,X) :- part(X), X != base.",
                                  "part(c;d).", "#const n = 3."])
def test_a_prior_that_is_a_program_is_one_line(tmp_path: Path, line: str, capsys: pytest.CaptureFixture[str]
                                               ) -> None:
    prior = tmp_path / GEOMETRIC_PRIOR
    prior.write_text(PRIOR + line + "\n")
    assert main(["precedence", "learn", "--prior", str(prior)]) == 2
    error = capsys.readouterr().err.strip().splitlines()
    assert len(error) == 1 and error[0].startswith(f"error: {prior}:3: "), error
    assert "expected part/1, must_precede/2 and precedence_edge/2 facts only" in error[0]
    (tmp_path / "assembly.toml").write_text("name = 't'\n" + "".join(
        f"[parts.{p}]\nname = '{p}'\n" for p in ("base", "a", "b")))
    with pytest.raises(PlannerError, match=f"{GEOMETRIC_PRIOR}:3: "):
        learn_for_assembly(load_assembly(str(tmp_path)))
