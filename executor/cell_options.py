"""The options every command that builds a :class:`executor.trial.Cell` shares (``trial``,
``campaign``, ``serve``, ``bench executor``): the execution layer (``--layer``), the seed of
the cell's systematic errors (``--cell-seed``) and one option per magnitude of the
cell's uncertainty (:class:`executor.world.perturbation.PerturbationModel`; defaults,
units and reasons in docs/cell.md)."""

from __future__ import annotations

import argparse
from dataclasses import fields
from typing import Any

from bridge.cli_types import MAX_SEED, finite_float, int_in
from executor.control.ilc import LAYERS
from executor.world.perturbation import PerturbationModel

_HELP = {
    "grasp_offset_bias": ("habitual lateral grasp offset per part shape, at most [m]", 0.02),
    "grasp_offset_random": ("per-execution lateral grasp offset, at most [m]", 0.02),
    "grasp_tilt_bias": ("habitual tilt of the part in the hand per part shape, at most [deg]", 20.0),
    "grasp_tilt_random": ("per-execution tilt of the part in the hand, at most [deg]", 20.0),
    "vision_bias": ("calibration bias of each hole's estimated position, at most [m]", 0.02),
    "vision_sigma": ("per-execution vision error, standard deviation per axis [m]", 0.02),
    "vision_max": ("total vision error, at most [m]", 0.05),
    "friction_min": ("friction coefficient of a hole, lower end of its range", 2.0),
    "friction_max": ("friction coefficient of a hole, upper end of its range", 2.0),
    "friction_jitter": ("per-execution change of a hole's friction coefficient, at most", 1.0),
}
"""Help text and the largest value accepted, per field of PerturbationModel."""


def add_cell_arguments(parser: argparse.ArgumentParser, layer: bool = True) -> None:
    """``--layer`` (unless ``layer`` is False), ``--cell-seed`` and ``--<magnitude>`` options."""
    group = parser.add_argument_group("execution layer and uncertainty of the cell (docs/cell.md)")
    if layer:
        group.add_argument("--layer", choices=list(LAYERS), default="full",
                           help="execution layer: pure position control along the DMP, admittance P, "
                           "admittance PI, PI + phase stopping, all + ILC (default full)")
    group.add_argument("--cell-seed", type=int_in(0, MAX_SEED), default=0,
                       help="seed of the cell's systematic errors (default 0)")
    defaults = PerturbationModel()
    for f in fields(PerturbationModel):
        text, high = _HELP[f.name]
        group.add_argument(f"--{f.name.replace('_', '-')}", type=finite_float(0.0, high),
                           default=getattr(defaults, f.name), metavar="X",
                           help=f"{text} (default {getattr(defaults, f.name)})")


def perturbation_from_args(args: argparse.Namespace) -> PerturbationModel:
    """The model the ``--<magnitude>`` options describe; ExecutorError if inconsistent."""
    return PerturbationModel(**{f.name: getattr(args, f.name) for f in fields(PerturbationModel)}).check()


def cell_keywords(args: argparse.Namespace) -> dict[str, Any]:
    """Keyword arguments of :class:`executor.trial.Cell` from the options."""
    keywords: dict[str, Any] = {"perturbation": perturbation_from_args(args), "cell_seed": args.cell_seed}
    if hasattr(args, "layer"):
        keywords["layer"] = args.layer
    return keywords
