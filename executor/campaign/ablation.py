"""``./run.sh bench executor --ablation --trials N --seed S [--json]``: what each part of
the execution layer adds, measured side by side.

Every variant of :data:`executor.control.ilc.LAYERS` (pure position control along the
DMP, admittance P, admittance PI, PI + phase stopping, all + ILC) runs ``N`` trials of
every campaign pair (the fitting rows of Fig. 18 and the too-big pairs) on the same
seeded perturbations: the trials of a pair are run as groups of ``--executions``
consecutive executions (default 5) in one cell, group ``g`` with cell seed ``S + g``
(its systematic errors) and execution ``j`` with trial seed ``S + g·E + j`` (its random
errors), so with ILC execution ``j`` learns from executions ``0..j−1`` of that pair in
that cell.  A last run, PI + phase stopping with the systematic errors set to zero
(:func:`executor.world.perturbation.random_only`), gives the force
deviation the random part alone leaves: the floor no learning across executions can go
below.

Per variant (fitting pairs unless said): the share of executions that fit at the first
attempt and after the second, false fits (too-big pairs reported fitting), the median
and 95th percentile of the first attempt's maximal sustained force deviation [N]
(the statistic of eq. 6), the share of attempts whose force deviation reached F_stop,
attempts rescued by the wiggle (fit after a wiggle), the
median trial wall time [s].  For ILC, per execution index 1..E, the median maximal
force deviation and the first-attempt share of the full layer, next to PI + phase
stopping without ILC on the same executions, also per pair (``by_pair``).
"""

from __future__ import annotations

import multiprocessing
import statistics
from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor
from typing import Any

import msgspec
import numpy as np

from bridge.cell_settings import Magnitudes
from bridge.progress import progress
from executor import ExecutorError
from executor.campaign.pairs import CampaignPair, campaign_pairs
from executor.cell_description import CellDescription
from executor.control.ilc import LAYERS
from executor.world.perturbation import random_only

FLOOR = "random_only"
"""The extra run: PI + phase stopping with only the random part of the perturbations."""

_CELL: Any = None
"""This process's cell of the run's product (one PyBullet client per part shape), made by
:func:`_make_cell` for each run: a run in process never uses a cell of an earlier run's
product or of its files before an edit."""


def _make_cell(assembly: str) -> None:
    """This process's cell of ``assembly``, made now (an earlier one closed)."""
    from executor.trial import Cell

    global _CELL
    if _CELL is not None:
        _CELL.close()
    _CELL = Cell(assembly)


def _run_group(task: tuple[str, int, str, str, list[int], Magnitudes]) -> list[dict[str, Any]]:
    """One group: consecutive executions of one pair in a fresh cell state (cell seed)."""
    variant, cell_seed, part, hole, seeds, magnitudes = task
    assert _CELL is not None, "a group run before its cell was made"
    _CELL.reset_state(layer="pi_phase_stop" if variant == FLOOR else variant,
                      magnitudes=random_only(magnitudes) if variant == FLOOR else magnitudes, cell_seed=cell_seed)
    return [_CELL.run_trial(part, hole, seed).to_json() for seed in seeds]


def _quantile(values: Sequence[float], q: float) -> float:
    return float(np.quantile(values, q)) if values else 0.0


def _first_force(result: dict[str, Any]) -> float:
    return float(result["evidence"][0]["max_force_dev"])


def variant_row(name: str, rows: Sequence[tuple[bool, int, dict[str, Any]]], f_stop: float) -> dict[str, Any]:
    """One variant's line of the table from its trials' JSON (``rows``: whether the pair
    fits, execution index, the trial).  ``force_past_stop``: the share of all attempts on
    fitting pairs whose sustained force deviation reached ``f_stop`` [N] (eq. 6), the wiggle's
    and the retry's work included: how often this layer let the contact forces grow to
    where the cell would stop."""
    fitting = [r for fit, _, r in rows if fit]
    forces = [_first_force(r) for r in fitting]
    attempts = [e for r in fitting for e in r["evidence"]]
    return {
        "name": name,
        "fitting_first_attempt": sum(r["outcome"] == "fit" and r["attempts"] == 1 for r in fitting) / len(fitting),
        "fitting_after_retry": sum(r["outcome"] == "fit" for r in fitting) / len(fitting),
        "false_fits": sum(r["outcome"] == "fit" for fit, _, r in rows if not fit),
        "max_force_dev_median": statistics.median(forces),
        "max_force_dev_p95": _quantile(forces, 0.95),
        "force_past_stop": sum(e["max_force_dev"] >= f_stop for e in attempts) / len(attempts),
        "wiggle_rescues": sum(e["wiggles"] > 0 and e["outcome"] == "fit" for e in attempts),
        "duration_median_s": statistics.median(r["duration_s"] for _, _, r in rows),
    }


def run_ablation(assembly: str, trials: int, seed: int, executions: int, workers: int,
                 magnitudes: Magnitudes, pairs: Sequence[CampaignPair] | None = None) -> dict[str, Any]:
    """The ablation table (see the module text) as a JSON-ready dict, over ``pairs``
    (default: every campaign pair; at least one must fit)."""
    if trials < 1 or executions < 1 or workers < 1:
        raise ExecutorError(f"--trials {trials} / --executions {executions} / --jobs {workers}: "
                            "expected positive numbers")
    pairs = campaign_pairs() if pairs is None else list(pairs)
    if not any(pair.fits for pair in pairs):
        raise ExecutorError("--pairs: expected at least one fitting pair (the table is over fitting pairs)")
    groups = [list(range(g * executions, min(trials, (g + 1) * executions)))
              for g in range((trials + executions - 1) // executions)]
    variants = [*LAYERS, FLOOR]
    tasks = [(variant, seed + g, pair.part, pair.hole, [seed + j for j in group], magnitudes)
             for variant in variants for g, group in enumerate(groups) for pair in pairs
             if pair.fits or variant != FLOOR]
    if workers == 1:
        _make_cell(assembly)
        outputs = [_run_group(task) for task in progress(tasks, desc="ablation", total=len(tasks), unit="group")]
    else:
        with ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn"),
                                 initializer=_make_cell, initargs=(assembly,)) as pool:
            outputs = list(progress(pool.map(_run_group, tasks), desc="ablation", total=len(tasks), unit="group"))
    fits = {(p.part, p.hole): p.fits for p in pairs}
    by_variant: dict[str, list[tuple[bool, int, dict[str, Any]]]] = {v: [] for v in variants}
    for task, results in zip(tasks, outputs):
        for index, result in enumerate(results):
            by_variant[task[0]].append((fits[task[2], task[3]], index, result))

    def per_execution(name: str) -> list[list[dict[str, Any]]]:
        return [[r for fit, i, r in by_variant[name] if fit and i == j] for j in range(executions)]

    def pair_medians(name: str) -> dict[str, list[float]]:
        """Median max force deviation per execution index, per fitting pair."""
        return {f"{p.part}:{p.hole}": [statistics.median(_first_force(r) for r in rs) for rs in
                                       [[r for fit, i, r in by_variant[name] if fit and i == j
                                         and (r["part"], r["hole"]) == (p.part, p.hole)] for j in range(executions)]]
                for p in pairs if p.fits}

    full, without = per_execution("full"), per_execution("pi_phase_stop")
    floor = [_first_force(r) for _, _, r in by_variant[FLOOR]]
    f_stop = CellDescription().thresholds.f_stop  # the cells of the ablation have the built-in description
    return {
        "trials": trials, "seed": seed, "executions_per_cell": executions,
        "perturbation": msgspec.to_builtins(magnitudes),
        "variants": [variant_row(name, by_variant[name], f_stop) for name in LAYERS],
        "ilc": {
            "executions": list(range(1, executions + 1)),
            "max_force_dev_median": [statistics.median(map(_first_force, rs)) for rs in full],
            "first_attempt": [sum(r["outcome"] == "fit" and r["attempts"] == 1 for r in rs) / len(rs) for rs in full],
            "without_ilc_max_force_dev_median": [statistics.median(map(_first_force, rs)) for rs in without],
            "random_only_floor_max_force_dev_median": statistics.median(floor),
            "random_only_first_attempt": variant_row(FLOOR, by_variant[FLOOR], f_stop)["fitting_first_attempt"],
            "by_pair": pair_medians("full"),
            "by_pair_without_ilc": pair_medians("pi_phase_stop"),
        },
    }


def format_ablation(report: dict[str, Any]) -> str:
    """The table as text lines."""
    header = (f"{'variant':<15} {'1st att.':>8} {'retry':>6} {'false':>5} {'dF med':>7} {'dF p95':>7} "
              f"{'F>=stop':>7} {'wiggle':>6} {'s/trial':>7}")
    lines = [header, "-" * len(header)]
    for v in report["variants"]:
        lines.append(f"{v['name']:<15} {v['fitting_first_attempt']:>8.3f} {v['fitting_after_retry']:>6.3f} "
                     f"{v['false_fits']:>5d} {v['max_force_dev_median']:>7.2f} {v['max_force_dev_p95']:>7.2f} "
                     f"{v['force_past_stop']:>7.3f} {v['wiggle_rescues']:>6d} {v['duration_median_s']:>7.2f}")
    ilc = report["ilc"]
    lines.append("ILC (full layer), per execution of a pair in a cell: " + ", ".join(
        f"#{k}: dF {f:.2f} N, 1st {s:.2f}" for k, f, s in
        zip(ilc["executions"], ilc["max_force_dev_median"], ilc["first_attempt"])))
    lines.append("without ILC (pi_phase_stop), same executions: " + ", ".join(
        f"#{k}: {f:.2f} N" for k, f in zip(ilc["executions"], ilc["without_ilc_max_force_dev_median"])))
    lines.append(f"random part only (floor): dF {ilc['random_only_floor_max_force_dev_median']:.2f} N, "
                 f"1st attempt {ilc['random_only_first_attempt']:.3f}")
    return "\n".join(lines)
