"""Control laws of the FASTKIT cable robot (paper §2.2, §3.1), behind one interface.

A controller is a frozen object of gains. :func:`taut.cdpr.simulate` precomputes, once per run
and with the *nominal* model, the reference quantities every law needs (a
:class:`ControlContext`: cable lengths, wrench matrices, reference tensions from the tension
distribution, unstretched-length set-points) and then calls :meth:`Controller.command` at the
control rate with the measurements. A command is either motor torques (N m) or motor speed
set-points (rad/s) for the servo drives.

Deployment synchronisation (task mode, eq. 8) is part of the context: with a base motion the
reference cable rates are ``l_dot = A t_P - B_b q_dot_b``, i.e. the winches pay out or reel in
what the moving active base takes away, so either law holds the platform on its own reference
while the base moves.

Measurements are set by :class:`taut.cdpr.Sensing`: by default quantised encoders (with the
seeded encoder offsets), the drives' torques, and a pose and twist *estimated* from the
encoders on the nominal model (FASTKIT has no exteroceptive sensor; the paper's ongoing work
adds cameras); ``Sensing(ideal_pose=True)`` gives the true pose and twist.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass, fields, is_dataclass
from typing import Any, ClassVar, Literal

import numpy as np

from ..._validate import as_nonnegative, as_positive
from .dynamics import DynamicsModel

__all__ = ["Controller", "VelocityController", "TorqueController", "CONTROLLERS"]

CommandMode = Literal["torque", "speed"]


@dataclass(frozen=True)
class ControlContext:
    """Nominal reference quantities at the T control instants (built by ``simulate``).

    Attributes
    ----------
    dynamics : DynamicsModel
    dt : float
        Control period, s.
    ref_poses, ref_vel, ref_acc : (T, 6)
        Platform reference (m, rad; ``[v; omega]``; ``[a; alpha]``).
    W : (T, 6, m)
        Nominal wrench matrices at the reference poses (eq. 18).
    W_pinv : (T, m, 6)
        Their pseudo-inverses.
    tensions : (T, m)
        Reference tensions from the tension distribution for gravity plus the reference
        inertial wrench, N.
    L0, L0_dot, L0_ddot : (T, m)
        Unstretched-length set-points and their rates (eq. 8 with the stretch ``T L0 / EA``
        removed), m, m/s, m/s^2.
    com : (T, 3)
        Reference point P to centre of mass, world frame, m.
    com_skew_T : (T, 3, 3)
        Transposed cross-product matrices of ``com``.
    inertia : (T, 3, 3)
        Nominal inertia about the centre of mass, world frame, kg m^2.
    R_ref : (T, 3, 3)
        Reference rotations.
    mass : float
        Nominal moving mass, kg.
    t_min, t_max : (m,)
        Tension limits, N.
    exits, exit_vel : (T, m, 3)
        Nominal world exit points (m) and their velocities (m/s).
    attach : (m, 3)
        Attachment points in the platform frame, m.
    """

    dynamics: DynamicsModel
    dt: float
    ref_poses: np.ndarray
    ref_vel: np.ndarray
    ref_acc: np.ndarray
    W: np.ndarray
    W_pinv: np.ndarray
    tensions: np.ndarray
    L0: np.ndarray
    L0_dot: np.ndarray
    L0_ddot: np.ndarray
    com: np.ndarray
    com_skew_T: np.ndarray
    inertia: np.ndarray
    R_ref: np.ndarray
    mass: float
    t_min: np.ndarray
    t_max: np.ndarray
    exits: np.ndarray
    exit_vel: np.ndarray
    attach: np.ndarray


@dataclass(frozen=True)
class Measurement:
    """What a controller sees at one instant, for B plants: ``p`` (B, 3) position of P, m;
    ``R`` (B, 3, 3); ``v`` (B, 3) m/s and ``w`` (B, 3) rad/s (world), true or estimated (see
    :class:`taut.cdpr.Sensing`); ``L0`` (B, m) encoder cable lengths, m; ``speed`` (B, m)
    motor speeds, rad/s; ``tension`` (B, m) measured or estimated tensions, N (NaN without a
    tension measurement)."""

    p: np.ndarray
    R: np.ndarray
    v: np.ndarray
    w: np.ndarray
    L0: np.ndarray
    speed: np.ndarray
    tension: np.ndarray


class Controller(ABC):
    """Interface: ``mode`` ("torque" or "speed") and ``command(ctx, k, meas)`` -> (B, m)."""

    name: ClassVar[str] = "controller"
    mode: ClassVar[CommandMode] = "torque"

    @abstractmethod
    def command(self, ctx: ControlContext, k: int, meas: Measurement) -> np.ndarray:
        """Motor torques (N m) or speed set-points (rad/s) at control step ``k``."""

    def describe(self) -> dict[str, Any]:
        """Name and gains, JSON-friendly (public attributes of a custom controller that is
        not a dataclass)."""
        if is_dataclass(self):
            gains = {f.name: getattr(self, f.name) for f in fields(self)}
        else:
            gains = {k: v for k, v in vars(self).items() if not k.startswith("_")}
        out: dict[str, Any] = {"name": self.name, "mode": self.mode}
        for k, v in gains.items():
            out[k] = v.tolist() if isinstance(v, np.ndarray) else v
        return out


def _validated(obj: Any) -> None:
    for f in fields(obj):
        v = getattr(obj, f.name)
        check = as_nonnegative if f.name in ("joint_damping", "tension_gain") else as_positive
        object.__setattr__(obj, f.name, check(v, f"controller.{f.name}"))


@dataclass(frozen=True)
class VelocityController(Controller):
    """Velocity control (FASTKIT §2.2): motor speed set-points from the first-order model
    (eqs. 1, 8) for the reference twist plus a joint-space correction on the cable lengths,

        theta_dot_cmd = (N / r) (L0_dot_ref + length_gain (L0_ref - L0_encoder)
                                 + tension_gain (T_meas - t_ref) L0_ref / EA).

    The servo drives close the speed loop (see :class:`DynamicsModel`). With
    ``tension_gain = 0`` tensions are not controlled: they are whatever the geometry errors
    make them. With ``tension_gain > 0`` a cable pulled above its reference tension pays out
    (an admittance on the tension the controller sees: by default the drives' torque-based
    estimate, see :class:`taut.cdpr.Sensing`; a run without a tension measurement is refused).

    Parameters
    ----------
    length_gain : float
        1/s (default 20: a 50 ms joint-space time constant).
    tension_gain : float
        1/s (default 0: pure velocity control); the tension error's stretch
        ``(T - t_ref) L0 / EA`` is paid out at this rate.

    Examples
    --------
    >>> VelocityController().mode
    'speed'
    """

    length_gain: float = 20.0
    tension_gain: float = 0.0
    name: ClassVar[str] = "velocity"
    mode: ClassVar[CommandMode] = "speed"

    def __post_init__(self) -> None:
        _validated(self)

    def command(self, ctx: ControlContext, k: int, meas: Measurement) -> np.ndarray:
        rate = ctx.L0_dot[k] + self.length_gain * (ctx.L0[k] - meas.L0)
        if self.tension_gain > 0.0:
            rate = rate + self.tension_gain * (meas.tension - ctx.tensions[k]) * ctx.L0[k] \
                / ctx.dynamics.cable_stiffness
        return rate / ctx.dynamics.length_per_rad


@dataclass(frozen=True)
class TorqueController(Controller):
    """Torque control (FASTKIT §2.2): task-space PD plus feed-forward of gravity and platform
    dynamics, tensions from the tension distribution, motor torques with friction
    compensation from the *estimated* (nominal) friction model.

    With ``e`` the pose error of P (position, rotation vector) and ``e_dot`` the twist error,
    the commanded accelerations ``a = Kp e + Kd e_dot`` give the wrench correction
    ``dw = [M (a + alpha x c); I alpha + c x M (a + alpha x c)]``; the tensions are
    ``t = clip(t_ref + W_ref^+ dw, t_min, t_max)`` where ``t_ref`` is the closed-form tension
    distribution for gravity plus the reference inertial wrench (precomputed over the
    reference, batched); the motor torques invert the nominal winch model, gearbox loss in
    the direction of power flow included (:meth:`DynamicsModel.holding_torque`):

        tau + tau_g(tau, t, theta_dot) = (r/N) t - tau_f_est(theta_dot) - J theta_ddot_ref
                                         + joint_damping (theta_dot - theta_dot_ref).

    Pose and twist are what :class:`taut.cdpr.Sensing` gives (by default estimated from the
    encoders on the nominal model).

    Parameters
    ----------
    position_stiffness, position_damping : float
        ``Kp`` (1/s^2) and ``Kd`` (1/s) of the translation (default 3 Hz, damping ratio 0.9).
    rotation_stiffness, rotation_damping : float
        Same for the rotation.
    joint_damping : float
        Motor-speed damping about the reference speed, N m s/rad (default 2e-3).

    Examples
    --------
    >>> TorqueController().mode
    'torque'
    """

    position_stiffness: float = 355.0
    position_damping: float = 34.0
    rotation_stiffness: float = 355.0
    rotation_damping: float = 34.0
    joint_damping: float = 2.0e-3
    name: ClassVar[str] = "torque"
    mode: ClassVar[CommandMode] = "torque"

    def __post_init__(self) -> None:
        _validated(self)

    def command(self, ctx: ControlContext, k: int, meas: Measurement) -> np.ndarray:
        ref = ctx.ref_poses[k]
        Rr = ctx.R_ref[k]
        E = Rr @ np.swapaxes(meas.R, 1, 2)                        # R_ref R^T
        er = 0.5 * np.stack([E[:, 2, 1] - E[:, 1, 2], E[:, 0, 2] - E[:, 2, 0],
                             E[:, 1, 0] - E[:, 0, 1]], axis=1)
        a = (self.position_stiffness * (ref[:3] - meas.p)
             + self.position_damping * (ctx.ref_vel[k, :3] - meas.v))
        alpha = (self.rotation_stiffness * er
                 + self.rotation_damping * (ctx.ref_vel[k, 3:] - meas.w))
        CT = ctx.com_skew_T[k]                                   # [c]x^T
        f = ctx.mass * (a - alpha @ CT)                          # M (a + alpha x c)
        mom = alpha @ ctx.inertia[k].T + f @ CT                  # I alpha + c x f
        t = ctx.tensions[k] + np.hstack([f, mom]) @ ctx.W_pinv[k].T
        t = np.clip(t, ctx.t_min, ctx.t_max)
        d = ctx.dynamics
        kl = d.length_per_rad
        speed_ref = ctx.L0_dot[k] / kl
        load = (kl * t - d.friction(meas.speed) - d.rotor_inertia * ctx.L0_ddot[k] / kl
                + self.joint_damping * (meas.speed - speed_ref))
        return d.holding_torque(load, t, meas.speed)


#: Controller names accepted by the CLI.
CONTROLLERS = {"velocity": VelocityController, "torque": TorqueController}
