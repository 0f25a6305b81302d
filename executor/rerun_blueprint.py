"""The Rerun blueprint of the cell's entities (see :mod:`executor.rerun_log`).

One tab per cell: the 3D scene (static geometry, tool path, search path) above the
outcome log, next to force and torque (measured vs desired over ``sim_time``), the
deviations of eqs. 6 and 7, and the force over the DMP phase (paper Fig. 17: switch
the time panel to the ``dmp_phase`` timeline).
"""

from __future__ import annotations

from collections.abc import Sequence

import rerun.blueprint as rrb


def cell_views(cell_id: str) -> rrb.Container:
    """The views of one cell: 3D scene, force/torque plots, Fig. 17, outcome log."""
    root = f"executor/{cell_id}"
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
    tabs = [*extra, *(cell_views(cell_id) for cell_id in cell_ids)]
    return rrb.Blueprint(
        rrb.Tabs(*tabs), rrb.TimePanel(timeline="sim_time"), collapse_panels=False
    )
