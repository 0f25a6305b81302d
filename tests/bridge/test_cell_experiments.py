"""Precedence experiments and plan steps at a cell, over a real Zenoh session to ``executor
serve`` in its own process: the truth cell answers experiments from the product's
precedence, a bad or impossible experiment gets an error reply and the cell keeps serving;
the sim cell inserts a fitting peg and records it, and observes why a step fails (the
physics, not a rule). Plan steps of two runs: a
cell builds one product at a time, and a refused step changes nothing (another run's step
is ``run_active``, a step the product does not allow is ``invalid_step`` or ``unknown_id``).
One cell of each backend for both."""

from __future__ import annotations

import queue
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest
import zenoh

from asp.assemble.cli import truth_facts
from asp.plans.plans import plans
from asp.session.cells import start_cell
from asp.session.precedence import CellOracle
from bridge.assembly import load_assembly
from bridge.cell_settings import ServeSettings
from bridge.client import CellDirectory, CellRefused, request_experiment, request_insert, request_step
from bridge.messages import ErrorReply, InsertRequest, StepReply, StepRequest
from bridge.precedence.experiment import (
    ExperimentStep,
    PrecedenceExperiment,
    decode_outcome_reply,
)
from bridge.session import free_loopback_endpoint, open_session

HOLES = {"p1": "r1", "p2": "r2", "p3": "s1", "p4": "s2", "sh": "br"}


@contextmanager
def one_cell(backend: str, stop_s: float = 30.0, rrd: Path | None = None) -> Iterator[zenoh.Session]:
    """A cell ``c1`` of Cranfield with ``backend`` (recording to ``rrd`` if given, recording id
    ``sim-test``), and a planner's session connected to it; the cell must stop cleanly within
    ``stop_s`` [s] afterwards (a cell flushes its recording as it stops)."""
    endpoint = free_loopback_endpoint()
    recording = {} if rrd is None else {"rrd": str(rrd), "recording_id": "sim-test"}
    cell = start_cell(ServeSettings(cell_id="c1", backend=backend, listen=(endpoint,), **recording))
    session = open_session(connect=(endpoint,))
    try:
        CellDirectory(session).wait_for(1, timeout=30)
        yield session
    finally:
        session.close()
        assert cell.stop(timeout=stop_s) == 0


def step(session: zenoh.Session, run: str, number: int, part: str, hole: str | None) -> StepReply:
    request = StepRequest(id=f"{run}-{number}-{part}-{hole}", assembly=run, step=number, part=part, hole=hole,
                          seed=1)
    return request_step(session, "c1", request, timeout=120)


def refusal_code(session: zenoh.Session, run: str, number: int, part: str, hole: str | None) -> str:
    """The code of the refusal of this step."""
    with pytest.raises(CellRefused) as refusal:
        step(session, run, number, part, hole)
    return refusal.value.reply.code


def experiment(name: str, pair: tuple[str, str], sequence: str, placed: str = "",
               seed: int = 0) -> PrecedenceExperiment:
    """An experiment on Cranfield: parts named by space-separated ids, pegs in their plan-1 holes."""
    def steps(parts: str) -> tuple[ExperimentStep, ...]:
        return tuple(ExperimentStep(p, HOLES.get(p)) for p in parts.split())

    return PrecedenceExperiment(id=name, pair=pair, sequence=steps(sequence), placed=steps(placed), seed=seed)


@pytest.mark.slow
@pytest.mark.timeout(180)
def test_truth_cell_answers_experiments_from_the_precedence_and_builds_one_product_at_a_time() -> None:
    with one_cell("truth") as session:
        done = request_experiment(session, "c1", experiment("e1", ("p1", "sp"), "p3 p4 sp", placed="bp"), 30)
        assert (done.outcome, done.failed_step, done.pair) == ("success", None, ("p1", "sp"))
        # sp needs p4 (the square pegs hold the separator): the step that places sp fails
        failed = request_experiment(session, "c1", experiment("e2", ("p4", "sp"), "p3 sp", placed="bp"), 30)
        assert (failed.outcome, failed.failed_step, failed.reason) == ("failed", 2, "precedence")
        assert "without p4" in failed.detail
        refusals = (
            experiment("e3", ("bp", "p1"), "p1", placed="p3"),  # p3 set in a plate that is not there
            PrecedenceExperiment(id="e4", pair=("p1", "p2"), placed=(ExperimentStep("bp"),),  # s1 twice
                                 sequence=(ExperimentStep("p3", "s1"), ExperimentStep("p2", "s1"))),
            PrecedenceExperiment(id="e5", pair=("p1", "p2"), sequence=(ExperimentStep("p2", "zz"),)),  # no hole zz
        )
        for bad_one in refusals:
            with pytest.raises(CellRefused) as refused:
                request_experiment(session, "c1", bad_one, 30)
            assert refused.value.reply.code == "invalid_step", refused.value
        box: queue.SimpleQueue[bytes] = queue.SimpleQueue()
        session.get("cell/c1/precedence", lambda reply: box.put(reply.ok.payload.to_bytes()),
                    payload=b'{"kind":"precedence_experiment","id":"x","pair":["a","b"],"sequence":[{"part":"a"}]}',
                    timeout=10.0)
        bad = decode_outcome_reply(box.get(timeout=15.0))
        assert isinstance(bad, ErrorReply) and bad.code == "malformed"
        again = request_experiment(session, "c1", experiment("e6", ("p1", "sp"), "p3 p4 sp", placed="bp"), 30)
        assert again.outcome == "success"  # still serving
        # the session's oracle: holes from its assignment, the steps before the tested one set by hand
        oracle = CellOracle(session, "c1", HOLES)
        tested = PrecedenceExperiment(id="o1", pair=("p4", "sp"),
                                      sequence=(ExperimentStep("bp"), ExperimentStep("p3"), ExperimentStep("sp")))
        assert oracle.sent(tested).placed == (ExperimentStep("bp"), ExperimentStep("p3", "s1"))
        outcome = oracle.run(tested)
        assert (outcome.outcome, outcome.failed_step, outcome.reason) == ("failed", 3, "precedence")
        # "B then A" at the truth cell: the precedence shows at the later part's step, blamed on no part
        then_a = PrecedenceExperiment(id="o2", pair=("p4", "sp"), sequence=tuple(
            ExperimentStep(p) for p in ("bp", "p3", "sp", "p4")))
        outcome = oracle.run(then_a)
        assert (outcome.outcome, outcome.failed_step, outcome.reason, outcome.blocked_by) == (
            "failed", 3, "precedence", ())
        # plan steps: one product at a time, refusals change nothing
        plan = plans(truth_facts(load_assembly("cranfield")))[0].steps
        assert step(session, "a", 1, "bp", None).result == "fit"
        assert refusal_code(session, "b", 1, "bp", None) == "run_active"
        assert refusal_code(session, "a", 2, "zz", None) == "unknown_id"
        assert refusal_code(session, "a", 2, "none", None) == "unknown_id"
        assert refusal_code(session, "a", 2, "p1", None) == "invalid_step"  # a peg needs a hole
        assert refusal_code(session, "a", 2, "sp", "r1") == "invalid_step"  # a spacer goes without one
        assert refusal_code(session, "a", 2, "bp", None) == "invalid_step"  # already placed
        reply = step(session, "a", 2, "p3", "s1")
        assert reply.result == "fit" and dict(reply.pose_errors_mm).keys() == {"bp", "p3"}
        placed = {"bp", "p3"}
        for number, planned in enumerate((s for s in plan if s.part not in placed), start=3):
            assert step(session, "a", number, planned.part, planned.hole).result == "fit"
        # the product is complete: the next run starts a fresh world
        reply = step(session, "b", 1, "bp", None)
        assert reply.result == "fit" and dict(reply.pose_errors_mm).keys() == {"bp"}


@pytest.mark.slow
@pytest.mark.timeout(900)
def test_sim_cell_logs_an_insertion_observes_why_a_step_fails_and_keeps_its_world_when_another_run_is_refused(
        tmp_path: Path) -> None:
    from bridge.recording.reader import column_values, read_recording

    rrd = tmp_path / "c1.rrd"
    with one_cell("sim", stop_s=120.0, rrd=rrd) as session:
        # one simulated insertion, logged
        reply = request_insert(session, "c1", InsertRequest(id="i1", part="p1", hole="br", seed=3, experiment=7), 60)
        assert reply.result == "fit"
        assert reply.evidence is not None and reply.evidence.attempts >= 1
        assert reply.evidence.end_error < 0.01 and reply.evidence.duration_s > 0
        # a peg before the back plate: it reaches its goal height in air, and falls once let go
        fell = request_experiment(session, "c1", experiment("s1", ("bp", "p1"), "p1", seed=1), 300)
        assert (fell.outcome, fell.failed_step, fell.reason) == ("failed", 1, "unsupported")
        assert fell.sim_s > 0.0
        with pytest.raises(CellRefused) as refused:  # a peg set by hand where the plate is not
            request_experiment(session, "c1", experiment("s2", ("bp", "p2"), "p2", placed="p1"), 300)
        assert refused.value.reply.code == "invalid_step" and "p1 did not stay" in refused.value.reply.error
        # fp goes in without sp (it rests on pd and the pins), but sp then cannot: "B then A"
        # sees sp blocked, and the cell names fp as the part it touched
        oracle = CellOracle(session, "c1", HOLES, seed=1, timeout_s=300)
        before_fp = PrecedenceExperiment(id="s3", pair=("sp", "fp"), sequence=tuple(
            ExperimentStep(p) for p in ("bp", "p1", "p2", "p3", "p4", "sh", "ph", "pd", "fp", "sp")))
        assert len(oracle.sent(before_fp).sequence) == 2  # fp then sp; the rest set by hand
        outcome = oracle.run(before_fp)
        assert (outcome.outcome, outcome.failed_step, outcome.reason) == ("failed", 10, "blocked")
        assert outcome.blocked_by == ("fp",), outcome
        # a plan step's run keeps its world when another run's step is refused
        assert step(session, "a", 1, "bp", None).result == "fit"
        assert refusal_code(session, "b", 1, "p1", "r1") == "run_active"
        assert refusal_code(session, "a", 2, "p3", None) == "invalid_step"
        reply = step(session, "a", 2, "p3", "s1")
        assert reply.result == "fit" and dict(reply.pose_errors_mm).keys() == {"bp", "p3"}
    summary = read_recording([rrd])
    assert set(summary.recording_ids) == {"sim-test"}
    assert any(path.startswith("/executor/c1/wrench") for path in summary.entities)
    assert set(column_values([rrd], "/executor/c1/outcome", "experiment")) == {7}
