"""Experiment outcomes as ASP facts (``experiments.lp``), written by ``precedence explore``
and read by ``precedence learn --experiments``.

One experiment E (1-based) is ``experiment(E,"id",A,B)`` (the request id as a string, the
tested pair: can B go before A), ``experiment_step(E,I,P)`` per step (I 1-based), and
``experiment_success(E)`` or ``experiment_failed(E,I,Reason)`` (Reason: blocked, jammed,
unsupported, precedence, size) with ``experiment_blocker(E,P)`` per placed part P the failing
part was seen touching. The file is read as data (ground facts only); each experiment is checked as
the bridge checks a message (:mod:`bridge.precedence.experiment`).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import clingo
import msgspec

from asp import PlannerError
from asp.precedence.explore.knowledge import Trial
from asp.solve import read_ground_facts, write_facts
from bridge.precedence.experiment import MAX_STEPS, PrecedenceExperiment, PrecedenceOutcome

MAX_TRIALS = 10_000
"""The most experiments a file holds."""
_SIGNATURES = {"experiment": 4, "experiment_step": 3, "experiment_success": 1, "experiment_failed": 3,
               "experiment_blocker": 2}


def trial_facts(trials: Sequence[Trial]) -> list[clingo.Symbol]:
    """The facts of the trials (E numbered from 1 in order)."""
    atoms: list[clingo.Symbol] = []
    for e, trial in enumerate(trials, 1):
        number = clingo.Number(e)
        a, b = trial.experiment.pair
        atoms.append(clingo.Function("experiment", [number, clingo.String(trial.experiment.id),
                                                    clingo.Function(a), clingo.Function(b)]))
        atoms += [clingo.Function("experiment_step", [number, clingo.Number(i), clingo.Function(step.part)])
                  for i, step in enumerate(trial.experiment.sequence, 1)]
        outcome = trial.outcome
        if outcome.outcome == "success":
            atoms.append(clingo.Function("experiment_success", [number]))
        else:
            assert outcome.failed_step is not None and outcome.reason is not None
            atoms.append(clingo.Function("experiment_failed", [number, clingo.Number(outcome.failed_step),
                                                               clingo.Function(outcome.reason)]))
            atoms += [clingo.Function("experiment_blocker", [number, clingo.Function(p)]) for p in outcome.blocked_by]
    return atoms


def write_trials(path: Path | str, trials: Sequence[Trial]) -> None:
    """Write the trials' facts to ``path`` (atomically)."""
    write_facts(path, trial_facts(trials), header=f"{len(trials)} precedence experiments and their outcomes")


def _value(symbol: clingo.Symbol) -> Any:
    if symbol.type == clingo.SymbolType.Number:
        return symbol.number
    if symbol.type == clingo.SymbolType.String:
        return symbol.string
    return symbol.name if symbol.type == clingo.SymbolType.Function and not symbol.arguments else str(symbol)


def load_trials(path: Path | str, parts: Sequence[str]) -> tuple[Trial, ...]:
    """The trials of ``path``; PlannerError naming ``path:line`` or the experiment at a bad fact,
    an unknown part, a missing or double outcome, or an experiment the bridge would refuse."""
    path = Path(path)
    expected = ("experiment/4, experiment_step/3, experiment_success/1, experiment_failed/3 and "
                "experiment_blocker/2 facts")
    heads: dict[int, tuple[int, str, str, str]] = {}
    steps: dict[int, dict[int, str]] = {}
    outcomes: dict[int, dict[str, Any]] = {}
    blockers: dict[int, list[str]] = {}
    for line, atom in read_ground_facts(path, expected, max_facts=MAX_TRIALS * (MAX_STEPS + 2)):
        arity = _SIGNATURES.get(atom.name)
        values = [_value(a) for a in atom.arguments]
        if arity != len(values) or not isinstance(values[0], int) or not 1 <= values[0] <= MAX_TRIALS:
            raise PlannerError(f"{path}:{line}: {str(atom)[:60]}: expected {expected} with E a number "
                               f"1..{MAX_TRIALS}")
        e = values[0]
        if atom.name in ("experiment_step", "experiment_blocker") and values[-1] not in parts:
            raise PlannerError(f"{path}:{line}: {values[-1]} is not a part ({' '.join(parts)})")
        if atom.name == "experiment":
            unknown = [v for v in values[2:] if v not in parts]
            if unknown or not isinstance(values[1], str) or e in heads:
                raise PlannerError(f"{path}:{line}: {str(atom)[:60]}: expected experiment(E,\"id\",A,B) once per "
                                   f"E with A and B parts ({' '.join(parts)})")
            heads[e] = (line, values[1], values[2], values[3])
        elif atom.name == "experiment_step":
            if not isinstance(values[1], int) or values[1] in steps.setdefault(e, {}):
                raise PlannerError(f"{path}:{line}: {atom}: expected one experiment_step(E,I,P) per step I")
            steps[e][values[1]] = values[2]
        elif atom.name == "experiment_blocker":
            blockers.setdefault(e, []).append(values[1])
        else:
            if e in outcomes:
                raise PlannerError(f"{path}:{line}: {atom}: experiment {e} has a second outcome; expected one")
            outcomes[e] = ({"outcome": "success"} if atom.name == "experiment_success" else
                           {"outcome": "failed", "failed_step": values[1], "reason": values[2]})
    trials = []
    for e in sorted(set(heads) | set(steps) | set(outcomes) | set(blockers)):
        numbers = sorted(steps.get(e, {}))
        if e not in heads or e not in outcomes or numbers != list(range(1, len(numbers) + 1)):
            raise PlannerError(f"{path}: experiment {e}: expected experiment/4, steps 1..N and one outcome")
        line, request, a, b = heads[e]
        sequence = [{"part": steps[e][i]} for i in sorted(steps[e])]
        try:
            experiment = msgspec.convert({"kind": "precedence_experiment", "id": request, "pair": [a, b],
                                          "sequence": sequence}, PrecedenceExperiment)
            outcome = msgspec.convert({"kind": "precedence_outcome", "id": request, "cell": "file", "pair": [a, b],
                                       "blocked_by": sorted(blockers.get(e, ())), **outcomes[e]}, PrecedenceOutcome)
        except msgspec.ValidationError as exc:
            raise PlannerError(f"{path}:{line}: experiment {e}: {exc}") from None
        if outcome.failed_step is not None and outcome.failed_step > len(experiment.sequence):
            raise PlannerError(f"{path}:{line}: experiment {e} fails at step {outcome.failed_step} of "
                               f"{len(experiment.sequence)}; expected a step of the experiment")
        trials.append(Trial(experiment, outcome, f"{path}:{line}"))
    return tuple(trials)
