"""A resume never changes the cell: ``session.json`` keeps the backend, the delay and the
product's digest; a resume runs with them (whatever its own options say), refuses a
product edited since the start, and says what it resumes. Ids of the documented longest
length (64 characters) go through a whole session and its resume; a learned product
without a complete assignment ends the session (``done``) with exit code 3; and the
summary's truth comparison is coherent (real sessions with truth cells on loopback)."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import pytest

from asp.session.journal import JournalEntry, read_journal, read_records
from asp.session.settings import (
    SessionSettings,
    new_session_file,
    product_digest,
    write_session_file,
)
from tests.conftest import TRUTH_SESSION, Runner

pytestmark = [pytest.mark.timeout(120), pytest.mark.slow]  # whole sessions, 3-8 s each

PEG_A, PEG_B = "p" + "a" * 63, "q" + "b" * 63  # part ids of 64 characters
HOLE_A, HOLE_B = "h" + "c" * 63, "k" + "d" * 63  # hole ids of 64 characters


def two_peg_product(folder: Path, ids: tuple[str, str, str, str] = (PEG_A, PEG_B, HOLE_A, HOLE_B), *,
                    thick_peg_m: float = 0.012) -> Path:
    """A product of two round pegs and two round holes (``ids``: the thin peg, the thick
    one, the small hole, the large one; by default every id 64 characters): the thin peg
    fits both holes, the peg of ``thick_peg_m`` [m] the large one (d 12.8 mm) if thinner;
    its ``sizes.lp`` says it does."""
    peg_a, peg_b, hole_a, hole_b = ids
    folder.mkdir()
    (folder / "assembly.toml").write_text(f"""name = "long ids"
[parts.bp]
role = "base"
start = [0.30, -0.40]
[parts.{peg_a}]
role = "peg"
shape = "round"
start = [0.20, 0.40]
[parts.{peg_b}]
role = "peg"
shape = "round"
start = [0.30, 0.40]
[holes.{hole_a}]
position = [0.53, 0.0]
[holes.{hole_b}]
position = [0.65, 0.0]
""")
    (folder / "geometry.toml").write_text(f"""[plate]
top_z = 0.10
tile_size = 0.04
tile_thickness = 0.025
chamfer = 0.0008
polygon_sides = 24
base_size = [0.20, 0.24]
base_center = [0.59, 0.0]
base_thickness = 0.02
[hole_shapes.small]
holes = ["{hole_a}"]
kind = "round"
size = 0.0108
[hole_shapes.large]
holes = ["{hole_b}"]
kind = "round"
size = 0.0128
[part_shapes.thin]
parts = ["{peg_a}"]
kind = "round"
size = 0.0100
length = 0.05
mass = 0.04
demo_hole = "{hole_a}"
[part_shapes.thick]
parts = ["{peg_b}"]
kind = "round"
size = {thick_peg_m}
length = 0.05
mass = 0.05
demo_hole = "{hole_b}"
""")
    (folder / "sizes.lp").write_text(f"part({peg_a};{peg_b}). hole({hole_a};{hole_b}).\n"
                                     f"fits({peg_a},{hole_a}). fits({peg_a},{hole_b}). fits({peg_b},{hole_b}).\n")
    (folder / "demos.txt").write_text(f"bp {peg_a} {peg_b}\nbp {peg_b} {peg_a}\n")
    return folder


def cranfield_copy(root: Path, folder: Path) -> Path:
    """The Cranfield product's description files (no generated assets) in ``folder``."""
    folder.mkdir()
    for name in ("assembly.toml", "geometry.toml", "sizes.lp", "precedence.lp", "demos.txt"):
        shutil.copy(root / "data" / "cranfield" / name, folder / name)
    return folder


def as_if_killed(run: Path, keep: int) -> None:
    """Make ``run`` a session killed after its first ``keep`` journal lines."""
    journal = run / "journal.jsonl"
    journal.write_text("".join(journal.read_text().splitlines(keepends=True)[:keep]))
    record = json.loads((run / "session.json").read_text())
    (run / "session.json").write_text(json.dumps({**record, "status": "running"}))


def session(run_main: Runner, *args: str, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    """``session --json --plans 1 ARGS`` in this process (the session's process start: e.g.
    ``tests/session/test_session_cells.py``), its cells processes of their own."""
    return run_main("session", "--json", "--plans", "1", *args, cwd=cwd, timeout=90)


def test_a_resume_from_another_folder_keeps_the_backend_and_says_what_it_resumes(tmp_path: Path,
                                                                                run_main: Runner) -> None:
    """A session on a product given by a path relative to its folder, resumed from another
    folder: ``session.json`` keeps the product folder as an absolute path (a shipped one by
    its name), and the resume keeps the run's backend and settings, saying so. The product's
    ids are of the documented longest length (64 characters): they go through the session
    and its resume."""
    (tmp_path / "here").mkdir()
    product, run = two_peg_product(tmp_path / "here" / "plate"), tmp_path / "run"
    first = session(run_main, "--backend", "truth", "--delay", "0.01", "--assembly", "plate", "--out", str(run),
                    cwd=tmp_path / "here")
    assert first.returncode == 0, first.stderr
    truth = {(PEG_A, HOLE_A), (PEG_A, HOLE_B), (PEG_B, HOLE_B)}
    assert {tuple(pair) for pair in json.loads(first.stdout)["fits"]} == truth
    started = [r for r in read_records(run / "journal.jsonl") if not isinstance(r, JournalEntry)]
    assert started and all(len(r.id) > 128 for r in started)  # the run id, two 64-character ids, a number
    kept = json.loads((run / "session.json").read_text())
    assert (kept["backend"], kept["delay_s"]) == ("truth", 0.01) and len(kept["product"]) == 64
    assert kept["assembly"] == str(product)
    as_if_killed(run, keep=2)  # 1 experiment finished
    resumed = session(run_main, "--resume", str(run), "--seed", "5", cwd=tmp_path)  # no --backend: the run's
    assert resumed.returncode == 0, resumed.stderr
    assert f"resuming {run} (start 2): 1 experiment(s) journaled" in resumed.stderr
    assert "backend truth (delay 0.01 s)" in resumed.stderr
    assert f"warning: resume: ignoring --seed 5 (a resume keeps the settings of {run / 'session.json'})" \
        in resumed.stderr
    journal = read_journal(run / "journal.jsonl")
    assert len(journal) == json.loads(resumed.stdout)["experiments"] > 1
    assert all(entry.evidence is None for entry in journal)  # a truth cell's answers: a sim cell gives evidence
    assert {tuple(pair) for pair in json.loads(resumed.stdout)["fits"]} == truth


def test_a_resume_of_an_edited_product_is_refused_changing_nothing(tmp_path: Path, run_main: Runner,
                                                                  root: Path) -> None:
    product, run = cranfield_copy(root, tmp_path / "product"), tmp_path / "run"
    run.mkdir()
    record = new_session_file(SessionSettings(assembly=str(product), backend="truth"), "r")
    record.product = product_digest(product)
    write_session_file(run, record)
    (run / "journal.jsonl").write_text('{"id":"r.p1.br.1","part":"p1","hole":"br","result":"fit","cell":"c1"}\n')
    before = {path.name: path.read_bytes() for path in run.iterdir()}
    with (product / "sizes.lp").open("a") as sizes:
        sizes.write("% edited after the session started\n")
    refused = session(run_main, "--resume", str(run))
    assert refused.returncode == 2 and refused.stdout == ""
    assert refused.stderr == (
        f"error: --resume {run}: the product {product} changed since the session started (digest "
        f"{product_digest(product)[:12]}, {run / 'session.json'} says {record.product[:12]}); its journaled "
        "observations are of the product as it was: start a new session\n")
    assert {path.name: path.read_bytes() for path in run.iterdir() if path.name != ".lock"} == before


def test_a_learned_product_without_an_assignment_exits_3_and_is_done(tmp_path: Path, run_main: Runner) -> None:
    # the thick peg (13 mm) passes neither hole, though sizes.lp says it fits the larger one
    product = two_peg_product(tmp_path / "product", ("p1", "p2", "h1", "h2"), thick_peg_m=0.013)
    run = tmp_path / "run"
    done = run_main(*TRUTH_SESSION[:3], "--assembly", str(product), "--out", str(run), timeout=90)
    assert done.returncode == 3, done.stderr
    error = "the assembly is not solvable: part p2 fits no hole"
    assert done.stderr.endswith(f"error: {error}\n")
    assert f"no plan: {error}\n" in done.stdout and "assignment: none\n" in done.stdout
    # sizes.lp is not what was learned, and there is no precedence.lp: no match, not "unknown"
    assert ("versus the truth: sizes equal False, every true precedence learned unknown (no precedence.lp); "
            "matches truth: False\n") in done.stdout
    record = json.loads((run / "session.json").read_text())
    assert (record["status"], record["plans"], record["error"], record["matches_truth"]) == ("done", [], error, False)
    assert not (run / "assignment.lp").exists()
