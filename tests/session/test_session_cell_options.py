"""The session passes the sim cell's execution layer and uncertainty to the cells it
starts, as one settings document, and gives each cell its own cell seed derived from the
session seed; the document the cell reads back is the one the session wrote."""

from __future__ import annotations

from pathlib import Path

import pytest

from assembly_constraints.asp.session.cells import CellProcess, cell_seed
from assembly_constraints.asp.session.cli import build_parser, session_settings
from assembly_constraints.asp.session.run import session_cell
from assembly_constraints.asp.session.settings import new_session_file
from assembly_constraints.executor.serve import build_parser as serve_parser
from assembly_constraints.executor.serve import serve_settings_of


def _cells(argv: list[str], run: Path) -> list:
    settings = session_settings(build_parser().parse_args(argv))
    record = new_session_file(settings, "r")
    return [session_cell(settings, record, run, k, ["tcp/127.0.0.1:7447"], None) for k in (1, 2)]


def test_each_cell_gets_the_layer_the_magnitudes_and_a_cell_seed_of_its_own(tmp_path: Path) -> None:
    first, second = _cells(["--seed", "7", "--layer", "position", "--grasp-tilt-bias", "2.5"], tmp_path)
    assert first.cell.layer == "position" and first.cell.magnitudes.grasp_tilt_bias == 2.5
    assert first.cell.magnitudes.vision_sigma == 0.0015  # the defaults are passed too
    assert (first.cell.cell_seed, second.cell.cell_seed) == (7, 8)
    assert cell_seed(2**32 - 1, 2) == 0


def test_a_sim_cell_keeps_its_ilc_state_in_the_run_folder_and_a_truth_cell_none(tmp_path: Path) -> None:
    sim = _cells([], tmp_path)[0]
    truth = _cells(["--backend", "truth"], tmp_path)[0]
    assert sim.ilc_state == str(tmp_path / "c1-ilc.json") and truth.ilc_state is None
    assert sim.rrd == str(tmp_path / "c1.rrd")


def test_the_cell_reads_back_the_document_the_session_wrote(tmp_path: Path) -> None:
    """The argv of a started cell is ``--settings JSON`` (no argv fragments), and
    ``executor serve`` decodes it into the same settings (paths made absolute, lifeline on)."""
    settings = _cells(["--seed", "3", "--friction-max", "0.6"], Path("relative-run"))[1]
    argv = CellProcess.command(settings)  # the argv only: no process is started
    assert argv[argv.index("serve") + 1:][0] == "--settings" and len(argv[argv.index("serve") + 1:]) == 2
    read = serve_settings_of(serve_parser().parse_args(argv[argv.index("serve") + 1:]))
    assert read.cell == settings.cell and read.lifeline and read.rrd == str(Path("relative-run/c2.rrd").absolute())


def test_a_cell_description_reaches_every_cell_by_its_absolute_path(tmp_path: Path,
                                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    """``session --cell-description FILE`` (relative to the caller) is in every cell's
    settings as an absolute path, and the cell builds its Cell with that file's values."""
    from assembly_constraints.executor.trial import cell_setup

    (tmp_path / "cell.toml").write_text("[thresholds]\nf_stop = 7.5\n")
    monkeypatch.chdir(tmp_path)
    first, second = _cells(["--cell-description", "cell.toml"], tmp_path)
    assert first.cell.description == second.cell.description == str(tmp_path / "cell.toml")
    assert cell_setup(first.cell).description.thresholds.f_stop == 7.5
