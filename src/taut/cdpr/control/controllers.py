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

Measurements are ideal (platform pose and twist as from an external tracker, encoder lengths
with the seeded encoder offsets): the paper's ongoing work adds cameras for the pose.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass, fields
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


@dataclass(frozen=True)
class Measurement:
    """What a controller sees at one instant, for B plants: ``p`` (B, 3) position of P, m;
    ``R`` (B, 3, 3); ``v`` (B, 3) m/s and ``w`` (B, 3) rad/s (world); ``L0`` (B, m) encoder
    cable lengths, m; ``speed`` (B, m) motor speeds, rad/s."""

    p: np.ndarray
    R: np.ndarray
    v: np.ndarray
    w: np.ndarray
    L0: np.ndarray
    speed: np.ndarray


class Controller(ABC):
    """Interface: ``mode`` ("torque" or "speed") and ``command(ctx, k, meas)`` -> (B, m)."""

    name: ClassVar[str] = "controller"
    mode: ClassVar[CommandMode] = "torque"

    @abstractmethod
    def command(self, ctx: ControlContext, k: int, meas: Measurement) -> np.ndarray:
        """Motor torques (N m) or speed set-points (rad/s) at control step ``k``."""

    def describe(self) -> dict[str, Any]:
        """Name and gains, JSON-friendly."""
        return {"name": self.name, **{f.name: getattr(self, f.name) for f in fields(self)}}  # type: ignore[arg-type]


def _validated(obj: Any) -> None:
    for f in fields(obj):
        v = getattr(obj, f.name)
        check = as_nonnegative if f.name.startswith("joint_damping") else as_positive
        object.__setattr__(obj, f.name, check(v, f"controller.{f.name}"))


@dataclass(frozen=True)
class VelocityController(Controller):
    """Velocity control (FASTKIT §2.2): motor speed set-points from the first-order model
    (eqs. 1, 8) for the reference twist plus a joint-space correction on the cable lengths,

        theta_dot_cmd = (N / r) (L0_dot_ref + length_gain (L0_ref - L0_encoder)).

    The servo drives close the speed loop (see :class:`DynamicsModel`). Tensions are not
    controlled: they are whatever the geometry errors make them.

    Parameters
    ----------
    length_gain : float
        1/s (default 20: a 50 ms joint-space time constant).

    Examples
    --------
    >>> VelocityController().mode
    'speed'
    """

    length_gain: float = 20.0
    name: ClassVar[str] = "velocity"
    mode: ClassVar[CommandMode] = "speed"

    def __post_init__(self) -> None:
        _validated(self)

    def command(self, ctx: ControlContext, k: int, meas: Measurement) -> np.ndarray:
        rate = ctx.L0_dot[k] + self.length_gain * (ctx.L0[k] - meas.L0)
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
    reference, batched); the motor torques invert the winch model:

        tau = ((r/N) t - tau_f_est(theta_dot) - J theta_ddot_ref
               + joint_damping (theta_dot - theta_dot_ref)) / eta.

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
        return (kl * t - d.friction(meas.speed) - d.rotor_inertia * ctx.L0_ddot[k] / kl
                + self.joint_damping * (meas.speed - speed_ref)) / d.efficiency


#: Controller names accepted by the CLI.
CONTROLLERS = {"velocity": VelocityController, "torque": TorqueController}
