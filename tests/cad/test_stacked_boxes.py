"""A product with no hole and no pin, three boxes stacked on each other (each part rests on
the one below): imported, it leaves nothing to learn, and ``plan``, ``session`` (truth and
sim backends) and ``assemble`` place its parts in the order the geometry forces, the two
boxes by hand (the cell has no operation that locates a part resting on a face)."""

from __future__ import annotations

import json
import math
import tomllib
from collections.abc import Callable
from pathlib import Path

import pytest
import trimesh

from assembly_constraints.cli import main
from executor.cad.cli import run_import
from tests.cad.conftest import manual_reasons
from tests.cad.test_closed_pockets import _write
from tests.conftest import Runner

ORDER = ["base", "lower", "upper"]


def _stack(folder: Path) -> None:
    """A 100 x 100 x 10 mm base, a 40 x 40 x 20 mm box on it and a 30 x 30 x 15 mm box on
    that one, as STL [mm]."""
    folder.mkdir()
    bottom = 0.0
    for name, (x, y, z) in zip(ORDER, ((100.0, 100.0, 10.0), (40.0, 40.0, 20.0), (30.0, 30.0, 15.0))):
        box = trimesh.creation.box((x, y, z))
        box.apply_translation((0.0, 0.0, bottom + z / 2))
        box.export(folder / f"{name}.stl")
        bottom += z


def _imported(tmp_path: Path, write: Callable[[Path], None]) -> Path:
    """The product ``write`` draws in ``tmp_path/cad``, imported quietly into ``tmp_path/out``."""
    write(tmp_path / "cad")
    out = tmp_path / "out"
    assert main(["-q", "import", str(tmp_path / "cad"), "--units", "mm", "--out", str(out)]) == 0
    return out


def _order(plan: list[dict]) -> list[tuple[str, str | None]]:
    return [(step["part"], step["hole"]) for step in plan]


def test_a_box_under_another_goes_in_from_above(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # Assembled, the lower box is free only sideways (the upper one sits on it), but it
    # supports the upper one, which every plan places after it: its way in is judged
    # with the upper box out, from above, and the pairs stay the base's and the support's.
    _stack(tmp_path / "cad")
    assert main(["import", str(tmp_path / "cad"), "--units", "mm", "--out", str(tmp_path / "out")]) == 0
    assert ("part lower: insertion axis -z (leaves along +z with upper out, placed after it); free in the "
            "assembled product along +x, -x, +y, -y") in capsys.readouterr().out
    derived = run_import(tmp_path / "cad", tmp_path / "again", "mm", None).derived
    assert derived.stages == [["lower", "upper"]]
    assert derived.axis == {"lower": "+z", "upper": "+z"}
    assert derived.reasons == {("base", "lower"): "base", ("lower", "upper"): "supports"}
    reasons = manual_reasons(tmp_path / "again")
    assert set(reasons) == {"lower", "upper"} and not any("not from above" in why for why in reasons.values())


def test_a_product_with_no_hole_is_planned_by_least_travel(tmp_path: Path, run_main: Runner) -> None:
    # With no hole there is no centre of the holes: each part is carried to the base's
    # centre in the cell (base_center of [plate]), the one order's cost its straight legs
    # from home (the cell origin) to each start, on to that centre, and back, whole mm each.
    out = _imported(tmp_path, _stack)
    done = run_main("plan", str(out / "sizes.lp"), str(out / "geometric_precedence.lp"), "--assembly", str(out),
                    "--optimal", "--json")
    assert done.returncode == 0, done.stderr
    result = json.loads(done.stdout)
    assert [_order(plan) for plan in result["plans"]] == [[(part, None) for part in ORDER]]
    starts = {pid: part["start"] for pid, part in tomllib.loads((out / "assembly.toml").read_text())["parts"].items()}
    centre = tomllib.loads((out / "geometry.toml").read_text())["plate"]["base_center"]
    stops = [[0.0, 0.0]] + [point for pid in ORDER for point in (starts[pid], centre)] + [[0.0, 0.0]]
    assert result["cost"] == sum(round(1000 * math.dist(a, b)) for a, b in zip(stops, stops[1:]))


@pytest.mark.slow
def test_stacked_boxes_are_planned_learned_and_assembled(tmp_path: Path, run_main: Runner,
                                                        capsys: pytest.CaptureFixture[str]) -> None:
    out = _imported(tmp_path, _stack)
    assert "no hole and no pin found: sizes.lp names no part and no hole, nothing to learn" in capsys.readouterr().out
    done = run_main("plan", str(out / "sizes.lp"), str(out / "geometric_precedence.lp"), "--assembly", str(out),
                    "--json", "-n", "0")
    assert done.returncode == 0, done.stderr
    assert [_order(plan) for plan in json.loads(done.stdout)["plans"]] == [[(part, None) for part in ORDER]]
    for backend in ("truth", "sim"):
        run = tmp_path / f"run-{backend}"
        done = run_main("session", "--backend", backend, "--json", "--assemble", "--assembly", str(out), "--out",
                        str(run), timeout=240)
        assert done.returncode == 0, done.stderr
        result = json.loads(done.stdout)
        assert result["experiments"] == 0 and result["fits"] == []
        assert "nothing to learn" in result["assumption"]
        assert [_order(plan) for plan in result["plans"]] == [[(part, None) for part in ORDER]]
        assert result["must_precede"] == [["base", "lower"], ["base", "upper"], ["lower", "upper"]]
        report = result["assembly"]
        assert report["assembled"] and "error" not in report, report
        assert [step["skill"] for step in report["steps"]][1:] == ["manual", "manual"]
    done = run_main("assemble", "--run", str(tmp_path / "run-sim"), "--backend", "truth", "--json", timeout=120)
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["assembled"]


@pytest.mark.slow
def test_an_empty_hole_with_no_peg_leaves_nothing_to_learn(tmp_path: Path, run_main: Runner,
                                                          capsys: pytest.CaptureFixture[str]) -> None:
    # A block with an empty d 8 hole through it and a plate lying on its top: sizes.lp names
    # the hole and no part, which the session refused ("expected at least one part/1 and one hole/1").
    out = _imported(tmp_path, _write)
    assert "no part in a hole or on a pin: sizes.lp names no part, nothing to learn" in capsys.readouterr().out
    done = run_main("session", "--backend", "truth", "--json", "--assemble", "--assembly", str(out), "--out",
                    str(tmp_path / "run"), timeout=120)
    assert done.returncode == 0, done.stderr
    result = json.loads(done.stdout)
    assert result["experiments"] == 0 and "nothing to learn" in result["assumption"]
    assert [_order(plan) for plan in result["plans"]] == [[("block", None), ("plate", None)]]
    assert result["assembly"]["assembled"]
