"""The planner's end of plan execution over Zenoh: one :class:`assembly_constraints.bridge.messages.StepRequest`
per step to one cell, waited for (a lost reply is sent again under the same id: the cell
answers a repeated request from its cache and never runs the step twice)."""

from __future__ import annotations

import uuid
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

import msgspec
import zenoh

from assembly_constraints.asp import PlannerError
from assembly_constraints.asp.session.cells import CellProcess, start_cell
from assembly_constraints.bridge import BridgeError
from assembly_constraints.bridge.cell_settings import ServeSettings
from assembly_constraints.bridge.client import CellDirectory, CellTimeout, request_step
from assembly_constraints.bridge.inputs import shorten
from assembly_constraints.bridge.messages import StepReply, StepRequest
from assembly_constraints.bridge.session import LOOPBACK_ANY_PORT, bound_endpoints, open_session

CELL_ID = "a1"
CELL_START_S = 60.0
"""How long a started cell may take to show its liveliness token [s]."""

SEND_ATTEMPTS = 3
"""A step whose reply is lost is sent this many times in all."""


class ZenohDriver:
    """Sends the steps of one plan run (a fresh world at the cell) to cell ``cell``;
    ``process``: the cell's process if this planner started it, so a cell that died is
    reported as exited (with its exit code) rather than as one that did not reply."""

    def __init__(self, session: zenoh.Session, cell: str, seed: int, timeout_s: float,
                 process: CellProcess | None = None) -> None:
        self.session, self.cell, self.seed, self.timeout_s = session, cell, seed, timeout_s
        self.process = process
        self.run_id = uuid.uuid4().hex[:16]

    def step(self, number: int, part: str, hole: str | None) -> StepReply:
        request = StepRequest(id=f"{self.run_id}-{number}", assembly=self.run_id, step=number, part=part, hole=hole,
                              seed=self.seed, timeout_s=self.timeout_s)
        for attempt in range(1, SEND_ATTEMPTS + 1):
            try:
                return request_step(self.session, self.cell, request, self.timeout_s)
            except CellTimeout as exc:
                self._check_alive(number, part)
                if attempt == SEND_ATTEMPTS:
                    raise PlannerError(f"step {number} ({part}): {exc}; gave up after {attempt} sends") from None
            except BridgeError as exc:
                raise PlannerError(f"step {number} ({part}): {exc}") from None
        raise AssertionError("unreachable")

    def _check_alive(self, number: int, part: str) -> None:
        """PlannerError naming the exit code if the cell process this planner started has
        ended (a reply then never comes: sending again is pointless)."""
        if self.process is None:
            return
        code = self.process.exit_code(timeout=1.0)
        if code is not None:
            last = self.process.last_line()
            output = f"; its last output: {shorten(last, 200)}" if last else ""
            raise PlannerError(f"step {number} ({part}): cell {self.cell} exited (code {code}) during the step"
                               f"{output}")


@contextmanager
def assembling_cell(served: ServeSettings, seed: int, timeout_s: float, *, listen: Sequence[str] = (),
                    connect: Sequence[str] = ()) -> Iterator[ZenohDriver]:
    """Start one cell (``executor serve``, a fresh world of ``served.assembly``) on loopback
    and yield a driver for one plan run in it; the cell is stopped on exit.  ``served``:
    the cell's settings (backend, ``block_holes``, ``rrd``, ``zenoh_config``, also the
    planner's; ``cell``: the sim cell's,
    :func:`assembly_constraints.asp.assemble.settings.assembling_cell_settings`), its cell
    id and the endpoint it connects to set here; ``seed`` seeds the cell's random errors,
    ``timeout_s`` bounds one step [s]; ``listen``/``connect``: the planner's endpoints."""
    listen = list(listen) or [LOOPBACK_ANY_PORT]
    zenoh_config = served.zenoh_config
    session = open_session(listen, connect, None if zenoh_config is None else Path(zenoh_config))
    try:
        listen = bound_endpoints(session, listen)  # the port the cell connects to, as bound
        directory = CellDirectory(session)
        process = start_cell(msgspec.structs.replace(served, cell_id=CELL_ID, connect=tuple(listen[:1])))
        try:
            # Its queryables reach us with its liveliness token: a step sent before might find no one.
            directory.wait_for(1, timeout=CELL_START_S)
            yield ZenohDriver(session, CELL_ID, seed, timeout_s, process)
        finally:
            process.stop()
            directory.close()
    finally:
        session.close()
