"""A plugin backend (``--backend MODULE:CLASS``, docs/backends.md) that raises an
unexpected exception during a request: the request gets an error reply ``failed`` naming
the exception, and the cell keeps serving the next ones."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
import zenoh

from assembly_constraints.asp.session.cells import CellProcess, start_cell
from assembly_constraints.bridge.cell_settings import ServeSettings
from assembly_constraints.bridge.client import CellDirectory, CellRefused, request_insert
from assembly_constraints.bridge.messages import Evidence, InsertRequest, Result
from assembly_constraints.bridge.session import free_loopback_endpoint, open_session
from assembly_constraints.executor.backend_plugin import CellContext

pytestmark = pytest.mark.timeout(60)


class FaultyBackend:
    """Fits every pair, but has a bug for the holes named in option ``broken`` (comma-separated):
    a KeyError, a ZeroDivisionError or a RecursionError by the hole's position in it."""

    def __init__(self, context: CellContext) -> None:
        self._broken = context.option("broken").split(",")

    def run(self, request: InsertRequest) -> tuple[Result, Evidence | None]:
        if request.hole in self._broken:
            bug = self._broken.index(request.hole) % 3
            if bug == 0:
                return {"fit": "fit"}[request.hole], None  # type: ignore[return-value]
            if bug == 1:
                return "fit", Evidence(attempts=1 // 0, max_force_dev=0, max_torque_dev=0, end_error=0, duration_s=0)
            return self.run(request)
        return "fit", None

    def close(self) -> None:
        pass


@pytest.fixture
def planner() -> Iterator[tuple[str, zenoh.Session, CellDirectory, list[CellProcess]]]:
    endpoint = free_loopback_endpoint()
    session = open_session(listen=(endpoint,))
    directory = CellDirectory(session)
    cells: list[CellProcess] = []
    try:
        yield endpoint, session, directory, cells
    finally:
        for cell in cells:
            cell.kill()
        directory.close()
        session.close()


@pytest.mark.slow
def test_a_request_whose_backend_raises_gets_failed_and_the_cell_keeps_serving(planner) -> None:
    endpoint, session, directory, cells = planner
    backend = f"{__name__}:{FaultyBackend.__name__}"
    cells.append(start_cell(ServeSettings(cell_id="c1", backend=backend, connect=(endpoint,),
                                          backend_options={"broken": "q1,q2,q3"})))
    directory.wait_for(1, timeout=30)
    for number, (hole, raised) in enumerate([("q1", "KeyError: 'q1'"), ("q2", "ZeroDivisionError: integer"),
                                             ("q3", "RecursionError: maximum recursion")]):
        with pytest.raises(CellRefused) as refused:
            request_insert(session, "c1", InsertRequest(id=f"bug{number}", part="p1", hole=hole), timeout=20)
        reply = refused.value.reply
        assert reply.code == "failed" and reply.id == f"bug{number}", reply
        assert reply.error.startswith(f"the backend raised {raised}") and "test_backend_errors.py:" in reply.error
        assert request_insert(session, "c1", InsertRequest(id=f"ok{number}", part="p1", hole="h1"), 20).result == "fit"
    assert cells[0].popen.poll() is None
