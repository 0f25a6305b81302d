"""The planner's end of plan execution over Zenoh: one :class:`bridge.messages.StepRequest`
per step to one cell, waited for (a lost reply is sent again under the same id: the cell
answers a repeated request from its cache and never runs the step twice)."""

from __future__ import annotations

import uuid

import zenoh

from asp import PlannerError
from bridge import BridgeError
from bridge.client import CellTimeout, request_step
from bridge.messages import StepReply, StepRequest

SEND_ATTEMPTS = 3
"""A step whose reply is lost is sent this many times in all."""


class ZenohDriver:
    """Sends the steps of one plan run (a fresh world at the cell) to cell ``cell``."""

    def __init__(self, session: zenoh.Session, cell: str, seed: int, timeout_s: float) -> None:
        self.session, self.cell, self.seed, self.timeout_s = session, cell, seed, timeout_s
        self.run_id = uuid.uuid4().hex[:16]

    def step(self, number: int, part: str, hole: str | None) -> StepReply:
        request = StepRequest(id=f"{self.run_id}-{number}", assembly=self.run_id, step=number, part=part, hole=hole,
                              seed=self.seed, timeout_s=self.timeout_s)
        for attempt in range(1, SEND_ATTEMPTS + 1):
            try:
                return request_step(self.session, self.cell, request, self.timeout_s)
            except CellTimeout as exc:
                if attempt == SEND_ATTEMPTS:
                    raise PlannerError(f"step {number} ({part}): {exc}; gave up after {attempt} sends") from None
            except BridgeError as exc:
                raise PlannerError(f"step {number} ({part}): {exc}") from None
        raise AssertionError("unreachable")
