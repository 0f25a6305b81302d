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
- :class:`ErrorReply` (cell → planner): the request was refused, with a reason code.

Versions: 3 added the step messages; insert messages did not change, so a cell still
serves a version-2 insert request and answers it as version 2.
"""

from __future__ import annotations

from typing import Annotated, Final, Literal

import msgspec

from bridge import BridgeError
from bridge.assembly import ID_PATTERN
from bridge.inputs import duplicate_key
from bridge.keys import CELL_ID_PATTERN
from bridge.product.tables import MAX_ID_CHARS

PROTOCOL_VERSION: Final = 3
"""2: requests carry ``timeout_s``; replies echo ``part`` and ``hole``. 3: step request and reply."""
INSERT_VERSIONS: Final = frozenset({2, 3})
"""Versions of insert and error messages accepted (their form is the same in both)."""
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
"""The most placed parts a step reply reports."""

RequestId = Annotated[str, msgspec.Meta(pattern=rf"^[A-Za-z0-9_.:-]{{1,{MAX_REQUEST_ID}}}$")]
AspId = Annotated[str, msgspec.Meta(pattern=ID_PATTERN)]
"""A part or hole id: a lower-case ASP constant."""
CellId = Annotated[str, msgspec.Meta(pattern=CELL_ID_PATTERN)]
Seed = Annotated[int, msgspec.Meta(ge=0, lt=2**32)]
Count = Annotated[int, msgspec.Meta(ge=0, le=MAX_COUNT)]
Version = Annotated[int, msgspec.Meta(ge=1, le=MAX_COUNT, description="protocol version")]
NonNegative = Annotated[float, msgspec.Meta(ge=0.0, le=MAX_VALUE)]
Result = Literal["fit", "no_fit"]
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
    """How the part was placed: fixture, insert, insert_over, insert_socket, manual (by hand: the cell has no
    operation for it), or truth."""
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


class MessageError(BridgeError):
    """A payload that is not a valid message; ``code`` is the ErrorReply code to send."""

    def __init__(self, code: ErrorCode, text: str) -> None:
        super().__init__(text)
        self.code: ErrorCode = code


_REQUEST_DECODER = msgspec.json.Decoder(InsertRequest)
_STEP_DECODER = msgspec.json.Decoder(StepRequest)
_REPLY_DECODER = msgspec.json.Decoder(InsertReply | StepReply | ErrorReply)


def encode(message: msgspec.Struct) -> bytes:
    """Serialise a message (any message struct of the bridge) to JSON bytes; MessageError if it
    exceeds the size cap."""
    data = msgspec.json.encode(message)
    if len(data) > MAX_MESSAGE_BYTES:
        raise MessageError("oversized", f"message of {len(data)} bytes exceeds the "
                           f"{MAX_MESSAGE_BYTES}-byte cap")
    return data


def decode_checked(decoder: msgspec.json.Decoder, payload: bytes, what: str,
                   versions: frozenset[int] | None = None):
    """Decode ``payload`` with ``decoder``: size cap, types, no key twice, and the protocol
    version ``v`` in ``versions`` (default: this module's, by message kind); MessageError
    (with its code) naming ``what`` otherwise."""
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
    if versions is not None:
        accepted = versions
    else:
        accepted = frozenset({PROTOCOL_VERSION}) if isinstance(message, (StepRequest, StepReply)) else INSERT_VERSIONS
    if message.v not in accepted:
        raise MessageError("version", f"{what} has protocol version {message.v}; "
                           f"expected {' or '.join(map(str, sorted(accepted)))}")
    return message


def decode_request(payload: bytes) -> InsertRequest:
    """Validate and decode an insert request; MessageError (with a code) if invalid."""
    return decode_checked(_REQUEST_DECODER, payload, "insert request")


def decode_step_request(payload: bytes) -> StepRequest:
    """Validate and decode a step request; MessageError (with a code) if invalid."""
    return decode_checked(_STEP_DECODER, payload, "step request")


def decode_reply(payload: bytes) -> InsertReply | StepReply | ErrorReply:
    """Validate and decode a cell's reply; MessageError if invalid."""
    return decode_checked(_REPLY_DECODER, payload, "reply")
