"""The step loop: the planner drives a cell through a plan, one step request at a time,
and recovers from failed steps.

Each step goes to the cell (which retries a failed insertion once, as in the paper);
a step that still fails is recorded as an observation ``no_fit(P,H)`` with its evidence,
and the rest is re-planned from the current state (:func:`asp.assemble.replan.replan`:
placed parts stay placed).  A part placed without a hole that fails, or no assignment
left, stops the run (:class:`AssemblyStopped`, exit code 3), the placed parts staying
where they are.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Protocol

from asp import PlannerError
from asp.assemble.replan import replan, with_no_fit
from asp.plans.assign import LearnedFacts, UnsolvableAssembly
from asp.plans.plans import Plan, PlanStep
from bridge.messages import StepReply

MAX_REPLANS = 20
"""A run stops after this many re-plans (each one withdraws a part-hole pair, so it ends anyway)."""


class StepDriver(Protocol):
    """Carries out plan steps in a cell (over Zenoh, or a fake in tests)."""

    def step(self, number: int, part: str, hole: str | None) -> StepReply:
        """Step ``number`` (1-based): place ``part`` (into ``hole``); the cell's reply."""
        ...


class AssemblyStopped(PlannerError):
    """The product cannot be finished; ``report`` is the JSON so far (``assembled`` false)."""

    def __init__(self, message: str, report: dict) -> None:
        super().__init__(message)
        self.report = report


@dataclass
class _Run:
    plan: Plan
    steps: list[dict] = field(default_factory=list)
    replans: list[dict] = field(default_factory=list)
    observations: list[dict] = field(default_factory=list)
    done: list[PlanStep] = field(default_factory=list)
    errors_mm: dict[str, float] = field(default_factory=dict)

    def report(self, original: Plan, assembled: bool) -> dict:
        return {"plan": original.as_json(), "steps": self.steps, "assembled": assembled,
                "manual": manual_parts(self.steps), "final_pose_error_mm": self.errors_mm, "replans": self.replans,
                "observations": self.observations, "final_plan": self.plan.as_json()}


def manual_parts(steps: list[dict]) -> list[str]:
    """The parts of the report's ``steps`` the cell answered as placed by hand (skill
    ``manual``: its arm has no operation for them), in step order."""
    return [s["part"] for s in steps if s["skill"] == "manual" and s["outcome"] == "fit"]


def with_manual_reasons(report: dict, reasons: Mapping[str, str]) -> dict:
    """``report`` with ``"manual_reasons"``: why each of its ``manual`` parts is placed by
    hand, where the product says (``reasons``: part -> reason, ``[manual.<id>]`` of its
    geometry, :attr:`bridge.assembly.Assembly.manual`)."""
    return dict(report, manual_reasons={part: reasons[part] for part in report["manual"] if part in reasons})


def step_json(reply: StepReply) -> dict:
    e = reply.evidence
    return {"part": reply.part, "hole": reply.hole, "skill": e.skill, "outcome": reply.result,
            "attempts": e.attempts, "duration_s": round(e.duration_s, 3), "max_force_dev": round(e.max_force_dev, 3),
            "sim_time_s": round(e.sim_time_s, 3), "pose_error_mm": round(e.pose_error_mm, 3), "cell": reply.cell}


def execute(facts: LearnedFacts, plan: Plan, driver: StepDriver, max_replans: int = MAX_REPLANS) -> dict:
    """Run ``plan`` in the cell of ``driver`` with monitoring and re-planning; the JSON report
    ``{"plan", "steps", "assembled", "manual", "final_pose_error_mm", "replans", "observations",
    "final_plan"}`` (``manual``: :func:`manual_parts`).  AssemblyStopped (with the report)
    when the product cannot be finished."""
    run = _Run(plan)
    while len(run.done) < len(run.plan.steps):
        step = run.plan.steps[len(run.done)]
        reply = driver.step(len(run.steps) + 1, step.part, step.hole)
        run.steps.append(step_json(reply))
        run.errors_mm = {p: round(e, 3) for p, e in reply.pose_errors_mm}
        if reply.result == "fit":
            run.done.append(step)
            continue
        if step.hole is None:
            raise AssemblyStopped(f"step {len(run.steps)}: part {step.part} could not be placed "
                                  f"({reply.evidence.attempts} attempts); it needs no hole, so no other plan helps",
                                  run.report(plan, False))
        run.observations.append({"fact": f"no_fit({step.part},{step.hole})", "step": len(run.steps),
                                 "evidence": run.steps[-1]})
        facts = with_no_fit(facts, step.part, step.hole)
        reason = (f"{step.part} did not go into {step.hole} ({reply.evidence.attempts} attempts): "
                  f"no_fit({step.part},{step.hole})")
        if len(run.replans) >= max_replans:
            raise AssemblyStopped(f"{reason}; stopped after {max_replans} re-plans", run.report(plan, False))
        try:
            run.plan = replan(facts, run.done)
        except UnsolvableAssembly as exc:
            placed = " ".join(s.part for s in run.done) or "none"
            raise AssemblyStopped(f"{reason}; no complete assignment is left: {exc} "
                                  f"(placed parts stay where they are: {placed})", run.report(plan, False)) from None
        run.replans.append({"step": len(run.steps), "reason": reason, "plan": run.plan.as_json()})
    return run.report(plan, True)
