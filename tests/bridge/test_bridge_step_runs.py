"""Plan steps of two runs at one cell, over a real Zenoh session to ``executor serve`` in
its own process: a cell builds one product at a time, and a refused step changes
nothing (another run's step is ``run_active``, a step the product does not allow is
``invalid_step`` or ``unknown_id``)."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

import pytest
import zenoh

from asp.assemble.cli import truth_facts
from asp.plans.plans import plans
from asp.session.cells import start_cell
from bridge.assembly import load_assembly
from bridge.cell_settings import ServeSettings
from bridge.client import CellDirectory, CellRefused, request_step
from bridge.messages import StepReply, StepRequest
from bridge.session import free_loopback_endpoint, open_session


@contextmanager
def one_cell(backend: str, stop_s: float = 30.0) -> Iterator[zenoh.Session]:
    """A cell ``c1`` of Cranfield with ``backend``, and a planner's session connected to it;
    the cell must stop cleanly within ``stop_s`` [s] afterwards."""
    endpoint = free_loopback_endpoint()
    cell = start_cell(ServeSettings(cell_id="c1", backend=backend, listen=(endpoint,)))
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


def refused(session: zenoh.Session, run: str, number: int, part: str, hole: str | None) -> str:
    """The code of the refusal of this step."""
    with pytest.raises(CellRefused) as refusal:
        step(session, run, number, part, hole)
    return refusal.value.reply.code


@pytest.mark.timeout(120)
@pytest.mark.slow
def test_truth_cell_builds_one_product_at_a_time_and_refuses_what_is_not_the_product() -> None:
    plan = plans(truth_facts(load_assembly("cranfield")))[0].steps
    with one_cell("truth") as session:
        assert step(session, "a", 1, "bp", None).result == "fit"
        assert refused(session, "b", 1, "bp", None) == "run_active"
        assert refused(session, "a", 2, "zz", None) == "unknown_id"
        assert refused(session, "a", 2, "none", None) == "unknown_id"
        assert refused(session, "a", 2, "p1", None) == "invalid_step"  # a peg needs a hole
        assert refused(session, "a", 2, "sp", "r1") == "invalid_step"  # a spacer goes without one
        assert refused(session, "a", 2, "bp", None) == "invalid_step"  # already placed
        reply = step(session, "a", 2, "p3", "s1")
        assert reply.result == "fit" and dict(reply.pose_errors_mm).keys() == {"bp", "p3"}
        placed = {"bp", "p3"}
        for number, planned in enumerate((s for s in plan if s.part not in placed), start=3):
            assert step(session, "a", number, planned.part, planned.hole).result == "fit"
        # the product is complete: the next run starts a fresh world
        reply = step(session, "b", 1, "bp", None)
        assert reply.result == "fit" and dict(reply.pose_errors_mm).keys() == {"bp"}


@pytest.mark.slow
@pytest.mark.timeout(300)
def test_sim_cell_keeps_its_world_when_another_run_is_refused() -> None:
    with one_cell("sim", stop_s=120.0) as session:  # closing the world is slow on a loaded machine
        assert step(session, "a", 1, "bp", None).result == "fit"
        assert refused(session, "b", 1, "p1", "r1") == "run_active"
        assert refused(session, "a", 2, "p3", None) == "invalid_step"
        reply = step(session, "a", 2, "p3", "s1")
        assert reply.result == "fit" and dict(reply.pose_errors_mm).keys() == {"bp", "p3"}
