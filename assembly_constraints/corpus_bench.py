"""``./run.sh bench corpus``: every product of real CAD in the corpus, imported, learned
and assembled as a user would, each against the truth derived by hand for it.

For each product folder of ``--corpus`` (default ``tests/cad/corpus``; ``--product NAME``,
repeatable, picks some), in ``--out DIR/<name>/`` (default a temporary folder):

1. ``import meshes/ --config import.toml`` (in this process, timed);
2. ``session --backend truth`` (a child process): its fit relation against ``truth.toml``,
   each truth row ok, wrong or missing (the feature not found by the import, or the pair
   decided neither way);
3. ``executor teach`` and ``session --assemble`` on the sim cell (child processes): the
   learned relation against the truth, each pair said to be observed (an experiment in
   physics), entailed (by the size model from observed pairs) or taken from the CAD
   (``sizes.lp``: no cell can try it, the part placed by hand), and the assembly of plan 1:
   each part's final pose error [mm] or ``manual``, the largest over the parts the cell
   placed itself against the 2 mm target.

``--truth-only`` stops after step 2. A product whose step fails gets its row with that
step and the step's one-line error; the bench goes on with the next. Verdicts: ``exact``
(every truth pair right in both sessions, none missing, every part placed by the cell,
within 2 mm, every learned pair observed or entailed), ``sound`` (nothing wrong, but pairs
missing, taken from the CAD, or parts placed by hand: the row says which), ``wrong`` (a
pair learned against the truth, or a part the cell placed more than 2 mm off), ``failed``
(a step did not finish). One table row per product as it finishes, then the details;
``--json FILE`` writes the rows (rewritten after each product). Exit code 1 when a
product is wrong or failed, 2 on bad options.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from asp.session.cells import ROOT, STOP_S
from asp.session.settings import fit_text
from asp.solve import atoms_by_name, load_atoms
from assembly_constraints.corpus_truth import (
    CorpusImport,
    FitCount,
    TruthError,
    compare_fits,
    feature_holes,
    import_product,
    read_truth,
)
from bridge.cli_types import MAX_SEED, ArgumentParser, int_in, number_in, one_line
from bridge.errors import ToolError

CORPUS = ROOT / "tests" / "cad" / "corpus"
"""The repository's corpus of real CAD (absent from an installed package: give --corpus)."""
TARGET_MM = 2.0
"""The largest final pose error [mm] of a part the cell placed itself."""


class BenchError(ToolError):
    """Bad options of the bench: one line, exit 2."""


class StepFailed(Exception):
    """A step of one product did not finish: the ``step`` and its one-line ``error``."""

    def __init__(self, step: str, error: str) -> None:
        super().__init__(f"{step}: {error}")
        self.step, self.error = step, error


@dataclass
class Learned:
    """A sim session's relation: ``fits`` against the truth, the ``experiments``, and how
    each compared pair was learned (``sources``): ``observed`` (an experiment in physics),
    ``entailed`` (by the size model from other answers), ``CAD`` (taken from ``sizes.lp``:
    no cell can try it) or ``demonstrated``; the pairs observed with the room the sim cell
    gives a fit whose room it does not resolve (``widened``, the CAD's room per side where
    above 0), not at the CAD's room."""

    fits: FitCount
    experiments: int
    sources: dict[tuple[str, str], str]
    widened: list[str]

    def count(self, source: str) -> int:
        return sum(s == source for s in self.sources.values())

    def as_json(self) -> dict[str, Any]:
        return {**self.fits.as_json(), "experiments": self.experiments,
                **{key: self.count(source) for key, source in (("observed", "observed"), ("entailed", "entailed"),
                                                              ("from_cad", "CAD"), ("demonstrated", "demonstrated"))},
                "sources": {f"{p}->{h}": source for (p, h), source in sorted(self.sources.items())},
                "widened": self.widened}


@dataclass
class Assembled:
    """Plan 1 assembled in the sim cell: each part's final pose error [mm] (``errors``) and
    the skill of its last step (``skills``): ``manual`` (placed by hand, fixed at its goal)
    and ``fixture`` (the base, set on its locating pins) test nothing of the cell."""

    errors: dict[str, float]
    skills: dict[str, str]

    @property
    def manual(self) -> list[str]:
        return [part for part in self.errors if self.skills.get(part) == "manual"]

    @property
    def placed(self) -> dict[str, float]:
        """The errors [mm] of the parts the cell placed with a skill of its own."""
        return {part: mm for part, mm in self.errors.items() if self.skills.get(part) not in ("manual", "fixture")}

    @property
    def worst_mm(self) -> float | None:
        """The largest final pose error [mm] of the parts the cell placed (None: none)."""
        return max(self.placed.values(), default=None)

    def as_json(self) -> dict[str, Any]:
        return {"final_pose_error_mm": {p: self.skills.get(p) if p not in self.placed else mm
                                        for p, mm in self.errors.items()},
                "manual": self.manual, "max_mm": self.worst_mm, "target_mm": TARGET_MM}


@dataclass
class Row:
    """One product's figures; what a failed step left unset is None."""

    product: str
    parts: int | None = None
    import_s: float | None = None
    truth: FitCount | None = None
    sim: Learned | None = None
    assembly: Assembled | None = None
    failed: StepFailed | None = None
    seconds: dict[str, float] = field(default_factory=dict)

    @property
    def wrong(self) -> list[str]:
        """What is wrong: pairs against the truth, parts the cell placed beyond the target."""
        found = [] if self.truth is None else [f"truth session: {self.truth.describe(p)}" for p in self.truth.wrong]
        if self.sim is not None:
            found += [f"sim session: {self.sim.fits.describe(pair)} ({self.sim.sources[pair]})"
                      for pair in self.sim.fits.wrong]
        if self.assembly is not None:
            found += [f"assembly: {part} {mm:.2f} mm off (target {TARGET_MM:g} mm)"
                      for part, mm in self.assembly.placed.items() if mm > TARGET_MM]
        return found

    @property
    def short_of_exact(self) -> list[str]:
        """Why a product with nothing wrong is not exact (empty: it is)."""
        found = [f"{len(c.missing)} truth pair(s) missing in the {name} session: {', '.join(c.missing)}"
                 for name, c in (("truth", self.truth), ("sim", self.sim.fits if self.sim else None))
                 if c is not None and c.missing]
        if self.sim is not None and self.sim.count("CAD"):
            found.append(f"{self.sim.count('CAD')} pair(s) taken from the CAD, not observed")
        if self.assembly is not None and self.assembly.manual:
            found.append(f"{len(self.assembly.manual)} part(s) placed by hand: {' '.join(self.assembly.manual)}")
        if self.sim is None and self.failed is None:
            found.append("not learned nor assembled in physics (--truth-only)")
        return found

    @property
    def verdict(self) -> str:
        if self.wrong:
            return "wrong"
        if self.failed is not None:
            return f"failed: {self.failed.step}"
        return "sound" if self.short_of_exact else "exact"

    def as_json(self) -> dict[str, Any]:
        return {"product": self.product, "parts": self.parts, "import_s": self.import_s,
                "truth": None if self.truth is None else self.truth.as_json(),
                "sim": None if self.sim is None else self.sim.as_json(),
                "assembly": None if self.assembly is None else self.assembly.as_json(),
                "failed": None if self.failed is None else {"step": self.failed.step, "error": self.failed.error},
                "wrong": self.wrong, "short_of_exact": self.short_of_exact, "verdict": self.verdict,
                "seconds": self.seconds}


def _tool(step: str, argv: list[str], log: Path, timeout: float, accept: tuple[int, ...] = (0,)) -> str:
    """Run ``assembly-constraints ARGV`` as a child process (this interpreter, the
    packages' folder on its PYTHONPATH); its standard output. Its standard error goes to
    ``log``. StepFailed (its last error line) on an exit code not in ``accept``, or after
    ``timeout`` [s] (SIGTERM, so it stops the cells it started; SIGKILL :data:`STOP_S` later)."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), *filter(None, [os.environ.get("PYTHONPATH")])]))
    with log.open("w") as errors:
        child = subprocess.Popen([sys.executable, "-m", "assembly_constraints", *argv], stdout=subprocess.PIPE,
                                 stderr=errors, text=True, env=env)
        try:
            out, _ = child.communicate(timeout=timeout)
        except BaseException as stopped:  # the timeout, Ctrl-C, SIGTERM: the child stops too
            child.send_signal(signal.SIGTERM)
            try:
                child.wait(STOP_S)
            except subprocess.TimeoutExpired:
                child.kill()
                child.wait()
            if isinstance(stopped, subprocess.TimeoutExpired):
                raise StepFailed(step, f"no result within {timeout:g} s (stopped)") from None
            raise
    if child.returncode not in accept:
        lines = [line for line in log.read_text(errors="replace").splitlines() if line.strip()]
        said = next((line for line in reversed(lines) if line.startswith("error")), lines[-1] if lines else "")
        raise StepFailed(step, one_line(f"exit {child.returncode}: {said}", 400))
    return out


def _session(step: str, done: CorpusImport, run: Path, extra: list[str], timeout: float) -> tuple[dict, list]:
    """``session --assembly OUT --out RUN --json EXTRA``, waiting for its cell up to
    ``timeout`` [s]: its JSON result and the atoms of
    its ``learned.lp``. A session that learned but has no plan, or whose assembly stopped,
    exits 3 with its result: the caller reads ``error`` and ``assembly`` in it."""
    # a cell that reads a large product starts slowly on a loaded machine: the step's time bounds that wait too
    out = _tool(step, ["session", "--assembly", str(done.out), "--out", str(run), "--json",
                       "--wait-for-cell", f"{timeout:g}", *extra], run.with_suffix(".log"), timeout, accept=(0, 3))
    try:
        result = json.loads(out)
    except json.JSONDecodeError:
        raise StepFailed(step, "no JSON result on its standard output") from None
    if not (run / "learned.lp").is_file():
        raise StepFailed(step, one_line(result.get("error") or "no learned.lp written", 400))
    return result, load_atoms([run / "learned.lp"])


def _decided(atoms: list) -> tuple[set[tuple[str, str]], set[tuple[str, str]]]:
    """``learned.lp``'s ``fits`` and ``no_fit`` pairs."""
    return ({(p, h) for p, h in atoms_by_name(atoms, "fits", 2)},
            {(p, h) for p, h in atoms_by_name(atoms, "no_fit", 2)})


def _learned(done: CorpusImport, holes: dict[str, str], result: dict, atoms: list) -> Learned:
    """The sim session's relation against the truth, each compared pair's source."""
    count = compare_fits(done, holes, *_decided(atoms))
    tried = {(p, h) for _, p, h, _ in atoms_by_name(atoms, "tried", 4)}
    stated = {(p, h) for p, h in atoms_by_name(atoms, "not_observed", 2)}
    shown = {(p, h) for p, h in result.get("demonstrated", [])}
    sources = {pair: "observed" if pair in tried else "CAD" if pair in stated else
               "demonstrated" if pair in shown else "entailed" for pair in count.pairs}
    nominal = result.get("nominal_fits") or {}
    return Learned(count, result["experiments"], sources,
                   [fit_text(nominal.get("cad_room_m", {}), p, h) for p, h in nominal.get("pairs", [])])


def bench_product(folder: Path, out: Path, truth_only: bool, seed: int, timeout: float) -> Row:
    """Every step of the module docstring on one corpus product, in ``out``."""
    row = Row(folder.name)
    try:
        truth = read_truth(folder)
        row.parts = 1 + len(truth["parts"])
        started = time.perf_counter()
        try:
            done = import_product(folder, out / "import")
        except Exception as exc:  # any failure of the import is this product's, reported in its row
            raise StepFailed("import", one_line(exc if isinstance(exc, ToolError) else f"{type(exc).__name__}: {exc}",
                                                400)) from None
        row.import_s = row.seconds["import"] = round(time.perf_counter() - started, 2)
        holes = feature_holes(done)
        started = time.perf_counter()
        _, atoms = _session("truth session", done, out / "truth", ["--backend", "truth", "--seed", str(seed)],
                            timeout)
        row.seconds["truth session"] = round(time.perf_counter() - started, 2)
        row.truth = compare_fits(done, holes, *_decided(atoms))
        if truth_only:
            return row
        started = time.perf_counter()
        _tool("teach", ["executor", "teach", "--assembly", str(done.out)], out / "teach.log", timeout)
        row.seconds["teach"] = round(time.perf_counter() - started, 2)
        started = time.perf_counter()
        result, atoms = _session("sim session", done, out / "sim", ["--assemble", "--seed", str(seed)], timeout)
        row.seconds["sim session"] = round(time.perf_counter() - started, 2)
        row.sim = _learned(done, holes, result, atoms)
        report = result.get("assembly")
        if report is None:
            raise StepFailed("sim session", one_line(result.get("error") or "no plan to assemble", 400))
        row.assembly = Assembled(dict(report["final_pose_error_mm"]), {s["part"]: s["skill"] for s in report["steps"]})
        if not report["assembled"]:
            raise StepFailed("assemble", one_line(report.get("error") or "not assembled", 400))
    except TruthError as exc:
        row.failed = StepFailed("truth.toml", str(exc))
    except StepFailed as failed:
        row.failed = failed
    return row


COLUMNS = ("product", "parts", "import s", "truth fits ok/total", "sim experiments",
           "sim fits ok/total (observed, entailed, CAD)", "wrong", "assembled max mm", "manual steps", "verdict")


def _cells(row: Row) -> list[str]:
    """A row's table cells (``-``: not measured, the step failed or was not run)."""
    sim, assembly = row.sim, row.assembly
    worst = None if assembly is None else assembly.worst_mm
    return [row.product, "-" if row.parts is None else str(row.parts),
            "-" if row.import_s is None else f"{row.import_s:.1f}",
            "-" if row.truth is None else f"{row.truth.ok}/{row.truth.total}",
            "-" if sim is None else str(sim.experiments),
            "-" if sim is None else (f"{sim.fits.ok}/{sim.fits.total} "
                                     f"({sim.count('observed')}, {sim.count('entailed')}, {sim.count('CAD')})"),
            str(len(row.wrong)),
            "-" if assembly is None else f"{worst:.2f}" if worst is not None else
            "all manual" if assembly.manual and row.failed is None else "none placed",
            "-" if assembly is None else str(len(assembly.manual)),
            row.verdict]


def _details(row: Row) -> list[str]:
    """The lines under the table on one product: the step that failed, what is wrong,
    why it is not exact, each part's final error."""
    lines = [] if row.failed is None else [f"failed at {row.failed.step}: {row.failed.error}"]
    lines += [f"WRONG {w}" for w in row.wrong] + row.short_of_exact
    if row.sim is not None and row.sim.widened:
        lines.append(f"observed with the sim cell's room, not at the CAD's room (0 unless given): "
                     f"{' '.join(row.sim.widened)}")
    if row.assembly is not None:
        placed = row.assembly.placed
        lines.append("final pose error: " + ", ".join(
            f"{p} {mm:.2f} mm" if p in placed else f"{p} {row.assembly.skills.get(p)}"
            for p, mm in row.assembly.errors.items()))
    return [f"{row.product}: {line}" for line in lines]


def _write_json(path: Path, rows: list[Row]) -> None:
    """The rows as JSON in ``path``, replaced whole (a reader never sees half a file)."""
    partial = path.with_name(path.name + ".partial")
    partial.write_text(json.dumps({"target_mm": TARGET_MM, "rows": [r.as_json() for r in rows]}, indent=1) + "\n")
    partial.replace(path)


def _products(corpus: Path, names: list[str]) -> list[Path]:
    """The product folders to run: ``names`` in ``corpus``, or every folder with a truth."""
    if not corpus.is_dir():
        raise BenchError(f"--corpus {corpus}: no such folder (the corpus is the repository's tests/cad/corpus)")
    found = sorted(p for p in corpus.iterdir() if (p / "truth.toml").is_file())
    if not names:
        if not found:
            raise BenchError(f"--corpus {corpus}: no product folder (one holding truth.toml)")
        return found
    unknown = [n for n in names if not (corpus / n / "truth.toml").is_file()]
    if unknown:
        raise BenchError(f"--product {unknown[0]}: no {corpus / unknown[0] / 'truth.toml'}; expected one of: "
                         f"{', '.join(p.name for p in found) or '(none: no folder of it holds truth.toml)'}")
    return [corpus / n for n in dict.fromkeys(names)]


def main(argv: list[str]) -> int:
    parser = ArgumentParser(prog="bench corpus", description="Every product of the corpus of real CAD imported, "
                            "learned with the truth and the sim backends and assembled in the sim cell, each against "
                            "the truth derived by hand for it; exit 1 when one is wrong or failed.")
    parser.add_argument("--product", action="append", default=[], metavar="NAME",
                        help="a product folder of the corpus (repeatable; default every folder holding truth.toml)")
    parser.add_argument("--corpus", type=Path, default=CORPUS, help="the corpus folder (default tests/cad/corpus)")
    parser.add_argument("--out", type=Path, default=None,
                        help="keep each product's import, runs and logs in OUT/NAME (default a temporary folder)")
    parser.add_argument("--json", type=Path, default=None, metavar="FILE", help="also write the rows as JSON to FILE")
    parser.add_argument("--truth-only", action="store_true",
                        help="import and the truth session only: no teaching, no physics")
    parser.add_argument("--seed", type=int_in(0, MAX_SEED), default=0, help="the sessions' seed (default 0)")
    parser.add_argument("--step-timeout", type=number_in(float, 1.0, 86400.0), default=3600.0, metavar="S",
                        help="a product's step that takes longer is stopped and reported failed (default 3600)")
    args = parser.parse_args(argv)
    products = _products(args.corpus, args.product)
    if args.out is not None:
        taken = [str(args.out / p.name) for p in products if (args.out / p.name).exists()]
        if taken:
            raise BenchError(f"--out: {taken[0]} exists; give a folder without the products' names in it")
    rows: list[Row] = []
    print("| " + " | ".join(COLUMNS) + " |\n|" + "---|" * len(COLUMNS), flush=True)
    with tempfile.TemporaryDirectory(prefix="bench-corpus-") as tmp:
        for folder in products:
            out = (Path(tmp) if args.out is None else args.out) / folder.name
            out.mkdir(parents=True)
            rows.append(bench_product(folder, out, args.truth_only, args.seed, args.step_timeout))
            print("| " + " | ".join(_cells(rows[-1])) + " |", flush=True)
            if args.json is not None:
                _write_json(args.json, rows)
    print()
    for row in rows:
        for line in _details(row):
            print(line)
    bad = [row for row in rows if row.verdict == "wrong" or row.failed is not None]
    counts = {v: sum(r.verdict.split(":")[0] == v for r in rows) for v in ("exact", "sound", "wrong", "failed")}
    print(", ".join(f"{n} {v}" for v, n in counts.items()) + f" of {len(rows)} product(s)"
          + (f"; exit 1: {', '.join(f'{r.product} {r.verdict}' for r in bad)}" if bad else ""))
    return 1 if bad else 0
