"""Plan steps served over Zenoh (``executor serve``): the :class:`Assembler` of the current
plan run, kept between its steps. One run at a time: a step of another run (``assembly``
id) is refused (:class:`executor.backend_plugin.RunActive`) while the current run's product is
unfinished, and starts a fresh world with every part on the tray once it is complete. A
refused step (another run, or one the product does not allow) changes nothing. Holes
blocked with ``--block-hole`` get their obstacle in every fresh world. With
``--uncertainty cell`` every world gets the cell's uncertainty and execution layer, and
the ILC corrections are kept across the plan runs this cell serves (in memory: not
saved).

Precedence experiments (:meth:`AssemblyRunner.run_experiment`) run each in a world of
their own, made for the experiment and closed after it, beside the plan run's world,
which they leave as it was."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from bridge.messages import StepEvidence, StepRequest
from bridge.precedence.experiment import PrecedenceExperiment
from executor import ExecutorError
from executor.assembly.product import Product, load_product
from executor.assembly.step import DEFAULT_LAYER, SETTLE_S, Assembler, StepRecord, check_product_step
from executor.backend_plugin import ExperimentRun, InvalidStep, check_experiment, check_run
from executor.cell_description import CellDescription
from executor.control.ilc import ExecutionLayer, Ilc

if TYPE_CHECKING:
    from executor.assembly.recording import AssemblyRecorder
    from executor.world.perturbation import CellBias


def step_evidence(record: StepRecord) -> StepEvidence:
    """The bridge form of a step record."""
    return StepEvidence(skill=record.skill, attempts=record.attempts, max_force_dev=record.max_force_dev,
                        max_torque_dev=record.max_torque_dev, duration_s=record.duration_s,
                        sim_time_s=record.sim_time_s, pose_error_mm=record.pose_error * 1000.0)


class AssemblyRunner:
    """One assembling world at a time, keyed by the plan run's id."""

    def __init__(self, assembly: str, blocked: Sequence[str] = (), recorder: AssemblyRecorder | None = None, *,
                 bias: CellBias | None = None, layer: ExecutionLayer = DEFAULT_LAYER,
                 description: CellDescription | None = None) -> None:
        """``bias``/``layer``: the cell's (``--uncertainty cell``), else the assembling
        cell's own (:class:`Assembler`); with an ILC layer one :class:`Ilc` serves every run;
        ``description``: the cell's gripper, gains, thresholds, admittance and ILC
        parameters (default :class:`CellDescription`)."""
        self.description = d = CellDescription() if description is None else description
        self.product: Product = load_product(assembly, d)
        self.bias, self.layer = bias, layer
        self.ilc = Ilc(d.ilc, d.gains, d.admittance) if layer.ilc else None
        self.blocked = list(blocked)
        for hole in self.blocked:
            if hole not in self.product.geometry.holes:
                raise ExecutorError(f"--block-hole {hole}: expected a hole of the plate "
                                    f"({', '.join(sorted(self.product.geometry.holes))})")
        self.recorder = recorder
        self._run: str | None = None
        self._assembler: Assembler | None = None

    def assembler(self, run: str) -> Assembler:
        """The world of plan run ``run`` (a fresh one for a new run)."""
        if self._assembler is None or run != self._run:
            self.close()
            self._assembler = Assembler(self.product, self.recorder, description=self.description,
                                        bias=self.bias,
                                        layer=self.layer, ilc=self.ilc)
            if self.recorder is not None:
                self.recorder.attach(self._assembler.world)
            for hole in self.blocked:
                self._assembler.block_hole(hole)
            self._run = run
        return self._assembler

    def run_step(self, request: StepRequest) -> tuple[StepRecord, dict[str, float]]:
        """Carry out the step; the record and every placed part's distance from its goal [mm].

        RunActive, UnknownPair or InvalidStep before anything moves: a step of another run
        while this one is unfinished, or a step the product does not allow."""
        current = None if self._assembler is None else self._run
        placed = set() if self._assembler is None else self._assembler.placed
        check_run(current, request.assembly, self.product.parts, placed)
        check_product_step(self.product, request.part, request.hole, placed if request.assembly == current else ())
        assembler = self.assembler(request.assembly)
        record = assembler.run_step(request.part, request.hole, request.seed)
        errors = assembler.pose_errors()
        if self.recorder is not None:
            self.recorder.log_plan_step(record.part, record.hole, record.outcome, record.attempts,
                                        record.pose_error * 1000.0)
            self.recorder.flush()
        return record, {part: errors[part] * 1000.0 for part in sorted(assembler.placed)}

    def run_experiment(self, experiment: PrecedenceExperiment) -> ExperimentRun:
        """In a fresh world (blocked holes obstructed): set ``experiment.placed`` at their goals
        by hand (:meth:`Assembler.place_by_hand`), then carry out ``experiment.sequence`` step by
        step up to the first that fails. UnknownPair or InvalidStep before anything is made
        (:func:`check_experiment`); InvalidStep when a placed part does not stay at its goal."""
        product = self.product
        check_experiment(experiment, parts=product.parts, pegs=product.pegs, holes=product.geometry.holes)
        assembler = Assembler(product, description=self.description, bias=self.bias, layer=self.layer, ilc=self.ilc)
        try:
            for hole in self.blocked:
                assembler.block_hole(hole)
            fell = assembler.place_by_hand([(step.part, step.hole) for step in experiment.placed])
            if fell:
                raise InvalidStep(f"the known state does not hold: {', '.join(sorted(fell))} did not stay at "
                                  "its goal once set there (no state the product can be in)")
            sim_s = SETTLE_S if experiment.placed else 0.0  # the placed parts are left to the physics that long
            for k, step in enumerate(experiment.sequence, start=1):
                record = assembler.run_step(step.part, step.hole, experiment.seed)
                sim_s += record.sim_time_s
                if record.outcome != "fit":
                    touched = f", touching {' '.join(record.involved)}" if record.involved else ""
                    where = (f"left {record.pose_error * 1000.0:.1f} mm from its goal" if record.reason == "unsupported"
                             else "put back on the tray")
                    detail = (f"{step.part} {record.reason} after {record.attempts} attempt(s): largest force "
                              f"deviation {record.max_force_dev:.1f} N, {where}{touched}")
                    return ExperimentRun(k, record.reason, record.involved, detail, sim_s)
            return ExperimentRun(sim_s=sim_s)
        finally:
            assembler.close()

    def close(self) -> None:
        if self._assembler is not None:
            self._assembler.close()
            self._assembler = None
