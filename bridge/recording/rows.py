"""One row of several archetypes logged at one given instant.

``RecordingStream.log`` stamps every call with its own ``log_time`` (the wall clock at
the call; setting that timeline by hand does not override it), so archetypes logged one
after another land microseconds apart, and a viewer paused at the first of them draws the
others as not there yet. :func:`log_row` sends them column-wise with one-row time
columns instead: every archetype of the row is at exactly the instant given.
"""

from __future__ import annotations

from collections.abc import Sequence

import rerun as rr


def log_row(rec: rr.RecordingStream, entity: str, parts: Sequence[rr.AsComponents],
            at: Sequence[rr.TimeColumn] | None, static: bool = False) -> None:
    """Log ``parts`` on ``entity`` as one row: at the instant ``at`` (one-row time columns,
    ``log_time`` among them when the row belongs on it), else ``static`` or at the
    stream's current time."""
    if at is None:
        rec.log(entity, *parts, static=static)
        return
    batches = [batch for part in parts for batch in part.as_component_batches()]
    rec.send_columns(entity, indexes=at, columns=[batch.partition([len(batch.as_arrow_array())])
                                                  for batch in batches])
