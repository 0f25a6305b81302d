"""Real mini-campaigns on the PyBullet cell: two worker processes, fitting and
non-fitting pairs, Fig. 17/18 written, the Fig. 17 recording read back; the results
are the same on one worker or two (seeds do not depend on scheduling): outcomes exactly,
figures within the bounds of ``tests/_tolerances.py`` (the workers are other processes)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from bridge.recording.reader import column_values, read_recording
from tests._tolerances import END_BOUND, FORCE_BOUND

pytestmark = pytest.mark.slow  # real PyBullet campaigns, 10-15 s each


def test_mini_campaign_with_plots(tmp_path: Path, run_main) -> None:
    done = run_main("executor", "campaign", "--trials", "1", "--seed", "3", "--pairs", "p1:br,p3:r1", "--jobs", "2",
                    "--json", "--plot", str(tmp_path))
    assert done.returncode == 0, done.stdout + done.stderr
    report = json.loads(done.stdout)
    assert report["all_correct"] and report["false_fits"] == 0 and report["jobs"] == 2
    rows = {(p["part"], p["hole"]): p for p in report["pairs"]}
    assert rows[("p1", "br")]["after_second"] == 1 and rows[("p1", "br")]["fits"]
    assert rows[("p3", "r1")]["correct"] == 1 and not rows[("p3", "r1")]["fits"]

    for name in ("fig18_table.png", "fig17_forces.png"):
        assert (tmp_path / name).read_bytes()[:4] == b"\x89PNG"
    rrd = tmp_path / "fig17.rrd"
    entities = read_recording(rrd).under("executor/fig17")
    for name in ("scene", "tool/tip", "tool/path", "search/path", "wrench/force/measured",
                 "wrench/force/desired", "deviation/force", "outcome"):
        assert any(p.startswith(f"/executor/fig17/{name}") for p in entities), name
    assert entities["/executor/fig17/tool/tip"].rows > 100
    texts = [row[0] for row in column_values(rrd, "executor/fig17/outcome", "TextLog:text")]
    assert any(t.startswith("p1→r1") and ": fit " in t for t in texts)
    assert sum(1 for t in texts if t.startswith("p3→r1") and ": no_fit " in t) >= 1
    assert any("/by_phase/" in p for p in entities), "Fig. 17 series over the DMP phase"


def test_real_results_do_not_depend_on_scheduling() -> None:
    import functools

    from executor.campaign.pairs import select_pairs
    from executor.campaign.run import CellRunner, run_campaign, stdout_to_stderr

    pairs = select_pairs("tp:r1,p1:s1")  # fits, cheaper than blocked parts (no_fit: the campaign above)
    factory = functools.partial(CellRunner, "cranfield")
    with stdout_to_stderr():
        one = run_campaign(pairs, trials=2, seed=7, workers=1, factory=factory)
        two = run_campaign(pairs, trials=2, seed=7, workers=2, factory=factory)

    def outcomes(results: list[list[dict]]) -> list:
        return [[(r["outcome"], r["attempts"]) for r in row] for row in results]

    def figures(results: list[list[dict]]) -> np.ndarray:
        return np.array([[(r["max_force_dev"], r["end_error"]) for r in row] for row in results])

    assert outcomes(one) == outcomes(two)
    # Two workers are other processes: the figures within what cannot change an outcome.
    assert np.all(np.abs(figures(one) - figures(two)) < [FORCE_BOUND, END_BOUND])
    assert [r["outcome"] for row in one for r in row] == ["fit"] * 4
