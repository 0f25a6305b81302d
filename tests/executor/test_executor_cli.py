"""The executor's command line: JSON contract, bad input → exit code 2 (in this process), Rerun file."""

from __future__ import annotations

import json
import shutil

import pytest


@pytest.mark.slow
def test_unknown_part_exits_2_naming_it(run_main):
    proc = run_main("executor", "trial", "--part", "zz", "--hole", "r1")
    assert proc.returncode == 2
    assert "unknown part 'zz'" in proc.stderr and "p1" in proc.stderr
    assert "Traceback" not in proc.stderr


@pytest.mark.slow
def test_unknown_hole_exits_2_naming_it(run_main):
    proc = run_main("executor", "trial", "--part", "p1", "--hole", "h9")
    assert proc.returncode == 2
    assert "unknown hole 'h9'" in proc.stderr


@pytest.mark.slow
def test_part_without_demonstration_exits_2(tmp_path, root, run_main):
    folder = tmp_path / "cell"
    shutil.copytree(root / "data" / "cranfield", folder, ignore=shutil.ignore_patterns("demonstrations"))
    proc = run_main("executor", "trial", "--part", "p1", "--hole", "r1", "--assembly", str(folder))
    assert proc.returncode == 2
    assert "no demonstration" in proc.stderr and "round_peg" in proc.stderr


@pytest.mark.slow
def test_trial_json_contract_and_rerun_file(tmp_path, run_main):
    rrd = tmp_path / "trial.rrd"
    proc = run_main("executor", "trial", "--part", "p4", "--hole", "s2", "--seed", "4", "--json", "--rrd", str(rrd))
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    trial = out["trials"][0]
    for key in ("outcome", "attempts", "max_force_dev", "max_torque_dev", "end_error", "duration_s"):
        assert key in trial
    assert trial["outcome"] == "fit"
    assert out["summary"]["trials"] == 1
    from bridge.recording.reader import read_recording

    entities = read_recording(rrd).entities
    assert any("wrench/force/measured" in path for path in entities)
    assert any("search/path" in path for path in entities)
