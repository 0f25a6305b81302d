"""``./run.sh executor campaign``: the paper's Fig. 18 robustness campaign, and more.

Runs ``--trials`` (default 40) randomised executions of every fitting pair of the
paper's Fig. 18 table (round peg ``p1`` and tight round peg ``tp`` in the small round
``r1`` = H1, big round ``br`` = H3 and square ``s1`` = H4 holes; square peg ``p3`` in
``br`` and ``s1``; shaft ``sh`` in ``br``) and of every non-fitting pair of parts
{p1, p3, sh, tp} × holes {r1, s1, br} (``p3``→``r1``, ``sh``→``r1``, ``sh``→``s1``),
which the paper did not run. Each trial is a fresh grasp error and hole-pose error
(seeded), up to two attempts (paper 3.2).

The pairs are spread over ``--jobs`` processes (default: the cores of this
machine), each with its own DIRECT PyBullet cell (the same cell seed: the same
systematic errors); the trials of one pair run in order in one process (with ILC an
execution learns from the ones before it). Trial ``i`` of pair ``k`` always uses seed
``S + k·N + i`` (N trials per pair), so the table does not depend on scheduling.

Prints the table (1st-trial successes, successes after the 2nd trial, correct
'no_fit' for non-fitting pairs); ``--json`` prints ``{"pairs": [...], "all_correct",
"false_fits", ...}``; ``--plot DIR`` writes ``fig18_table.png``, ``fig17_forces.png``
(measured vs desired force over DMP phase for a success ``p1``→``r1`` and a failure
``p3``→``r1``, as in the paper) and ``fig17.rrd`` (those two trials in Rerun).
"""

from __future__ import annotations

import argparse
import contextlib
import functools
import json
import multiprocessing
import os
import statistics
import sys
import time
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

from bridge.cell_settings import add_cell_arguments, cell_settings_of
from bridge.cli_types import (
    MAX_SEED,
    ArgumentParser,
    add_assembly_argument,
    add_jobs_argument,
    int_in,
    nonempty_path,
)
from bridge.progress import progress
from executor import ExecutorError
from executor.campaign.pairs import (
    HOLE_NAMES,
    PAIRS_ARGUMENT,
    PART_NAMES,
    CampaignPair,
    PairStats,
    pair_stats,
    select_pairs,
)

if TYPE_CHECKING:  # the cell's modules (PyBullet, trimesh, SciPy, Rerun) only where a cell is made:
    from executor.trial import CellSetup  # a worker of an injected runner starts without them


class TrialRunner(Protocol):
    """Runs one trial and returns ``TrialResult.to_json()`` (``outcome``, ``attempts``,
    ``duration_s``, ...)."""

    def __call__(self, part: str, hole: str, seed: int) -> dict[str, Any]: ...


RunnerFactory = Callable[[], TrialRunner]
"""Builds a runner inside a worker process (must be picklable: a module-level
function or a ``functools.partial`` of one)."""


class CellRunner:
    """A :class:`executor.trial.Cell` in DIRECT mode, reused for every trial of a worker;
    ``setup``: what the cell is (:class:`executor.trial.CellSetup`; default: the default cell)."""

    def __init__(self, assembly: str, setup: CellSetup | None = None) -> None:
        from executor.trial import Cell, CellSetup

        self.cell = Cell(assembly, setup=CellSetup() if setup is None else setup)

    def __call__(self, part: str, hole: str, seed: int) -> dict[str, Any]:
        return self.cell.run_trial(part, hole, seed=seed, max_attempts=2).to_json()


# -- worker processes -------------------------------------------------------------------

_RUNNER: TrialRunner | None = None


def _init_worker(factory: RunnerFactory) -> None:
    global _RUNNER
    _RUNNER = factory()


def _run_task(task: tuple[int, str, str, list[int]]) -> tuple[int, list[dict[str, Any]]]:
    pair_index, part, hole, seeds = task
    assert _RUNNER is not None, "worker not initialised"
    return pair_index, [_RUNNER(part, hole, seed) for seed in seeds]


def run_campaign(
    pairs: Sequence[CampaignPair],
    trials: int,
    seed: int,
    workers: int,
    factory: RunnerFactory,
) -> list[list[dict[str, Any]]]:
    """Results per pair (``trials`` dicts each, in seed order), run on ``workers``
    processes (1: in this process), with a progress bar over the pairs on a terminal.

    The trials of one pair run in order in one process: with ILC, an execution depends
    on the executions of the same pair before it (the learned correction), so the table
    does not depend on scheduling."""
    if trials < 1 or workers < 1:
        raise ExecutorError(f"--trials {trials} / --jobs {workers}: expected positive numbers")
    tasks = [(k, pair.part, pair.hole, [seed + k * trials + i for i in range(trials)])
             for k, pair in enumerate(pairs)]
    results: list[list[dict[str, Any]]] = [[] for _ in pairs]

    def store(item: tuple[int, list[dict[str, Any]]]) -> None:
        k, pair_results = item
        results[k] = pair_results

    if workers == 1:
        _init_worker(factory)
        for task in progress(tasks, desc="campaign", total=len(tasks), unit="pair"):
            store(_run_task(task))
        return results
    with ProcessPoolExecutor(
        workers, mp_context=multiprocessing.get_context("spawn"),
        initializer=_init_worker, initargs=(factory,),
    ) as pool:
        futures = [pool.submit(_run_task, task) for task in tasks]
        try:
            for future in progress(as_completed(futures), desc="campaign", total=len(futures), unit="pair"):
                store(future.result())
        except BrokenProcessPool as exc:
            raise ExecutorError(
                f"campaign: a worker process died ({exc}); expected it to finish its trials"
            ) from exc
        except BaseException:  # a failed trial or Ctrl-C: do not run the rest
            pool.shutdown(wait=False, cancel_futures=True)
            raise
    return results


@dataclass
class CampaignRun:
    """A finished campaign: per-pair results (``TrialResult.to_json()`` dicts, seed
    order), their Fig. 18 counts and the wall time [s]."""

    pairs: list[CampaignPair]
    results: list[list[dict[str, Any]]]
    stats: list[PairStats]
    wall_s: float

    @property
    def durations(self) -> list[float]:
        """Wall time of every trial [s]."""
        return [r["duration_s"] for rs in self.results for r in rs]


def timed_campaign(
    pairs: Sequence[CampaignPair], trials: int, seed: int, workers: int, factory: RunnerFactory,
) -> CampaignRun:
    """:func:`run_campaign` plus counts and wall time."""
    start = time.perf_counter()
    results = run_campaign(pairs, trials, seed, workers, factory)
    wall_s = time.perf_counter() - start
    stats = [pair_stats(pair, rs) for pair, rs in zip(pairs, results)]
    return CampaignRun(list(pairs), results, stats, wall_s)


# -- report -----------------------------------------------------------------------------

def format_table(stats: Sequence[PairStats]) -> str:
    """The Fig. 18 table (fitting pairs) followed by the non-fitting pairs."""
    header = (
        f"{'object':<18} {'hole':<20} {'fits':<4} {'n':>3} {'1st trial':>9} "
        f"{'after 2nd':>9} {'correct':>7} {'ratio %':>7} {'median s':>8}"
    )
    lines = [header, "-" * len(header)]
    for s in stats:
        first = f"{s.first_trial:>9}" if s.fits else f"{'-':>9}"
        second = f"{s.after_second:>9}" if s.fits else f"{'-':>9}"
        lines.append(
            f"{PART_NAMES.get(s.part, s.part) + ' ' + s.part:<18} "
            f"{HOLE_NAMES.get(s.hole, s.hole) + ' ' + s.hole:<20} {'yes' if s.fits else 'no':<4} "
            f"{s.trials:>3} {first} {second} {s.correct:>7} {100 * s.correct_ratio:>7.1f} "
            f"{s.median_duration_s:>8.2f}"
        )
    return "\n".join(lines)


def campaign_report(run: CampaignRun, seed: int, workers: int) -> dict[str, Any]:
    """The ``--json`` document."""
    durations = run.durations
    return {
        "trials_per_pair": max((s.trials for s in run.stats), default=0),
        "seed": seed,
        "jobs": workers,
        "wall_s": run.wall_s,
        "trial_wall_median_s": statistics.median(durations) if durations else 0.0,
        "pairs": [asdict(s) | {"correct_ratio": s.correct_ratio} for s in run.stats],
        "all_correct": all(s.correct == s.trials for s in run.stats),
        "false_fits": sum(s.false_fits for s in run.stats),
    }


def build_parser() -> argparse.ArgumentParser:
    parser = ArgumentParser(
        prog="executor campaign",
        description="Fig. 18: randomised executions of every fitting pair of the paper's "
        "table plus every non-fitting pair of {p1,tp,p3,sh} x {r1,br,s1}.",
    )
    parser.add_argument("--trials", type=int_in(1, 10**5), default=40, help="executions per pair (default 40)")
    parser.add_argument("--seed", type=int_in(0, MAX_SEED), default=0, help="base seed (default 0)")
    add_jobs_argument(parser, "worker processes")
    parser.add_argument("--pairs", type=PAIRS_ARGUMENT, help="only these pairs, e.g. p1:r1,p3:r1 (default: all)")
    add_assembly_argument(parser)
    parser.add_argument("--json", action="store_true", help="print JSON instead of the table")
    parser.add_argument("--plot", metavar="DIR", type=nonempty_path, help="write Fig. 17 and Fig. 18 images here")
    add_cell_arguments(parser)
    return parser


def main(argv: Sequence[str]) -> int:
    """``executor campaign``; returns 0 when every outcome was correct, else 1."""
    from executor.trial import cell_setup

    args = build_parser().parse_args(list(argv))
    pairs = select_pairs(args.pairs)
    setup = cell_setup(cell_settings_of(args))  # the cell description checked before anything is written
    if args.plot:  # before the campaign, which takes minutes
        from bridge.files import check_writable, make_folder

        check_writable(make_folder(args.plot) / "fig18_table.png")
    with stdout_to_stderr():  # PyBullet prints its banner on fd 1, also in the workers
        run = timed_campaign(
            pairs, args.trials, args.seed, args.jobs,
            functools.partial(CellRunner, args.assembly, setup),
        )
        report = campaign_report(run, args.seed, args.jobs)
        if args.plot:
            from executor.campaign.plots import write_plots

            plots = write_plots(Path(args.plot), run.stats, args.assembly, args.seed)
            report["plots"] = [str(p) for p in plots]
    if args.json:
        print(json.dumps(report, indent=2))
    else:
        print(format_table(run.stats))
        print(
            f"all correct: {report['all_correct']}; too-big parts reported fitting: "
            f"{report['false_fits']}; {len(run.durations)} trials in {run.wall_s:.1f} s wall on "
            f"{args.jobs} worker(s), median {report['trial_wall_median_s']:.2f} s/trial"
        )
        for path in report.get("plots", []):
            print(f"wrote {path}")
    return 0 if report["all_correct"] else 1


@contextlib.contextmanager
def stdout_to_stderr() -> Iterator[None]:
    """Send file descriptor 1 to stderr meanwhile (also for child processes started
    meanwhile), so that C libraries' prints cannot mix into the table or the JSON."""
    sys.stdout.flush()
    saved = os.dup(1)
    os.dup2(2, 1)
    try:
        yield
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(saved)


