"""The backend a cell node's settings name: ``sim`` (:mod:`.sim`), ``truth`` (:mod:`.truth`)
or ``MODULE:CLASS`` (:mod:`assembly_constraints.executor.backend_plugin`), and the checks of
its settings made before the node opens its session."""

from __future__ import annotations

from pathlib import Path

from assembly_constraints.bridge.cell_settings import ServeSettings
from assembly_constraints.bridge.recording.sinks import Viewer
from assembly_constraints.executor.backend_plugin import Backend, CellContext, load_backend
from assembly_constraints.executor.serve.sim import SimBackend
from assembly_constraints.executor.serve.truth import TruthBackend


def backend_of(settings: ServeSettings) -> Backend:
    """The backend ``settings.backend`` names: the simulator, the geometry's truth or a user class."""
    rrd = None if settings.rrd is None else Path(settings.rrd)
    viewer = Viewer(settings.viewer_url)
    if settings.backend == "truth":
        return TruthBackend(settings.assembly, settings.delay_s, settings.cell_id, settings.recording_id, rrd, viewer,
                            settings.block_holes)
    if settings.backend == "sim":
        return SimBackend(settings.assembly, settings.cell_id, settings.recording_id, rrd, viewer,
                          settings.block_holes, settings.cell,
                          None if settings.ilc_state is None else Path(settings.ilc_state))
    return load_backend(settings.backend, CellContext(settings.cell_id, settings.assembly, rrd,
                                                      settings.recording_id, settings.backend_options))



def check_backend_settings(settings: ServeSettings) -> None:
    """Refuse bad settings before the node opens its session: a bad cell description
    (BridgeError naming the file, table and key), and for ``sim`` a damaged ILC state.
    A backend that does not use the description still refuses a bad file rather than
    silently ignoring it."""
    if settings.backend == "sim":
        from assembly_constraints.executor.trial import cell_keywords

        # Bad cell settings or description are refused here, before the session opens.
        description = cell_keywords(settings.cell)["description"]
        if settings.ilc_state is not None:
            from assembly_constraints.executor.control.ilc import offset_bound, read_state

            # So is a damaged state.
            read_state(Path(settings.ilc_state), description.ilc, offset_bound(description.admittance))
    elif settings.cell.description is not None:
        from assembly_constraints.executor.cell_description import load_cell_description

        # Not used by this backend, but a bad file is refused rather than silently ignored.
        load_cell_description(Path(settings.cell.description))
