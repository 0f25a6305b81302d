"""Every Zenoh key expression of the project, in one place.

A cell ``<id>`` serves insertions on the queryable ``cell/<id>/insert``, plan steps on
``cell/<id>/step`` (its world persists between steps), precedence experiments on
``cell/<id>/precedence``, and holds the
liveliness token ``cell/<id>/alive/<instance>`` while it is up (``<instance>``: a random
name of the process, so two processes claiming one id show as two tokens);
``cell/<id>/ping`` echoes its payload. The planner discovers cells by subscribing to
``cell/*/alive/*``. Before and while it serves, a cell process also holds the liveliness
token ``cell/<id>/claim/<instance>`` and answers queries on that key with its age: cells
claiming one id find each other there (:mod:`executor.claim`).
"""

from __future__ import annotations

import re

from bridge import BridgeError

CELL_ID_PATTERN = r"^[a-z][a-z0-9_-]{0,31}$"
"""A cell id: lower-case letter, then up to 31 of ``[a-z0-9_-]`` (one key chunk)."""

ALIVE_PATTERN = "cell/*/alive/*"
"""Liveliness key expression matching every cell's token."""

_CELL_ID = re.compile(CELL_ID_PATTERN)
_INSTANCE = r"([A-Za-z0-9_-]{1,64})"
_ALIVE_KEY = re.compile(rf"^cell/([^/]+)/alive/{_INSTANCE}$")
_CLAIM_KEY = re.compile(rf"^cell/([^/]+)/claim/{_INSTANCE}$")


def check_cell_id(cell_id: str) -> str:
    """Return ``cell_id`` if it is a valid cell id, else raise BridgeError."""
    if not _CELL_ID.match(cell_id):
        raise BridgeError(
            f"cell id {cell_id!r}: expected a lower-case letter then up to 31 of [a-z0-9_-]"
        )
    return cell_id


def insert_key(cell_id: str) -> str:
    """Queryable key on which cell ``cell_id`` serves insertion experiments."""
    return f"cell/{check_cell_id(cell_id)}/insert"


def step_key(cell_id: str) -> str:
    """Queryable key on which cell ``cell_id`` carries out plan steps."""
    return f"cell/{check_cell_id(cell_id)}/step"


def precedence_key(cell_id: str) -> str:
    """Queryable key on which cell ``cell_id`` runs precedence experiments
    (:mod:`bridge.precedence.experiment`)."""
    return f"cell/{check_cell_id(cell_id)}/precedence"


def alive_key(cell_id: str, instance: str = "0") -> str:
    """Liveliness token key held by the process ``instance`` of cell ``cell_id`` while it serves."""
    return f"cell/{check_cell_id(cell_id)}/alive/{instance}"


def ping_key(cell_id: str) -> str:
    """Queryable key on which cell ``cell_id`` echoes the payload unread (diagnostics,
    bare round-trip measurement)."""
    return f"cell/{check_cell_id(cell_id)}/ping"


def claim_key(cell_id: str, instance: str) -> str:
    """Liveliness token and queryable key of the process ``instance`` claiming cell ``cell_id``."""
    return f"cell/{check_cell_id(cell_id)}/claim/{instance}"


def claims_pattern(cell_id: str) -> str:
    """Key expression matching the claims of every process on cell id ``cell_id``."""
    return f"cell/{check_cell_id(cell_id)}/claim/*"


def instance_of_claim_key(key: str, cell_id: str) -> str | None:
    """The instance of a claim key ``cell/<cell_id>/claim/<instance>``; None for any other key."""
    match = _CLAIM_KEY.match(key)
    return match.group(2) if match is not None and match.group(1) == cell_id else None


def cell_of_alive_key(key: str) -> tuple[str, str] | None:
    """(cell id, instance) of a liveliness key ``cell/<id>/alive/<instance>``; None for any other key."""
    match = _ALIVE_KEY.match(key)
    if match is None or not _CELL_ID.match(match.group(1)):
        return None
    return match.group(1), match.group(2)
