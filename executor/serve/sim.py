"""The ``sim`` backend of a cell node: the PyBullet :class:`executor.trial.Cell`
(imported lazily) with the execution layer and uncertainty of its cell settings and its ILC
state; plan steps in the assembling world of :mod:`executor.assembly`
(kept between the steps of one plan run); precedence experiments each in a fresh
assembling world (:meth:`executor.assembly.step_backend.AssemblyRunner.run_experiment`)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from bridge.cell_settings import ServeSettings
from bridge.messages import Evidence, InsertRequest, Result, StepRequest
from bridge.precedence.experiment import PrecedenceExperiment
from bridge.recording.sinks import NO_VIEWER, Viewer
from executor.backend_plugin import ExperimentRun, StepOutcome

if TYPE_CHECKING:
    from executor.assembly.step_backend import AssemblyRunner
    from executor.trial import CellSetup


def _planner_numbered_logger() -> type:
    """AttemptLogger that logs a trial under the planner's experiment number, if given."""
    from executor.rerun_log import AttemptLogger

    class PlannerNumbered(AttemptLogger):
        planner_experiment: int | None = None

        def begin_attempt(self, part: str, hole: str, trial_seed: int, attempt: int,
                          experiment: int | None = None) -> None:
            super().begin_attempt(part, hole, trial_seed, attempt,
                                  experiment if experiment is not None else self.planner_experiment)

    return PlannerNumbered


class SimBackend:
    """The PyBullet cell (DIRECT mode); logs every attempt to Rerun if ``settings.rrd`` or
    ``settings.viewer_url`` is given."""

    def __init__(self, settings: ServeSettings, setup: CellSetup) -> None:
        """``settings``: the node's (assembly, cell id, recording, ``block_holes`` for plan
        steps, ``ilc_state``: the file its ILC corrections are loaded from and saved to,
        atomically after every update, so a resumed session's cell starts from them; with
        ``cell.uncertainty`` ``cell`` plan steps get the Cell's systematic errors, layer
        and an ILC, with ``random`` their own); ``setup``: what the Cell is, its
        description already decoded (:func:`executor.trial.cell_setup`)."""
        from executor.rerun_log import LogTarget
        from executor.trial import Cell

        rrd = None if settings.rrd is None else Path(settings.rrd)
        viewer = Viewer(settings.viewer_url)
        _PlannerNumbered = _planner_numbered_logger()
        target = LogTarget(rrd_path=rrd, recording_id=settings.recording_id, viewer=viewer,
                           send_blueprint=False)  # the planner sends it
        self._logger = (_PlannerNumbered(settings.cell_id, target)
                        if rrd is not None or viewer != NO_VIEWER else None)
        ilc_state = None if settings.ilc_state is None else Path(settings.ilc_state)
        self._cell = Cell(settings.assembly, gui=False, logger=self._logger, ilc_state=ilc_state, setup=setup)
        self._assembly, self._blocked, self._cell_id = settings.assembly, list(settings.block_holes), settings.cell_id
        self._cell_uncertainty = settings.cell.uncertainty == "cell"
        self._runner: AssemblyRunner | None = None

    def _assembling(self) -> AssemblyRunner:
        """The assembling runner, made on the first plan step or precedence experiment."""
        if self._runner is None:
            from executor.assembly.recording import AssemblyRecorder
            from executor.assembly.step_backend import AssemblyRunner

            recorder = None if self._logger is None else AssemblyRecorder(self._logger.rec, self._cell_id)
            cell = self._cell
            self._runner = (AssemblyRunner(self._assembly, self._blocked, recorder, bias=cell.bias,
                                           layer=cell.layer)
                            if self._cell_uncertainty else AssemblyRunner(self._assembly, self._blocked, recorder))
        return self._runner

    def run_step(self, request: StepRequest) -> StepOutcome:
        from executor.assembly.step_backend import step_evidence

        record, errors = self._assembling().run_step(request)
        result: Result = "fit" if record.outcome == "fit" else "no_fit"
        return result, step_evidence(record), errors

    def run_precedence(self, experiment: PrecedenceExperiment) -> ExperimentRun:
        return self._assembling().run_experiment(experiment)

    def run(self, request: InsertRequest) -> tuple[Result, Evidence | None]:
        if self._logger is not None:
            self._logger.planner_experiment = request.experiment or None
        trial = self._cell.run_trial(request.part, request.hole, seed=request.seed).to_json()
        evidence = Evidence(attempts=int(trial["attempts"]),
                            max_force_dev=float(trial["max_force_dev"]),
                            max_torque_dev=float(trial["max_torque_dev"]),
                            end_error=float(trial["end_error"]),
                            duration_s=float(trial["duration_s"]))
        return trial["outcome"], evidence

    def close(self) -> None:
        self._cell.close()
        if self._runner is not None:
            self._runner.close()
        if self._logger is not None:
            self._logger.close()
