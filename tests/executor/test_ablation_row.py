"""One variant's line of the ablation table, from trials' JSON (no simulation)."""

from __future__ import annotations

from assembly_constraints.executor.campaign.ablation import format_ablation, variant_row


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
