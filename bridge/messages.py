"""Typed, versioned JSON messages between the planner and the cells.

Every message is a msgspec struct serialised as a JSON object with a ``kind`` tag and a
protocol version ``v``. Payloads are size-capped (:data:`MAX_MESSAGE_BYTES`) and
validated on receipt: types, identifier patterns, ranges and the version. Nothing in a
message is ever executed; ids are matched against fixed patterns before use.

- :class:`InsertRequest` (planner → cell): insert ``part`` into ``hole``;
- :class:`InsertReply` (cell → planner): the outcome ``fit``/``no_fit`` and its evidence;
- :class:`StepRequest` (planner → cell, since version 3): carry out one step of a plan in
  the cell's persistent world (pick the part, place it, into ``hole`` if it has one);
- :class:`StepReply` (cell → planner): the step's outcome, its evidence and how far every
  placed part is from its goal;
- :class:`PrecedenceRequest` (planner → cell, since version 4): a precedence experiment:
  from a known state (the base with ``placed`` parts at their goals) assemble ``sequence``;
- :class:`PrecedenceReply` (cell → planner): success, or the failing step and why
  (:data:`FailureReason`), with every step's evidence;
- :class:`ErrorReply` (cell → planner): the request was refused, with a reason code.

Versions: 3 added the step messages, 4 the precedence messages; the older messages did
not change, so a cell still serves a version-2 insert request and a version-3 step request
and answers each in its request's version.
"""

from __future__ import annotations

from typing import Annotated, Final, Literal

import msgspec

from bridge import BridgeError
from bridge.assembly import ID_PATTERN
from bridge.inputs import duplicate_key
from bridge.keys import CELL_ID_PATTERN
from bridge.product.tables import MAX_ID_CHARS

PROTOCOL_VERSION: Final = 4
"""2: requests carry ``timeout_s``; replies echo ``part`` and ``hole``. 3: step request and reply.
4: precedence request and reply."""
INSERT_VERSIONS: Final = frozenset({2, 3, 4})
"""Versions of insert and error messages accepted (their form is the same in all)."""
STEP_VERSIONS: Final = frozenset({3, 4})
"""Versions of step messages accepted (their form is the same in both)."""
MAX_MESSAGE_BYTES: Final = 16 * 1024
"""Largest accepted payload [bytes]; bigger messages are refused unread."""

MAX_COUNT: Final = 2**31 - 1
"""The largest count or number a message holds (an experiment number, attempts, a version)."""
MAX_RUN_ID: Final = 64
"""The longest run id [characters] a planner builds request ids from (a session's recording id)."""
MAX_REQUEST_ID: Final = MAX_RUN_ID + 2 * (1 + MAX_ID_CHARS) + 1 + len(str(MAX_COUNT))
"""The longest request id [characters]: ``<run>.<part>.<hole>.<n>`` with ids of the
longest documented length and ``n`` up to :data:`MAX_COUNT` (205)."""
MAX_VALUE: Final = 1e9
"""The largest measurement, duration or timeout a message holds [its unit: N, N m, m, s, mm]."""
MAX_ERROR_CHARS: Final = 2000
"""The longest error text of an ErrorReply [characters]."""
MAX_PLACED: Final = 1000
"""The most placed parts a step reply reports, a precedence request sets up or assembles."""

RequestId = Annotated[str, msgspec.Meta(pattern=rf"^[A-Za-z0-9_.:-]{{1,{MAX_REQUEST_ID}}}$")]
AspId = Annotated[str, msgspec.Meta(pattern=ID_PATTERN)]
"""A part or hole id: a lower-case ASP constant."""
CellId = Annotated[str, msgspec.Meta(pattern=CELL_ID_PATTERN)]
Seed = Annotated[int, msgspec.Meta(ge=0, lt=2**32)]
Count = Annotated[int, msgspec.Meta(ge=0, le=MAX_COUNT)]
Version = Annotated[int, msgspec.Meta(ge=1, le=MAX_COUNT, description="protocol version")]
NonNegative = Annotated[float, msgspec.Meta(ge=0.0, le=MAX_VALUE)]
Result = Literal["fit", "no_fit"]
FailureReason = Literal["blocked", "jammed", "unsupported", "precedence", "size"]
"""Why a step of a precedence experiment failed. Observed in physics (``sim``): ``blocked``
(the part did not get into its place: it stopped above its entry, or against another
part), ``jammed`` (it entered its place and stuck before its goal), ``unsupported`` (it
reached its goal but did not stay there once let go). Stated by the ``truth`` backend from
the product's known facts, without physics: ``precedence`` (a part that must precede it is
not placed), ``size`` (the peg does not pass its hole)."""
ErrorCode = Literal["malformed", "oversized", "version", "unknown_id", "id_reused", "invalid_step", "busy",
                    "expired", "failed", "run_active"]
"""Why a request was refused: it is invalid (``malformed``, ``oversized``, ``version``), names an
unknown part or hole (``unknown_id``), reuses the id of another request (``id_reused``), is a
plan step the product does not allow (``invalid_step``: a peg without a hole, a part placed
twice); the cell's queue is full (``busy``), the request waited past its ``timeout_s``
(``expired``), the experiment could not run (``failed``), or the step belongs to another plan
run while the cell's world holds an unfinished one (``run_active``). Only the last four are
worth sending again."""


class _Message(msgspec.Struct, frozen=True, forbid_unknown_fields=True, tag_field="kind"):
    """Base of the tagged messages: immutable, unknown fields refused."""


class InsertRequest(_Message, tag="insert", frozen=True):
    """Insert ``part`` into ``hole``; ``id`` makes the request idempotent at the cell."""

    id: Annotated[RequestId, msgspec.Meta(description="request id: the same request again gets the cached reply "
                                          "and is never run twice; the same id with other fields is refused")]
    part: Annotated[AspId, msgspec.Meta(description="the part to insert, e.g. p3")]
    hole: Annotated[AspId, msgspec.Meta(description="the hole to insert it into, e.g. s1")]
    seed: Annotated[Seed, msgspec.Meta(description="seed of a simulated cell's randomisation")] = 0
    retest: Annotated[bool, msgspec.Meta(description="a deliberate re-test of a pair already tried")] = False
    experiment: Annotated[Count, msgspec.Meta(description="the planner's experiment number (Rerun timeline "
                                            "experiment); 0: none")] = 0
    timeout_s: Annotated[NonNegative, msgspec.Meta(description="how long the planner waits for the reply [s]; a cell "
                                                   "drops the request when it is still queued after this long "
                                                   "(its client has gone); 0: no limit")] = 0.0
    v: Version = PROTOCOL_VERSION


class Evidence(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """What the cell measured during the insertion (None for the truth backend)."""

    attempts: Annotated[Count, msgspec.Meta(description="insertion attempts made")]
    max_force_dev: Annotated[NonNegative, msgspec.Meta(description="largest |F_mes - F_des| [N]")]
    max_torque_dev: Annotated[NonNegative, msgspec.Meta(description="largest |M_mes - M_des| [N m]")]
    end_error: Annotated[NonNegative, msgspec.Meta(description="distance of the final tool position from the goal [m]")]
    duration_s: Annotated[NonNegative, msgspec.Meta(description="duration of the attempts [s] (simulated time in "
                                                    "the simulator)")]


class InsertReply(_Message, tag="insert_reply", frozen=True):
    """The outcome of request ``id`` as observed by cell ``cell``."""

    id: Annotated[RequestId, msgspec.Meta(description="the request's id")]
    cell: Annotated[CellId, msgspec.Meta(description="the cell that ran the experiment")]
    part: Annotated[AspId, msgspec.Meta(description="the request's part, echoed")]
    hole: Annotated[AspId, msgspec.Meta(description="the request's hole, echoed")]
    result: Annotated[Result, msgspec.Meta(description="fit: the part went in; no_fit: it did not")]
    evidence: Annotated[Evidence | None, msgspec.Meta(description="the cell's measurements, or null")] = None
    wall_s: Annotated[NonNegative, msgspec.Meta(description="wall time the cell spent on the experiment [s]")] = 0.0
    v: Version = PROTOCOL_VERSION


class ErrorReply(_Message, tag="error", frozen=True):
    """A refused request: ``code`` says why, ``error`` says what was expected."""

    cell: Annotated[CellId, msgspec.Meta(description="the refusing cell")]
    code: Annotated[ErrorCode, msgspec.Meta(description="why: malformed, oversized, version, unknown_id, id_reused, "
                                            "invalid_step (do not send again); busy, expired, failed, run_active "
                                            "(worth sending again)")]
    error: Annotated[str, msgspec.Meta(max_length=MAX_ERROR_CHARS,
                                       description="what was wrong and what was expected, one line")]
    id: Annotated[RequestId | None, msgspec.Meta(description="the request's id; null when the payload could not "
                                                 "be read")] = None
    v: Version = PROTOCOL_VERSION


class StepRequest(_Message, tag="step", frozen=True):
    """Carry out step ``step`` of the plan run ``assembly``: pick ``part`` from the tray and
    place it (into ``hole``, None for a part placed without a hole). The cell keeps one world
    for one ``assembly`` at a time; a new ``assembly`` starts from a fresh world (every part on
    the tray) once the current one's product is complete, and is refused (``run_active``)
    before."""

    id: RequestId
    assembly: RequestId
    step: Annotated[int, msgspec.Meta(ge=1, le=10_000)]
    part: AspId
    hole: AspId | None = None
    seed: Seed = 0
    timeout_s: NonNegative = 0.0
    """As :attr:`InsertRequest.timeout_s` [s]."""
    v: Version = PROTOCOL_VERSION


class StepEvidence(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """What the cell measured during a plan step."""

    skill: Annotated[str, msgspec.Meta(pattern=r"^[a-z_]{1,32}$")]
    """How the part was placed: fixture, insert, insert_over, insert_socket, or truth."""
    attempts: Count
    max_force_dev: NonNegative
    """Largest ‖F_mes − F_des‖ of the insertions [N]."""
    max_torque_dev: NonNegative
    """Largest ‖M_mes − M_des‖ [N m]."""
    duration_s: NonNegative
    """Wall time of the step [s]."""
    sim_time_s: NonNegative
    """Simulated time of the step [s]."""
    pose_error_mm: NonNegative
    """Distance of the part from its goal after the step [mm]."""


class StepReply(_Message, tag="step_reply", frozen=True):
    """The outcome of step request ``id`` as observed by cell ``cell``; ``pose_errors_mm``:
    (part, distance [mm] from its goal) of every placed part after the step (pairs, so that a
    reply stays hashable)."""

    id: RequestId
    cell: CellId
    part: AspId
    hole: AspId | None
    result: Result
    evidence: StepEvidence
    pose_errors_mm: Annotated[tuple[tuple[AspId, NonNegative], ...], msgspec.Meta(max_length=MAX_PLACED)] = ()
    wall_s: NonNegative = 0.0
    v: Version = PROTOCOL_VERSION


ExperimentResult = Literal["success", "failed", "unstable"]
"""A precedence experiment's outcome (:class:`PrecedenceReply`)."""


class Placement(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """A part and the hole it goes into (None: a part placed without a hole)."""

    part: Annotated[AspId, msgspec.Meta(description="the part, e.g. p3")]
    hole: Annotated[AspId | None, msgspec.Meta(description="its hole, e.g. s1; null for a part placed without "
                                               "one")] = None


Placements = Annotated[tuple[Placement, ...], msgspec.Meta(max_length=MAX_PLACED)]


class PrecedenceRequest(_Message, tag="precedence", frozen=True):
    """A precedence experiment: in a fresh world, put the ``placed`` parts at their goals (set up
    by hand, not assembled), then assemble ``sequence`` step by step, stopping at the first step
    that fails; e.g. placed bp, p3, p4 and sequence sp, p1 tests whether sp may precede p1.
    Every part at most once in the two, every hole at most once."""

    id: Annotated[RequestId, msgspec.Meta(description="request id, as for insert")]
    placed: Annotated[Placements, msgspec.Meta(description="the known state: the parts already in place, "
                                               "with their holes")] = ()
    sequence: Annotated[Placements, msgspec.Meta(min_length=1, description="the steps to assemble, in order")] = ()
    seed: Annotated[Seed, msgspec.Meta(description="seed of a simulated cell's randomisation")] = 0
    timeout_s: Annotated[NonNegative, msgspec.Meta(description="as for insert [s]")] = 0.0
    v: Version = PROTOCOL_VERSION


class ExperimentStep(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """One step of a precedence experiment as the cell carried it out."""

    part: AspId
    hole: AspId | None
    result: Annotated[Result, msgspec.Meta(description="fit: the part is in place; no_fit: it is not")]
    reason: Annotated[FailureReason | None, msgspec.Meta(description="why it failed: blocked, jammed, "
                                                         "unsupported (observed in physics), precedence, size "
                                                         "(the truth backend); null when it fit")] = None
    involved: Annotated[tuple[AspId, ...], msgspec.Meta(max_length=MAX_PLACED, description=(
        "blocked: the other parts the part touched where it stopped; precedence: the parts that must "
        "precede it and were not placed; else empty"))] = ()
    evidence: StepEvidence | None = None


class PrecedenceReply(_Message, tag="precedence_reply", frozen=True):
    """The outcome of precedence experiment ``id`` as observed by cell ``cell``: ``result``
    ``success`` (every step fit), ``failed`` (the last of ``steps`` did not fit) or
    ``unstable`` (a part of ``placed`` did not stay at its goal once set there: the known state
    is not one the product can be in; nothing of the sequence ran)."""

    id: RequestId
    cell: CellId
    placed: Placements
    sequence: Placements
    result: ExperimentResult
    steps: Annotated[tuple[ExperimentStep, ...], msgspec.Meta(max_length=MAX_PLACED,
                                                              description="the steps run, in order")] = ()
    unstable: Annotated[tuple[AspId, ...], msgspec.Meta(max_length=MAX_PLACED, description=(
        "the placed parts that did not stay at their goal"))] = ()
    wall_s: NonNegative = 0.0
    sim_s: Annotated[NonNegative, msgspec.Meta(description="simulated time of the experiment [s]")] = 0.0
    v: Version = PROTOCOL_VERSION

    @property
    def failed_step(self) -> ExperimentStep | None:
        """The step that failed, None when none did."""
        return self.steps[-1] if self.result == "failed" else None


Request = InsertRequest | StepRequest | PrecedenceRequest
Reply = InsertReply | StepReply | PrecedenceReply


class MessageError(BridgeError):
    """A payload that is not a valid message; ``code`` is the ErrorReply code to send."""

    def __init__(self, code: ErrorCode, text: str) -> None:
        super().__init__(text)
        self.code: ErrorCode = code


_REQUEST_DECODER = msgspec.json.Decoder(InsertRequest)
_STEP_DECODER = msgspec.json.Decoder(StepRequest)
_PRECEDENCE_DECODER = msgspec.json.Decoder(PrecedenceRequest)
_REPLY_DECODER = msgspec.json.Decoder(InsertReply | StepReply | PrecedenceReply | ErrorReply)


def encode(message: Request | Reply | ErrorReply) -> bytes:
    """Serialise a message to JSON bytes; MessageError if it exceeds the size cap."""
    data = msgspec.json.encode(message)
    if len(data) > MAX_MESSAGE_BYTES:
        raise MessageError("oversized", f"message of {len(data)} bytes exceeds the "
                           f"{MAX_MESSAGE_BYTES}-byte cap")
    return data


def _decode(decoder: msgspec.json.Decoder, payload: bytes, what: str):
    if len(payload) > MAX_MESSAGE_BYTES:
        raise MessageError("oversized", f"{what} of {len(payload)} bytes exceeds the "
                           f"{MAX_MESSAGE_BYTES}-byte cap")
    try:
        message = decoder.decode(payload)
    except (msgspec.DecodeError, UnicodeDecodeError) as exc:
        raise MessageError("malformed", f"{what} is not valid: {exc}") from None
    twice = duplicate_key(payload)
    if twice is not None:
        raise MessageError("malformed", f"{what} is not valid: the key {twice!r} appears twice in one object; "
                           "expected each key once")
    accepted = (STEP_VERSIONS if isinstance(message, (StepRequest, StepReply)) else
                {PROTOCOL_VERSION} if isinstance(message, (PrecedenceRequest, PrecedenceReply)) else INSERT_VERSIONS)
    if message.v not in accepted:
        raise MessageError("version", f"{what} has protocol version {message.v}; "
                           f"expected {' or '.join(map(str, sorted(accepted)))}")
    return message


def decode_request(payload: bytes) -> InsertRequest:
    """Validate and decode an insert request; MessageError (with a code) if invalid."""
    return _decode(_REQUEST_DECODER, payload, "insert request")


def decode_step_request(payload: bytes) -> StepRequest:
    """Validate and decode a step request; MessageError (with a code) if invalid."""
    return _decode(_STEP_DECODER, payload, "step request")


def decode_precedence_request(payload: bytes) -> PrecedenceRequest:
    """Validate and decode a precedence request; MessageError (with a code) if invalid."""
    return _decode(_PRECEDENCE_DECODER, payload, "precedence request")


def decode_reply(payload: bytes) -> Reply | ErrorReply:
    """Validate and decode a cell's reply; MessageError if invalid."""
    return _decode(_REPLY_DECODER, payload, "reply")
