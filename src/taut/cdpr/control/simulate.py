"""Control simulation of a CDPR on fixed or mobile bases (FASTKIT paper §2.2, §3.1): a
controller at a fixed control rate drives the elastic-cable, winch and 6-DoF platform plant of
:mod:`taut.cdpr.control.plant`, with seeded model errors, optional base motion (deployment, eq. 8),
and monitors of tensions, tipping (eqs. 21-23) and motor saturation.

Entry points: :func:`simulate` (one run, full time histories) and :func:`monte_carlo` (B runs
with different seeded model errors, batched through one plant, summary numbers per run).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial
from typing import Any, Callable, Literal, Sequence, get_args

import numpy as np
from numpy.typing import ArrayLike

from ..._jit import HAVE_NUMBA, not_compiled_reason
from ..._validate import (MAX_CONTROL_STEPS, MAX_DURATION_S, MAX_RATE_HZ, as_array,
    as_bounded, as_choice, as_positive, require_instances)
from ...errors import InvalidInputError
from .._tol import DIVERGENCE_MARGIN, STABILITY_OMEGA_H, STEP_COUNT_SLACK
from ..kinematics.forward import rpy_from_matrices
from .controllers import (DESIGN_CONTROL_RATE, ControlContext, Controller, Measurement,
    TorqueController, VelocityController, check_controller)
from .dynamics import DynamicsModel
from ..model.robot import CableRobot
from .model_errors import ModelErrors, stack_perturbations
from .plant import Plant, PlantState, initial_state, stiffest_mode
from .references import Reference
from .sensing import Sensing, current_tension, estimate_pose, estimate_twist, quantise
from ._setup import BaseMotion, RefGeometry, build_context, reference_geometry
from .results import ControlResult, MonteCarloResult, assemble_result, summarise

__all__ = ["simulate", "monte_carlo", "ControlResult", "MonteCarloResult", "BaseMotion", "Backend"]

#: The control loops of :func:`simulate`: compiled (numba), plain numpy, or numba when it can.
Backend = Literal["auto", "numba", "numpy"]

_CHECK_EVERY = 50          # control steps between divergence checks
_MC_RECORD_EVERY = 10      # Monte Carlo keeps every 10th state for the tipping monitor

#: Default pre-roll of a run before t = 0, s (see :func:`simulate`'s ``settle``).
DEFAULT_SETTLE = 1.0

#: Most integration substeps per control step (1 MHz integration at a 1 kHz controller).
MAX_SUBSTEPS = 1000


@dataclass
class _Setup:
    robot: CableRobot
    dyn: DynamicsModel
    times: np.ndarray
    ctx: ControlContext
    geo: RefGeometry
    plant: Plant
    state: PlantState
    h: float
    substeps: int
    k0: int                 # first recorded step (after the settling pre-roll)
    sensing: Sensing
    quantum: float          # encoder resolution, m of cable per count
    delay: int              # latency, control periods
    noise: np.ndarray       # (n, B, m) tension noise, N, or (1, 1, m) zeros
    T_last: np.ndarray      # (B, m) tensions at the last substep, N
    tau_last: np.ndarray    # (B, m) motor torques at the last substep, N m
    est_p: np.ndarray       # (B, 3) pose estimate of P, m
    est_R: np.ndarray       # (B, 3, 3)
    est_v: np.ndarray       # (B, 3) filtered twist estimate minus the reference, m/s
    est_w: np.ndarray       # (B, 3) rad/s
    filter_gain: float      # per-step gain of the twist filter
    speed_last: np.ndarray  # (B, m) motor speeds at the previous control step, rad/s
    T_est: np.ndarray       # (B, m) filtered current-based tension estimate, N


def _prepare(robot: CableRobot, reference: Reference, controller: Controller,
             model_errors: Any, base_motion: Any, control_rate: float, duration: Any,
             dynamics: Any, substeps: int, external_wrench: Any, settle: Any,
             sensing: Any = None) -> _Setup:
    """Validate the inputs, precompute the nominal context, build and initialise the plant."""
    if not isinstance(robot, CableRobot):
        raise InvalidInputError("robot", "must be a taut.cdpr.CableRobot")
    if not isinstance(reference, Reference):
        raise InvalidInputError("reference", "must be a taut.cdpr.Reference (see "
                                             "pick_and_place, reference_from_samples)")
    check_controller(controller)
    if robot.dof != 6:
        raise InvalidInputError("robot", "the dynamics need a 6-DoF platform")
    sens = Sensing() if sensing is None else sensing
    if not isinstance(sens, Sensing):
        raise InvalidInputError("sensing", "must be a taut.cdpr.Sensing")
    if getattr(controller, "tension_gain", 0.0) > 0.0 and sens.tension == "none":
        raise InvalidInputError("sensing.tension", "VelocityController(tension_gain > 0) "
                                "needs a tension measurement: 'current' or 'load_cell'")
    dyn = DynamicsModel() if dynamics is None else dynamics
    if not isinstance(dyn, DynamicsModel):
        raise InvalidInputError("dynamics", "must be a taut.cdpr.DynamicsModel")
    rate = as_bounded(control_rate, "control_rate", MAX_RATE_HZ, "Hz")
    if (isinstance(substeps, bool) or not isinstance(substeps, (int, float, np.number))
            or not np.isfinite(substeps) or int(substeps) != substeps or substeps < 1):
        raise InvalidInputError("substeps", f"must be a positive integer, got {substeps!r}")
    if substeps > MAX_SUBSTEPS:
        raise InvalidInputError("substeps", f"{substeps:g} exceeds the accepted range "
                                            f"{MAX_SUBSTEPS} substeps per control step")
    dur = reference.duration if duration is None else \
        as_bounded(duration, "duration", MAX_DURATION_S, "s")
    if dur * rate > MAX_CONTROL_STEPS:
        raise InvalidInputError("duration", f"{dur:g} s at {rate:g} Hz is {dur * rate:.3g} "
                                f"control steps, more than {MAX_CONTROL_STEPS}")
    settle_s = as_bounded(settle, "settle", MAX_DURATION_S, "s", positive=False)
    if (dur + settle_s) * rate > MAX_CONTROL_STEPS:
        raise InvalidInputError("settle", f"{settle_s:g} s at {rate:g} Hz makes "
                                f"{(dur + settle_s) * rate:.3g} control steps with the "
                                f"{dur:g} s run, more than {MAX_CONTROL_STEPS}")
    dt = 1.0 / rate
    n = max(int(np.ceil(dur * rate - STEP_COUNT_SLACK)), 1)
    k0 = int(round(settle_s * rate))
    times = (np.arange(n + 1 + k0) - k0) * dt
    geo = reference_geometry(robot, times, base_motion)
    ctx = build_context(robot, dyn, times, reference, geo, dt)
    perts = stack_perturbations(robot, model_errors)
    if external_wrench is not None:
        external_wrench = as_array(external_wrench, "external_wrench", shape=(6,))
    plant = Plant(robot, dyn, perts, external_wrench)
    ex0 = geo.exits[0].T
    state = initial_state(plant, ex0, _parked_lengths(plant, ex0, ctx), ctx.ref_poses[0])
    h = dt / int(substeps)
    w_max = stiffest_mode(plant, state, ex0)
    w_drive = float(np.max(plant.eta * dyn.drive_speed_gain / plant.rotor_inertia))  # drive pole
    w_max = max(w_max, w_drive) if controller.mode == "speed" else w_max
    if w_max * h > STABILITY_OMEGA_H:
        need = w_max / STABILITY_OMEGA_H / int(substeps)
        raise InvalidInputError("control_rate", f"{rate:g} Hz with {int(substeps)} substep(s) "
                                f"is too slow for the semi-implicit Euler integrator: the "
                                f"stiffest mode ({w_max:.0f} rad/s) needs a rate of at least "
                                f"{need:.0f} Hz (or more substeps)")
    B, m = plant.B, robot.m
    noise = (np.random.default_rng(int(sens.seed)).normal(0.0, sens.tension_noise,
                                                          (len(times), B, m))
             if sens.tension_noise > 0.0 else np.zeros((1, 1, m)))
    T0, _, _ = plant.cables(state, ex0, np.zeros_like(ex0))
    R0 = np.repeat(ctx.R_ref[:1], B, axis=0)
    return _Setup(robot, dyn, times, ctx, geo, plant, state, h, int(substeps), k0, sens,
                  sens.quantum(dyn.length_per_rad), sens.delay_steps(rate), noise, T0,
                  state.integ.copy(), np.repeat(ctx.ref_poses[:1, :3], B, axis=0), R0,
                  np.zeros((B, 3)), np.zeros((B, 3)), sens.filter_gain(rate),
                  state.speed.copy(), T0.copy())


def _parked_lengths(plant: Plant, exits: np.ndarray, ctx: ControlContext) -> np.ndarray:
    """Unstretched lengths (B, m) of each plant parked at the reference start pose with the
    reference tensions on its *actual* geometry (tension-based homing): the run starts near
    equilibrium whatever the exit errors, and the geometry errors act through the control
    law (the velocity law drives the encoder lengths to its nominal set-points)."""
    from ..kinematics.cables import rotation_matrices
    R0 = rotation_matrices(ctx.ref_poses[:1, 3:])[0]
    att = ctx.ref_poses[0, :3, None] + R0 @ plant.robot.attach_local.T      # (3, m)
    L = np.linalg.norm(exits[None] + plant.exit_offsets - att[None], axis=1)  # (B, m)
    return plant.dyn.unstretched_length(L, ctx.tensions[0], plant.routing)


def _measure(setup: _Setup, k: int) -> Measurement:
    """The controller's measurements at step ``k`` (see :class:`Sensing`)."""
    pl, s, sens, ctx, d = setup.plant, setup.state, setup.sensing, setup.ctx, setup.dyn
    L0m = quantise(s.L0 + pl.length_offsets, setup.quantum)
    m_ = _measure_at(setup, k, pl, s, sens, ctx, d, L0m)
    setup.speed_last = s.speed.copy()
    return m_


def _measure_at(setup: _Setup, k: int, pl: Plant, s: PlantState, sens: Sensing,
                ctx: ControlContext, d: DynamicsModel, L0m: np.ndarray) -> Measurement:
    from .._tol import SENSING_FK_FIRST_ITERATIONS, SENSING_FK_ITERATIONS
    if sens.tension == "load_cell":
        tension = setup.T_last + setup.noise[k % len(setup.noise)]
    elif sens.tension == "current":
        acc = (s.speed - setup.speed_last) / ctx.dt if k > 0 else np.zeros_like(s.speed)
        raw = current_tension(d, setup.tau_last, s.speed, acc)
        a = 1.0 if k == 0 else setup.filter_gain
        setup.T_est = setup.T_est + a * (raw - setup.T_est)
        tension = setup.T_est + setup.noise[k % len(setup.noise)]
    else:
        tension = np.full_like(L0m, np.nan)
    if sens.ideal_pose:
        p, v = pl.pose_of(s)
        w = (s.R @ s.wb[:, :, None])[:, :, 0]
        return Measurement(p, s.R, v, w, L0m, s.speed, tension)
    t_known = setup.T_last + setup.noise[k % len(setup.noise)] \
        if sens.tension == "load_cell" else ctx.tensions[k][None]
    lengths = d.stretched_length(L0m, t_known, d.routing(L0m.shape[1]))
    it = SENSING_FK_FIRST_ITERATIONS if k == 0 else SENSING_FK_ITERATIONS
    setup.est_p, setup.est_R = estimate_pose(setup.est_p, setup.est_R, ctx.exits[k],
                                             ctx.attach, lengths, it)
    v, w = estimate_twist(setup.est_p, setup.est_R, ctx.exits[k], ctx.exit_vel[k], ctx.attach,
                          d.length_per_rad * s.speed)
    a = 1.0 if k == 0 else setup.filter_gain     # the filter acts on the deviation from
    vr, wr = ctx.ref_vel[k, :3], ctx.ref_vel[k, 3:]  # the reference twist (no lag on it)
    setup.est_v = setup.est_v + a * (v - vr - setup.est_v)
    setup.est_w = setup.est_w + a * (w - wr - setup.est_w)
    return Measurement(setup.est_p, setup.est_R, vr + setup.est_v, wr + setup.est_w, L0m,
                       s.speed, tension)


#: Advances every plant by one control period under a command: ``(cmd, k)`` -> tensions and
#: motor torques (B, m) of the first sub-step (recorded) and of the last (the sensors').
Advance = Callable[[np.ndarray, int], tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]


def _loop(setup: _Setup, controller: Controller,
          record: Callable[..., None],
          progress: Callable[[int, int], None] | None,
          compiled: bool = False) -> np.ndarray:
    """Run the control loop with the controller in Python, the sensing and the plant in
    numpy or (``compiled``) numba; returns the first diverged step per plant (-1 if none)."""
    pl, s = setup.plant, setup.state
    if compiled:
        step, measure = _compiled_advance(setup, controller.mode), _compiled_measure(setup)
    else:
        step, measure = _numpy_advance(setup, controller.mode), partial(_measure, setup)
    n = len(setup.times)
    lo, hi = setup.robot.bounds[0] - DIVERGENCE_MARGIN, setup.robot.bounds[1] + DIVERGENCE_MARGIN
    diverged = np.full(pl.B, -1)
    with np.errstate(all="ignore"):
        buf: list[np.ndarray] = []
        for k in range(n):
            buf.append(np.asarray(controller.command(setup.ctx, k, measure(k)), dtype=float))
            if k == 0:
                _check_command(buf[0], (pl.B, setup.robot.m))
                buf = buf * (setup.delay + 1)
            cmd = buf.pop(0)                   # computed setup.delay control periods ago
            snap = (s.xc.copy(), s.R.copy(), s.speed.copy())
            T0, tau0, setup.T_last, setup.tau_last = step(cmd, k)
            record(k, T0, tau0, snap)
            if k % _CHECK_EVERY == _CHECK_EVERY - 1 or k == n - 1:
                bad = ~np.all(np.isfinite(s.xc) & (s.xc > lo) & (s.xc < hi), axis=1) \
                    | ~np.all(np.isfinite(s.L0), axis=1)
                new = bad & (diverged < 0)
                diverged[new] = k
                if np.all(diverged >= 0):
                    break
            if progress is not None and k % 200 == 0:
                progress(k, n)
    if progress is not None:
        progress(n, n)
    return diverged


def _check_command(cmd: np.ndarray, shape: tuple[int, int]) -> None:
    """A controller's first command must broadcast to (B, m) (plants, cables)."""
    try:
        np.broadcast_to(cmd, shape)
    except ValueError:
        raise InvalidInputError("controller.command", f"returned shape {cmd.shape}; expected "
                                f"(B, m) = {shape} (plants, cables)") from None


def _numpy_advance(setup: _Setup, mode: str) -> Advance:
    """The numpy plant: ``substeps`` of :meth:`Plant.step` per control period."""
    pl, s, h = setup.plant, setup.state, setup.h
    exits_T = np.swapaxes(setup.geo.exits, 1, 2)
    vel_T = np.swapaxes(setup.geo.exit_vel, 1, 2)

    def advance(cmd: np.ndarray, k: int) -> tuple[np.ndarray, ...]:
        for j in range(setup.substeps):
            tau = pl.motor_torque(s, mode, cmd, h)
            T = pl.step(s, h, exits_T[k], vel_T[k], tau)
            if j == 0:
                T0, tau0 = T, tau
        return T0, tau0, T, tau
    return advance  # type: ignore[return-value]


def _compiled_advance(setup: _Setup, mode: str) -> Advance:
    """The compiled plant (:func:`taut.cdpr.control._kernel.plant_steps`): the same model as
    :func:`_numpy_advance`, for controllers that run in Python on the numba backend."""
    from ._kernel import plant_steps
    pl, s, C = setup.plant, setup.state, np.ascontiguousarray
    dyn, winch = _kernel_plant_arrays(setup)
    exits_T = C(np.swapaxes(setup.geo.exits, 1, 2))
    vel_T = C(np.swapaxes(setup.geo.exit_vel, 1, 2))
    body = (C(pl.exit_offsets), C(winch), C(pl.mass), C(pl.inertia), C(pl.inertia_inv),
            C(pl.attach_c), C(pl.g), C(np.r_[pl.f_ext, pl.m_ext]))
    code, shape = (1 if mode == "torque" else 0), (pl.B, setup.robot.m)

    def advance(cmd: np.ndarray, k: int) -> tuple[np.ndarray, ...]:
        out = [np.empty(shape) for _ in range(4)]
        plant_steps(code, C(np.broadcast_to(cmd, shape), dtype=float), dyn, exits_T[k],
                    vel_T[k], *body, s.xc, s.vc, s.R, s.wb, s.L0, s.speed, s.integ,
                    float(setup.h), int(setup.substeps), *out)
        return tuple(out)
    return advance  # type: ignore[return-value]


def _compiled_measure(setup: _Setup) -> Callable[[int], Measurement]:
    """The compiled sensing (:func:`taut.cdpr.control._kernel.measure`): the same as
    :func:`_measure`, for controllers that run in Python on the numba backend."""
    from ._kernel import measure
    pl, s, ctx, C = setup.plant, setup.state, setup.ctx, np.ascontiguousarray
    dyn, sv = _kernel_plant_arrays(setup)[0], _sensing_array(setup)
    B, m = pl.B, setup.robot.m
    fixed = (C(pl.com_local), s.L0, C(pl.length_offsets), s.speed, C(setup.noise),
             C(ctx.ref_poses), C(ctx.ref_vel), C(ctx.tensions),
             C(np.swapaxes(setup.geo.exits, 1, 2)), C(np.swapaxes(setup.geo.exit_vel, 1, 2)),
             C(ctx.attach.T))

    def measured(k: int) -> Measurement:
        P, V, W, Rm = np.empty((B, 3)), np.empty((B, 3)), np.empty((B, 3)), np.empty((B, 3, 3))
        L0m, T = np.empty((B, m)), np.empty((B, m))
        measure(k, sv, dyn, s.xc, s.vc, s.R, s.wb, *fixed, setup.T_last,
                setup.tau_last, setup.speed_last, setup.T_est, setup.est_p, setup.est_R,
                setup.est_v, setup.est_w, float(ctx.dt), P, Rm, V, W, L0m, T)
        return Measurement(P, Rm, V, W, L0m, s.speed, T)
    return measured


def _sensing_array(setup: _Setup) -> np.ndarray:
    """:class:`Sensing` in the layout of :func:`taut.cdpr.control._kernel.run` (``sens``)."""
    from .._tol import SENSING_FK_FIRST_ITERATIONS, SENSING_FK_ITERATIONS
    sens = setup.sensing
    return np.array([float(sens.ideal_pose), setup.quantum,
                     {"none": 0.0, "current": 1.0, "load_cell": 2.0}[sens.tension],
                     setup.filter_gain, float(setup.delay), float(SENSING_FK_ITERATIONS),
                     float(SENSING_FK_FIRST_ITERATIONS)])


def _kernel_plant_arrays(setup: _Setup) -> tuple[np.ndarray, np.ndarray]:
    """The nominal drive and cable constants ``dyn`` and the per-plant winch values
    ``winch`` (5, B, m) in the layout of :func:`taut.cdpr.control._kernel.run`."""
    from .._tol import FRICTION_SPEED_WIDTH
    d, pl, m = setup.dyn, setup.plant, setup.robot.m
    eta_b = d.efficiency if d.backdrive_efficiency is None else d.backdrive_efficiency
    dyn = np.array([d.cable_stiffness, d.cable_damping, d.length_per_rad, d.efficiency,
                    d.peak_torque, d.motor_speed_limit, d.rotor_inertia,
                    d.friction_static, d.friction_coulomb, d.friction_viscous,
                    d.stribeck_speed, FRICTION_SPEED_WIDTH, d.drive_speed_gain,
                    d.drive_integral_gain, eta_b, *d.routing(m)])
    winch = np.stack([pl.eta, pl.eta_b, pl.friction_scale * np.ones_like(pl.eta),
                      pl.rotor_inertia, pl.routing])
    return dyn, winch


def _backend(backend: str, controller: Controller) -> str:
    """Resolve ``backend`` to "numba" (the compiled loop: built-in velocity and torque laws),
    "numba_plant" (the controller in Python, the plant compiled: any other controller) or
    "numpy" (numba as set up by :mod:`taut._jit`)."""
    as_choice(backend, get_args(Backend), "backend")
    if backend == "numpy" or (backend == "auto" and not HAVE_NUMBA):
        return "numpy"
    if not HAVE_NUMBA:
        raise InvalidInputError("backend", not_compiled_reason())
    return "numba" if type(controller) in (VelocityController, TorqueController) \
        else "numba_plant"


def _loop_numba(setup: _Setup, controller: Controller, rec_every: int, n_rec_plants: int
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Run the compiled loop; returns records (n/rec_every, Brec, 12 + 3m), per-plant
    summaries (B, 6) and the first diverged step per plant (-1 if none)."""
    from ._kernel import run
    pl, s, ctx, geo = setup.plant, setup.state, setup.ctx, setup.geo
    n, m, B = len(setup.times), setup.robot.m, pl.B
    if isinstance(controller, VelocityController):
        mode, gains = 0, np.array([controller.length_gain, controller.tension_gain, 0, 0, 0],
                                  float)
    else:
        c = controller
        mode, gains = 1, np.array([c.position_stiffness, c.position_damping,  # type: ignore[attr-defined]
                                   c.rotation_stiffness, c.rotation_damping,  # type: ignore[attr-defined]
                                   c.joint_damping], float)  # type: ignore[attr-defined]
    dyn, winch = _kernel_plant_arrays(setup)
    sv = _sensing_array(setup)
    rec = np.full(((n + rec_every - 1) // rec_every, n_rec_plants, 12 + 3 * m), np.nan)
    summ = np.zeros((B, 6))
    summ[:, 2], summ[:, 3] = np.inf, -np.inf
    diverged = np.full(B, -1, dtype=np.int64)
    lo = setup.robot.bounds[0] - DIVERGENCE_MARGIN
    hi = setup.robot.bounds[1] + DIVERGENCE_MARGIN
    C = np.ascontiguousarray
    with np.errstate(all="ignore"):
        run(mode, gains, dyn, C(ctx.L0), C(ctx.L0_dot), C(ctx.L0_ddot), C(ctx.ref_poses),
            C(ctx.ref_vel), C(ctx.R_ref), C(ctx.tensions), C(ctx.W_pinv), C(ctx.com_skew_T),
            C(ctx.inertia), float(ctx.mass), C(ctx.t_min), C(ctx.t_max),
            C(np.swapaxes(geo.exits, 1, 2)), C(np.swapaxes(geo.exit_vel, 1, 2)),
            C(pl.exit_offsets), C(pl.length_offsets), C(winch),
            C(pl.mass), C(pl.inertia), C(pl.inertia_inv), C(pl.attach_c), C(pl.com_local),
            C(pl.g), C(np.r_[pl.f_ext, pl.m_ext]), s.xc, s.vc, s.R, s.wb, s.L0, s.speed,
            s.integ, float(setup.h), int(setup.substeps), lo, hi, _CHECK_EVERY, rec,
            int(rec_every), summ, int(setup.k0), diverged, sv, C(setup.noise),
            C(ctx.attach.T), setup.est_p, setup.est_R, setup.est_v, setup.est_w,
            setup.T_last, setup.tau_last, np.zeros((setup.delay + 1, B, m)),
            setup.speed_last, setup.T_est, float(ctx.dt))
    return rec, summ, diverged


def simulate(robot: CableRobot, reference: Reference, controller: Controller, *,
             model_errors: ModelErrors | None = None, base_motion: BaseMotion | None = None,
             control_rate: float = DESIGN_CONTROL_RATE, duration: float | None = None,
             dynamics: DynamicsModel | None = None, substeps: int = 1,
             external_wrench: ArrayLike | None = None, settle: float = DEFAULT_SETTLE,
             backend: Backend = "auto", sensing: Sensing | None = None,
             progress: Callable[[int, int], None] | None = None) -> ControlResult:
    """Simulate a controller driving the cable robot along a reference.

    Parameters
    ----------
    robot : CableRobot
        Nominal model (the controller's); 6-DoF platform.
    reference : Reference
        Platform reference, e.g. :func:`taut.cdpr.pick_and_place`.
    controller : Controller
        :class:`~taut.cdpr.VelocityController`, :class:`~taut.cdpr.TorqueController`,
        :class:`~taut.cdpr.ComputedTorqueController` or any object following the controller
        protocol (:mod:`taut.cdpr.control.controllers`).
    model_errors : ModelErrors, optional
        Seeded errors of the plant against the nominal model (default none).
    base_motion : BaseMotion, optional
        Poses of the bases over time (deployment in task mode, eq. 8).
    control_rate : float
        Hz (default 1 kHz).
    duration : float, optional
        s (default the reference's duration).
    dynamics : DynamicsModel, optional
        Cables and winches (default the FASTKIT values).
    substeps : int
        Integrator steps per control period.
    external_wrench : (6,), optional
        Constant extra wrench on the plant (N, N m about the centre of mass), not known to
        the controller.
    settle : float
        Pre-roll, s: before t = 0 the controller holds the reference's start pose for this
        long (not recorded), so the run starts from the closed-loop rest state of this
        controller and plant rather than from the switch-on transient. The plant starts the
        pre-roll at rest in elastic equilibrium with the nominal unstretched lengths.
    backend : {"auto", "numba", "numpy"}
        "numba" (needs numba): the compiled loop for the built-in velocity and torque laws;
        any other controller runs in Python once per control step with the plant compiled.
        "numpy": everything in numpy. "auto" picks numba when it can. Every controller runs
        on both and they compute the same model.
    sensing : Sensing, optional
        What the controller measures (default ``Sensing()``: encoders and drive torques,
        pose estimated from the encoders on the nominal model; ``Sensing(ideal_pose=True)``
        for the true pose).
    progress : callable(done, total), optional
        Called during the run (controllers running in Python) or at its end (the compiled
        loop).

    Returns
    -------
    ControlResult
        ``status`` ``"ok"`` (every monitor clean), ``"infeasible"`` (limits violated: see
        ``events``) or ``"diverged"`` (the message names the time; arrays end there).

    Raises
    ------
    InvalidInputError, InfeasiblePoseError
        Bad input: wrong types, NaN, non-positive rates, a control rate the integrator cannot
        keep stable (the message gives the minimum), a reference leaving the wrench-feasible
        workspace (first time and pose named).

    Examples
    --------
    >>> from taut.io.cdpr_model import load_cdpr_model
    >>> from taut.cdpr import pick_and_place, VelocityController, with_stabilisers
    >>> robot = with_stabilisers(load_cdpr_model("fastkit"))  # task mode: stabilisers down
    >>> ref = pick_and_place(robot, [[-0.5, 0, 1.0], [0.5, 0, 1.0]], dwell=0.1)
    >>> run = simulate(robot, ref, VelocityController())
    >>> run.success, bool(run.tracking_error.max() < 1e-3)
    (True, True)
    """
    if model_errors is not None and not isinstance(model_errors, ModelErrors):
        raise InvalidInputError("model_errors", "must be a taut.cdpr.ModelErrors")
    used = _backend(backend, controller)
    setup = _prepare(robot, reference, controller, model_errors, base_motion, control_rate,
                     duration, dynamics, substeps, external_wrench, settle, sensing)
    n, m = len(setup.times), robot.m
    if used == "numba":
        rec_n, _, div_n = _loop_numba(setup, controller, 1, 1)
        r0 = rec_n[:, 0]
        hist = {"xc": r0[:, :3], "R": r0[:, 3:12].reshape(-1, 3, 3), "T": r0[:, 12:12 + m],
                "tau": r0[:, 12 + m:12 + 2 * m], "speed": r0[:, 12 + 2 * m:]}
        if progress is not None:
            progress(n, n)
        return assemble_result(setup, controller, hist, int(div_n[0]))
    return _run_python(setup, controller, progress, used == "numba_plant")


def _run_python(setup: _Setup, controller: Controller,
                progress: Callable[[int, int], None] | None, compiled: bool) -> ControlResult:
    """One run of the control loop with the controller in Python on a prepared set-up
    (plant 0 recorded), sensing and plant compiled or in numpy."""
    n, m = len(setup.times), setup.robot.m
    rec = {"xc": np.empty((n, 3)), "R": np.empty((n, 3, 3)), "T": np.empty((n, m)),
           "tau": np.empty((n, m)), "speed": np.empty((n, m))}

    def record(k: int, T: np.ndarray, tau: np.ndarray, snap: tuple) -> None:
        rec["xc"][k], rec["R"][k], rec["T"][k] = snap[0][0], snap[1][0], T[0]
        rec["tau"][k], rec["speed"][k] = tau[0], snap[2][0]

    div = int(_loop(setup, controller, record, progress, compiled)[0])
    return assemble_result(setup, controller, rec, div)


def monte_carlo(robot: CableRobot, reference: Reference, controller: Controller,
                model_errors: Sequence[ModelErrors], *, base_motion: BaseMotion | None = None,
                control_rate: float = DESIGN_CONTROL_RATE, duration: float | None = None,
                dynamics: DynamicsModel | None = None, substeps: int = 1,
                settle: float = DEFAULT_SETTLE, backend: Backend = "auto", sensing: Sensing | None = None,
                progress: Callable[[int, int], None] | None = None) -> MonteCarloResult:
    """Run one simulation per entry of ``model_errors``, batched through one plant (the
    per-step work is vectorised over runs), keeping summary numbers per run.

    Returns
    -------
    MonteCarloResult
        Arrays (B,) of worst tracking error, tension extremes, slack time, over-tension,
        minimum tipping margin and per-run success/status.
    """
    errs = list(require_instances(model_errors, ModelErrors, "model_errors"))
    if not errs:
        raise InvalidInputError("model_errors", "needs at least one ModelErrors")
    used = _backend(backend, controller)
    setup = _prepare(robot, reference, controller, errs, base_motion, control_rate,
                     duration, dynamics, substeps, None, settle, sensing)
    acc = summarise(setup)
    if used == "numba":
        rec, summ, div = _loop_numba(setup, controller, _MC_RECORD_EVERY, len(errs))
        acc.from_kernel(rec, summ, _MC_RECORD_EVERY)
        if progress is not None:
            progress(len(setup.times), len(setup.times))
    else:
        div = _loop(setup, controller, acc.record, progress, used == "numba_plant")
    return acc.result(div, controller.name)

