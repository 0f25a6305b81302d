"""``bench precedence-physics``: the sequences that test each cover edge (clingo), the
verdict and table logic against a fake cell, and one enforced edge in physics."""

from __future__ import annotations

from contextlib import contextmanager

import pytest

from assembly_constraints.asp import PlannerError
from assembly_constraints.asp.bench.precedence_physics import (
    SequenceRun,
    edge_runs,
    edge_sequence,
    report_json,
    run_sequence,
    table,
    verdict,
    violated_pairs,
)
from assembly_constraints.asp.plans.plans import PlanStep
from assembly_constraints.asp.precedence.relation import reduction, true_relation
from assembly_constraints.bridge.assembly import load_assembly
from assembly_constraints.bridge.cell_settings import ServeSettings
from assembly_constraints.bridge.messages import StepEvidence, StepReply

CRANFIELD = load_assembly("cranfield")
RELATION = true_relation(CRANFIELD)
EDGES = reduction(RELATION)


def test_cranfield_has_13_cover_edges() -> None:
    assert len(EDGES) == 13 and ("bp", "p1") in EDGES and ("pd", "fp") in EDGES


@pytest.mark.parametrize("edge", EDGES, ids=lambda e: f"{e[0]}-{e[1]}")
def test_each_violating_sequence_breaks_exactly_its_edge_and_the_compliant_one_none(edge) -> None:
    a, b = edge
    violating = edge_sequence(RELATION, edge, violate=True)
    assert sorted(violating) == sorted(RELATION.parts)
    assert violated_pairs(RELATION, violating) == [edge]
    assert violating.index(b) == violating.index(a) - 1  # b right before a: nothing between them to blame
    compliant = edge_sequence(RELATION, edge, violate=False)
    assert violated_pairs(RELATION, compliant) == [] and RELATION.admits(compliant)
    assert edge_sequence(RELATION, edge, violate=True) == violating  # deterministic


def test_the_violating_sequence_places_the_first_part_as_early_as_possible() -> None:
    assert edge_sequence(RELATION, ("bp", "p1"), violate=True)[:2] == ("p1", "bp")
    assert edge_sequence(RELATION, ("sh", "pd"), violate=True)[:4] == ("bp", "ph", "pd", "sh")
    # The front plate goes last in every admitted sequence, so p1 right before it.
    assert edge_sequence(RELATION, ("p1", "fp"), violate=False)[-2:] == ("p1", "fp")


def test_a_pair_that_is_no_cover_edge_is_refused() -> None:
    with pytest.raises(PlannerError, match="bp-fp: not a cover edge"):
        edge_sequence(RELATION, ("bp", "fp"), violate=True)


class FakeCell:
    """Fails the step of part ``fails`` (None: never)."""

    def __init__(self, fails: str | None) -> None:
        self.fails = fails
        self.asked: list[str] = []

    def step(self, number: int, part: str, hole: str | None) -> StepReply:
        self.asked.append(part)
        ok = part != self.fails
        evidence = StepEvidence(skill="truth", attempts=1 if ok else 2, max_force_dev=3.0, max_torque_dev=0.0,
                                duration_s=0.0, sim_time_s=0.0, pose_error_mm=0.5 if ok else 40.0)
        return StepReply(id=f"s{number}", cell="fake", part=part, hole=hole, result="fit" if ok else "no_fit",
                         evidence=evidence, pose_errors_mm=(("bp", 0.25),))


def _runs(fails: str | None, edge=("p1", "fp")) -> tuple[list[SequenceRun], list[FakeCell]]:
    cells: list[FakeCell] = []

    @contextmanager
    def cell():
        cells.append(FakeCell(fails))
        yield cells[-1]

    holes = {"p1": "r1", "p2": "r2", "p3": "s2", "p4": "s1", "sh": "br"}
    pending = list(edge_runs(RELATION, {p: holes.get(p) for p in RELATION.parts}, [edge]))
    return [run_sequence(cell, run) for run in pending], cells


def test_a_failure_at_the_breaking_step_is_detection_and_stops_the_run() -> None:
    (violating, compliant), cells = _runs("p1")
    assert [s.part for s in violating.sequence][-2:] == ["fp", "p1"] and violating.break_step == 10
    assert violating.failed_step == 10 and violating.detected and verdict(violating) == "enforced"
    assert compliant.failed_step == 9 and not compliant.completed  # p1 fails in the admitted order too
    assert len(cells) == 2  # a fresh cell per sequence
    text = table([("p1", "fp")], [violating, compliant])
    assert "10: p1 no_fit (2 att., 3 N, 40.0 mm" in text and "NOT ASSEMBLED" in text
    assert "1/1 edges enforced" in text and "0/1 compliant assembled" in text


def test_a_completed_violating_sequence_is_reported_not_hidden() -> None:
    (violating, compliant), _ = _runs(None)
    assert violating.completed and not violating.detected
    assert verdict(violating) == "completed (not enforced)" and compliant.completed
    report = report_json(CRANFIELD, 0, [("p1", "fp")], [violating, compliant])
    assert report["violating_completed"] == 1 and report["enforced"] == 0 and report["compliant_assembled"] == 1
    assert report["edges"][0]["verdict"] == "completed (not enforced)"
    assert len(report["edges"][0]["violating"]["steps"]) == 10


def test_a_failure_after_the_breaking_step_is_not_detection() -> None:
    (violating, _), _ = _runs("p4", edge=("bp", "p1"))  # p1 bp ... p4 later
    assert violating.break_step == 2 and violating.failed_step is not None and violating.failed_step > 2
    assert not violating.detected and verdict(violating) == "failed late"


def test_a_cell_error_ends_the_run_with_the_message() -> None:
    @contextmanager
    def broken():
        raise PlannerError("step 1 (p1): the cell is gone")
        yield

    run = run_sequence(broken, SequenceRun("violating", [PlanStep("p1", "r1"), PlanStep("bp", None)], 2))
    assert run.error == "step 1 (p1): the cell is gone" and run.failed_step == 1
    assert verdict(run) == "cell error" and not run.completed


@pytest.mark.slow
def test_a_peg_before_the_back_plate_is_detected_in_physics() -> None:
    """Edge bp->p1 in a real cell (PyBullet over Zenoh), up to its breaking step: p1 let go
    in r1 while the back plate still waits on the tray falls, and the step says no_fit."""
    from assembly_constraints.asp.assemble.driver import assembling_cell

    (violating, _) = edge_runs(RELATION, {"p1": "r1"} | {p: None for p in RELATION.parts if p != "p1"},
                               [("bp", "p1")])
    served = ServeSettings(assembly=str(CRANFIELD.folder))
    run = run_sequence(lambda: assembling_cell(served, 0, 120.0), violating, stop_at_break=True)
    assert run.error is None
    assert [s["part"] for s in run.steps] == ["p1"] and run.steps[0]["outcome"] == "no_fit"
    assert run.steps[0]["pose_error_mm"] > 20.0 and run.detected and verdict(run) == "enforced"
