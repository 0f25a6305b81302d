"""``session.json`` is the encoded settings with one decoder: what a session writes reads
back equal; a folder of the untyped format 1 (the cell's options as argv strings) is
decoded; settings out of range built in Python are refused naming the field (a size
prior's tolerance too, and a tolerance without a prior); a resume runs with the kept
backend and names the options it ignores; the product digest follows the product's files."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from asp import PlannerError
from asp.session.settings import (
    SESSION_FILE,
    DecidedPrior,
    SessionSettings,
    checked,
    new_session_file,
    product_digest,
    read_session_file,
    resumed_settings,
    write_session_file,
)
from bridge.cell_settings import CellSettings, Magnitudes


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


def test_a_resume_runs_with_the_kept_backend_and_names_the_options_it_ignores() -> None:
    record = new_session_file(SessionSettings(backend="truth", delay_s=0.5, seed=3,
                                              cell=CellSettings(cell_seed=3)), "rec-1")
    given = SessionSettings(backend="sim", delay_s=2.0, seed=3, policy="random", cells=4,
                            cell=CellSettings(layer="position", cell_seed=3))
    settings, ignored = resumed_settings(given, record)
    assert (settings.backend, settings.delay_s, settings.cells) == ("truth", 0.5, 4)  # how many cells: this start's
    # --backend sim is the default: a resume cannot tell it from no option, so it is not named
    assert ignored == ["--policy random", "--delay 2.0", "the cell options"]
    assert resumed_settings(SessionSettings(seed=3, cell=CellSettings(cell_seed=3)), record)[1] == []


def test_a_folder_that_kept_no_backend_is_resumed_with_the_given_one(tmp_path: Path) -> None:
    (tmp_path / SESSION_FILE).write_text('{"format": 2, "assembly": "cranfield", "policy": "best", "seed": 0, '
                                         '"recording_id": "r"}')
    record = read_session_file(tmp_path)
    assert (record.backend, record.delay_s, record.product) == (None, None, None)
    settings, ignored = resumed_settings(SessionSettings(backend="truth", delay_s=0.1), record)
    assert (settings.backend, record.backend, record.delay_s, ignored) == ("truth", "truth", 0.1, [])


def test_the_product_digest_follows_every_product_file(tmp_path: Path, root: Path) -> None:
    for name in ("assembly.toml", "geometry.toml", "sizes.lp"):
        (tmp_path / name).write_bytes((root / "data" / "cranfield" / name).read_bytes())
    digests = {product_digest(tmp_path)}
    assert product_digest(tmp_path) in digests  # the same files, the same digest
    (tmp_path / "demos.txt").write_text("")  # an empty file is not an absent one
    digests.add(product_digest(tmp_path))
    (tmp_path / "sizes.lp").write_text((tmp_path / "sizes.lp").read_text() + " ")
    digests.add(product_digest(tmp_path))
    (tmp_path / "notes.txt").write_text("not a product file")
    assert product_digest(tmp_path) in digests and len(digests) == 3
    (tmp_path / "cell_order.lp").write_text("cell_before(p1,fp).\n")  # the cell's own orders
    digests.add(product_digest(tmp_path))
    assert len(digests) == 4
