"""The optional ``dynamics:`` section of a cable-robot model file: elastic cables and winches
(:class:`taut.cdpr.DynamicsModel`; every key optional, defaults are the FASTKIT values).

Keys (SI, motor side): ``cable_stiffness`` (EA, N), ``cable_damping`` (N s),
``drum_diameter`` (m), ``gear_ratio``, ``efficiency``, ``motor_torque_limit`` (N m),
``motor_speed_limit`` (rad/s), ``rotor_inertia`` (kg m^2), ``friction_static``,
``friction_coulomb`` (N m), ``friction_viscous`` (N m s/rad), ``stribeck_speed`` (rad/s),
``drive_speed_gain`` (N m s/rad), ``drive_integral_gain`` (N m/rad).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from pydantic import BaseModel, ConfigDict

from ..cdpr.dynamics_model import DynamicsModel
from .cdpr_model import preset_path
from .files import read_mapping, validate_mapping

__all__ = ["load_cdpr_dynamics", "dynamics_from_mapping"]


class _Dynamics(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)
    cable_stiffness: float = 2.0e4
    cable_damping: float = 50.0
    drum_diameter: float = 0.08
    gear_ratio: float = 5.0
    efficiency: float = 0.7
    motor_torque_limit: float = 0.6
    motor_speed_limit: float = 250.0
    rotor_inertia: float = 4.5e-5
    friction_static: float = 0.02
    friction_coulomb: float = 0.015
    friction_viscous: float = 2.0e-5
    stribeck_speed: float = 5.0
    drive_speed_gain: float = 0.027
    drive_integral_gain: float = 4.0


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
    return DynamicsModel(**raw.dynamics.model_dump())


def load_cdpr_dynamics(source: str | Path) -> DynamicsModel:
    """The cables and winches of a preset name or model file (defaults where the file has no
    ``dynamics:`` section)."""
    s = str(source)
    p = Path(s)
    if not p.exists() and p.suffix == "" and "/" not in s and "\\" not in s:
        p = preset_path(s)
    data = read_mapping(p)
    return dynamics_from_mapping(data.get("dynamics") if isinstance(data, dict) else None)
