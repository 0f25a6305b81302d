"""``./run.sh sizes learn|evaluate``: JSON contract, facts output, bad input exits 2."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from asp.solve import atoms_by_name, load_atoms


def test_learn_json_follows_the_contract_and_writes_facts(tmp_path: Path, run_main) -> None:
    out = tmp_path / "learned.lp"
    done = run_main("sizes", "learn", "--assembly", "cranfield", "--policy", "systematic", "--json", "--out", str(out))
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    assert set(report) == {"policy", "model", "assumption", "model_changes", "experiments", "count", "fits"}
    assert report["policy"] == "systematic" and report["model"] == "line" and report["model_changes"] == []
    assert report["assumption"].startswith("size model line: every part and hole on one size line")
    assert report["count"] == len(report["experiments"]) == 25  # Fig. 5 in paper order: no entailment
    assert set(report["experiments"][0]) == {"part", "hole", "result"}
    assert ["sh", "br"] in report["fits"] and ["sh", "s1"] not in report["fits"] and len(report["fits"]) == 17
    atoms = load_atoms([out])
    assert len(atoms_by_name(atoms, "fits", 2)) == 17
    assert len(atoms_by_name(atoms, "tried", 4)) == 25
    assert atoms_by_name(atoms, "size_model", 1) == [("line",)]
    assert "% assumes: size model line" in out.read_text()


def test_learn_from_a_truth_file_keeps_its_order(tmp_path: Path, run_main) -> None:
    truth = tmp_path / "truth.lp"
    truth.write_text("part(big). part(small). hole(wide). hole(narrow).\n"
                     "fits(small,wide). fits(small,narrow). fits(big,wide).\n")
    report = json.loads(run_main("sizes", "learn", "--truth", str(truth), "--policy", "systematic", "--json").stdout)
    assert report["experiments"][0] == {"part": "big", "hole": "wide", "result": "fit"}
    assert sorted(map(tuple, report["fits"])) == [("big", "wide"), ("small", "narrow"), ("small", "wide")]


@pytest.mark.slow
def test_evaluate_json_follows_the_contract(tmp_path: Path, run_main) -> None:
    plot = tmp_path / "fig19.png"
    done = run_main("sizes", "evaluate", "--assembly", "cranfield", "--policy", "systematic", "--relabelings", "30",
                "--json", "--plot", str(plot), "--compare", "random")
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    assert set(report) == {"policy", "cases", "mean", "min", "min_share", "max", "max_share", "histogram"}
    assert report["cases"] == 30 == sum(report["histogram"].values())
    assert 15 <= report["min"] <= report["mean"] <= report["max"] <= 25
    assert report["histogram"][str(report["min"])] == round(report["min_share"] * 30)
    assert plot.stat().st_size > 1000


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("part(a;b). hole(x;y). fits(a,x). fits(b,y).", "not a biorder"),
        ("part(a). hole(x). fits(a,z).", "'z' is not a declared hole"),
        ("part(a). hole(x). fits(c,x).", "'c' is not a declared part"),
        ("part(a). hole(x) fits(a,x).", "does not parse"),
        ("fits(a,x).", "expected at least one part/1"),
    ],
)
def test_bad_truth_exits_2_with_a_clear_message(tmp_path: Path, text: str, message: str, run_main) -> None:
    truth = tmp_path / "truth.lp"
    truth.write_text(text + "\n")
    done = run_main("sizes", "learn", "--truth", str(truth))
    assert done.returncode == 2
    assert message in done.stderr and str(truth) in done.stderr
    assert "Traceback" not in done.stderr


@pytest.mark.parametrize(
    "args",
    [
        ["learn", "--assembly", "nowhere"],
        ["learn", "--assembly", "cranfield", "--policy", "psychic"],
        ["evaluate", "--assembly", "cranfield", "--policy", "systematic", "--relabelings", "many"],
        ["learn", "--truth", "/nonexistent/truth.lp"],
    ],
)
def test_bad_arguments_exit_2(args: list[str], run_main) -> None:
    done = run_main("sizes", *args)
    assert done.returncode == 2 and "Traceback" not in done.stderr and done.stderr.strip()


def test_assembly_sizes_with_an_undeclared_part_exits_2(tmp_path: Path, run_main) -> None:
    (tmp_path / "assembly.toml").write_text('[parts.a]\nname = "a"\n[holes.x]\nname = "x"\n')
    (tmp_path / "sizes.lp").write_text("part(a;ghost). hole(x). fits(a,x).\n")
    done = run_main("sizes", "learn", "--assembly", str(tmp_path))
    assert done.returncode == 2
    assert "ghost" in done.stderr and "assembly.toml" in done.stderr
