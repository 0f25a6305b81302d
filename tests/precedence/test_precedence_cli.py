"""The ``precedence`` command line: JSON contracts, files written, help."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from asp.precedence.relation import load_relation, true_relation
from bridge.assembly import load_assembly


@pytest.mark.slow
def test_learn_json_facts_dot_png_and_count_of_the_facts(tmp_path: Path, root: Path, run_main) -> None:
    out, dot, png = tmp_path / "learned.lp", tmp_path / "g.dot", tmp_path / "g.png"
    result = run_main("precedence", "learn", str(root / "data/battery/demos.txt"), "--json",
                     "--out", str(out), "--dot", str(dot), "--png", str(png))
    assert result.returncode == 0, result.stderr
    data = json.loads(result.stdout)
    assert set(data) == {"parts", "must_precede", "reduction", "admitted"}
    assert data["admitted"] == 5
    assert ["r2", "i1"] in data["reduction"] and ["o", "i1"] not in data["reduction"]
    assert set(load_relation([out]).pairs()) == {tuple(p) for p in data["must_precede"]}
    assert '"o" -> "i1" [color=grey' in dot.read_text() and '"r2" -> "i1";' in dot.read_text()
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    counted = run_main("precedence", "count", str(out), "--json")
    assert json.loads(counted.stdout) == {"admitted": 5}


def test_count_and_sample_from_the_assembly(root: Path, run_main) -> None:
    counted = run_main("precedence", "count", "--assembly", "cranfield", "--json")
    assert json.loads(counted.stdout) == {"admitted": 5320}
    sampled = run_main("precedence", "sample", "--assembly", "cranfield", "-n", "20", "--seed", "9")
    again = run_main("precedence", "sample", "--assembly", str(root / "data/cranfield"), "-n", "20", "--seed", "9")
    lines = sampled.stdout.split("\n")[:-1]
    assert len(lines) == 20 and sampled.stdout == again.stdout
    truth = true_relation(load_assembly("cranfield"))
    assert all(truth.admits(line.split()) for line in lines)


@pytest.mark.slow
def test_evaluate_json_plot_and_guided_keys(tmp_path: Path, run_main) -> None:
    plot = tmp_path / "fig12.png"
    result = run_main("precedence", "evaluate", "--assembly", "cranfield", "--demonstrations", "5,20",
                      "--trials", "200", "--json", "--plot", str(plot))
    data = json.loads(result.stdout)
    assert set(data) == {"total", "generator", "trials", "results"} and data["generator"] == "uniform"
    assert [set(r) for r in data["results"]] == [{"m", "mean", "p_all", "p_more_than_half", "histogram"}] * 2
    assert plot.read_bytes()[:4] == b"\x89PNG"
    guided = json.loads(
        run_main("precedence", "evaluate", "--assembly", "battery", "--guided", "--trials", "50", "--json").stdout)
    assert set(guided) == {"total", "demos_to_exact", "mean", "random_mean"}
    assert guided["total"] == 6


def test_suggest_proposes_every_part_once(root: Path, run_main) -> None:
    result = run_main("precedence", "suggest", str(root / "data/battery/demos.txt"), "--json")
    data = json.loads(result.stdout)
    assert sorted(data["suggestion"]) == sorted(["o", "r1", "r2", "i1", "i2"])
    learned = [["o", x] for x in ("r1", "r2", "i1", "i2")] + [["r1", "i1"], ["r2", "i1"], ["r2", "i2"]]
    assert data["undecided"] and all(pair in learned for pair in data["undecided"])


@pytest.mark.parametrize("command", ["learn", "count", "enumerate", "sample", "evaluate", "suggest"])
def test_every_subcommand_has_help(command: str, run_main) -> None:
    result = run_main("precedence", command, "--help")
    assert result.returncode == 0 and "usage:" in result.stdout


def test_count_needs_exactly_one_source(run_main) -> None:
    result = run_main("precedence", "count")
    assert result.returncode == 2 and "expected either --assembly A or facts files" in result.stderr


def test_learn_evidence_flags_a_wrong_demonstration_and_min_support_keeps_its_constraint(
    tmp_path: Path, run_main
) -> None:
    path = tmp_path / "demos.txt"
    path.write_text("o r1 i1 r2 i2\no r2 i2 r1 i1\no r1 i1 r2 i2\no r2 i2 r1 i1\no i1 r1 r2 i2\n")
    result = run_main("precedence", "learn", str(path), "--json", "--evidence", "--min-support", "2")
    data = json.loads(result.stdout)
    assert set(data) == {"parts", "must_precede", "reduction", "admitted", "evidence", "suspects"}
    assert data["suspects"] == [{"line": f"{path}:5", "removes": [["r1", "i1"]]}]
    assert ["r1", "i1"] in data["must_precede"] and data["admitted"] == 6
    assert {"pair": ["r1", "i1"], "support": 4, "contradict": 1} in data["evidence"]
    assert f"warning: {path}:5:" in result.stderr
