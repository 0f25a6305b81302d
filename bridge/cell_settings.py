"""The settings of a cell, as typed structs: what a simulated cell is (execution layer,
cell seed, the magnitudes of its uncertainty) and the one document a cell is started
with (:class:`ServeSettings`, ``executor serve --settings DOC``).

Here in ``bridge`` because both sides use them: the planner builds the document for each
cell it starts, the cell decodes it. The command-line options that build the same
structs by hand are in :mod:`bridge.cell_arguments`. Units and reasons of the
magnitudes in docs/cell.md.
"""

from __future__ import annotations

from typing import Annotated, Literal, TypeVar

import msgspec

from bridge import BridgeError
from bridge.cli_types import MAX_SEED
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
    """The magnitudes of a simulated cell's uncertainty (the fields of
    :class:`executor.world.perturbation.PerturbationModel`, whose defaults are these).
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
        if self.friction_min > self.friction_max:
            raise ValueError(f"friction_min {self.friction_min} > friction_max {self.friction_max}; "
                             "expected an ordered range")


MAGNITUDE_FIELDS: tuple[msgspec.structs.FieldInfo, ...] = msgspec.structs.fields(Magnitudes)
"""The magnitudes in their order: name, default and type (with its range and description)."""


class CellSettings(msgspec.Struct, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """What a simulated cell is: its execution layer, the seed of its systematic errors,
    the magnitudes of its uncertainty and the uncertainty of its plan steps.

    ``description``: the path of a cell description file overriding the cell's own
    parameters (gripper, controller gains, thresholds, ILC); None: the built-in ones.
    Reserved here so the document that starts a cell has its place; a cell refuses
    one until it can read it.
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
    expected `int`, got `str```: the field first, as the project's messages put it."""
    message, sep, where = str(exc).rpartition(" - at `")
    if not sep:
        return str(exc)
    field = where.rstrip("`").removeprefix("$").removeprefix(".")
    return f'"{field}": {message[:1].lower()}{message[1:]}'


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
