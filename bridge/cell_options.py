"""The options of a simulated cell, shared by the cell's commands (``executor trial``,
``campaign``, ``serve``, ``bench executor``) and the session that starts cells: the
execution layer (``--layer``), the seed of the cell's systematic errors (``--cell-seed``)
and one option per magnitude of the cell's uncertainty (the fields of
:class:`assembly_constraints.executor.world.perturbation.PerturbationModel`, whose defaults are the ones
here; units and reasons in docs/cell.md).  Here in ``bridge`` so the planner can pass
them on to ``executor serve`` without importing the cell."""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from pathlib import Path

from assembly_constraints.bridge.cli_types import MAX_SEED, finite_float, int_in

LAYER_NAMES = ("position", "admittance_p", "admittance_pi", "pi_phase_stop", "full")
"""The execution layers (:data:`assembly_constraints.executor.control.ilc.LAYERS`), from the least to the whole."""
DEFAULT_LAYER = "full"


@dataclass(frozen=True)
class Magnitude:
    """One magnitude of the uncertainty: its default, the largest value accepted, and help."""

    default: float
    high: float
    help: str


MAGNITUDES = {
    "grasp_offset_bias": Magnitude(0.0005, 0.02, "habitual lateral grasp offset per part shape, at most [m]"),
    "grasp_offset_random": Magnitude(0.001, 0.02, "per-execution lateral grasp offset, at most [m]"),
    "grasp_tilt_bias": Magnitude(1.5, 20.0, "habitual tilt of the part in the hand per part shape, at most [deg]"),
    "grasp_tilt_random": Magnitude(1.0, 20.0, "per-execution tilt of the part in the hand, at most [deg]"),
    "vision_bias": Magnitude(0.001, 0.02, "calibration bias of each hole's estimated position, at most [m]"),
    "vision_sigma": Magnitude(0.0015, 0.02, "per-execution vision error, standard deviation per axis [m]"),
    "vision_max": Magnitude(0.006, 0.05, "total vision error, at most [m]"),
    "vision_yaw_bias": Magnitude(0.5, 20.0, "calibration bias of each rect hole's estimated yaw, at most [deg]"),
    "vision_yaw_sigma": Magnitude(0.5, 20.0, "per-execution error of a rect hole's estimated yaw, "
                                  "standard deviation [deg]"),
    "vision_yaw_max": Magnitude(2.0, 45.0, "total error of a rect hole's estimated yaw, at most [deg]"),
    "friction_min": Magnitude(0.2, 2.0, "friction coefficient of a hole, lower end of its range"),
    "friction_max": Magnitude(0.5, 2.0, "friction coefficient of a hole, upper end of its range"),
    "friction_jitter": Magnitude(0.03, 1.0, "per-execution change of a hole's friction coefficient, at most"),
}
"""The magnitudes by field name of PerturbationModel, in its order."""


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
    for name, m in MAGNITUDES.items():
        group.add_argument(f"--{name.replace('_', '-')}", type=finite_float(0.0, m.high), default=m.default,
                           metavar="X", help=f"{m.help} (default {m.default})")


def add_cell_description_argument(parser: argparse.ArgumentParser) -> None:
    """``--cell-description FILE``: the cell's gripper, gains, thresholds, admittance and
    ILC parameters overridden by a TOML file (docs/cell.md)."""
    parser.add_argument("--cell-description", type=Path, metavar="FILE",
                        help="TOML file overriding the cell's gripper, gains, thresholds, admittance or ILC "
                        "parameters (docs/cell.md; default: the built-in description)")


ASSEMBLY_UNCERTAINTIES = ("random", "cell")
"""The uncertainty of the assembling cell's plan steps: ``random`` (the default) its own
random-only model, no ILC; ``cell`` the cell's model of the options (systematic part from
the cell seed) with its execution layer and ILC (docs/assembly.md)."""


def add_assembly_uncertainty_argument(parser: argparse.ArgumentParser) -> None:
    """``--uncertainty {random,cell}`` of the assembling cell (plan steps)."""
    parser.add_argument("--uncertainty", choices=ASSEMBLY_UNCERTAINTIES, default=ASSEMBLY_UNCERTAINTIES[0],
                        help="plan steps: random = the assembling cell's own random errors only, no ILC; cell = "
                        "the cell's uncertainty (--cell-seed, magnitudes) with its --layer and ILC (default random)")


def cell_argv(args: argparse.Namespace) -> list[str]:
    """The ``--layer`` and ``--<magnitude>`` options of ``args`` (parsed with
    :func:`add_cell_arguments`) as command-line arguments of ``executor serve``."""
    argv = ["--layer", args.layer]
    for name in MAGNITUDES:
        argv += [f"--{name.replace('_', '-')}", repr(float(getattr(args, name)))]
    return argv


def parse_cell_argv(argv: list[str]) -> argparse.Namespace:
    """Read back what :func:`cell_argv` wrote; ValueError naming the option if it is not that."""
    parser = argparse.ArgumentParser(add_help=False, exit_on_error=False)
    add_cell_arguments(parser, cell_seed=False)
    try:
        args, rest = parser.parse_known_args(argv)
    except argparse.ArgumentError as exc:
        raise ValueError(str(exc)) from None
    if rest:
        raise ValueError(f"unexpected {' '.join(rest)}")
    return args
