"""The ablation table: one variant's line from trials' JSON (no simulation), and the
documented command through to its JSON on a reduced run."""

from __future__ import annotations

import json

import msgspec
import pytest

from bridge.cell_settings import Magnitudes
from executor.campaign.ablation import format_ablation, run_ablation, variant_row
from executor.campaign.pairs import CampaignPair
from executor.control.ilc import LAYERS
from tests.conftest import error_lines


def _trial(outcome: str, attempts: list[tuple[str, float, int]]) -> dict:
    """A trial's JSON with the fields the table reads: (outcome, max |dF| [N], wiggles) per attempt."""
    return {"outcome": outcome, "attempts": len(attempts), "duration_s": 1.0,
            "evidence": [{"outcome": o, "max_force_dev": f, "wiggles": w} for o, f, w in attempts]}


def test_force_past_stop_is_the_share_of_attempts_on_fitting_pairs_that_reached_f_stop():
    rows = [
        (True, 0, _trial("fit", [("fit", 5.0, 0)])),
        (True, 1, _trial("fit", [("no_fit", 30.0, 0), ("fit", 8.0, 0)])),  # stopped by eq. (6), then fitted
        (True, 2, _trial("fit", [("fit", 31.5, 1)])),  # jammed, freed by the wiggle
        (False, 0, _trial("no_fit", [("no_fit", 30.0, 0), ("no_fit", 30.0, 0)])),  # too big: not counted
    ]
    row = variant_row("position", rows, f_stop=30.0)
    assert row["force_past_stop"] == 2 / 4
    assert row["fitting_first_attempt"] == 2 / 3 and row["fitting_after_retry"] == 1.0
    assert row["wiggle_rescues"] == 1 and row["false_fits"] == 0
    ilc = {"executions": [1], "max_force_dev_median": [5.0], "first_attempt": [1.0],
           "without_ilc_max_force_dev_median": [5.0], "random_only_floor_max_force_dev_median": 5.0,
           "random_only_first_attempt": 1.0}
    table = format_ablation({"variants": [row], "ilc": ilc})
    assert "F>=stop" in table and " 0.500 " in table


@pytest.mark.slow
def test_the_documented_ablation_command_prints_its_json_on_a_reduced_run(run_main):
    """``bench executor --ablation --json`` through to its output, on one fitting pair and one
    execution per variant (six real trials): the JSON holds every layer and the magnitudes."""
    done = run_main("bench", "executor", "--ablation", "--trials", "1", "--executions", "1", "--seed", "7311",
                   "--pairs", "p1:r1", "--json", "--jobs", "1")
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    assert [v["name"] for v in report["variants"]] == list(LAYERS)
    assert report["perturbation"] == msgspec.to_builtins(Magnitudes())
    assert report["ilc"]["executions"] == [1] and set(report["ilc"]["by_pair"]) == {"p1:r1"}


def test_the_ablation_refuses_pairs_none_of_which_fits(run_main):
    done = run_main("bench", "executor", "--ablation", "--trials", "1", "--pairs", "p3:r1", "--json")
    lines = error_lines(done.stderr)
    assert done.returncode == 2 and len(lines) == 1 and "fitting pair" in lines[0], done.stderr


def test_each_ablation_run_in_process_uses_a_cell_of_its_own_product(monkeypatch: pytest.MonkeyPatch):
    """Two runs in one process (one worker): the second's trials are run by a cell of its
    product, not by the cell the first one made (no simulation: a cell that names its product)."""
    made: list[str] = []

    class NamedCell:
        def __init__(self, assembly: str) -> None:
            made.append(assembly)

        def reset_state(self, **_: object) -> None:
            pass

        def run_trial(self, part: str, hole: str, seed: int) -> object:
            trial = _trial("fit", [("fit", 1.0, 0)]) | {"part": part, "hole": hole}
            return type("Trial", (), {"to_json": lambda _self: trial})()

        def close(self) -> None:
            pass

    monkeypatch.setattr("executor.trial.Cell", NamedCell)
    for assembly in ("first", "second"):
        report = run_ablation(assembly, trials=1, seed=0, executions=1, workers=1, magnitudes=Magnitudes(),
                              pairs=[CampaignPair("p1", "r1", True)])
        assert [v["name"] for v in report["variants"]] == list(LAYERS)
    assert made == ["first", "second"]
