"""A session with truth cells on a product that stacks a bush and a gear onto one pin
(``capacity = 2`` in its ``assembly.toml``): it learns, assigns both to the pin and plans
the bush before the gear, and ``assemble`` takes its plan."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tests.plans.test_stacked_holes import stacked_product


@pytest.mark.slow
def test_a_session_plans_two_parts_onto_one_pin_the_lower_first(run_session, run_main, tmp_path: Path) -> None:
    product = stacked_product(tmp_path / "stacked")
    run = tmp_path / "run"
    result = run_session("--assembly", str(product), "--out", str(run), "--plans", "3")
    assert len(result["plans"]) == 3
    for plan in result["plans"]:
        order = [step["part"] for step in plan]
        assert {step["part"]: step["hole"] for step in plan} == {"bp": None, "bush": "pin", "gear": "pin",
                                                                 "peg": "hole"}
        assert order.index("bush") < order.index("gear")
    assert "capacity(pin,2)." in (run / "learned.lp").read_text()
    done = run_main("assemble", "--run", str(run), "--backend", "truth", "--json", timeout=120)
    report = json.loads(done.stdout)
    assert done.returncode == 0 and report["assembled"] and report["plan"] == result["plans"][0]
    assert [step["hole"] for step in report["steps"] if step["part"] in ("bush", "gear")] == ["pin", "pin"]
