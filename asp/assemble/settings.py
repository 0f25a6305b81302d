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
    rule, ``franka`` a Franka arm through franky with ``backend_options``, docs/franka.md),
    ``seed`` of its random grasp, vision and search errors, obstacles in
    ``block_holes``, ``timeout_s`` [s] for one step, its recording saved to ``rrd``;
    ``cell``: with ``uncertainty`` ``cell``, the plan steps get that cell's uncertainty,
    layer and ILC (then only a sim cell); with ``random`` (the default) their own random
    errors, and the other fields of ``cell`` keep their defaults (a franka cell: its
    errors are the arm's own; ``layer`` and ``description`` are its). ``listen``,
    ``connect``, ``zenoh_config``: the planner's Zenoh endpoints and config file.
    """

    inputs: tuple[str, ...] = ()
    run: str | None = None
    plan: Annotated[int, Meta(ge=1, le=MAX_PLAN_INDEX)] = 1
    assembly: str | None = None
    seed: Seed = 0
    block_holes: tuple[str, ...] = ()
    backend: Literal["sim", "truth", "franka"] = "sim"
    backend_options: dict[str, str] = {}
    timeout_s: Annotated[float, Meta(gt=0.0, le=MAX_STEP_S)] = 300.0
    rrd: str | None = None
    cell: CellSettings = DEFAULT_CELL
    listen: tuple[str, ...] = ()
    connect: tuple[str, ...] = ()
    zenoh_config: str | None = None


def check_assembling_backend(settings: AssemblySettings) -> None:
    """PlannerError naming the option given where it has no effect: ``--backend-option``
    but with ``franka``; ``--block-hole`` and ``--save`` with ``franka`` (obstacles and
    recordings are the simulated cells')."""
    if settings.backend_options and settings.backend != "franka":
        raise PlannerError(f"--backend-option {next(iter(settings.backend_options))}: only --backend franka takes "
                           "options (docs/franka.md)")
    if settings.backend == "franka":
        given = ["--block-hole"] * bool(settings.block_holes) + ["--save"] * (settings.rrd is not None)
        if given:
            raise PlannerError(f"{given[0]} has no effect with --backend franka (a real arm: no obstacle is put "
                               "in a hole, nothing is recorded to Rerun); drop it")


def assembling_cell_settings(cell: CellSettings, backend: str) -> CellSettings:
    """``cell``, checked for an assembling cell; PlannerError naming the option if one was
    given where it would have no effect: with the ``truth`` backend (the geometry rule
    simulates nothing), with ``franka`` one that draws errors (the arm's are its own; its
    ``--layer`` is the arm's execution layer), or a cell option without ``--uncertainty cell``."""
    changed = changed_cell_options(cell)
    if backend == "franka":
        drawn = ["--uncertainty cell"] * (cell.uncertainty == "cell") + [o for o in changed if o != "--layer"]
        if drawn:
            raise PlannerError(f"{drawn[0]} has no effect with --backend franka (the arm's errors are its own, none "
                               "is drawn); drop it")
        return cell
    if backend == "truth" and (cell.uncertainty == "cell" or changed):
        option = "--uncertainty cell" if cell.uncertainty == "cell" else changed[0]
        raise PlannerError(f"{option} has no effect with --backend truth (the geometry rule simulates nothing); "
                           "drop it or use --backend sim")
    if cell.uncertainty != "cell" and changed:
        raise PlannerError(f"{changed[0]}: --layer, --cell-seed and the uncertainty magnitudes need "
                           "--uncertainty cell")
    return cell
