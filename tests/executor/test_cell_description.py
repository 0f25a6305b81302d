"""The cell description (executor/cell_description.py): its defaults are those the
documented example file states, an override file changes only its keys, bad values are
refused in one line naming file, table and key, and what it says reaches the cell (the
gripper, the thresholds, the ILC bounds)."""

from __future__ import annotations

import json
from pathlib import Path

import msgspec
import numpy as np
import pytest

from assembly_constraints.cli import main
from bridge import BridgeError
from bridge.product import Gripper
from executor import ExecutorError
from executor.cell_description import CellDescription, load_cell_description
from executor.control.admittance import AdmittanceParams
from executor.control.detector import Thresholds
from executor.control.ilc import ExecutionTrace, Ilc, offset_bound, read_state
from executor.trial import Cell, CellSetup
from executor.world.geometry import arm_urdf_text
from tests.conftest import ROOT

EXAMPLE = ROOT / "docs" / "examples" / "cell.toml"


def test_the_documented_example_is_the_default() -> None:
    assert load_cell_description(EXAMPLE) == CellDescription() == load_cell_description(None)


def test_an_override_changes_only_its_keys(tmp_path: Path) -> None:
    path = tmp_path / "cell.toml"
    path.write_text("[thresholds]\nf_stop = 25.0\n\n[admittance]\nbound = 0.001\n")
    described, default = load_cell_description(path), CellDescription()
    assert described.thresholds == msgspec.structs.replace(default.thresholds, f_stop=25.0)
    assert described.admittance == msgspec.structs.replace(default.admittance, bound=0.001)
    assert (described.gains, described.gripper, described.ilc) == (default.gains, default.gripper, default.ilc)


@pytest.mark.parametrize(("text", "message"), [
    ("[thresholds]\nf_stop = 0\n", "[thresholds] f_stop: expected a number in (0, 1000] N, got 0"),
    ("[thresholds]\npersist_steps = 2.5\n", "[thresholds] persist_steps: expected an integer in 1 .. 10000"),
    ("[gains]\nk_rot = \"60\"\n", "[gains] k_rot: expected a number in (0, 1e6], got '60'"),
    ("[ilc]\nforgetting = 1.5\n", "[ilc] forgetting: expected a number in (0, 1], got 1.5"),
    ("[search]\nmax_radius = 0\n", "[search] max_radius: expected a number in (0, 0.05] m, got 0"),
    ("[gripper]\nflange_mass = 1.0\n", "[gripper] flange_inertia: expected a number in (0, 1] kg m^2, got nothing"),
    ("[controller]\nk = 1\n", "controller: unknown table or key; expected one of gripper, gains"),
    ("[admittance]\nbound = nan\n", "[admittance] bound: expected a number in (0, 0.5] (m or rad), got nan"),
    ("thresholds = 3\n", "[thresholds]: expected a table with the keys f_stop"),
    ("[ilc\n", "not valid TOML"),
    ("x = " + "[" * 100000 + "]" * 100000 + "\n", "nested too deeply; expected a cell description (TOML)"),
])
def test_a_bad_override_is_refused_in_one_line(tmp_path: Path, text: str, message: str) -> None:
    path = tmp_path / "cell.toml"
    path.write_text(text)
    with pytest.raises(BridgeError) as error:
        load_cell_description(path)
    assert str(error.value).startswith(f"{path}: ") and message in str(error.value), str(error.value)
    assert "\n" not in str(error.value)


def test_the_cell_uses_its_description() -> None:
    gripper = Gripper(flange_mass=1.0, flange_inertia=0.004, flange_length=0.08, grasp_depth=0.02)
    described = CellDescription(gripper=gripper, thresholds=Thresholds(f_stop=25.0),
                                admittance=AdmittanceParams(bound=0.001))
    cell, default = Cell(setup=CellSetup(description=described)), Cell()
    try:
        assert cell.thresholds.f_stop == 25.0 and default.thresholds.f_stop == 30.0
        assert cell.geometry.gripper == gripper  # Cranfield has no [gripper] of its own
        part = cell.geometry.parts["p1"]
        assert arm_urdf_text(part, cell.geometry.gripper) != arm_urdf_text(part, default.geometry.gripper)
        assert cell.ilc.bound.tolist() == [0.001] * 3 + [0.035] * 2
    finally:
        cell.close()
        default.close()


def test_the_ilc_corrections_stay_within_the_admittance_bounds(tmp_path: Path) -> None:
    d = CellDescription(admittance=AdmittanceParams(bound=0.001))
    ilc = Ilc(d.ilc, d.gains, d.admittance)
    trace = ExecutionTrace()
    for k in range(1000):  # a large constant lateral deviation: the correction saturates
        trace.add(k / 1000, np.array([500.0, 0.0, 0.0, 0.0, 0.0]))
    for _ in range(10):
        learned = ilc.update("round_peg:r1", trace)
    assert np.isclose(np.max(learned[:, 0]), 0.001)
    state = tmp_path / "ilc.json"
    default = CellDescription()
    entry = {"iterations": 1, "correction": [[0.0015, 0, 0, 0, 0]] * default.ilc.bins}
    state.write_text(json.dumps({"keys": {"round_peg:r1": entry}}))
    assert read_state(state, default.ilc, offset_bound(default.admittance))[1] == {"round_peg:r1": 1}
    with pytest.raises(ExecutorError, match=r"correction\[0\]\[0\]: expected a number within ±0.001 m"):
        read_state(state, d.ilc, offset_bound(d.admittance))


@pytest.mark.slow
def test_a_threshold_of_the_file_decides_the_trial(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``executor trial --cell-description``: with F_stop at 1 N the detector stops a
    round peg that fits (its sustained deviation is several N); the default lets it in."""
    path = tmp_path / "cell.toml"
    path.write_text("[thresholds]\nf_stop = 1.0\n")
    outcomes = []
    for extra in ([], ["--cell-description", str(path)]):
        assert main(["executor", "trial", "--part", "p1", "--hole", "r1", "--json", *extra]) == 0
        outcomes.append(json.loads(capsys.readouterr().out)["trials"][0]["outcome"])
    assert outcomes == ["fit", "no_fit"]


def test_the_served_sim_cell_decodes_its_description_once(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """``executor serve``: the description is decoded once, before the session opens, and
    what it says reaches the cell the backend starts."""
    from bridge.cell_settings import CellSettings, ServeSettings
    from executor import trial
    from executor.serve.backends import backend_starter

    path = tmp_path / "cell.toml"
    path.write_text("[thresholds]\nf_stop = 7.5\n")
    reads: list[Path | None] = []

    def counted(file: Path | None) -> CellDescription:
        reads.append(file)
        return load_cell_description(file)

    monkeypatch.setattr(trial, "load_cell_description", counted)
    start = backend_starter(ServeSettings(cell=CellSettings(description=str(path))))
    assert reads == [path]
    backend = start()
    try:
        assert reads == [path]
        assert backend._cell.thresholds.f_stop == 7.5  # type: ignore[attr-defined]
    finally:
        backend.close()
