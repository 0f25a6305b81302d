"""The precedence experiment messages: round trip, and refusal of what the planner or a cell
must never send (the tested part in the sequence, a failure without its step)."""

from __future__ import annotations

import re

import pytest

from bridge.messages import MessageError, encode
from bridge.precedence.experiment import (
    ExperimentStep,
    PrecedenceExperiment,
    PrecedenceOutcome,
    decode_experiment,
    decode_outcome,
)


def test_experiment_and_outcome_round_trip() -> None:
    experiment = PrecedenceExperiment(id="run.1", pair=("sh", "pd"),
                                      sequence=(ExperimentStep("bp"), ExperimentStep("pd", None)))
    assert decode_experiment(encode(experiment)) == experiment
    assert experiment.tested == "sh<pd"
    outcome = PrecedenceOutcome(id="run.1", cell="truth", pair=("sh", "pd"), outcome="failed",
                                failed_step=2, reason="unsupported", detail="pd fell off")
    assert decode_outcome(encode(outcome)) == outcome


@pytest.mark.parametrize(("payload", "expected"), [
    (b'{"kind":"precedence_experiment","id":"x","pair":["a","b"],"sequence":[{"part":"a"},{"part":"b"}]}',
     "pair[0] absent"),
    (b'{"kind":"precedence_experiment","id":"x","pair":["a","b"],"sequence":[{"part":"b"},{"part":"c"}]}',
     "last step to place b"),
    (b'{"kind":"precedence_experiment","id":"x","pair":["a","b"],"sequence":[]}', "length"),
    (b'{"kind":"precedence_experiment","id":"x","pair":["a","b"],"sequence":[{"part":"b"}],"v":2}', "version"),
    (b'{"kind":"precedence_outcome","id":"x","cell":"c","pair":["a","b"],"outcome":"failed"}',
     "both set exactly when"),
    (b'{"kind":"precedence_outcome","id":"x","cell":"c","pair":["a","b"],"outcome":"success",'
     b'"failed_step":1,"reason":"blocked"}', "both set exactly when"),
    (b'{"kind":"precedence_outcome","id":"x","cell":"c","pair":["a","b"],"outcome":"failed",'
     b'"failed_step":1,"reason":"fell"}', "reason"),
])
def test_bad_messages_are_refused_naming_the_field(payload: bytes, expected: str) -> None:
    decode = decode_experiment if b"experiment" in payload else decode_outcome
    with pytest.raises(MessageError, match=re.escape(expected)):
        decode(payload)
