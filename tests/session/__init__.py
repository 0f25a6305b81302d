"""Tests of the session over Zenoh (asp/session), and what they share."""

from __future__ import annotations

from pathlib import Path

EXACT_CELL = tuple(arg for name in ("grasp-offset-bias", "grasp-offset-random", "grasp-tilt-bias", "grasp-tilt-random",
                                    "vision-bias", "vision-sigma", "vision-yaw-bias", "vision-yaw-sigma")
                   for arg in (f"--{name}", "0"))
"""The session's options of a sim cell without pose errors: the part where the hand
believes it, the holes where the cell's vision does. Its experiments then decide on the
cross-sections alone; each ``no_fit`` still runs both attempts, its search over
:data:`EXACT_SEARCH`'s radius (the default's 4.6 mm spirals were 6-19 s of a ``no_fit``'s
wall time in the task board's session at a load of 10, 2-5 s after). The cell's default
uncertainty through a session is ``tests/session/test_session_sim.py``'s, each section
relation's trial under it ``tests/executor/test_rect_trials.py``'s."""
EXACT_SEARCH = "[search]\nmax_radius = 0.001\nslow_time = 0\n"
"""The cell description of :data:`EXACT_CELL`'s hole search: 1 mm around the hole (a
pitch), no slow pass out after a first pass that found nothing."""


def exact_cell(folder: Path) -> tuple[str, ...]:
    """The session's options of a sim cell without pose errors: :data:`EXACT_CELL` and the
    cell description :data:`EXACT_SEARCH`, written in ``folder`` (``cell.toml``)."""
    description = folder / "cell.toml"
    description.write_text(EXACT_SEARCH, encoding="utf-8")
    return (*EXACT_CELL, "--cell-description", str(description))
