"""The torque loop's health, without an arm: the harness counts the robot cycles whose
command arrived as libfranka does (``control_command_success_rate``), and the franka
backend repeats an insertion attempt whose loop fell below :data:`MIN_COMMAND_RATE`
instead of answering with its outcome, and fails the request after
:data:`LATE_REPEATS` repeats, the part carried back."""

from __future__ import annotations

import logging
from types import SimpleNamespace

import numpy as np
import pytest

pytest.importorskip("franky_sim")
pytest.importorskip("mujoco")

from executor import ExecutorError  # noqa: E402
from executor.control.detector import Detector, Thresholds  # noqa: E402
from executor.franka.backend import LATE_REPEATS, MIN_COMMAND_RATE, FrankaBackend  # noqa: E402
from executor.franka.sim_server import COMMAND_WINDOW, CommandRate  # noqa: E402
from executor.skills.insertion import InsertionResult  # noqa: E402
from executor.skills.search import SearchResult  # noqa: E402


def test_the_rate_is_the_share_of_the_last_cycles_of_a_motion_with_a_command() -> None:
    rate = CommandRate()
    rate.tick(True, False)  # before the motion's first command: not counted
    assert rate.value == 0.0
    for tick in range(COMMAND_WINDOW):
        rate.tick(True, tick % 4 != 3)
    assert rate.value == pytest.approx(0.75)
    for _ in range(COMMAND_WINDOW):
        rate.tick(True, True)
    assert rate.value == 1.0  # the window slides
    rate.tick(False, False)
    assert rate.value == 0.0  # no motion: 0, as libfranka reports it


class _Cell:
    """A franka cell whose attempts ran with the given torque-loop rates (each reaches its goal)."""

    def __init__(self, rates: list[float]) -> None:
        self.rates = rates
        self.controller = SimpleNamespace(lowest_rate=1.0)
        self.calls: list[str] = []

    def insert(self, part: str, hole: str, rng: np.random.Generator) -> tuple[InsertionResult, Detector, SearchResult]:
        self.controller.lowest_rate = self.rates.pop(0)
        self.calls.append("insert")
        return (InsertionResult(True, True, 0.001, False, 0, 1.0, None), Detector(Thresholds()),
                SearchResult(True, np.zeros(2), 0.1, np.zeros((0, 3))))

    def lift(self) -> None:
        self.calls.append("lift")

    def put_back(self) -> None:
        self.calls.append("put_back")


def _backend(cell: _Cell) -> FrankaBackend:
    backend = object.__new__(FrankaBackend)
    backend.cell = cell  # type: ignore[assignment]
    return backend


def test_an_attempt_whose_torque_loop_fell_behind_is_repeated_not_answered(caplog: pytest.LogCaptureFixture) -> None:
    cell = _Cell([MIN_COMMAND_RATE / 2, 0.95])
    with caplog.at_level(logging.WARNING):
        result, _ = _backend(cell)._attempt("p1", "h1", 1, np.random.default_rng(0))
    assert result.reached and cell.calls == ["insert", "lift", "insert"]
    assert "no evidence, repeated" in caplog.text


def test_a_torque_loop_behind_in_every_repeat_fails_the_request_with_the_part_back() -> None:
    cell = _Cell([MIN_COMMAND_RATE / 2] * (LATE_REPEATS + 1))
    with pytest.raises(ExecutorError, match="too loaded for a 1 kHz loop; no outcome recorded"):
        _backend(cell)._attempt("p1", "h1", 1, np.random.default_rng(0))
    assert cell.calls == ["insert", "lift"] * (LATE_REPEATS + 1) + ["put_back"]
