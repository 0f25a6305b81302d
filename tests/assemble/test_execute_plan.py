"""The planner's side of plan execution (asp.assemble): the step loop, the no_fit
observation of a failed step, re-planning from the current state, the stop with exit
code 3; against a fake cell that answers from the true sizes and a set of blocked holes."""

from __future__ import annotations

import json
import re

import pytest

from asp.assemble.cli import truth_facts
from asp.assemble.execute import AssemblyStopped, execute
from asp.plans.plans import Plan, PlanStep, check_plan, plans
from asp.precedence.relation import true_relation
from bridge.assembly import load_assembly
from bridge.messages import StepEvidence, StepReply
from tests.conftest import ROOT


class FakeCell:
    """Places a part when it fits the hole (true sizes) and the hole is not blocked."""

    def __init__(self, fits: frozenset[tuple[str, str]], blocked: set[str], manual: frozenset[str] = frozenset()
                 ) -> None:
        self.fits, self.blocked, self.manual = fits, blocked, manual
        self.placed: dict[str, str | None] = {}
        self.asked: list[tuple[int, str, str | None]] = []

    def step(self, number: int, part: str, hole: str | None) -> StepReply:
        self.asked.append((number, part, hole))
        ok = hole is None or ((part, hole) in self.fits and hole not in self.blocked)
        assert part not in self.placed, "a placed part was placed again"
        if ok:
            assert hole is None or hole not in self.placed.values(), "two parts in one hole"
            self.placed[part] = hole
        skill = "manual" if part in self.manual else "truth"
        evidence = StepEvidence(skill=skill, attempts=1 if ok else 2, max_force_dev=0.0, max_torque_dev=0.0,
                                duration_s=0.0, sim_time_s=0.0, pose_error_mm=0.0)
        return StepReply(id=f"s{number}", cell="fake", part=part, hole=hole, result="fit" if ok else "no_fit",
                         evidence=evidence, pose_errors_mm=tuple((p, 0.0) for p in sorted(self.placed)))


def _run(assembly: str, blocked: set[str], manual: frozenset[str] = frozenset()) -> tuple[dict, FakeCell]:
    facts = truth_facts(load_assembly(assembly))
    cell = FakeCell(facts.fits, blocked, manual)
    return execute(facts, plans(facts, n=1)[0], cell), cell


def test_the_default_cranfield_plan_is_executed_step_by_step() -> None:
    report, cell = _run("cranfield", set())
    assert report["assembled"] is True and report["replans"] == []
    assert [s["part"] for s in report["steps"]] == [s["part"] for s in report["plan"]]
    assert set(report["final_pose_error_mm"]) == set(cell.placed) and len(cell.placed) == 10
    json.dumps(report)  # the report is JSON


def test_the_parts_a_cell_places_by_hand_are_named_in_the_report() -> None:
    """A cell whose arm has no operation for the covers and the head (the Franka cell)
    answers their steps with skill manual: the report lists them, in step order."""
    report, _ = _run("cranfield", set(), frozenset({"sp", "pd", "ph", "fp"}))
    assert report["assembled"] is True
    assert report["manual"] == [s["part"] for s in report["steps"] if s["part"] in {"sp", "pd", "ph", "fp"}]
    assert len(report["manual"]) == 4 and _run("cranfield", set())[0]["manual"] == []


@pytest.mark.parametrize("assembly, blocked, spare, parts", [
    ("spare", "r1", "r3", 4),
    ("graded", "h7", "h3", 8),  # a d 12.8 mm hole of the default plan; its twin h3 is free
    ("graded", "h1", "h3", 8),  # the thinnest peg's hole: p1 goes into a looser one
])
def test_a_blocked_hole_is_replanned_into_the_spare_hole(assembly: str, blocked: str, spare: str, parts: int) -> None:
    report, cell = _run(assembly, {blocked})
    assert report["assembled"] is True
    assert report["replans"], "no re-plan recorded"
    for replan in report["replans"]:
        assert set(replan) == {"step", "reason", "plan"} and "no_fit" in replan["reason"]
    # Placed parts stayed placed: every new plan begins with what was done before it.
    facts = truth_facts(load_assembly(assembly))
    final = Plan(tuple(PlanStep(s["part"], s["hole"]) for s in report["final_plan"]))
    assert check_plan(facts, final.steps) == []
    assert blocked not in cell.placed.values() and spare in cell.placed.values() and len(cell.placed) == parts
    assert all(o["fact"].endswith(f",{blocked})") for o in report["observations"])


@pytest.mark.parametrize("hole", ["h4", "h5", "h6"])
def test_the_graded_board_with_a_blocked_large_hole_stops(hole: str) -> None:
    """p4..p6 have no alternative: the free hole is smaller than theirs."""
    with pytest.raises(AssemblyStopped) as stopped:
        _run("graded", {hole})
    assert "no complete assignment is left" in str(stopped.value) and stopped.value.report["assembled"] is False
    named = re.search(r"not solvable: parts? (.*?) fit", str(stopped.value)).group(1).split()
    assert named and set(named) <= {"p4", "p5", "p6"}, str(stopped.value)


@pytest.mark.parametrize("hole", ["r1", "s1", "br"])
def test_cranfield_with_a_blocked_hole_stops_naming_the_part_without_a_hole(hole: str) -> None:
    with pytest.raises(AssemblyStopped) as stopped:
        _run("cranfield", {hole})
    report = stopped.value.report
    assert report["assembled"] is False
    part = str(stopped.value).split("part ")[-1].split(" ")[0]
    assert part in {"p1", "p2", "p3", "p4", "sh"}, str(stopped.value)
    assert "placed parts stay where they are" in str(stopped.value)
    assert report["observations"][-1]["fact"].endswith(f",{hole})")


@pytest.mark.slow
def test_the_command_line_stops_with_exit_code_3(run_cli) -> None:
    done = run_cli("assemble", "--backend", "truth", "--block-hole", "s2", "--json", timeout=60)
    assert done.returncode == 3, done.stderr
    report = json.loads(done.stdout)
    assert report["assembled"] is False and "fewer holes than parts" in done.stderr


@pytest.mark.slow  # starts a truth cell
def test_a_plan_file_is_executed_as_written(run_main) -> None:
    """examples/taskboard-plan.json: the task board's pegs each in its own hole, in the file's
    order (not the order of the assembly's first plan)."""
    plan = ROOT / "examples" / "taskboard-plan.json"
    done = run_main("assemble", "--assembly", "taskboard", str(plan), "--backend", "truth", "--json", timeout=120)
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    assert report["assembled"] is True and not report["replans"]
    written = [(s["part"], s["hole"]) for s in json.loads(plan.read_text())]
    assert [(s["part"], s["hole"]) for s in report["steps"]] == written


@pytest.mark.parametrize("args, expected", [
    (("--block-hole", "zz"), "--block-hole zz: expected a hole"),
    (("missing.json",), "missing.json"),
    (("--run", "."), "session.json"),
])
def test_bad_input_exits_2_with_one_line(run_main, tmp_path, args, expected) -> None:
    done = run_main("assemble", "--backend", "truth", *args, cwd=tmp_path)
    assert done.returncode == 2, done.stderr
    assert expected in done.stderr and len(done.stderr.strip().splitlines()) == 1


@pytest.mark.slow
def test_assemble_and_bench_of_facts_files_respect_precedence_edges(run_cli) -> None:
    """The shipped precedence.lp holds precedence_edge/2 only: assemble and bench assemble
    of the facts files follow its closure."""
    files = [str(ROOT / "data" / "cranfield" / name) for name in ("sizes.lp", "precedence.lp")]
    truth = true_relation(load_assembly("cranfield"))
    done = run_cli("assemble", *files, "--backend", "truth", "--json", timeout=60)
    assert done.returncode == 0, done.stderr
    assert truth.admits([step["part"] for step in json.loads(done.stdout)["steps"]])
    done = run_cli("bench", "assemble", *files, "--plans", "3", "--backend", "truth", "--json", timeout=60)
    assert done.returncode == 0, done.stderr
    for report in json.loads(done.stdout)["plans"]:
        assert truth.admits([step["part"] for step in report["steps"]])
