"""The cell settings (:class:`bridge.cell_settings.CellSettings`) turned into what a
:class:`executor.trial.Cell` takes."""

from __future__ import annotations

from typing import Any

import msgspec

from bridge.cell_settings import CellSettings, Magnitudes
from executor import ExecutorError
from executor.world.perturbation import PerturbationModel


def perturbation_of(magnitudes: Magnitudes) -> PerturbationModel:
    """The perturbation model of these magnitudes; ExecutorError if inconsistent."""
    return PerturbationModel(**msgspec.structs.asdict(magnitudes)).check()


def cell_keywords(settings: CellSettings) -> dict[str, Any]:
    """Keyword arguments of :class:`executor.trial.Cell` from the settings; ExecutorError
    when they name a cell description file (the cell does not read one yet)."""
    if settings.description is not None:
        raise ExecutorError(f"cell description {settings.description}: this cell does not read description "
                            "files yet; expected none (null)")
    return {"layer": settings.layer, "perturbation": perturbation_of(settings.magnitudes),
            "cell_seed": settings.cell_seed}
