"""Time-optimal motion of the platform along a pick-and-place path (FASTKIT issue 30, part 4).

The path is a polyline of waypoints (pick -> lift -> carry -> place); the platform stops at
every waypoint (gripping, releasing and the corners need it), keeps its orientation level
and follows each straight segment ``p(s) = p_k + s e`` (``|e| = 1``) with a time law
``s(t)``. The time-optimal law is found by reachability analysis on a grid of ``s``
(H. Pham and Q.-C. Pham, "A new approach to time-optimal path parameterization based on
reachability analysis", IEEE T-RO 34(3), 2018: TOPP-RA), written here for this robot
rather than through the ``toppra`` package. Choice: on a straight segment with a level
platform the path acceleration is ``a = e u`` (``u = s_dd``, no centripetal term) and the
angular velocity is zero, so the dynamic constraints at a grid point involve ``u`` alone and
the speed limits ``x = s_d^2`` alone; the admissible set of TOPP-RA's per-grid linear
programme is then the box ``[u_lo, u_hi] x [0, x_max]``, two small exact LPs per grid
point give it (cable tensions as variables, so tipping and sliding rows enter unchanged),
and the backward (controllable sets) and forward (greedy) passes are closed-form. The
``toppra`` package would have needed the same tension-polytope constraints hand-written
as its "canonical linear" form and an extra dependency for no gain.

Constraints at every grid point ``s_k`` (the platform and the carried box, ``m`` their
mass and ``c`` their first moment ``sum m_j c_j`` about P):

* dynamics with inertia, FASTKIT eq. 17 with the d'Alembert force:
  ``W t + w_g - [m a; c x a] = 0`` (angular acceleration zero), i.e.
  ``W t - u [m e; c x e] = -w_g``;
* tension limits (eq. 20), shrunk by ``tension_margin`` N on both sides (by a fraction
  of it, :data:`MARGIN_STEPS`, at grid points where the platform cannot rest with all of
  it);
* tipping of the mobile bases (eqs. 21-23) with ``tipping_margin`` N m to spare, and the
  friction rows where the model has a friction coefficient;
* winch torque: ``k_l t_i / eta + (J / k_l) |l_dd_i| + tau_s <= tau_rated`` (the
  winding-in torque of :mod:`taut.cdpr.control.dynamics`, the rated, continuous torque),
  with the cable acceleration ``l_dd_i = (u_i . e) u + (1 - (u_i . e)^2) s_d^2 / l_i``
  bounded through the speed limit (linear in ``t`` and ``u``);
* winch speed: ``|u_i . e| s_d <= k_l omega_max`` (the cable speed at the motor limit);
* an optional cap on the platform speed and acceleration (a margin fraction is accepted
  where the grid point admits ``min(ACCEL_ROOM, cap)`` each way).

A segment may have moving exits (:class:`AnchorMotion`, the active base driving along,
:mod:`taut.cdpr.mission.moving_carry`): each grid point then has its own robot, the cable
rates are taken relative to the exits, the moving base's d'Alembert force adds a term in
``u`` to its tipping and friction rows, and its speed and acceleration limits cap ``s_d``
and ``u``; the admissible set stays a box.

The acceleration of an interval ``[s_k, s_{k+1}]`` must be admissible at both ends
(TOPP-RA checks the left end only); the trajectory is then sampled at ``rate`` Hz and
smoothed by a moving average of ``smoothing`` s per segment (straight lines kept, rest at
every waypoint kept): the average of admissible accelerations over a few centimetres of
path, which the margins cover (the simulated run re-checks every limit).
Units: SI (m, s, N, N m).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Callable

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import linprog

from ..._outcome import check_status
from .._tol import REST_ACCEL_SLACK
from ..._validate import (MAX_ACCELERATION, MAX_MASS_KG, MAX_RATE_HZ, MAX_SPEED,
                          as_array, as_bounded, as_count, require_instance)
from ...errors import InvalidInputError
from ..control.dynamics import DynamicsModel
from ..control.references import Reference, waypoint_segments
from ..kinematics.cables import as_poses, cable_state, gravity_wrench, tipping_matrix
from ..model.parts import Payload
from ..model.robot import CableRobot
from ..statics.sliding import sliding_rows

__all__ = ["TimedPath", "time_optimal_path", "with_box"]

#: Default grid intervals per metre of path (at least MIN_GRID per segment): each grid
#: point costs two small LPs (~10 ms with SciPy's HiGHS); the margins cover the path between
#: grid points and the simulated run re-checks it.
GRID_PER_M = 15
MIN_GRID = 8
#: Most grid intervals a segment may ask for.
MAX_GRID = 100_000
#: Defaults chosen so the torque controller of the simulated run (1 kHz, estimated
#: states) stays within every limit (measured on the FASTKIT preset, 5 kg box, moves of
#: 3 m): tension kept off each limit, N; tipping moment kept below zero, N m; platform
#: acceleration cap, m/s^2 (the LP's box on u); platform speed cap, m/s (the winch limit
#: is 2 m/s of cable: a law riding it saturates the motors' speed under tracking error);
#: smoothing window, s (the bang-bang acceleration averaged over it, so the winch torques
#: ramp instead of stepping; it lengthens each segment by the window).
TENSION_MARGIN_N = 8.0
TIPPING_MARGIN_NM = 5.0
DEFAULT_MAX_ACCEL_MPS2 = 4.0
#: Fractions of the tension margin tried in turn at a grid point where the platform cannot
#: rest with the whole margin (near the workspace's edge the margin shrinks there only).
MARGIN_STEPS = (1.0, 0.5, 0.25, 0.0)
#: Acceleration and deceleration a grid point must admit before a margin fraction is
#: accepted there, m/s^2 (else the next, smaller fraction: a margin that leaves the platform
#: no room to brake would make it creep; the last fraction only needs rest).
ACCEL_ROOM = 1.0
DEFAULT_MAX_SPEED_MPS = 1.5
SMOOTHING_S = 0.1


@dataclass(frozen=True)
class TimedPath:
    """A time-optimal law along a polyline of waypoints.

    Attributes
    ----------
    success : bool
        Every grid point admits rest (``u = 0``, ``s_d = 0``) and a law was found.
    status : str
        ``"ok"`` or ``"infeasible"``.
    message : str
    duration : float
        s, from rest at the first waypoint to rest at the last (no dwell).
    peak_speed : float
        m/s.
    times : (T,)
        s, at ``rate`` Hz.
    positions, velocities, accelerations : (T, 3)
        m, m/s, m/s^2.
    grid_positions : (G, 3)
        Grid points of every segment (each segment's end repeated at the next start), m.
    grid_speed : (G,)
        Planned speed at the grid points, m/s.
    speed_limit : (G,)
        Largest speed the winch and speed limits allow at each grid point, m/s.
    accel_bounds : (G, 2)
        Admissible path acceleration ``[u_lo, u_hi]`` at each grid point, m/s^2.
    segment_times : (S,)
        Duration of each segment, s.
    grid_segment : (G,) int
        Segment of each grid point.
    smoothing : float
        The moving-average window applied, s.
    """

    success: bool
    status: str
    message: str
    duration: float
    peak_speed: float
    times: np.ndarray
    positions: np.ndarray
    velocities: np.ndarray
    accelerations: np.ndarray
    grid_positions: np.ndarray
    grid_speed: np.ndarray
    speed_limit: np.ndarray
    accel_bounds: np.ndarray
    segment_times: np.ndarray
    grid_segment: np.ndarray
    smoothing: float

    def __post_init__(self) -> None:
        check_status(self.status)

    def reference(self) -> Reference:
        """The law as a control reference (level orientation)."""
        z = np.zeros_like(self.positions)
        return Reference(self.times.copy(), np.hstack([self.positions, z]),
                         np.hstack([self.velocities, z]), np.hstack([self.accelerations, z]))


def with_box(robot: CableRobot, mass: float) -> CableRobot:
    """``robot`` carrying a box of ``mass`` kg in place of its payload (same centre of mass;
    inertia scaled by the mass ratio, zero when the model's payload has no mass)."""
    require_instance(robot, CableRobot, "robot")
    m = as_bounded(mass, "mass", MAX_MASS_KG, "kg", positive=False)
    p = robot.payload
    scale = m / p.mass if p.mass > 0 else 0.0
    return replace(robot, payload=Payload(m, p.com, p.inertia * scale))


@dataclass(frozen=True)
class _Limits:
    """Constants of the constraints (private)."""

    kl: float
    eta: float
    j_over_kl: float
    torque_budget: float     # rated - static friction, N m
    cable_speed: float       # m/s
    tension_margin: float
    tipping_margin: float
    max_speed: float
    max_accel: float
    smoothing: float


def _limits(dyn: DynamicsModel, tension_margin: float, tipping_margin: float,
            max_speed: float | None, max_accel: float, smoothing: float) -> _Limits:
    kl = dyn.length_per_rad
    return _Limits(kl, dyn.efficiency, dyn.rotor_inertia / kl,
                   dyn.rated_torque - dyn.friction_static, dyn.max_cable_speed,
                   tension_margin, tipping_margin,
                   np.inf if max_speed is None else max_speed, max_accel, smoothing)


@dataclass(frozen=True)
class AnchorMotion:
    """Exits moving with the path coordinate ``s`` (a base driving along with the platform,
    :mod:`taut.cdpr.mission.moving_carry`); per grid point of one straight segment.

    Attributes
    ----------
    robots : tuple of CableRobot (G,)
        The robot at each grid point (bases placed there).
    exit_rate : (m, 3)
        ``d(exit point)/ds`` of every cable, m/m (zero on a standing base).
    tip_rate : (E,)
        Edge moment per unit path acceleration ``u`` from the moving bases' d'Alembert
        forces, N m per m/s^2 (FASTKIT eqs. 21-23 with :attr:`Base.acceleration`).
    slide_rate : (F,)
        Change of the friction rows' right-hand side per unit ``u``, N per m/s^2.
    base_rate : float
        Largest ``|d(base position)/ds|``, m/m (> 0: a standing base is ``motion=None``).
    base_speed, base_accel : float
        The moving base's speed (m/s) and acceleration (m/s^2) limits.
    """

    robots: tuple[CableRobot, ...]
    exit_rate: np.ndarray
    tip_rate: np.ndarray
    slide_rate: np.ndarray
    base_rate: float
    base_speed: float
    base_accel: float


def _states(robot: CableRobot, P: np.ndarray, motion: AnchorMotion | None) -> tuple[
        np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """W (G, n, m), gravity wrench (G, n), unit vectors (G, m, 3), lengths (G, m), tipping
    rows (G, E, m), their right-hand side (G, E) and friction rows (G, F, m) at the grid
    poses ``P`` (G, 6); with ``motion`` each pose with its own robot."""
    if motion is None:
        sts = [cable_state(robot, P, validated=True)]
        robots = [robot]
    else:
        robots = list(motion.robots)
        sts = [cable_state(r, P[k:k + 1], validated=True) for k, r in enumerate(robots)]
    W, unit, L = (np.concatenate([getattr(st, f) for st in sts]) for f in ("W", "unit",
                                                                         "lengths"))
    wg = np.concatenate([gravity_wrench(r, st.R) for r, st in zip(robots, sts)])
    m = robot.m
    tip = (np.concatenate([tipping_matrix(r, st.unit) for r, st in zip(robots, sts)])
           if robot.has_tipping else np.zeros((len(P), 0, m)))
    rhs = np.stack([np.broadcast_to(-r.edge_weight_moment, (robot.n_edges,)) for r in robots])
    rhs = np.broadcast_to(rhs, (len(P), robot.n_edges))
    S = (np.concatenate([sliding_rows(r, st.unit)[0] for r, st in zip(robots, sts)])
         if robot.has_sliding else np.zeros((len(P), 0, m)))
    return W, wg, unit, L, tip, rhs, S


def _grid_bounds(robot: CableRobot, pts: np.ndarray, e: np.ndarray, lim: _Limits,
                 motion: AnchorMotion | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Speed limit (G,) m/s and admissible acceleration (G, 2) m/s^2 at grid points
    ``pts`` (G, 3) of a segment of direction ``e``; NaN bounds where rest is inadmissible.
    With ``motion`` the exits move with ``s``: the cable length rate is
    ``u_i . (e - exit_rate_i)`` per unit ``s_d`` and the moving bases' inertia loads their
    tipping and friction rows in proportion to ``u``."""
    P = np.hstack([pts, np.zeros_like(pts)])
    W, wg, unit, L, tip, tip_rhs, S = _states(robot, P, motion)
    n, m = W.shape[1], robot.m
    mc = robot.platform.mass * robot.platform.com + robot.payload.mass * robot.payload.com
    d = np.concatenate([robot.total_mass * e, np.cross(mc, e)])[:n]
    rel = e[None] - (0.0 if motion is None else motion.exit_rate)          # (m, 3)
    ue = np.einsum("gmk,mk->gm", unit, rel)                                # (G, m)
    vmax = np.minimum(lim.max_speed, lim.cable_speed / np.maximum(np.abs(ue), 1e-12).max(1))
    s_rhs = sliding_rows(robot, unit[:1])[1] if robot.has_sliding else np.zeros(0)
    tip_u, slide_u, acap = np.zeros(tip.shape[1]), np.zeros(S.shape[1]), lim.max_accel
    if motion is not None:
        tip_u, slide_u = motion.tip_rate, -motion.slide_rate
        vmax = np.minimum(vmax, motion.base_speed / motion.base_rate)
        acap = min(acap, motion.base_accel / motion.base_rate)
    rel2 = np.einsum("mk,mk->m", rel, rel)
    bounds = np.full((len(P), 2), np.nan)
    for k in range(len(P)):
        cen = (rel2 - ue[k] ** 2) * vmax[k] ** 2 / L[k]
        budget = lim.torque_budget - lim.j_over_kl * cen
        tq = np.hstack([np.eye(m) * lim.kl / lim.eta, lim.j_over_kl * ue[k][:, None]])
        A_ub = np.vstack([np.hstack([tip[k], tip_u[:, None]]),
                          np.hstack([S[k], slide_u[:, None]]), tq,
                          tq * np.r_[np.ones(m), -1.0]])
        b_ub = np.concatenate([tip_rhs[k] - lim.tipping_margin, s_rhs, budget, budget])
        bounds[k] = _accel_range(robot, A_ub, b_ub, np.hstack([W[k], -d[:, None]]), -wg[k],
                                 lim, acap)
    return vmax, bounds


def _accel_range(robot: CableRobot, A_ub: np.ndarray, b_ub: np.ndarray, A_eq: np.ndarray,
                 b_eq: np.ndarray, lim: _Limits, acap: float) -> np.ndarray:
    """``[u_lo, u_hi]`` (2,) m/s^2 over tensions and ``u`` (two LPs), with the largest
    fraction of the tension margin that leaves :data:`ACCEL_ROOM` (NaN: no rest)."""
    m = robot.m
    out = np.full(2, np.nan)
    for frac in MARGIN_STEPS:
        mg = frac * lim.tension_margin
        box = [(a + mg, b - mg) for a, b in zip(robot.t_min, robot.t_max)] + [(-acap, acap)]
        for j, sign in enumerate((1.0, -1.0)):
            c = np.zeros(m + 1)
            c[-1] = sign
            res = linprog(c, A_ub=A_ub, b_ub=b_ub, A_eq=A_eq, b_eq=b_eq, bounds=box,
                          method="highs")
            out[j] = res.x[-1] if res.status == 0 else np.nan
        room = min(ACCEL_ROOM, acap) if frac > 0 else 0.0
        if out[0] <= REST_ACCEL_SLACK - room and out[1] >= room - REST_ACCEL_SLACK:
            break
    return out


def _passes(h: float, xmax: np.ndarray, ulo: np.ndarray, uhi: np.ndarray
            ) -> tuple[np.ndarray, np.ndarray]:
    """TOPP-RA backward (controllable sets) and forward (greedy) passes on a box-shaped
    admissible set: squared speeds ``x`` (N+1,) and accelerations ``u`` (N,), rest to rest.
    ``ulo``/``uhi`` (N,) are the interval bounds, ``xmax`` (N+1,) the grid speed limits."""
    N = len(ulo)
    up = np.empty(N + 1)
    up[N] = 0.0
    for k in range(N - 1, -1, -1):
        up[k] = min(xmax[k], up[k + 1] - 2.0 * h * ulo[k])
    x = np.zeros(N + 1)
    u = np.zeros(N)
    for k in range(N):
        u[k] = max(ulo[k], min(uhi[k], (up[k + 1] - x[k]) / (2.0 * h)))
        x[k + 1] = max(0.0, x[k] + 2.0 * h * u[k])
    x[N] = 0.0                                     # rest at the end (rounding aside)
    u[N - 1] = -x[N - 1] / (2.0 * h)
    return x, u


def _sample(h: float, x: np.ndarray, u: np.ndarray, rate: float, window: int
            ) -> np.ndarray:
    """Path coordinate ``s`` (m) of one segment's law sampled at ``rate`` Hz from rest to
    rest (both ends included), averaged over a moving ``window`` of samples (a box filter:
    the acceleration becomes the window's mean, so it ramps instead of stepping)."""
    sd = np.sqrt(np.maximum(x, 0.0))
    dt = 2.0 * h / np.maximum(sd[:-1] + sd[1:], 1e-300)
    knots = np.concatenate([[0.0], np.cumsum(dt)])
    t = np.arange(int(np.ceil(knots[-1] * rate)) + 1) / rate
    k = np.clip(np.searchsorted(knots, t, side="right") - 1, 0, len(u) - 1)
    tau = t - knots[k]
    s = np.clip(h * k + sd[k] * tau + 0.5 * u[k] * tau ** 2, 0.0, h * len(u))
    s[-1] = h * len(u)
    if window < 2:
        return s
    ext = np.concatenate([s, np.full(window - 1, s[-1])])
    return np.convolve(ext, np.ones(window) / window)[:len(ext)]


def time_optimal_path(robot: CableRobot, waypoints: ArrayLike, *,
                      dynamics: DynamicsModel | None = None, grid: int | None = None,
                      tension_margin: float = TENSION_MARGIN_N,
                      tipping_margin: float = TIPPING_MARGIN_NM,
                      max_speed: float | None = DEFAULT_MAX_SPEED_MPS,
                      max_accel: float = DEFAULT_MAX_ACCEL_MPS2, smoothing: float = SMOOTHING_S,
                      rate: float = 1000.0) -> TimedPath:
    """Time-optimal motion through ``waypoints``, at rest at each (TOPP-RA, see the module
    docstring for the constraints).

    Parameters
    ----------
    robot : CableRobot
        Bases placed, stabilisers as during the motion, payload = the carried box
        (:func:`with_box`).
    waypoints : array_like (W, 3)
        Platform positions, m, W >= 2, consecutive ones distinct.
    dynamics : DynamicsModel, optional
        Winches (default the FASTKIT values).
    grid : int, optional
        Grid intervals per segment (default 15 per metre, at least 8).
    tension_margin : float
        N kept off both tension limits.
    tipping_margin : float
        N m kept below the tipping threshold of every base edge.
    max_speed : float or None
        Platform speed cap, m/s (None: only the winch speed limit).
    max_accel : float
        Platform acceleration cap, m/s^2.
    smoothing : float
        Moving-average window on the law, s (0: the raw bang-bang law, optimal on the
        grid; see the module constants).
    rate : float
        Sampling rate of the returned law, Hz.

    Returns
    -------
    TimedPath
        ``success=False`` (status ``"infeasible"``) naming the first grid point where the
        platform cannot even rest within the (shrunk) limits.

    Examples
    --------
    >>> from taut.io.cdpr_model import load_cdpr_model
    >>> from taut.cdpr import with_stabilisers
    >>> robot = with_box(with_stabilisers(load_cdpr_model("fastkit")), 2.0)
    >>> law = time_optimal_path(robot, [[-1.0, 0, 0.8], [1.0, 0, 0.8]])
    >>> law.success, bool(law.peak_speed > 1.0), bool(law.duration < 2.5)
    (True, True, True)
    """
    require_instance(robot, CableRobot, "robot")
    wp = as_array(waypoints, "waypoints")
    if wp.ndim != 2 or wp.shape[1] != 3 or wp.shape[0] < 2:
        raise InvalidInputError("waypoints", "must be at least two (x, y, z) positions, m")
    as_poses(robot, wp, "waypoints")
    dyn = DynamicsModel() if dynamics is None else dynamics
    lim = checked_limits(robot, dyn, tension_margin, tipping_margin, max_speed, max_accel,
                         smoothing)
    rate = as_bounded(rate, "rate", MAX_RATE_HZ, "Hz")
    return _plan(robot, wp, lim, None if grid is None else as_count(grid, "grid", minimum=1,
                                                                   maximum=MAX_GRID), rate)


def checked_limits(robot: CableRobot, dyn: DynamicsModel, tension_margin: float,
                   tipping_margin: float, max_speed: float | None, max_accel: float,
                   smoothing: float) -> _Limits:
    """The options of :func:`time_optimal_path` validated (fields named) into the
    constraints' constants."""
    if not isinstance(dyn, DynamicsModel):
        raise InvalidInputError("dynamics", "must be a taut.cdpr.DynamicsModel")
    tm = as_bounded(tension_margin, "tension_margin", float(robot.t_max.max()), "N",
                    positive=False)
    tpm = as_bounded(tipping_margin, "tipping_margin", 1e6, "N m", positive=False)
    vcap = None if max_speed is None else as_bounded(max_speed, "max_speed", MAX_SPEED, "m/s")
    acap = as_bounded(max_accel, "max_accel", MAX_ACCELERATION, "m/s^2")
    sm = as_bounded(smoothing, "smoothing", 10.0, "s", positive=False)
    return _limits(dyn, tm, tpm, vcap, acap, sm)


def _plan(robot: CableRobot, wp: np.ndarray, lim: _Limits, grid: int | None, rate: float,
          motion_for: Callable[[int, np.ndarray], AnchorMotion | None] | None = None
          ) -> TimedPath:
    """The engine of :func:`time_optimal_path` on validated inputs; ``motion_for(k, pts)``
    gives segment ``k``'s moving exits at its grid points ``pts`` (None: standing)."""
    out: list[list[np.ndarray]] = [[], [], [], []]
    gp, gs, gl, gb, seg_t = [], [], [], [], []
    t0 = 0.0
    for k, (length, e) in enumerate(waypoint_segments(wp)):
        N = grid or max(MIN_GRID, int(np.ceil(GRID_PER_M * length)))
        pts = wp[k] + np.linspace(0.0, length, N + 1)[:, None] * e
        motion = None if motion_for is None else motion_for(k, pts)
        vmax, ub = _grid_bounds(robot, pts, e, lim, motion)
        bad = ~((ub[:, 0] <= REST_ACCEL_SLACK) & (ub[:, 1] >= -REST_ACCEL_SLACK))
        if bad.any():
            i = int(np.argmax(bad))
            return _failed(f"the platform cannot rest at {np.round(pts[i], 3).tolist()} m "
                           f"(segment {k + 1}) within the tension, torque and tipping "
                           "limits less the margins")
        ulo = np.maximum(ub[:-1, 0], ub[1:, 0])
        uhi = np.minimum(ub[:-1, 1], ub[1:, 1])
        h = length / N
        x, u = _passes(h, vmax ** 2, ulo, uhi)
        s = _sample(h, x, u, rate, int(round(lim.smoothing * rate)))
        T = (len(s) - 1) / rate
        v = np.gradient(s, 1.0 / rate)
        a = np.gradient(v, 1.0 / rate)
        out[0].append(t0 + np.arange(len(s) - 1) / rate)
        for lst, arr in zip(out[1:], (wp[k] + s[:-1, None] * e, v[:-1, None] * e,
                                      a[:-1, None] * e)):
            lst.append(arr)
        t0 += T
        seg_t.append(T)
        gp.append(pts)
        gs.append(np.sqrt(x))
        gl.append(vmax)
        gb.append(ub)
    times = np.concatenate(out[0] + [[t0]])
    pos = np.concatenate(out[1] + [wp[-1:]])
    vel = np.concatenate(out[2] + [np.zeros((1, 3))])
    acc = np.concatenate(out[3] + [np.zeros((1, 3))])
    speed = np.linalg.norm(vel, axis=1)
    return TimedPath(True, "ok", f"time-optimal law through {len(wp)} waypoints: "
                     f"{t0:.3f} s, peak speed {speed.max():.3f} m/s", t0, float(speed.max()),
                     times, pos, vel, acc, np.concatenate(gp), np.concatenate(gs),
                     np.concatenate(gl), np.concatenate(gb), np.array(seg_t),
                     np.concatenate([np.full(len(g), k) for k, g in enumerate(gp)]),
                     lim.smoothing)


def _failed(message: str) -> TimedPath:
    z3, z1 = np.zeros((0, 3)), np.zeros(0)
    return TimedPath(False, "infeasible", message, float("nan"), float("nan"), z1, z3, z3, z3,
                     z3, z1, z1, np.zeros((0, 2)), z1, np.zeros(0, dtype=int), 0.0)


def fixed_profile_duration(law: TimedPath, speed: float = 1.0) -> float:
    """Duration of the same path on a fixed trapezoidal profile that respects the same
    constraints: on every segment cruise at ``speed`` m/s (FASTKIT's 1 m/s; lower where
    the winch speed limit is lower), accelerate and brake at the largest constant rate
    admissible at every grid point of those phases (bisection on the law's
    ``accel_bounds``), plus the same smoothing window; s (``inf`` when some segment admits
    no constant rate).

    The baseline of :func:`taut.cdpr.plan_mission`; the time-optimal law is never slower
    (up to its interval-both-ends rule)."""
    v_cap = as_bounded(speed, "speed", MAX_SPEED, "m/s")
    if not law.success:
        return float("nan")
    total = 0.0
    for k in range(len(law.segment_times)):
        sel = law.grid_segment == k
        pts, ub = law.grid_positions[sel], law.accel_bounds[sel]
        s = np.linalg.norm(pts - pts[0], axis=1)
        d = float(s[-1])
        v = min(v_cap, float(law.speed_limit[sel].min()))

        def ok(a: float) -> bool:
            up = (np.sqrt(2 * a * s) < v) & (s < d / 2)
            down = (np.sqrt(2 * a * (d - s)) < v) & (s >= d / 2)
            return bool(np.all(ub[up, 1] >= a) and np.all(ub[down, 0] <= -a))

        lo, hi = 0.0, float(np.nanmax(np.abs(ub)))
        for _ in range(40):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if ok(mid) else (lo, mid)
        if lo <= 0:
            return float("inf")
        t = d / v + v / lo if d >= v * v / lo else 2.0 * np.sqrt(d / lo)
        total += t + law.smoothing
    return total
