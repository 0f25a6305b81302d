"""``session.json`` is the encoded settings with one decoder: what a session writes reads
back equal; a folder of the untyped format 1 (the cell's options as argv strings) is
decoded; settings out of range built in Python are refused naming the field (a size
prior's tolerance too, and a tolerance without a prior)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from assembly_constraints.asp import PlannerError
from assembly_constraints.asp.session.settings import (
    SESSION_FILE,
    DecidedPrior,
    SessionSettings,
    checked,
    new_session_file,
    read_session_file,
    write_session_file,
)
from assembly_constraints.bridge.cell_settings import CellSettings, Magnitudes


def test_what_a_session_writes_reads_back_equal(tmp_path: Path) -> None:
    settings = SessionSettings(seed=4, confirm=1, cell=CellSettings(layer="admittance_p", cell_seed=4,
                                                                    magnitudes=Magnitudes(vision_bias=0.002)))
    record = new_session_file(settings, "rec-1")
    record.fits, record.status = [("p1", "r1")], "done"
    record.prior = DecidedPrior(kind="cad", tolerance_m=5e-4, pairs=4, decided=[("p1", "r2", "no_fit")])
    write_session_file(tmp_path, record)
    assert read_session_file(tmp_path) == record
    data = json.loads((tmp_path / SESSION_FILE).read_text())
    assert data["format"] == 2 and data["cell"]["magnitudes"]["vision_bias"] == 0.002
    assert data["prior"]["decided"] == [["p1", "r2", "no_fit"]] and data["size_prior"] is None
    assert "plans" not in data  # not known yet: absent, not null


def test_a_format_1_folder_is_decoded_with_its_cell_options(tmp_path: Path) -> None:
    (tmp_path / SESSION_FILE).write_text(json.dumps({
        "assembly": "cranfield", "policy": "best", "seed": 7, "recording_id": "r", "starts": 2,
        "cell_options": ["--layer", "position", "--grasp-tilt-bias", "2.5", "--friction-max", "0.6"]}))
    record = read_session_file(tmp_path)
    assert record.cell == CellSettings(layer="position", cell_seed=7,
                                       magnitudes=Magnitudes(grasp_tilt_bias=2.5, friction_max=0.6))
    assert record.starts == 2 and record.format == 2


def test_a_format_1_option_that_is_not_the_cells_is_refused_naming_it(tmp_path: Path) -> None:
    (tmp_path / SESSION_FILE).write_text(json.dumps({
        "assembly": "cranfield", "policy": "best", "seed": 0, "recording_id": "r", "cell_options": ["--gui", "1"]}))
    with pytest.raises(PlannerError, match=r'"cell_options": --gui: expected --layer or a magnitude'):
        read_session_file(tmp_path)


@pytest.mark.parametrize(("settings", "field"), [(SessionSettings(cells=65), '"cells"'),
                                                 (SessionSettings(timeout_s=0.0), '"timeout_s"'),
                                                 (SessionSettings(seed=-1), '"seed"'),
                                                 (SessionSettings(size_prior="cad", tolerance_m=0.2), '"tolerance_m"'),
                                                 (SessionSettings(tolerance_m=0.001), "tolerance_m 0.001: applies to")])
def test_settings_built_in_python_are_checked(settings: SessionSettings, field: str) -> None:
    with pytest.raises(PlannerError, match=f"^session settings: {field}"):
        checked(settings)


def test_an_unknown_policy_is_refused_naming_it() -> None:
    with pytest.raises(PlannerError, match="^session settings: policy 'fastest': expected one of"):
        checked(SessionSettings(policy="fastest"))
