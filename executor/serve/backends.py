"""The backend a cell node's settings name: ``sim`` (:mod:`.sim`), ``truth`` (:mod:`.truth`),
``franka`` (:mod:`executor.franka.backend`) or ``MODULE:CLASS`` (:mod:`executor.backend_plugin`): its settings
checked before the node opens its session, the backend started after the node claimed its
cell id."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from bridge.cell_settings import ServeSettings
from executor.backend_plugin import Backend, CellContext, load_backend
from executor.serve.sim import SimBackend
from executor.serve.truth import TruthBackend


def backend_starter(settings: ServeSettings) -> Callable[[], Backend]:
    """Check the settings the backend needs and return what starts it. A bad cell
    description is refused here (BridgeError naming the file, table and key): for ``sim``
    it is decoded here, once, and handed to the cell, and a damaged ILC state or a skill
    not taught on the product as it is (:func:`executor.skills.dmp.check_product_skills`)
    is refused too; the other backends do not use it, but refuse a bad file rather than silently
    ignoring it."""
    if settings.backend == "sim":
        from executor.control.ilc import offset_bound, read_state
        from executor.skills.dmp import check_product_skills
        from executor.trial import cell_setup
        from executor.world.geometry import load_geometry

        setup = cell_setup(settings.cell)
        description = setup.description
        check_product_skills(load_geometry(settings.assembly, description))  # a skill the cell cannot run
        if settings.ilc_state is not None:
            read_state(Path(settings.ilc_state), description.ilc, offset_bound(description.admittance))
        return lambda: SimBackend(settings, setup)
    if settings.backend == "franka":
        from executor.franka.backend import franka_starter

        return franka_starter(settings)
    if settings.cell.description is not None:
        from executor.cell_description import load_cell_description

        load_cell_description(Path(settings.cell.description))
    if settings.backend == "truth":
        return lambda: TruthBackend(settings)
    rrd = None if settings.rrd is None else Path(settings.rrd)
    return lambda: load_backend(settings.backend, CellContext(settings.cell_id, settings.assembly, rrd,
                                                              settings.recording_id, settings.backend_options))
