"""Parameters of the moving cable robot: elastic cables and winches (FASTKIT paper, §2.1.1
and Table 1). Kept apart from :class:`~taut.cdpr.model.robot.CableRobot` (geometry and statics) so
the static analyses stay unchanged; a model file carries them in an optional ``dynamics:``
section (see :mod:`taut.io.cdpr_model`).

Units: SI, float64. Motor-side quantities (torque N m, speed rad/s, inertia kg m^2) are at the
motor shaft, before the gearhead.

Winch model (one per cable). With ``theta`` the motor angle, ``N`` the gear ratio, ``r`` the
drum radius, ``kl = r / N``, the unstretched (paid-out) cable length is
``L0 = L0(0) + kl theta`` and

    J theta_ddot = kl T - tau - tau_g(tau, T, theta_dot) - tau_f(theta_dot),

where ``T`` is the cable tension, ``tau`` the motor torque (positive winds the cable in) and
``tau_f`` the motor friction: static (breakaway) ``tau_s``, Coulomb ``tau_c``, viscous ``b``,
Stribeck speed ``w_s``. A sliding rotor feels ``F(w) sign(w) + b w`` with the Stribeck level
``F(w) = tau_c + (tau_s - tau_c) exp(-(w / w_s)^2)``; a rotor at rest stays at rest while the
other torques on it stay within ``[-tau_s, tau_s]`` and breaks away when they exceed it.
The plant integrates this set-valued law at a fixed step by its implicit Euler
discretisation (Kikuuwe, Takesue, Sano, Mochiyama, Fujimoto, "Fixed-step friction
simulation: from classical Coulomb model to modern continuous models", IROS 2005: Coulomb
friction as a set-valued law integrated by backward Euler; :meth:`DynamicsModel.friction_step`): with ``z = J w + h (kl T - tau - tau_g)``,
``f = clip(z / h, -F(w), F(w))`` and ``w_new = (z - h f) / (J + h b)``, so a rotor whose
torques cannot overcome the friction within the step stops exactly (stick), the level at
rest is the breakaway torque ``tau_s``, and the friction's power ``(f + b w_new) w_new`` is
never negative. The controllers and the current-based tension estimate use the smooth
compensation model :meth:`DynamicsModel.friction` (the same levels, ``sign`` replaced by
``tanh(w / w_eps)``). The gearbox loss
``tau_g`` follows the direction of power flow (a load-dependent Coulomb friction of the mesh):
with ``s = tanh(w / w_eps)``,

    tau_g = s ((1 - eta) max(-s tau, 0) + (1 - eta_b) max(s kl T, 0)),

so when the motor drives the load (winding in, ``s = -1``) ``J theta_ddot = kl T - eta tau``
and when the load drives the motor (paying out under tension, ``s = +1``)
``J theta_ddot = eta_b kl T - tau``: lowering 45 N needs ``eta_b kl T = 0.25 N m``, lifting
it ``kl T / eta = 0.51 N m`` (Table 1's 0.6 N m working point). The dissipated power
``tau_g w`` is never negative. At rest the regularised loss vanishes and the stiction holds
up to ``tau_s`` (a real mesh holds any torque in ``[eta_b kl T, kl T / eta]``).

Motor torque: the drive saturates at ``peak_torque``; ``rated_torque`` is the continuous
rating, and the run's monitor reports every episode above it longer than ``peak_duration``
(a stated time rule, not a thermal model).

Cable model: the cable runs from the drum over a fixed routing (pulleys, the mast) of length
``rho`` (``routing_length``, m) to the exit point, then the free span ``L`` to the platform;
with ``L0`` the unstretched free span (the drum pays out ``L0`` at ``kl`` per radian) the
whole unstretched cable between drum and platform is ``L0 + rho`` and, with one tension along
it (frictionless pulleys),
``T = max(0, (EA (L - L0) + d (L_dot - L0_dot)) / (L0 + rho))``: stiffness
``k = EA / (L0 + rho)``, unilateral (no force when the cable is shorter than its unstretched
length).
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any

import numpy as np

from ..._validate import as_finite_scalar
from ...errors import InvalidModelError

__all__ = ["DynamicsModel"]

# Values the FASTKIT paper gives (Table 1, §2.1.1).
_PAPER = ("drum_diameter", "gear_ratio", "efficiency", "rated_torque",
          "motor_speed_limit")


@dataclass(frozen=True)
class DynamicsModel:
    """Elastic cables and winches of a CDPR, validated on construction.

    Defaults are the FASTKIT values: from the paper where it gives them (Table 1), otherwise
    documented assumptions (marked *assumed*).

    Parameters
    ----------
    cable_stiffness : float
        ``EA`` of every cable, N (*assumed* 20 kN, of the order of a 1.5-2 mm UHMWPE braid;
        the paper gives no cable data). ``k = EA / L0``.
    cable_damping : float
        ``d`` of every cable, N s (*assumed* 50 N s, a few % of critical damping of the
        platform modes); the damping force is ``d (L_dot - L0_dot) / L0`` (strain rate). 0 disables it.
    drum_diameter : float
        m (Table 1: 0.08 m).
    gear_ratio : float
        Motor turns per drum turn (Table 1: 5:1).
    efficiency : float
        Transmission efficiency in (0, 1] when the motor drives the load (Table 1: 70 %).
    backdrive_efficiency : float, optional
        Efficiency in (0, 1] when the load drives the motor (paying out under tension);
        default (None) the forward ``efficiency`` (the paper gives one figure).
    rated_torque : float
        Continuous motor torque, N m (Table 1's 0.6 N m working point).
    peak_torque : float
        Torque the drive saturates at, N m (*assumed* 1.8 N m: three times the rated torque,
        typical of servo drives); at least ``rated_torque``.
    peak_duration : float
        Longest time above the rated torque the drive sustains, s (*assumed* 1 s, a typical
        servo's peak-current time); longer episodes are reported by the run's monitor.
    motor_speed_limit : float
        rad/s (250 rad/s = 2387 rpm: the 2 m/s maximum cable speed of Table 1 through the
        5:1 gearhead and 0.04 m drum radius; the 1600 rpm of Table 1 is the working point).
    rotor_inertia : float
        Motor rotor + gearhead + drum reflected to the motor shaft, kg m^2 (*assumed*
        4.5e-5: 3e-5 rotor of a 0.6 N m servo, 1e-5 gearhead, drum 1.3e-4 / 25).
    friction_static, friction_coulomb : float
        N m at the motor (*assumed* 0.02 and 0.015 N m, ~3 % of the working torque): the
        breakaway torque of a rotor at rest and the sliding level at speed.
    friction_viscous : float
        N m s/rad at the motor (*assumed* 2e-5).
    stribeck_speed : float
        rad/s at the motor (*assumed* 5 rad/s).
    drive_speed_gain, drive_integral_gain : float
        Proportional (N m s/rad) and integral (N m/rad) gains of the servo drive's speed loop,
        used when a controller sends speed set-points (*assumed* 0.027 and 4: a ~420 rad/s
        speed-loop bandwidth ``eta K / J`` for the rotor inertia above).
    routing_length : float or sequence of float
        Length of each cable between its drum and its exit point, m: one value for every
        cable or one per cable (0: the free span only). It adds to the elastic length:
        ``k = EA / (L0 + routing_length)``. *Assumed* 2.3 m: a FASTKIT winch at the foot of
        its 2.4 m mast (the preset file gives 2.30 m to the upper and 2.15 m to the lower
        exit pulleys).
    """

    cable_stiffness: float = 2.0e4
    cable_damping: float = 50.0
    drum_diameter: float = 0.08
    gear_ratio: float = 5.0
    efficiency: float = 0.7
    backdrive_efficiency: float | None = None
    rated_torque: float = 0.6
    peak_torque: float = 1.8
    peak_duration: float = 1.0
    motor_speed_limit: float = 250.0
    rotor_inertia: float = 4.5e-5
    friction_static: float = 0.02
    friction_coulomb: float = 0.015
    friction_viscous: float = 2.0e-5
    stribeck_speed: float = 5.0
    drive_speed_gain: float = 0.027
    drive_integral_gain: float = 4.0
    routing_length: float | tuple[float, ...] = 2.3

    def __post_init__(self) -> None:
        if self.backdrive_efficiency is None:
            object.__setattr__(self, "backdrive_efficiency", self.efficiency)
        positive = ("cable_stiffness", "drum_diameter", "gear_ratio", "efficiency",
                    "backdrive_efficiency", "rated_torque", "peak_torque", "peak_duration",
                    "motor_speed_limit", "rotor_inertia", "stribeck_speed")
        object.__setattr__(self, "routing_length", _routing(self.routing_length))
        for f in fields(self):
            if f.name == "routing_length":
                continue
            v = as_finite_scalar(getattr(self, f.name), f"dynamics.{f.name}")
            if f.name in positive and not v > 0:
                raise InvalidModelError(f"dynamics.{f.name}", f"must be positive, got {v:g}")
            if v < 0:
                raise InvalidModelError(f"dynamics.{f.name}",
                                        f"must be non-negative, got {v:g}")
            object.__setattr__(self, f.name, v)
        for name in ("efficiency", "backdrive_efficiency"):
            if getattr(self, name) > 1.0:
                raise InvalidModelError(f"dynamics.{name}",
                                        f"must be in (0, 1], got {getattr(self, name):g}")
        if self.peak_torque < self.rated_torque:
            raise InvalidModelError("dynamics.peak_torque", f"peak torque {self.peak_torque:g} "
                                    f"N m is below the rated torque {self.rated_torque:g} N m")
        if self.friction_static < self.friction_coulomb:
            raise InvalidModelError("dynamics.friction_static", "static friction "
                                    f"{self.friction_static:g} N m is below Coulomb friction "
                                    f"{self.friction_coulomb:g} N m")

    @property
    def drum_radius(self) -> float:
        """m."""
        return 0.5 * self.drum_diameter

    @property
    def length_per_rad(self) -> float:
        """Cable length paid out per motor radian, ``r / N``, m/rad."""
        return self.drum_radius / self.gear_ratio

    @property
    def max_cable_speed(self) -> float:
        """Cable speed at the motor speed limit, m/s."""
        return self.motor_speed_limit * self.length_per_rad

    @property
    def max_cable_tension(self) -> float:
        """Tension the motor lifts continuously at its rated torque (no friction), N."""
        return self.rated_torque * self.efficiency / self.length_per_rad

    def routing(self, m: int) -> np.ndarray:
        """Routing length of each of ``m`` cables (m,), m; raises InvalidModelError when a
        per-cable list has another length."""
        r = np.asarray(self.routing_length, dtype=float)
        if r.ndim == 0:
            return np.full(m, float(r))
        if r.shape != (m,):
            raise InvalidModelError("dynamics.routing_length", f"has {r.size} values, the "
                                    f"robot has {m} cables")
        return r.copy()

    def unstretched_length(self, length: Any, tension: Any, routing: Any) -> np.ndarray:
        """Unstretched free span ``L0`` (m) of cables of free length ``length`` (m) under
        ``tension`` (N) with ``routing`` (m) of routed cable: ``T = EA (L - L0) / (L0 + rho)``
        solved, ``L0 = (EA L - T rho) / (EA + T)``.

        Examples
        --------
        >>> d = DynamicsModel(cable_stiffness=1000.0)
        >>> L0 = d.unstretched_length(3.0, 10.0, 2.0)
        >>> round(float(L0), 6), round(float(d.stretched_length(L0, 10.0, 2.0)), 12)
        (2.950495, 3.0)
        """
        EA = self.cable_stiffness
        T = np.asarray(tension, dtype=float)
        return (EA * np.asarray(length, dtype=float) - T * routing) / (EA + T)

    def stretched_length(self, L0: Any, tension: Any, routing: Any) -> np.ndarray:
        """Free span (m) of cables with unstretched free span ``L0`` (m) under ``tension``
        (N): ``L0 + T (L0 + rho) / EA``."""
        L0 = np.asarray(L0, dtype=float)
        return L0 + np.asarray(tension, dtype=float) * (L0 + routing) / self.cable_stiffness

    def friction_level(self, speed: Any, scale: Any = 1.0) -> np.ndarray:
        """Stribeck level ``F(w) = tau_c + (tau_s - tau_c) exp(-(w / w_s)^2)`` (N m, >= 0)
        at motor speeds ``w`` (rad/s), times ``scale``: the breakaway torque at rest, the
        Coulomb level at speed."""
        w = np.asarray(speed, dtype=float)
        return np.asarray(scale) * (self.friction_coulomb + (
            self.friction_static - self.friction_coulomb) * np.exp(-(w / self.stribeck_speed) ** 2))

    def friction_step(self, speed: Any, net: Any, h: float, inertia: Any, scale: Any = 1.0
                      ) -> tuple[np.ndarray, np.ndarray]:
        """One implicit Euler step of a rotor with set-valued friction (Kikuuwe et al. 2005,
        see the module docstring): motor speeds ``w`` (rad/s), the other torques on the rotor
        ``net`` (N m), step ``h`` (s), rotor inertias (kg m^2), friction ``scale``. Returns
        the new speeds and the friction torque that acted (N m, Coulomb/static part plus
        viscous on the new speed).

        Examples
        --------
        >>> d = DynamicsModel()
        >>> w, f = d.friction_step(np.zeros(2), np.array([0.019, 0.021]), 1e-3, 4.5e-5)
        >>> bool(w[0] == 0.0), bool(w[1] > 0.0), round(float(f[0]), 3)   # holds below 0.02 N m
        (True, True, 0.019)
        """
        w = np.asarray(speed, dtype=float)
        z = inertia * w + h * np.asarray(net, dtype=float)
        F = self.friction_level(w, scale)
        f = np.clip(z / h, -F, F)
        b = np.asarray(scale) * self.friction_viscous
        w_new = (z - h * f) / (inertia + h * b)
        return w_new, f + b * w_new

    def friction(self, speed: np.ndarray, scale: Any = 1.0) -> np.ndarray:
        """Smooth friction model ``F(w) tanh(w / w_eps) + b w`` (N m, same sign as
        ``speed``) at motor speeds (rad/s), multiplied by ``scale`` (broadcast): what the
        controllers compensate and the current-based tension estimate inverts (the plant's
        rotors stick, :meth:`friction_step`).

        Examples
        --------
        >>> d = DynamicsModel()
        >>> float(d.friction(np.array(100.0)))          # Coulomb + viscous at speed
        0.017
        >>> float(d.friction(np.array(0.0)))
        0.0
        """
        from .._tol import FRICTION_SPEED_WIDTH
        w = np.asarray(speed, dtype=float)
        return self.friction_level(w, scale) * np.tanh(w / FRICTION_SPEED_WIDTH) \
            + np.asarray(scale) * self.friction_viscous * w

    def gear_loss(self, tau: Any, tension: Any, speed: Any, efficiency: Any = None,
                  backdrive_efficiency: Any = None) -> np.ndarray:
        """Gearbox loss torque ``tau_g`` (N m at the motor, same sign as ``speed``) for motor
        torques ``tau`` (N m), cable tensions ``tension`` (N) and motor speeds ``speed``
        (rad/s), with the direction of power flow (see the module docstring); the
        efficiencies default to this model's (arrays broadcast, for perturbed plants).

        Examples
        --------
        >>> d = DynamicsModel(backdrive_efficiency=0.5)
        >>> round(float(d.gear_loss(0.3, 45.0, 100.0)), 3)        # lowering: (1 - 0.5) kl T
        0.18
        >>> round(float(d.gear_loss(0.6, 45.0, -100.0)), 3)       # lifting: -(1 - 0.7) tau
        -0.18
        """
        from .._tol import FRICTION_SPEED_WIDTH
        eta = self.efficiency if efficiency is None else efficiency
        eta_b = (self.efficiency if self.backdrive_efficiency is None
                 else self.backdrive_efficiency) if backdrive_efficiency is None \
            else backdrive_efficiency
        s = np.tanh(np.asarray(speed, dtype=float) / FRICTION_SPEED_WIDTH)
        load = self.length_per_rad * np.asarray(tension, dtype=float)
        return s * ((1.0 - eta) * np.maximum(-s * np.asarray(tau, dtype=float), 0.0)
                    + (1.0 - eta_b) * np.maximum(s * load, 0.0))

    def holding_torque(self, load: Any, tension: Any, speed: Any) -> np.ndarray:
        """Motor torque ``tau`` (N m) solving ``tau + tau_g(tau, T, w) = load`` for the
        net torque ``load`` (N m at the motor, e.g. ``kl T - tau_f - J theta_ddot``), cable
        tensions ``T`` (N) and motor speeds ``w`` (rad/s): the inverse of the gearbox loss
        (``load / eta`` winding in, ``load - (1 - eta_b) kl T`` paying out).

        Examples
        --------
        >>> d = DynamicsModel(backdrive_efficiency=0.5)
        >>> kT = d.length_per_rad * 45.0
        >>> bool(np.isclose(d.holding_torque(kT, 45.0, 100.0), 0.5 * kT))
        True
        >>> bool(np.isclose(d.holding_torque(kT, 45.0, -100.0), kT / 0.7))
        True
        """
        from .._tol import FRICTION_SPEED_WIDTH
        s = np.tanh(np.asarray(speed, dtype=float) / FRICTION_SPEED_WIDTH)
        kT = self.length_per_rad * np.asarray(tension, dtype=float)
        eta_b = self.efficiency if self.backdrive_efficiency is None else \
            self.backdrive_efficiency
        z = np.asarray(load, dtype=float) - (1.0 - eta_b) * s * np.maximum(s * kT, 0.0)
        return np.where(z * s < 0.0, z / (1.0 - (1.0 - self.efficiency) * s * s), z)

    def without_losses(self) -> "DynamicsModel":
        """The same winches with no friction, no cable damping and 100 % efficiency
        (for energy-conservation checks)."""
        from dataclasses import replace
        return replace(self, cable_damping=0.0, friction_static=0.0, friction_coulomb=0.0,
                       friction_viscous=0.0, efficiency=1.0,
                       backdrive_efficiency=1.0)

    def describe(self) -> dict[str, Any]:
        """JSON-friendly parameters, with which ones come from the FASTKIT paper."""
        out: dict[str, Any] = {f.name: getattr(self, f.name) for f in fields(self)}
        if isinstance(self.routing_length, tuple):
            out["routing_length"] = list(self.routing_length)
        out["from_paper"] = list(_PAPER)
        return out


def _routing(value: Any) -> float | tuple[float, ...]:
    """``routing_length`` validated: one non-negative length or a non-empty list of them, m."""
    name = "dynamics.routing_length"
    if isinstance(value, (list, tuple, np.ndarray)):
        vals = tuple(as_finite_scalar(v, name) for v in np.asarray(value, dtype=object).ravel())
        if not vals:
            raise InvalidModelError(name, "is an empty list")
    else:
        vals = (as_finite_scalar(value, name),)
    if min(vals) < 0:
        raise InvalidModelError(name, f"must be non-negative, got {min(vals):g} m")
    return vals if isinstance(value, (list, tuple, np.ndarray)) else vals[0]
