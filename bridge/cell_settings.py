"""The settings of a cell, as typed structs: what a simulated cell is (execution layer,
cell seed, the magnitudes of its uncertainty) and the one document a cell is started
with (:class:`ServeSettings`, ``executor serve --settings DOC``).

Here in ``bridge`` because both sides use them: the planner builds the document for each
cell it starts, the cell decodes it. The command-line options that build the same
structs by hand (:func:`add_cell_arguments`, :func:`cell_settings_of`) are here too,
shared by the cell's commands (``executor trial``, ``campaign``, ``serve``, ``bench
executor``) and the planner's commands that start cells (``session``, ``assemble``).
Units and reasons of the magnitudes in docs/cell.md.
"""

from __future__ import annotations

import argparse
import re
from pathlib import Path
from typing import Annotated, Any, Literal, TypeVar

import msgspec

from bridge import BridgeError
from bridge.cli_types import MAX_SEED, finite_float, int_in
from bridge.inputs import shorten

Layer = Literal["position", "admittance_p", "admittance_pi", "pi_phase_stop", "full"]
"""An execution layer (:data:`executor.control.ilc.LAYERS`)."""
LAYER_NAMES: tuple[Layer, ...] = ("position", "admittance_p", "admittance_pi", "pi_phase_stop", "full")
"""The execution layers, from the least to the whole."""
DEFAULT_LAYER: Layer = "full"

Uncertainty = Literal["random", "cell"]
"""The uncertainty of the assembling cell's plan steps: ``random`` its own random-only
model, no ILC; ``cell`` the cell's model (systematic part from the cell seed) with its
execution layer and ILC (docs/assembly.md)."""
ASSEMBLY_UNCERTAINTIES: tuple[Uncertainty, ...] = ("random", "cell")

_T = TypeVar("_T")

Seed = Annotated[int, msgspec.Meta(ge=0, le=MAX_SEED)]


def _m(high: float, description: str) -> msgspec.Meta:
    """A magnitude: at least 0, at most ``high``."""
    return msgspec.Meta(ge=0.0, le=high, description=description)


class Magnitudes(msgspec.Struct, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """The magnitudes of a simulated cell's uncertainty
    (:mod:`executor.world.perturbation` draws the errors from them).
    Each field's description gives its unit; ``executor trial`` and friends offer one
    ``--<field>`` option per field."""

    grasp_offset_bias: Annotated[float, _m(0.02, "habitual lateral grasp offset per part shape, at most [m]")] = 0.0005
    grasp_offset_random: Annotated[float, _m(0.02, "per-execution lateral grasp offset, at most [m]")] = 0.001
    grasp_tilt_bias: Annotated[float, _m(20.0, "habitual tilt of the part in the hand per part shape, "
                                               "at most [deg]")] = 1.5
    grasp_tilt_random: Annotated[float, _m(20.0, "per-execution tilt of the part in the hand, at most [deg]")] = 1.0
    vision_bias: Annotated[float, _m(0.02, "calibration bias of each hole's estimated position, at most [m]")] = 0.001
    vision_sigma: Annotated[float, _m(0.02, "per-execution vision error, standard deviation per axis [m]")] = 0.0015
    vision_max: Annotated[float, _m(0.05, "total vision error, at most [m]")] = 0.006
    vision_yaw_bias: Annotated[float, _m(20.0, "calibration bias of each rect hole's estimated yaw, "
                                               "at most [deg]")] = 0.5
    vision_yaw_sigma: Annotated[float, _m(20.0, "per-execution error of a rect hole's estimated yaw, "
                                                "standard deviation [deg]")] = 0.5
    vision_yaw_max: Annotated[float, _m(45.0, "total error of a rect hole's estimated yaw, at most [deg]")] = 2.0
    friction_min: Annotated[float, _m(2.0, "friction coefficient of a hole, lower end of its range")] = 0.2
    friction_max: Annotated[float, _m(2.0, "friction coefficient of a hole, upper end of its range")] = 0.5
    friction_jitter: Annotated[float, _m(1.0, "per-execution change of a hole's friction coefficient, "
                                              "at most")] = 0.03

    def __post_init__(self) -> None:
        # decoding checks each field's range; a struct built in code is checked here
        for name in self.__struct_fields__:
            if not getattr(self, name) >= 0:
                raise ValueError(f"{name} = {getattr(self, name)}: expected a number >= 0")
        if self.friction_min > self.friction_max:
            raise ValueError(f"friction_min {self.friction_min} > friction_max {self.friction_max}; "
                             "expected an ordered range")


MAGNITUDE_FIELDS: tuple[msgspec.structs.FieldInfo, ...] = msgspec.structs.fields(Magnitudes)
"""The magnitudes in their order: name, default and type (with its range and description)."""


class CellSettings(msgspec.Struct, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """What a simulated cell is: its execution layer, the seed of its systematic errors,
    the magnitudes of its uncertainty and the uncertainty of its plan steps.

    ``description``: the path of a cell description file overriding the cell's own
    parameters (gripper, controller gains, thresholds, admittance, ILC; docs/cell.md),
    read and checked by the cell when it starts; None: the built-in ones.
    """

    layer: Layer = DEFAULT_LAYER
    cell_seed: Seed = 0
    magnitudes: Magnitudes = Magnitudes()
    uncertainty: Uncertainty = "random"
    description: str | None = None


DEFAULT_CELL = CellSettings()


class ServeSettings(msgspec.Struct, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """The one document a cell (``executor serve``) is started with.

    ``backend``: ``sim`` (PyBullet), ``truth`` (the geometry's answer, no simulation) or
    ``MODULE:CLASS`` (a user's backend, with ``backend_options``); ``delay_s`` [s]: how
    long each truth experiment takes; ``rrd``: the file of the cell's recording,
    ``recording_id`` the Rerun recording id shared with the planner, ``viewer_url`` a
    viewer it also streams to; ``ilc_state``: the file the sim cell keeps its learned
    ILC corrections in; ``block_holes``: holes with an obstacle for plan steps;
    ``lifeline``: exit when standard input closes (set by a supervising session);
    ``listen``, ``connect``, ``zenoh_config``: its Zenoh endpoints and config file;
    ``cell``: the simulated cell (unused by the other backends). Paths are absolute
    when a session writes them: the cell runs in another folder.
    """

    cell_id: str = "c1"
    backend: str = "sim"
    backend_options: dict[str, str] = {}
    assembly: str = "cranfield"
    delay_s: Annotated[float, msgspec.Meta(ge=0.0, le=3600.0)] = 0.0
    rrd: str | None = None
    recording_id: str | None = None
    viewer_url: str | None = None
    ilc_state: str | None = None
    block_holes: tuple[str, ...] = ()
    lifeline: bool = False
    listen: tuple[str, ...] = ()
    connect: tuple[str, ...] = ()
    zenoh_config: str | None = None
    cell: CellSettings = DEFAULT_CELL


def encode_settings(settings: msgspec.Struct) -> str:
    """The JSON text of a settings struct (every field, defaults too)."""
    return msgspec.json.encode(settings).decode("utf-8")


def validation_text(exc: msgspec.ValidationError) -> str:
    """msgspec's ``Expected `int`, got `str` - at `$.cell.cell_seed``` as ``"cell.cell_seed":
    expected `int`, got `str```, and ``Object missing required field `x``` as ``"x":
    missing (a required field)``: the field first, as the project's messages put it."""
    message, sep, where = str(exc).rpartition(" - at `")
    if not sep:
        message, where = str(exc), "$"
    field = where.rstrip("`").removeprefix("$").removeprefix(".")
    missing = re.fullmatch(r"Object missing required field `(.+)`", message)
    if missing:
        return f'"{".".join(filter(None, (field, missing.group(1))))}": missing (a required field)'
    return f'"{field}": {message[:1].lower()}{message[1:]}' if field else message


def decode_settings(data: bytes | str, kind: type[_T], source: str) -> _T:
    """``data`` decoded as a ``kind``; BridgeError naming ``source``, the field and what
    was expected when it is not one."""
    try:
        return msgspec.json.decode(data, type=kind)
    except msgspec.ValidationError as exc:
        raise BridgeError(f"{source}: {shorten(validation_text(exc), 200)}") from None
    except msgspec.DecodeError as exc:
        raise BridgeError(f"{source}: not JSON ({shorten(exc, 80)}); expected the {kind.__name__} "
                          "document") from None


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
    add_cell_description_argument(parser)


def add_cell_description_argument(parser: argparse.ArgumentParser) -> None:
    """``--cell-description FILE``: the cell's gripper, gains, thresholds, admittance and
    ILC parameters overridden by a TOML file (docs/cell.md), read by the cell."""
    parser.add_argument("--cell-description", type=Path, metavar="FILE",
                        help="TOML file overriding the cell's gripper, gains, thresholds, admittance or ILC "
                        "parameters (docs/cell.md; default: the built-in description)")


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
    if getattr(args, "cell_description", None) is not None:  # absolute: a cell may run in another folder
        values["description"] = str(Path(args.cell_description).resolve())
    return CellSettings(**{**values, "magnitudes": magnitudes, **fixed})


def changed_cell_options(settings: CellSettings) -> list[str]:
    """The options (``--layer``, ``--cell-seed``, ``--<magnitude>``) whose values in
    ``settings`` are not the defaults, in the order of the help page."""
    changed = [_option(name) for name in ("layer", "cell_seed")
               if getattr(settings, name) != getattr(DEFAULT_CELL, name)]
    return changed + [_option(field.name) for field in MAGNITUDE_FIELDS
                      if getattr(settings.magnitudes, field.name) != field.default]
