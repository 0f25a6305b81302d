"""The command-line options of a simulated cell, shared by the cell's commands (``executor
trial``, ``campaign``, ``serve``, ``bench executor``) and the planner's commands that start
cells (``session``, ``assemble``): the execution layer (``--layer``), the seed of the
cell's systematic errors (``--cell-seed``) and one option per magnitude of its uncertainty
(:class:`bridge.cell_settings.Magnitudes`, whose fields give the names, defaults, ranges
and units). :func:`cell_settings_of` turns the parsed options into the
:class:`bridge.cell_settings.CellSettings` the core takes."""

from __future__ import annotations

import argparse
from typing import Any

import msgspec

from bridge import BridgeError
from bridge.cell_settings import (
    ASSEMBLY_UNCERTAINTIES,
    DEFAULT_CELL,
    DEFAULT_LAYER,
    LAYER_NAMES,
    MAGNITUDE_FIELDS,
    CellSettings,
    Magnitudes,
)
from bridge.cli_types import MAX_SEED, finite_float, int_in


def _option(name: str) -> str:
    return f"--{name.replace('_', '-')}"


def add_cell_arguments(parser: argparse.ArgumentParser, *, layer: bool = True, cell_seed: bool = True) -> None:
    """``--layer`` (unless ``layer`` is False), ``--cell-seed`` (unless ``cell_seed`` is
    False) and the ``--<magnitude>`` options, in one argument group."""
    group = parser.add_argument_group("execution layer and uncertainty of the cell (docs/cell.md)")
    if layer:
        group.add_argument("--layer", choices=LAYER_NAMES, default=DEFAULT_LAYER,
                           help="execution layer: pure position control along the DMP, admittance P, "
                           f"admittance PI, PI + phase stopping, all + ILC (default {DEFAULT_LAYER})")
    if cell_seed:
        group.add_argument("--cell-seed", type=int_in(0, MAX_SEED), default=0,
                           help="seed of the cell's systematic errors (default 0)")
    for field in MAGNITUDE_FIELDS:
        meta = field.type.__metadata__[0]
        group.add_argument(_option(field.name), type=finite_float(0.0, meta.le), default=field.default,
                           metavar="X", help=f"{meta.description} (default {field.default})")


def add_assembly_uncertainty_argument(parser: argparse.ArgumentParser) -> None:
    """``--uncertainty {random,cell}`` of the assembling cell (plan steps)."""
    parser.add_argument("--uncertainty", choices=ASSEMBLY_UNCERTAINTIES, default=ASSEMBLY_UNCERTAINTIES[0],
                        help="plan steps: random = the assembling cell's own random errors only, no ILC; cell = "
                        "the cell's uncertainty (--cell-seed, magnitudes) with its --layer and ILC (default random)")


def cell_settings_of(args: argparse.Namespace, **fixed: Any) -> CellSettings:
    """The cell settings the options of :func:`add_cell_arguments` (and
    :func:`add_assembly_uncertainty_argument`) give; an option a parser lacks keeps its
    default, ``fixed`` sets fields the command decides (e.g. a session's cell seed)."""
    values: dict[str, Any] = {name: getattr(args, name) for name in ("layer", "cell_seed", "uncertainty")
                              if hasattr(args, name)}
    try:
        magnitudes = msgspec.convert({field.name: getattr(args, field.name) for field in MAGNITUDE_FIELDS},
                                     Magnitudes)
    except msgspec.ValidationError as exc:  # the options are each in range; their combination is not
        raise BridgeError(f"the cell's uncertainty: {exc}") from None
    return CellSettings(**{**values, "magnitudes": magnitudes, **fixed})


def changed_cell_options(settings: CellSettings) -> list[str]:
    """The options (``--layer``, ``--cell-seed``, ``--<magnitude>``) whose values in
    ``settings`` are not the defaults, in the order of the help page."""
    changed = [_option(name) for name in ("layer", "cell_seed")
               if getattr(settings, name) != getattr(DEFAULT_CELL, name)]
    return changed + [_option(field.name) for field in MAGNITUDE_FIELDS
                      if getattr(settings.magnitudes, field.name) != field.default]
