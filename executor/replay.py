"""A cell that answers from a recorded session: the worked example of a backend (docs/backends.md).

    assembly-constraints executor serve --backend executor.replay:ReplayBackend \\
        --backend-option journal=runs/<time>/journal.jsonl

The journal (``RUN/journal.jsonl``, written by every session) holds one JSON object a
line; the finished experiments are the objects without an ``event`` key, with ``part``,
``hole``, ``result`` (``fit``/``no_fit``) and ``evidence`` (the cell's measurements or
null). The backend answers a request for (part, hole) with the recorded answers of that
pair in their order (a re-test gets the next one; past the last, the last again), so a
planner run against it repeats the recorded session without a robot or a simulator.
Optional ``pace=recorded`` waits each answer's recorded wall time (``wall_s``).

It reads the JSON lines itself (the cell does not import the planner, which writes the
journal): a torn last line (the planner was killed while writing it) is skipped, any
other bad line is an error naming the file and line.
"""

from __future__ import annotations

import json
import time
from collections import defaultdict

import msgspec

from bridge.inputs import read_bytes
from bridge.messages import Evidence, InsertRequest, Result, StepRequest
from executor import ExecutorError
from executor.backend_plugin import CellContext, StepOutcome, UnknownPair

Answer = tuple[Result, Evidence | None, float]
"""A recorded answer: the result, its evidence, the cell's wall time [s]."""


def read_answers(path: str) -> dict[tuple[str, str], list[Answer]]:
    """(part, hole) → its recorded answers in journal order; ExecutorError naming file:line."""
    data = read_bytes(path, "session journal")
    lines = data.split(b"\n")
    answers: dict[tuple[str, str], list[Answer]] = defaultdict(list)
    for number, line in enumerate(lines[:-1], start=1):  # lines[-1]: empty, or a torn last line
        if not line.strip():
            continue
        try:
            record = json.loads(line)
            if not isinstance(record, dict):
                raise ValueError("not a JSON object")
            if "event" in record:  # experiment started / abandoned
                continue
            result = record["result"]
            if result not in ("fit", "no_fit"):
                raise ValueError(f"result {result!r}")
            evidence = msgspec.convert(record.get("evidence"), Evidence | None)
            answers[(str(record["part"]), str(record["hole"]))].append(
                (result, evidence, float(record.get("wall_s", 0.0))))
        except (ValueError, KeyError, TypeError, msgspec.ValidationError) as exc:
            raise ExecutorError(f"{path}:{number}: not a finished experiment of a session journal ({exc})") from None
    if not answers:
        raise ExecutorError(f"{path}: no finished experiment to replay")
    return dict(answers)


class ReplayBackend:
    """Answers each (part, hole) with its recorded answers in order (options: ``journal``,
    the journal file; ``pace``: ``recorded`` to wait the recorded wall times, default
    ``none``)."""

    def __init__(self, context: CellContext) -> None:
        self._answers = read_answers(context.option("journal"))
        pace = context.options.get("pace", "none")
        if pace not in ("none", "recorded"):
            raise ExecutorError(f"--backend-option pace={pace}: expected none or recorded")
        self._paced = pace == "recorded"
        self._asked: dict[tuple[str, str], int] = defaultdict(int)

    def run(self, request: InsertRequest) -> tuple[Result, Evidence | None]:
        pair = (request.part, request.hole)
        recorded = self._answers.get(pair)
        if recorded is None:
            raise UnknownPair(f"the journal has no experiment for ({request.part},{request.hole}); it has "
                              f"{len(self._answers)} pairs")
        result, evidence, wall_s = recorded[min(self._asked[pair], len(recorded) - 1)]
        self._asked[pair] += 1
        if self._paced:
            time.sleep(wall_s)
        return result, evidence

    def run_step(self, request: StepRequest) -> StepOutcome:
        """A journal holds experiments, not assemblies: a plan step is refused (``failed``)."""
        raise ExecutorError(f"the replay backend has no plan steps (step {request.step} of plan run "
                            f"{request.assembly})")

    def close(self) -> None:
        """Nothing to release."""
