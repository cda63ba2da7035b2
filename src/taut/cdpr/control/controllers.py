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

The controller protocol
-----------------------
Any object with these three members is a controller for :func:`taut.cdpr.simulate`,
:func:`taut.cdpr.monte_carlo` and ``reference_simulate``, on every ``backend``:

``name`` : str
    Shown in results (``ControlResult.controller["name"]``, ``MonteCarloResult.controller``).
``mode`` : "torque" or "speed"
    What ``command`` returns: motor torques, N m (saturated at the peak torque by the
    plant), or motor speed set-points, rad/s (tracked by the drives' PI speed loop).
``command(ctx, k, meas)`` -> (B, m) array
    The command at control step ``k`` (0-based, the settling pre-roll included) from the
    nominal :class:`ControlContext` ``ctx`` (arrays indexed by ``k``) and the
    :class:`Measurement` ``meas`` of the ``B`` plants run together (one in
    :func:`~taut.cdpr.simulate`; one per model-error draw in
    :func:`~taut.cdpr.monte_carlo`), so a law written with array operations over the
    leading axis batches for free. It must not keep state between calls that depends on
    the plant count.

``describe()`` -> dict is optional: subclasses of :class:`Controller` inherit one giving
the name, mode and gains (dataclass fields, or the public attributes of any other object);
an object that is not a subclass gets the same. It appears as ``ControlResult.controller``
and in the result's JSON. On ``backend="numba"`` the built-in :class:`VelocityController`
and :class:`TorqueController` run compiled with the plant; every other controller runs in
Python once per control step while the plant (its sub-steps) runs compiled; on
``backend="numpy"`` both run in numpy. The engines compute the same model
(tests/cdpr/control/test_control_laws.py checks a custom re-implementation of the velocity
law against the built-in on each).

Examples
--------
A joint-space PD on the encoder lengths in torque mode, with the holding torque of the
reference tensions as feed-forward:

>>> import numpy as np
>>> from taut.cdpr import pick_and_place, simulate, with_stabilisers
>>> from taut.io.cdpr_model import load_cdpr_model
>>> class LengthPD:
...     name, mode = "length_pd", "torque"
...     def __init__(self, stiffness=4.0e3):
...         self.stiffness = stiffness                      # N per m of cable
...     def command(self, ctx, k, meas):
...         d = ctx.dynamics
...         t = ctx.tensions[k] + self.stiffness * (meas.L0 - ctx.L0[k])
...         return d.length_per_rad * t / d.efficiency
>>> robot = with_stabilisers(load_cdpr_model("fastkit"))
>>> ref = pick_and_place(robot, [[-0.1, 0, 1.0], [0.1, 0, 1.0]], 0.3, dwell=0.05)
>>> run = simulate(robot, ref, LengthPD(), settle=0.2)
>>> run.controller
{'name': 'length_pd', 'mode': 'torque', 'stiffness': 4000.0}
>>> bool(np.all(np.isfinite(run.tensions)))
True
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass, fields, is_dataclass, replace
from typing import Any, ClassVar, Literal

import numpy as np

from ..._validate import as_nonnegative, as_positive
from ...errors import InvalidInputError
from .dynamics import DynamicsModel
from .sensing import Sensing
from ..model.robot import CableRobot
from ..statics.tension import _closed_form

__all__ = ["Controller", "VelocityController", "TorqueController", "ComputedTorqueController",
           "CONTROLLERS", "tune_for_rate"]

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
        Unstretched-length set-points and their rates (eq. 8 with the stretch
        ``T (L0 + rho) / EA`` removed, ``rho`` the routing length), m, m/s, m/s^2.
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
    robot : CableRobot
        The nominal robot (limits, gravity; the online tension distribution of
        :class:`ComputedTorqueController`).
    com_local : (3,)
        Nominal centre of mass in the platform frame (from P), m.
    inertia_local : (3, 3)
        Nominal inertia about the centre of mass in the platform frame, kg m^2.
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
    robot: CableRobot
    com_local: np.ndarray
    inertia_local: np.ndarray


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
    """Base of the controllers: ``name``, ``mode`` ("torque" or "speed") and
    ``command(ctx, k, meas)`` -> (B, m), plus :meth:`describe` (see the module docstring
    for the protocol; subclassing is optional)."""

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
            gains = {k: v for k, v in getattr(self, "__dict__", {}).items()
                     if not k.startswith("_")}
        out: dict[str, Any] = {"name": self.name, "mode": self.mode}
        for k, v in gains.items():
            out[k] = v.tolist() if isinstance(v, (np.ndarray, np.generic)) else v
        return out


_MODES = ("torque", "speed")


def check_controller(controller: Any) -> None:
    """Raise :class:`InvalidInputError` unless ``controller`` follows the protocol of the
    module docstring (its ``describe()``, if any, returning a dict)."""
    if isinstance(controller, type):
        raise InvalidInputError("controller", f"got the class {controller.__name__}; pass an "
                                              f"instance, e.g. {controller.__name__}()")
    if not callable(getattr(controller, "command", None)):
        raise InvalidInputError("controller", "needs a method command(ctx, k, meas), e.g. "
                                              "VelocityController() or TorqueController()")
    mode = getattr(controller, "mode", None)
    if not isinstance(mode, str) or mode not in _MODES:
        raise InvalidInputError("controller.mode", f"must be 'torque' or 'speed', got "
                                                   f"{mode!r}")
    if not isinstance(getattr(controller, "name", None), str):
        raise InvalidInputError("controller.name", "must be a str")
    if not isinstance(describe_controller(controller), dict):
        raise InvalidInputError("controller.describe", "must return a dict")


def describe_controller(controller: Any) -> Any:
    """``controller.describe()``, or :meth:`Controller.describe` of it when it has none."""
    own = getattr(controller, "describe", None)
    return own() if callable(own) else Controller.describe(controller)


#: Control rate the default gains of the built-in controllers are designed for (and the
#: default of :func:`taut.cdpr.simulate`), Hz.
DESIGN_CONTROL_RATE = 1000.0

#: Loop delay the default gains are designed for, s: :data:`DESIGN_CONTROL_RATE` without
#: latency (one control period from measurement to command plus half a period of
#: zero-order hold, see :func:`loop_delay`).
DESIGN_LOOP_DELAY = 1.5 / DESIGN_CONTROL_RATE


def loop_delay(control_rate: float, latency: float) -> float:
    """Delay around a sampled control loop, s: the latency, one control period from
    measurement to command, and half a period of zero-order hold (the standard
    approximation of a sample-and-hold as a half-period delay; Franklin, Powell, Workman,
    *Digital Control of Dynamic Systems*, 3rd ed., §6.3.2)."""
    return float(latency) + 1.5 / float(control_rate)


#: Most phase a delay may cost the motor-speed damping loop of the torque laws, rad (45 deg).
JOINT_DELAY_PHASE = np.pi / 4


def tune_for_rate(controller: Controller, sensing: Sensing,
                  control_rate: float = DESIGN_CONTROL_RATE,
                  dynamics: DynamicsModel | None = None) -> tuple[Controller, Sensing]:
    """A built-in controller's gains and the estimate filter for another control rate and
    latency, by one rule: a loop delay ``tau`` costs ``omega_c tau`` rad of phase at a loop's
    crossover ``omega_c``, and every loop keeps at most the phase it loses at the design
    point (1 kHz, no latency).

    * Loops closed through the cable lengths and the estimates (pose, twist, tension): with
      ``s = min(1, DESIGN_LOOP_DELAY / loop_delay(rate, latency))`` every bandwidth scales by
      ``s``: ``length_gain``, ``tension_gain``, ``position_damping``, ``rotation_damping``
      by ``s``, the stiffnesses by ``s^2`` (same damping ratio), ``Sensing.velocity_filter``
      by ``s``. Their fastest mode is not the 3 Hz task-space one: an encoder-estimated pose
      moves with the light rotors (``J (N / r)^2`` = 0.7 kg of cable-side mass against the
      10 kg platform), so the task-space damping acts on the rotor-cable mode; the uniform
      scale keeps that mode's phase loss too.
    * The motor-speed damping of the torque laws (collocated, its bandwidth
      ``joint_damping / J``) is kept unless that costs more than :data:`JOINT_DELAY_PHASE`,
      then lowered to it (``J`` the nominal rotor inertia of ``dynamics``).

    At 1 kHz without latency ``s = 1`` (the defaults); at 200 Hz with 5 ms latency
    ``s = 0.12`` and the default joint damping (44 rad/s) loses 0.55 rad, so it stays.

    Examples
    --------
    >>> c, s = tune_for_rate(TorqueController(), Sensing(latency=0.005), 200.0)
    >>> round(c.position_damping, 2), round(c.position_stiffness, 2), round(s.velocity_filter, 1)
    (4.08, 5.11, 3.6)
    >>> c.joint_damping
    0.002
    """
    if (type(controller) not in CONTROLLERS.values() or not is_dataclass(controller)
            or isinstance(controller, type)):
        raise InvalidInputError("controller", "tune_for_rate scales the gains of the built-in "
                                              "controllers only; tune a custom one yourself")
    if not isinstance(sensing, Sensing):
        raise InvalidInputError("sensing", "must be a taut.cdpr.Sensing")
    rate = as_positive(control_rate, "control_rate")
    dyn = DynamicsModel() if dynamics is None else dynamics
    if not isinstance(dyn, DynamicsModel):
        raise InvalidInputError("dynamics", "must be a taut.cdpr.DynamicsModel")
    tau = loop_delay(rate, sensing.latency)
    s = min(1.0, DESIGN_LOOP_DELAY / tau)
    gains = {f.name: getattr(controller, f.name) * (s * s if f.name.endswith("_stiffness")
                                                    else s) for f in fields(controller)}
    if "joint_damping" in gains:
        jd = getattr(controller, "joint_damping")
        gains["joint_damping"] = min(jd, JOINT_DELAY_PHASE * dyn.rotor_inertia / tau)
    return (replace(controller, **gains),
            replace(sensing, velocity_filter=sensing.velocity_filter * s))


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
class _TaskSpaceTorque(Controller):
    """Gains shared by the torque-mode controllers: task-space PD on the estimated pose and
    motor-speed damping (defaults: 3 Hz, damping ratio 0.9; 2e-3 N m s/rad)."""

    position_stiffness: float = 355.0
    position_damping: float = 34.0
    rotation_stiffness: float = 355.0
    rotation_damping: float = 34.0
    joint_damping: float = 2.0e-3
    mode: ClassVar[CommandMode] = "torque"

    def __post_init__(self) -> None:
        _validated(self)


@dataclass(frozen=True)
class TorqueController(_TaskSpaceTorque):
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

    name: ClassVar[str] = "torque"

    def command(self, ctx: ControlContext, k: int, meas: Measurement) -> np.ndarray:
        ref = ctx.ref_poses[k]
        Rr = ctx.R_ref[k]
        er = _rotation_error(Rr, meas.R)
        a = (self.position_stiffness * (ref[:3] - meas.p)
             + self.position_damping * (ctx.ref_vel[k, :3] - meas.v))
        alpha = (self.rotation_stiffness * er
                 + self.rotation_damping * (ctx.ref_vel[k, 3:] - meas.w))
        CT = ctx.com_skew_T[k]                                   # [c]x^T
        f = ctx.mass * (a - alpha @ CT)                          # M (a + alpha x c)
        mom = alpha @ ctx.inertia[k].T + f @ CT                  # I alpha + c x f
        t = ctx.tensions[k] + np.hstack([f, mom]) @ ctx.W_pinv[k].T
        t = np.clip(t, ctx.t_min, ctx.t_max)
        return _winch_torques(ctx, k, t, meas.speed, self.joint_damping)


def _rotation_error(R_ref: np.ndarray, R: np.ndarray) -> np.ndarray:
    """Rotation vectors (B, 3) of ``R_ref R^T`` (small-angle: the skew part), rad."""
    E = R_ref @ np.swapaxes(R, 1, 2)
    return 0.5 * np.stack([E[:, 2, 1] - E[:, 1, 2], E[:, 0, 2] - E[:, 2, 0],
                           E[:, 1, 0] - E[:, 0, 1]], axis=1)


def _winch_torques(ctx: ControlContext, k: int, t: np.ndarray, speed: np.ndarray,
                   joint_damping: float) -> np.ndarray:
    """Motor torques holding tensions ``t`` on the nominal winch model: friction, rotor
    inertia on the reference acceleration, gearbox loss in the direction of power flow
    (:meth:`DynamicsModel.holding_torque`) and damping about the reference motor speed."""
    d = ctx.dynamics
    kl = d.length_per_rad
    load = (kl * t - d.friction(speed) - d.rotor_inertia * ctx.L0_ddot[k] / kl
            + joint_damping * (speed - ctx.L0_dot[k] / kl))
    return d.holding_torque(load, t, speed)


@dataclass(frozen=True)
class ComputedTorqueController(_TaskSpaceTorque):
    """Computed-torque control of a cable robot: inverse dynamics of the platform at the
    *estimated* state, tensions distributed online, motor torques on the nominal winch model.

    The standard computed-torque law of rigid manipulators applied to the platform's
    Newton-Euler equations (Siciliano, Sciavicco, Villani, Oriolo, *Robotics: Modelling,
    Planning and Control*, Springer 2009, §8.5.2, eq. 8.57; for cable robots Pott, *Cable-Driven
    Parallel Robots: Theory and Application*, Springer 2018, §7, with the wrench matrix of
    FASTKIT eq. 18): with ``x_hat`` the estimated pose of P, ``e`` its error (position, rotation
    vector), ``e_dot`` the twist error,

        y = x_ddot_ref + Kd e_dot + Kp e
        w = M(x_hat) y + C(x_hat, x_dot_hat) - w_g(x_hat),

    i.e. with the centre of mass ``c = R c_b`` and inertia ``I = R I_b R^T`` of the nominal
    moving body, ``a_c = a + alpha x c + omega x (omega x c)``,
    ``w = [M (a_c - g); I alpha + omega x I omega + c x M (a_c - g)]``. The tensions solve
    ``W(x_hat) t = w`` within ``[t_min, t_max]`` by the library's closed-form tension
    distribution (Pott's improved closed form, batched; clipped to the limits where it has
    no solution), and the motor torques invert the nominal winch model with friction
    compensation (as :class:`TorqueController`). Unlike :class:`TorqueController`, which adds
    a PD correction through the reference ``W^+`` to tensions precomputed along the
    reference, every term here is evaluated at the estimated state.

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
    >>> ComputedTorqueController().mode
    'torque'
    """

    name: ClassVar[str] = "computed_torque"

    def command(self, ctx: ControlContext, k: int, meas: Measurement) -> np.ndarray:
        return _winch_torques(ctx, k, self.tensions(ctx, k, meas), meas.speed,
                              self.joint_damping)

    def tensions(self, ctx: ControlContext, k: int, meas: Measurement) -> np.ndarray:
        """Cable tensions (B, m) the law commands at step ``k``, N."""
        ref, vel, acc = ctx.ref_poses[k], ctx.ref_vel[k], ctx.ref_acc[k]
        a = (acc[:3] + self.position_damping * (vel[:3] - meas.v)
             + self.position_stiffness * (ref[:3] - meas.p))
        alpha = (acc[3:] + self.rotation_damping * (vel[3:] - meas.w)
                 + self.rotation_stiffness * _rotation_error(ctx.R_ref[k], meas.R))
        R, w = meas.R, meas.w
        c = R @ ctx.com_local                                      # (B, 3)
        inertia = R @ ctx.inertia_local @ np.swapaxes(R, 1, 2)     # (B, 3, 3)
        a_c = a + np.cross(alpha, c) + np.cross(w, np.cross(w, c))
        f = ctx.mass * (a_c - ctx.robot.gravity)
        Iw = np.einsum("bij,bj->bi", inertia, w)
        mom = np.einsum("bij,bj->bi", inertia, alpha) + np.cross(w, Iw) + np.cross(c, f)
        r = np.einsum("bij,mj->bmi", R, ctx.attach)                # (B, m, 3)
        vec = ctx.exits[k][None] - meas.p[:, None, :] - r
        u = vec / np.linalg.norm(vec, axis=2)[..., None]
        W = np.concatenate([np.swapaxes(u, 1, 2), np.swapaxes(np.cross(r, u), 1, 2)], axis=1)
        t = _closed_form(ctx.robot, W, np.hstack([f, mom]), np.ones(len(W), dtype=bool))
        return np.clip(t, ctx.t_min, ctx.t_max)


#: Controller names accepted by the CLI.
CONTROLLERS = {"velocity": VelocityController, "torque": TorqueController,
               "computed_torque": ComputedTorqueController}
