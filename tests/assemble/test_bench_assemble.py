"""``bench assemble``: plans drawn uniformly from a precedence relation, each with a
hole assignment, assembled in fresh cells; a part more than 2 mm from its goal counts as a
failure. Two drawn plans in two truth cells at once: ``tests/test_jobs.py``."""

from __future__ import annotations

from asp.assemble.cli import truth_facts
from asp.bench.assemble_plans import draw_plans, summary
from asp.plans.plans import check_plan
from asp.precedence.relation import true_relation
from bridge.assembly import load_assembly


def test_drawn_plans_pass_the_checker_and_the_seed_reproduces_them() -> None:
    cranfield = load_assembly("cranfield")
    facts = truth_facts(cranfield)
    drawn = draw_plans(facts, 20, seed=3)
    assert len(drawn) == 20
    relation = true_relation(cranfield)
    for plan in drawn:
        assert check_plan(facts, plan.steps) == []
        assert relation.admits([s.part for s in plan.steps])
        assert {s.part for s in plan.steps} == set(facts.parts)
    assert draw_plans(facts, 20, seed=3) == drawn
    assert draw_plans(facts, 20, seed=4) != drawn
    # Sequences and assignments both vary (5320 sequences, 4 assignments on Cranfield).
    assert len({tuple(s.part for s in p.steps) for p in drawn}) >= 15
    assert len({tuple(sorted((s.part, s.hole) for s in p.steps if s.hole)) for p in drawn}) >= 2


def test_the_summary_counts_a_part_beyond_2_mm_as_a_failure() -> None:
    def report(assembled: bool, worst: float, wall: float) -> dict:
        steps = [{"skill": "insert", "sim_time_s": wall / 10, "duration_s": wall / 20},
                 {"skill": "manual", "sim_time_s": 0.0, "duration_s": 0.0}]
        return {"assembled": assembled, "final_pose_error_mm": {"bp": 0.0, "sp": worst}, "replans": [],
                "wall_s": wall, "steps": steps}

    figures = summary([report(True, 1.5, 30.0), report(True, 2.4, 40.0), report(False, 0.5, 50.0)])
    assert figures["assembled"] == 2 and figures["within_tolerance"] == 1
    assert figures["worst_pose_error_mm"] == 2.4 and figures["worst_part"] == "sp" and figures["worst_plan"] == 2
    assert figures["median_wall_s"] == 40.0
    # the steps the arm carried out (not those placed by hand): their median simulated and cell time
    assert figures["steps"] == 3 and figures["median_step_sim_s"] == 4.0 and figures["median_step_cell_s"] == 2.0


def test_bad_input_is_one_line_and_exit_2(run_main, tmp_path) -> None:
    done = run_main("bench", "assemble", "--run", str(tmp_path), timeout=60)
    assert done.returncode == 2
    assert done.stderr.strip().count("\n") == 0 and "session.json" in done.stderr
