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
from typing import Any


from ..cdpr.control.dynamics import DynamicsModel
from .cdpr_model import _Dynamics, preset_path
from .files import StrictModel, read_mapping, validate_mapping

__all__ = ["load_cdpr_dynamics", "dynamics_from_mapping"]


class _Section(StrictModel):
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
