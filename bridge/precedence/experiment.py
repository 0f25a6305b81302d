"""A precedence experiment and its outcome: the messages between the planner and a cell.

An experiment tests the hypothesis that part ``a`` must precede part ``b`` (a pair the
demonstrations never contradicted) by assembling a short sequence that places ``b``
while ``a`` is absent. The cell starts from its known state (a fresh world: every part on
its tray, except the ``placed`` parts, set at their goals by hand: a peg in its hole),
carries out the steps in order and stops at the first that fails. A known state whose
placed parts do not stay where they were set (a peg set in a plate that is not there) is
refused (``invalid_step``): it is no state the product can be in, and no evidence on the pair.

- :class:`PrecedenceExperiment` (planner → cell, on :func:`bridge.keys.precedence_key`):
  ``pair`` = (a, b) and the ``sequence`` of steps, the last placing ``b``; ``a`` is in no
  step. The steps before the last are an order the planner knows feasible.
- :class:`PrecedenceOutcome` (cell → planner): ``success`` (every step done: ``b`` can go
  before ``a``), or ``failed``, with the 1-based ``failed_step`` and the ``reason``:
  ``blocked`` (the part could not reach its place: a placed part is in the way),
  ``jammed`` (it reached the entry and stuck), ``unsupported`` (it did not stay where it
  was put: nothing under it yet), and ``blocked_by``, the placed parts the failing part
  touched where it stopped, as the cell observed them (a field, never read from the
  ``detail`` prose). A failure at a step before the tested one says the known state could
  not be reached: the planner reports it, it is no evidence on the pair.

"B then A": a precedence the physics shows only when the first part comes second (a
cover goes in without the part under it, which then cannot go in). The planner reads a
failure of ``a``'s step, after ``b``, as ``a`` must precede ``b`` only when the cell saw
``a`` blocked by ``b`` alone (``blocked_by == (b,)``); any other cause, or none observed,
decides nothing. A ``truth`` cell states a precedence at the later part's step (reason
``precedence``, :func:`first_missing`): with every part that precedes ``a`` placed, its
``a`` step never fails.

Both are serialised with :func:`bridge.messages.encode`. A bad message is refused with
:class:`bridge.messages.ErrorReply`, as every other request (:func:`decode_experiment`,
:func:`decode_outcome`).
"""

from __future__ import annotations

from collections.abc import Collection, Mapping
from typing import Annotated, Final, Literal

import msgspec

from bridge.messages import (
    INSERT_VERSIONS,
    MAX_ERROR_CHARS,
    AspId,
    CellId,
    ErrorReply,
    MessageError,
    NonNegative,
    RequestId,
    Seed,
    Version,
    decode_checked,
)

EXPERIMENT_VERSION: Final = 1
"""Version of the precedence experiment messages."""
MAX_STEPS: Final = 1000
"""The most steps an experiment holds."""

Outcome = Literal["success", "failed"]
FailureReason = Literal["blocked", "jammed", "unsupported", "precedence", "size"]
"""Why a step failed: ``blocked`` (a placed part is in the part's way), ``jammed`` (it stuck
in its hole or on its pin), ``unsupported`` (it did not stay where it was put), observed in
physics; ``precedence`` (a part the product's known precedence puts first is absent) and
``size`` (the peg does not pass its hole), stated without physics by the ``truth`` cell."""


class ExperimentStep(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """Place ``part`` (into ``hole``; None: a part placed without a hole)."""

    part: AspId
    hole: AspId | None = None


class PrecedenceExperiment(msgspec.Struct, frozen=True, forbid_unknown_fields=True,
                           tag_field="kind", tag="precedence_experiment"):
    """Does ``pair[0]`` truly have to precede ``pair[1]``? Carry out ``sequence`` from a
    fresh world; its last step places ``pair[1]``, no step places ``pair[0]``; or, "B then
    A", it places ``pair[1]`` and then ``pair[0]`` (a precedence the physics shows only when
    the first part comes second: a cover that goes in without the part under it, which then
    cannot go in)."""

    id: Annotated[RequestId, msgspec.Meta(description="request id: the same request again gets the cached "
                                          "outcome and is never run twice")]
    pair: Annotated[tuple[AspId, AspId], msgspec.Meta(description="(a, b): the hypothesis a must precede b")]
    sequence: Annotated[tuple[ExperimentStep, ...], msgspec.Meta(min_length=1, max_length=MAX_STEPS,
                                                                 description="the steps, the last placing b")]
    placed: Annotated[tuple[ExperimentStep, ...], msgspec.Meta(max_length=MAX_STEPS, description=(
        "the known state: parts set at their goals by hand before the first step (a peg in its hole); "
        "empty: every part on its tray"))] = ()
    seed: Annotated[Seed, msgspec.Meta(description="seed of a simulated cell's randomisation")] = 0
    timeout_s: Annotated[NonNegative, msgspec.Meta(description="how long the planner waits for the outcome [s]; "
                                                   "0: no limit")] = 0.0
    v: Version = EXPERIMENT_VERSION

    def __post_init__(self) -> None:
        a, b = self.pair
        parts = [step.part for step in self.sequence]
        given = [step.part for step in self.placed] + parts
        if a == b:
            raise ValueError(f"pair ({a}, {b}): expected two different parts")
        then_a = self.then_first
        if parts[-2 if then_a else -1:] != ([b, a] if then_a else [b]):
            raise ValueError(f"sequence ends with {' '.join(parts[-2:])}: expected its last step to place {b}, "
                             f"pair[1] (or {b} then {a}, pair[0])")
        if a in parts[:-1] or (a in parts and not then_a):
            raise ValueError(f"sequence places {a}: expected pair[0] absent from it (but as the step after {b})")
        if a in given[:len(self.placed)] or b in given[:len(self.placed)]:
            raise ValueError(f"placed holds {a if a in given else b}: expected neither part of the pair in it")
        twice = next((p for i, p in enumerate(given) if p in given[:i]), None)
        if twice is not None:
            raise ValueError(f"placed and sequence give {twice} twice: expected each part at most once")

    @property
    def then_first(self) -> bool:
        """Whether the sequence places ``pair[0]`` after ``pair[1]`` ("B then A")."""
        return len(self.sequence) >= 2 and self.sequence[-1].part == self.pair[0]

    @property
    def tested(self) -> str:
        """The pair as ``a<b``."""
        return f"{self.pair[0]}<{self.pair[1]}"


class PrecedenceOutcome(msgspec.Struct, frozen=True, forbid_unknown_fields=True,
                        tag_field="kind", tag="precedence_outcome"):
    """What cell ``cell`` observed carrying out experiment ``id``."""

    id: Annotated[RequestId, msgspec.Meta(description="the experiment's id")]
    cell: Annotated[CellId, msgspec.Meta(description="the cell that ran it (truth: the truth oracle)")]
    pair: Annotated[tuple[AspId, AspId], msgspec.Meta(description="the experiment's pair, echoed")]
    outcome: Annotated[Outcome, msgspec.Meta(description="success: every step done; failed: see failed_step")]
    failed_step: Annotated[Annotated[int, msgspec.Meta(ge=1, le=MAX_STEPS)] | None,
                           msgspec.Meta(description="the 1-based step that failed; null on success")] = None
    reason: Annotated[FailureReason | None, msgspec.Meta(description="why it failed; null on success")] = None
    blocked_by: Annotated[tuple[AspId, ...], msgspec.Meta(max_length=MAX_STEPS, description=(
        "the placed parts the failed step's part touched where it stopped, as observed; empty: none seen "
        "(or not blocked)"))] = ()
    detail: Annotated[str, msgspec.Meta(max_length=MAX_ERROR_CHARS,
                                        description="what the cell saw, one line (may be empty)")] = ""
    sim_s: Annotated[NonNegative, msgspec.Meta(description="simulated (physics) time spent [s]; 0 for truth")] = 0.0
    wall_s: Annotated[NonNegative, msgspec.Meta(description="wall time the cell spent [s]")] = 0.0
    v: Version = EXPERIMENT_VERSION

    def __post_init__(self) -> None:
        if (self.outcome == "failed") != (self.failed_step is not None and self.reason is not None):
            raise ValueError(f"outcome {self.outcome} with failed_step {self.failed_step} and reason {self.reason}: "
                             "expected both set exactly when the outcome is failed")
        if self.blocked_by and self.outcome != "failed":
            raise ValueError(f"blocked_by {' '.join(self.blocked_by)} on a success: expected it empty")


def first_missing(experiment: PrecedenceExperiment,
                  before: Mapping[str, Collection[str]]) -> tuple[int, str, list[str]] | None:
    """The first step of ``experiment`` whose part needs a part not yet placed (set by hand
    or by an earlier step): its 1-based number, its part and the missing parts of
    ``before[part]`` (the parts that must precede it), sorted; None when no step does. How a
    cell that knows the precedence answers (``reason`` ``precedence``)."""
    placed = {step.part for step in experiment.placed}
    for number, step in enumerate(experiment.sequence, 1):
        missing = sorted(set(before.get(step.part, ())) - placed)
        if missing:
            return number, step.part, missing
        placed.add(step.part)
    return None


_EXPERIMENT_DECODER = msgspec.json.Decoder(PrecedenceExperiment)
_OUTCOME_DECODER = msgspec.json.Decoder(PrecedenceOutcome)
_VERSIONS: Final = frozenset({EXPERIMENT_VERSION})
_REPLY_DECODER = msgspec.json.Decoder(PrecedenceOutcome | ErrorReply)


def decode_experiment(payload: bytes) -> PrecedenceExperiment:
    """Validate and decode an experiment; :class:`bridge.messages.MessageError` (with a code) if invalid."""
    message: PrecedenceExperiment = decode_checked(_EXPERIMENT_DECODER, payload, "precedence experiment", _VERSIONS)
    return message


def decode_outcome(payload: bytes) -> PrecedenceOutcome:
    """Validate and decode an outcome; :class:`bridge.messages.MessageError` (with a code) if invalid."""
    message: PrecedenceOutcome = decode_checked(_OUTCOME_DECODER, payload, "precedence outcome", _VERSIONS)
    return message


def decode_outcome_reply(payload: bytes) -> PrecedenceOutcome | ErrorReply:
    """A cell's reply to an experiment: its outcome, or the error that refused it (each in
    its own versions); :class:`bridge.messages.MessageError` (with a code) if invalid."""
    message: PrecedenceOutcome | ErrorReply = decode_checked(_REPLY_DECODER, payload, "precedence reply",
                                                             _VERSIONS | INSERT_VERSIONS)
    accepted = _VERSIONS if isinstance(message, PrecedenceOutcome) else INSERT_VERSIONS
    if message.v not in accepted:
        raise MessageError("version", f"precedence reply has protocol version {message.v}; "
                           f"expected {' or '.join(map(str, sorted(accepted)))}")
    return message
