"""The Rerun layout both sides share: the application id, the entity roots and the blueprint.

Planner and cells log into one recording id of application :data:`APPLICATION_ID`, the
planner under ``planner/...``, cell ``<id>`` under ``executor/<id>/...``. The blueprint
has the planner's tab (knowledge matrix, graphs, assignment, experiment log), then one
tab per cell: the 3D scene (static geometry, tool path, search path) above the
outcome log, next to force and torque (measured vs desired over ``sim_time``), the
deviations of eqs. 6 and 7, and the force over the DMP phase (paper Fig. 17: switch
the time panel to the ``dmp_phase`` timeline); and one assembly tab per cell (the parts
and the arm moving over ``sim_time``, the plan steps, the force).
"""

from __future__ import annotations

from collections.abc import Sequence

import rerun.blueprint as rrb

APPLICATION_ID = "assembly_constraints"
PLANNER_ROOT = "planner"


def cell_root(cell_id: str) -> str:
    """Entity root of one cell's log: ``executor/<cell_id>``."""
    return f"executor/{cell_id}"


def assembly_root(cell_id: str) -> str:
    """Entity root of a cell's assembly (plan execution): ``executor/<cell_id>/assembly``."""
    return f"{cell_root(cell_id)}/assembly"


def assembly_views(cell_id: str) -> rrb.Container:
    """A cell's assembly tab: parts and arm in 3D, the plan steps, the measured force."""
    root = assembly_root(cell_id)
    return rrb.Horizontal(
        rrb.Spatial3DView(origin=root, name=f"{cell_id}: assembly", contents=["$origin/parts/**", "$origin/arm"]),
        rrb.Vertical(
            rrb.TextLogView(origin=f"{root}/steps", name="plan steps (timeline plan_step)"),
            rrb.TimeSeriesView(origin=f"{root}/force", name="force at the TCP [N] over sim_time"),
        ),
        column_shares=[2, 1],
        name=f"{cell_id} assembly",
    )


def planner_views() -> rrb.Container:
    """The planner's tab: knowledge matrix, graphs, assignment, experiment log."""
    return rrb.Horizontal(
        rrb.Vertical(
            rrb.TensorView(origin="planner/knowledge", name="knowledge (1 fit, 0 no fit, -1 unknown)"),
            rrb.TextLogView(origin="planner/experiments", name="experiments"),
        ),
        rrb.Vertical(
            rrb.GraphView(origin="planner/precedence", name="must precede"),
            rrb.GraphView(origin="planner/smaller", name="smaller than"),
        ),
        rrb.Vertical(
            rrb.GraphView(origin="planner/assignment", name="assignment"),
            rrb.TextDocumentView(origin="planner/assignment", name="assignment table"),
        ),
        name="planner",
    )


def cell_views(cell_id: str) -> rrb.Container:
    """The views of one cell: 3D scene, force/torque plots, Fig. 17, outcome log."""
    root = cell_root(cell_id)
    return rrb.Horizontal(
        rrb.Vertical(
            rrb.Spatial3DView(
                origin=root, name=f"{cell_id}: cell",
                contents=["$origin/scene/**", "$origin/tool/**", "$origin/search/**"],
            ),
            rrb.TextLogView(origin=f"{root}/outcome", name=f"{cell_id}: outcomes"),
            row_shares=[3, 1],
        ),
        rrb.Vertical(
            rrb.TimeSeriesView(origin=f"{root}/wrench/force", name="force [N] over sim_time"),
            rrb.TimeSeriesView(origin=f"{root}/wrench/torque", name="torque [Nm] over sim_time"),
            rrb.TimeSeriesView(
                origin=f"{root}/deviation", name="‖mes − des‖ (eqs. 6, 7) over sim_time"
            ),
            rrb.TimeSeriesView(
                origin=f"{root}/by_phase", name="force [N] over DMP phase (timeline dmp_phase)"
            ),
        ),
        column_shares=[1, 1],
        name=cell_id,
    )


def cell_blueprint(cell_ids: Sequence[str], extra: Sequence[rrb.Container] = ()) -> rrb.Blueprint:
    """A blueprint with one tab per cell (plus ``extra`` containers, e.g. the planner's)."""
    tabs = [*extra, *(cell_views(cell_id) for cell_id in cell_ids), *(assembly_views(c) for c in cell_ids)]
    return rrb.Blueprint(
        rrb.Tabs(*tabs), rrb.TimePanel(timeline="sim_time"), collapse_panels=False
    )
