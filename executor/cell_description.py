"""The cell's own parameters, apart from any product: the gripper, the impedance gains
(compliant and stiff), the admittance, the detector's thresholds, the hole search and
the ILC.

:class:`CellDescription` holds them with the defaults the measurements in docs/results.md
were made with; :func:`load_cell_description` reads an override file (TOML, any subset of
the tables and keys, docs/cell.md "The cell description"), so a run may change a gain
without touching code. A product's ``geometry.toml`` may still carry its own
``[gripper]``, which wins over the cell's (:func:`executor.world.geometry.load_geometry`).
Every bad value is one line naming the file, table and key (exit 2).
"""

from __future__ import annotations

from pathlib import Path

import msgspec

from bridge.product import Gripper, decode_toml_file
from executor.control.admittance import AdmittanceParams
from executor.control.detector import Thresholds
from executor.control.gains import POSITION_CONTROL_GAINS, ImpedanceGains
from executor.control.ilc import IlcParams
from executor.skills.search_params import SearchParams


def _default_gripper() -> Gripper:
    """Flange + F/T sensor + gripper of 1 kg and 0.004 kg m^2 (the stock link-7 inertia
    makes 1 kHz torque control unstable), 60 mm from the flange face to the fingertips,
    holding 20 mm of the part."""
    return Gripper(flange_mass=1.0, flange_inertia=0.004, flange_length=0.06, grasp_depth=0.02)


def _position_gains() -> ImpedanceGains:
    return POSITION_CONTROL_GAINS


class CellDescription(msgspec.Struct, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """The cell: ``gripper`` (used unless the product has its own), ``gains`` (the
    compliant impedance of every motion), ``position_gains`` (the stiff tracking of the
    ``position`` layer), ``admittance`` (its bounds also bound the ILC corrections),
    ``thresholds`` (eqs. 6 and 7, phase stopping, the goal check), ``search`` (the hole
    search before every insertion: its radius covers the cell's position errors), ``ilc``."""

    gripper: Gripper = msgspec.field(default_factory=_default_gripper)
    gains: ImpedanceGains = msgspec.field(default_factory=ImpedanceGains)
    position_gains: ImpedanceGains = msgspec.field(default_factory=_position_gains)
    admittance: AdmittanceParams = msgspec.field(default_factory=AdmittanceParams)
    thresholds: Thresholds = msgspec.field(default_factory=Thresholds)
    search: SearchParams = msgspec.field(default_factory=SearchParams)
    ilc: IlcParams = msgspec.field(default_factory=IlcParams)


def load_cell_description(path: Path | None) -> CellDescription:
    """The defaults, with the tables and keys of the TOML file ``path`` (if given)
    replacing theirs; BridgeError naming the file, table and key on bad input."""
    if path is None:
        return CellDescription()
    return decode_toml_file(path, "cell description (TOML)", CellDescription)
