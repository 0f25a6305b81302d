"""A cell that dies during a plan step is reported as exited, with its exit code, not as
a cell that did not reply in time (the planner started it and knows its process)."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from assembly_constraints.asp import PlannerError
from assembly_constraints.asp.assemble.driver import assembling_cell
from assembly_constraints.bridge.assembly import load_assembly
from assembly_constraints.bridge.cell_settings import ServeSettings

CRASHING_BACKEND = '''
import os


class Crash:
    """A cell backend that exits with code 7 at its first plan step."""

    def __init__(self, context):
        pass

    def run(self, request):
        os._exit(7)

    def run_step(self, request):
        os._exit(7)

    def close(self):
        pass
'''


@pytest.mark.slow  # starts a cell process
def test_a_cell_that_dies_at_step_one_is_reported_as_exited(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / "crashing_cell.py").write_text(CRASHING_BACKEND)
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(filter(None, [str(tmp_path), os.environ.get("PYTHONPATH")])))
    with assembling_cell(ServeSettings(assembly=str(load_assembly("cranfield").folder), backend="crashing_cell:Crash"),
                         0, 20.0) as driver:
        with pytest.raises(PlannerError, match=r"^step 1 \(bp\): cell a1 exited \(code 7\) during the step"):
            driver.step(1, "bp", None)
