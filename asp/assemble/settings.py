"""The settings of one assembly run (``./run.sh assemble``), as a typed struct built once
at the edge (:func:`asp.assemble.cli.assembly_settings`, or in Python)."""

from __future__ import annotations

from typing import Annotated, Literal

from msgspec import Meta, Struct

from asp import PlannerError
from bridge.cell_settings import DEFAULT_CELL, CellSettings, Seed, changed_cell_options

MAX_PLAN_INDEX = 1000
MAX_STEP_S = 86_400.0
"""``timeout_s``: at most a day [s]."""


class AssemblySettings(Struct, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """One plan executed step by step in a cell started for it.

    The plan: plan ``plan`` (1-based) of the session run folder ``run``, or of
    ``inputs`` (a plan JSON file and/or learned facts files), else of the assembly's
    true facts; ``assembly``: its parts, holes and geometry (None: the run's, else
    ``cranfield``). The cell: ``backend`` (``sim`` PyBullet, ``truth`` the geometry
    rule), ``seed`` of its random grasp, vision and search errors, obstacles in
    ``block_holes``, ``timeout_s`` [s] for one step, its recording saved to ``rrd``;
    ``cell``: with ``uncertainty`` ``cell``, the plan steps get that cell's uncertainty,
    layer and ILC (then only a sim cell); with ``random`` (the default) their own random
    errors, and the other fields of ``cell`` keep their defaults. ``listen``,
    ``connect``, ``zenoh_config``: the planner's Zenoh endpoints and config file.
    """

    inputs: tuple[str, ...] = ()
    run: str | None = None
    plan: Annotated[int, Meta(ge=1, le=MAX_PLAN_INDEX)] = 1
    assembly: str | None = None
    seed: Seed = 0
    block_holes: tuple[str, ...] = ()
    backend: Literal["sim", "truth"] = "sim"
    timeout_s: Annotated[float, Meta(gt=0.0, le=MAX_STEP_S)] = 300.0
    rrd: str | None = None
    cell: CellSettings = DEFAULT_CELL
    listen: tuple[str, ...] = ()
    connect: tuple[str, ...] = ()
    zenoh_config: str | None = None


def assembling_cell_settings(cell: CellSettings, backend: str) -> CellSettings:
    """``cell``, checked for an assembling cell; PlannerError naming the option if one was
    given where it would have no effect: with the ``truth`` backend (the geometry rule
    simulates nothing), or a cell option without ``--uncertainty cell``."""
    changed = changed_cell_options(cell)
    if backend == "truth" and (cell.uncertainty == "cell" or changed):
        option = "--uncertainty cell" if cell.uncertainty == "cell" else changed[0]
        raise PlannerError(f"{option} has no effect with --backend truth (the geometry rule simulates nothing); "
                           "drop it or use --backend sim")
    if cell.uncertainty != "cell" and changed:
        raise PlannerError(f"{changed[0]}: --layer, --cell-seed and the uncertainty magnitudes need "
                           "--uncertainty cell")
    return cell
