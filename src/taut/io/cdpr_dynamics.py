"""The optional ``dynamics:`` section of a cable-robot model file: elastic cables and winches
(:class:`taut.cdpr.DynamicsModel`; every key optional, defaults are the FASTKIT values).

Keys (SI, motor side): ``cable_stiffness`` (EA, N), ``cable_damping`` (N s),
``drum_diameter`` (m), ``gear_ratio``, ``efficiency`` and ``backdrive_efficiency``
(dimensionless, in (0, 1]; the second applies when the load drives the motor, default the
first), ``rated_torque`` and ``peak_torque`` (N m), ``peak_duration`` (s),
``motor_speed_limit`` (rad/s), ``rotor_inertia`` (kg m^2), ``friction_static`` (breakaway),
``friction_coulomb`` (N m), ``friction_viscous`` (N m s/rad), ``stribeck_speed`` (rad/s),
``drive_speed_gain`` (N m s/rad), ``drive_integral_gain`` (N m/rad), ``routing_length``
(m: one number for every cable or a list with one per cable, in the model's cable order).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Optional, Union

from pydantic import BaseModel, ConfigDict

from ..cdpr.control.dynamics import DynamicsModel
from .cdpr_model import preset_path
from .files import Number, read_mapping, validate_mapping

__all__ = ["load_cdpr_dynamics", "dynamics_from_mapping"]


class _Dynamics(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)
    # Defaults live in DynamicsModel only: a key left out keeps its default there; an
    # explicit null reaches DynamicsModel and is refused by its own checks.
    cable_stiffness: Optional[Number] = None
    cable_damping: Optional[Number] = None
    drum_diameter: Optional[Number] = None
    gear_ratio: Optional[Number] = None
    efficiency: Optional[Number] = None
    backdrive_efficiency: Optional[Number] = None
    rated_torque: Optional[Number] = None
    peak_torque: Optional[Number] = None
    peak_duration: Optional[Number] = None
    motor_speed_limit: Optional[Number] = None
    rotor_inertia: Optional[Number] = None
    friction_static: Optional[Number] = None
    friction_coulomb: Optional[Number] = None
    friction_viscous: Optional[Number] = None
    stribeck_speed: Optional[Number] = None
    drive_speed_gain: Optional[Number] = None
    drive_integral_gain: Optional[Number] = None
    routing_length: Optional[Union[Number, list[Number]]] = None


class _Section(BaseModel):
    model_config = ConfigDict(extra="forbid")
    dynamics: _Dynamics


def dynamics_from_mapping(data: dict[str, Any] | None) -> DynamicsModel:
    """A :class:`DynamicsModel` from a parsed ``dynamics:`` mapping (None: defaults).

    Raises ScenarioError (unknown key, NaN, wrong type, named ``dynamics.<key>``) or
    InvalidModelError (non-positive stiffness, efficiency above 1, ...)."""
    if data is None:
        return DynamicsModel()
    raw = validate_mapping(_Section, {"dynamics": data})
    return DynamicsModel(**raw.dynamics.model_dump(exclude_unset=True))


def load_cdpr_dynamics(source: str | Path) -> DynamicsModel:
    """The cables and winches of a preset name or model file (defaults where the file has no
    ``dynamics:`` section)."""
    s = str(source)
    p = Path(s)
    if not p.exists() and p.suffix == "" and "/" not in s and "\\" not in s:
        p = preset_path(s)
    data = read_mapping(p)
    return dynamics_from_mapping(data.get("dynamics") if isinstance(data, dict) else None)
