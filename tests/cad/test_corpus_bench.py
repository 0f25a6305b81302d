"""``bench corpus``: a corpus product run end to end against its truth, a wrong truth
reported wrong, a failed step reported in its row while the bench goes on."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from assembly_constraints.corpus_truth import CorpusImport, TruthError, compare_fits, read_truth
from tests.conftest import Runner

CORPUS = Path(__file__).parent / "corpus"


def _copy(corpus: Path, name: str, as_name: str | None = None) -> Path:
    """Corpus product ``name`` copied into ``corpus`` (as ``as_name``)."""
    return Path(shutil.copytree(CORPUS / name, corpus / (as_name or name)))


@pytest.mark.slow  # imports, teaches, learns in physics, assembles the hexagonal peg (153-260 s at load 15-20)
@pytest.mark.timeout(1200)
def test_a_product_is_learned_and_assembled_exactly_and_a_flipped_truth_is_reported_wrong(
        run_main: Runner, tmp_path: Path) -> None:
    # the bench in this process, its steps (the sessions, the teaching) processes of their own
    corpus = tmp_path / "corpus"
    _copy(corpus, "agh_hex_horizontal")
    done = run_main("bench", "corpus", "--corpus", str(corpus), "--product", "agh_hex_horizontal",
                    "--json", str(tmp_path / "exact.json"))
    assert done.returncode == 0, done.stdout + done.stderr
    (row,) = json.loads((tmp_path / "exact.json").read_text())["rows"]
    assert row["verdict"] == "exact", row
    assert (row["truth"]["ok"], row["truth"]["total"]) == (1, 1)
    # the peg in its hole observed in physics, along y, and assembled by the cell within 2 mm
    assert (row["sim"]["ok"], row["sim"]["total"], row["sim"]["observed"], row["sim"]["from_cad"]) == (1, 1, 1, 0)
    assert row["assembly"]["manual"] == [] and 0 <= row["assembly"]["max_mm"] < 2.0
    assert "| agh_hex_horizontal | 2 |" in done.stdout and "| exact |" in done.stdout
    # the same product with its one fit flipped in truth.toml: the import's relation is now wrong
    truth = _copy(corpus, "agh_hex_horizontal", "hex_flipped") / "truth.toml"
    text = truth.read_text()
    assert text.count("fits = true") == 1
    truth.write_text(text.replace("fits = true", "fits = false"))
    wrong = run_main("bench", "corpus", "--corpus", str(corpus), "--product", "hex_flipped", "--truth-only",
                     "--json", str(tmp_path / "wrong.json"))
    assert wrong.returncode == 1, wrong.stdout + wrong.stderr
    (row,) = json.loads((tmp_path / "wrong.json").read_text())["rows"]
    assert row["verdict"] == "wrong" and row["truth"]["ok"] == 0
    assert row["truth"]["wrong"] == ["hex_peg->h1 learned fit, the truth no_fit"]
    assert "exit 1: hex_flipped wrong" in wrong.stdout


def test_a_product_whose_step_fails_gets_its_row_and_the_bench_goes_on(run_main: Runner, tmp_path: Path) -> None:
    corpus = tmp_path / "corpus"
    shutil.rmtree(_copy(corpus, "agh_hex_horizontal", "a_no_meshes") / "meshes")
    (_copy(corpus, "agh_hex_horizontal", "b_bad_truth") / "truth.toml").write_text('base = "box"\nfits = 3\n')
    done = run_main("bench", "corpus", "--corpus", str(corpus), "--json", str(tmp_path / "rows.json"))
    assert done.returncode == 1
    rows = json.loads((tmp_path / "rows.json").read_text())["rows"]
    assert [(r["product"], r["verdict"]) for r in rows] == [("a_no_meshes", "failed: import"),
                                                             ("b_bad_truth", "failed: truth.toml")]
    assert "meshes" in rows[0]["failed"]["error"] and "\n" not in rows[0]["failed"]["error"]
    assert rows[1]["failed"]["error"].endswith("truth.toml: expected features (dict)")
    assert "0 exact, 0 sound, 0 wrong, 2 failed of 2 product(s); exit 1" in done.stdout


def test_an_unknown_product_is_refused_in_one_line(run_main: Runner) -> None:
    done = run_main("bench", "corpus", "--product", "no_such_product")
    assert done.returncode == 2 and "--product no_such_product: no " in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and "robosuite_nuts" in done.stderr


def test_a_pair_the_session_did_not_decide_is_missing_not_a_no_fit(tmp_path: Path) -> None:
    truth = {"base": "box", "parts": {"a": {"in": "f"}, "b": {"in": "f"}, "c": {"in": "f"}},
             "features": {"f": {"owner": "box", "kind": "hole", "axis_point": [0.0, 0.0, 0.0], "axis": "-z"}},
             "fits": [{"part": p, "feature": "f", "fits": p == "a"} for p in "abc"]}
    done = CorpusImport(truth, tmp_path, {}, (0.0, 0.0), {}, {})
    count = compare_fits(done, {"f": "h1"}, fits={("a", "h1"), ("b", "h1")}, no_fits=set())
    assert (count.ok, count.wrong, count.missing) == (1, [("b", "h1")], ["c->f (h1)"])
    assert count.as_json()["wrong"] == ["b->h1 learned fit, the truth no_fit"]


def test_a_truth_naming_an_unknown_further_feature_is_refused_in_one_line(tmp_path: Path) -> None:
    # also_in: the further features a part goes into at once (flynn_clutch's plates: the
    # shaft, and the outer holder's hole); each must be one of the truth's features.
    text = (CORPUS / "flynn_clutch" / "truth.toml").read_text()
    (tmp_path / "truth.toml").write_text(text)
    assert read_truth(tmp_path)["parts"]["outer_plate_a"]["also_in"] == ["holder_splines"]
    (tmp_path / "truth.toml").write_text(text.replace('also_in = ["holder_splines"]', 'also_in = ["holder"]', 1))
    with pytest.raises(TruthError, match=r"truth.toml: parts.outer_plate_a.also_in: expected a list of features$"):
        read_truth(tmp_path)
