"""A product from its CAD, end to end through the console front: a STEP assembly made by
build123d (``examples/step_pegs.py``: a plate, a round peg and a rect peg at 30°) is
imported, its skills taught in the cell, learned by a session in physics (a PyBullet cell)
with the size prior of its nominal sections and assembled; with that prior a session needs
fewer experiments than without it (a truth session: the count is the planner's, whatever
cell answers) and learns the same relation."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from tests.cad.test_import import _fits
from tests.conftest import ROOT, Runner
from tests.session import exact_cell

ASSEMBLY_BOUND_MM = 2.0
"""The largest final pose error of an assembled part [mm]."""
TOLERANCE_M = "0.0005"
"""The prior's tolerance [m]: the rect peg's 0.3 mm room is left to the experiments."""


def _session(run: Runner, backend: str, *argv: str) -> dict:
    done = run("session", "--backend", backend, "--json", *argv, timeout=240)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


@pytest.mark.slow
def test_a_build123d_step_product_is_learned_in_physics_and_assembled(run_main: Runner, tmp_path: Path) -> None:
    step, product = tmp_path / "pegs.step", tmp_path / "pegs"
    subprocess.run([sys.executable, str(ROOT / "examples" / "step_pegs.py"), str(step)], check=True, timeout=120)
    for argv in (("import", str(step), "--out", str(product)), ("executor", "teach", "--assembly", str(product))):
        done = run_main(*argv)
        assert done.returncode == 0, done.stderr
    truth = _fits(product / "sizes.lp")
    assert truth == {("round_peg", "h1"), ("rect_peg", "h3")}

    plain = _session(run_main, "truth", "--assembly", str(product), "--out", str(tmp_path / "plain"))
    assert {tuple(pair) for pair in plain["fits"]} == truth and plain["prior"] is None

    # the prior decides every pair but the rect peg's 0.3 mm room in its slot: that one
    # observed in physics, then the plan assembled by the sim cell (the command in this
    # process, its cell another; a sim session's command as a process:
    # tests/session/test_mixed_sections.py), the cell without pose errors (exact_cell: the
    # cell's default uncertainty through a session is tests/session/test_session_sim.py's)
    run = tmp_path / "prior"
    prior = _session(run_main, "sim", "--assembly", str(product), "--prior", "cad", "--tolerance", TOLERANCE_M,
                     "--assemble", "--out", str(run), *exact_cell(tmp_path))
    assert {tuple(pair) for pair in prior["fits"]} == truth
    assert prior["experiments"] < plain["experiments"]
    decided = {(p, h): r for p, h, r in prior["prior"]["decided"]}
    assert prior["prior"]["pairs"] == 6 and len(decided) == 5 and ("rect_peg", "h3") not in decided
    assert all((r == "fit") == ((p, h) in truth) for (p, h), r in decided.items())
    journal = [json.loads(line) for line in (run / "journal.jsonl").read_text().splitlines()]
    assert {(e["part"], e["hole"]): e["result"] for e in journal if "result" in e} == {("rect_peg", "h3"): "fit"}
    assert json.loads((run / "session.json").read_text())["prior"] == prior["prior"]
    assert "% Assumes: the CAD prior (tolerance 0.5 mm) decides 5 of 6 pairs:" in (run / "learned.lp").read_text()
    report = prior["assembly"]
    assert report["assembled"] and set(report["final_pose_error_mm"]) == {"plate", "round_peg", "rect_peg"}
    assert "truth" not in {step["skill"] for step in report["steps"]}  # the sim cell's skills
    assert max(report["final_pose_error_mm"].values()) <= ASSEMBLY_BOUND_MM
