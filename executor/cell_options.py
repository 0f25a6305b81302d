"""The cell's options (:mod:`assembly_constraints.bridge.cell_options`: ``--layer``, ``--cell-seed``, one per
magnitude of the uncertainty, ``--cell-description``) turned into what a
:class:`assembly_constraints.executor.trial.Cell` takes."""

from __future__ import annotations

import argparse
from typing import Any

from assembly_constraints.bridge.cell_options import MAGNITUDES
from assembly_constraints.executor.cell_description import load_cell_description
from assembly_constraints.executor.world.perturbation import PerturbationModel


def perturbation_from_args(args: argparse.Namespace) -> PerturbationModel:
    """The model the ``--<magnitude>`` options describe; ExecutorError if inconsistent."""
    return PerturbationModel(**{name: getattr(args, name) for name in MAGNITUDES}).check()


def cell_keywords(args: argparse.Namespace) -> dict[str, Any]:
    """Keyword arguments of :class:`assembly_constraints.executor.trial.Cell` from the options (the cell
    description read and checked here, before any cell starts)."""
    keywords: dict[str, Any] = {"perturbation": perturbation_from_args(args), "cell_seed": args.cell_seed,
                                "description": load_cell_description(getattr(args, "cell_description", None))}
    if hasattr(args, "layer"):
        keywords["layer"] = args.layer
    return keywords
