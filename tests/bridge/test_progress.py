"""Progress bars appear only on a terminal with INFO logging, never change the items."""

from __future__ import annotations

import io
import logging

import pytest

from assembly_constraints.bridge.progress import progress


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


@pytest.mark.parametrize(("tty", "level", "drawn"), [
    (True, logging.INFO, True), (True, logging.WARNING, False), (False, logging.INFO, False),
])
def test_a_bar_only_on_a_terminal_that_wants_info(tty: bool, level: int, drawn: bool,
                                                  monkeypatch: pytest.MonkeyPatch,
                                                  caplog: pytest.LogCaptureFixture) -> None:
    stream = Terminal() if tty else io.StringIO()
    monkeypatch.setattr("sys.stderr", stream)
    caplog.set_level(level)
    assert list(progress(iter(range(5)), desc="trials", total=5)) == [0, 1, 2, 3, 4]
    assert ("trials: 100%" in stream.getvalue()) is drawn
    assert drawn or stream.getvalue() == ""
