"""Results of the control simulation (frozen) and their assembly from the recorded histories
(private helpers of :mod:`taut.cdpr.control.simulate`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..._outcome import check_status
from .._tol import EVENT_TENSION_TOL, SATURATION_REL
from ..kinematics.forward import rpy_from_matrices
from .controllers import Controller, describe_controller
from .monitors import ControlEvent, episodes, tipping_margins
from ..._repr import CompactRepr

__all__ = ["ControlResult", "MonteCarloResult"]


@dataclass(frozen=True, repr=False)
class ControlResult(CompactRepr):
    """One simulated run (T recorded control instants).

    Attributes
    ----------
    times : (T,)
        s.
    poses : (T, 6)
        Platform pose (x, y, z, roll, pitch, yaw), m and rad.
    reference : (T, 6)
        Reference pose at the same instants.
    tracking_error : (T,)
        Position error ``|p - p_ref|`` of the reference point P, m.
    orientation_error : (T,)
        Rotation angle between platform and reference, rad.
    tensions : (T, m)
        Actual cable tensions, N.
    motor_torques, motor_speeds : (T, m)
        N m and rad/s (motor side).
    tipping_margin : (T, k)
        ``-m_Cj`` of eqs. 21-23 for every support-polygon edge of every mobile base from the
        actual tensions, N m (>= 0: stable).
    base_poses : (T, K, 3)
        Base poses (x, y, theta).
    events : tuple of ControlEvent
        Slack, over-tension, tipping, torque- and speed-saturation episodes.
    t_min, t_max : (m,)
        Tension limits, N.
    cable_names, edge_names : tuple of str
    controller : dict
        Controller name and gains.
    slack_time : float
        Time with at least one cable below t_min, s.
    worst_over_tension : float
        ``max(t - t_max)`` over cables and time, N (<= 0 when never exceeded).
    worst_under_tension : float
        ``max(t_min - t)``, N (<= 0 when never below).
    success : bool
    status : str
        ``"ok"``, ``"infeasible"`` (a monitor fired) or ``"diverged"``.
    message : str
    """

    times: np.ndarray
    poses: np.ndarray
    reference: np.ndarray
    tracking_error: np.ndarray
    orientation_error: np.ndarray
    tensions: np.ndarray
    motor_torques: np.ndarray
    motor_speeds: np.ndarray
    tipping_margin: np.ndarray
    base_poses: np.ndarray
    events: tuple[ControlEvent, ...]
    t_min: np.ndarray
    t_max: np.ndarray
    cable_names: tuple[str, ...]
    edge_names: tuple[str, ...]
    controller: dict[str, Any]
    slack_time: float
    worst_over_tension: float
    worst_under_tension: float
    success: bool
    status: str
    message: str

    def __post_init__(self) -> None:
        check_status(self.status)


@dataclass(frozen=True, repr=False)
class MonteCarloResult(CompactRepr):
    """B seeded runs; every array has shape (B,).

    Attributes
    ----------
    max_tracking_error, rms_tracking_error : m
    min_tension, max_tension : N
    slack_time : s
    worst_over_tension : N (``max(t - t_max)``)
    min_tipping_margin : N m
    success : bool, status : str
    controller : str
    message : str
    """

    max_tracking_error: np.ndarray
    rms_tracking_error: np.ndarray
    min_tension: np.ndarray
    max_tension: np.ndarray
    slack_time: np.ndarray
    worst_over_tension: np.ndarray
    min_tipping_margin: np.ndarray
    success: np.ndarray
    status: np.ndarray
    controller: str
    message: str


def _edge_names(robot: Any) -> tuple[str, ...]:
    out: list[str] = []
    count: dict[int, int] = {}
    for b in robot.edge_base:
        count[int(b)] = count.get(int(b), 0) + 1
        out.append(f"{robot.bases[int(b)].name} edge {count[int(b)]}")
    return tuple(out)


def _first_bad(setup: Any, xc: np.ndarray) -> int:
    lo, hi = setup.robot.bounds
    from .._tol import DIVERGENCE_MARGIN
    bad = ~np.all(np.isfinite(xc) & (xc > lo - DIVERGENCE_MARGIN) & (xc < hi + DIVERGENCE_MARGIN),
                  axis=1)
    return int(np.argmax(bad)) if bad.any() else len(xc)


def _cable_geometry(setup: Any, xc: np.ndarray, R: np.ndarray, sl: slice
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Actual exits (T, m, 3), unit vectors and P positions of plant 0."""
    pl = setup.plant
    exits = setup.geo.exits[sl] + pl.exit_offsets[0].T[None]
    att = xc[:, :, None] + R @ pl.attach_c[0]
    vec = exits - np.swapaxes(att, 1, 2)
    u = vec / np.linalg.norm(vec, axis=2, keepdims=True)
    p = xc - R @ pl.com_local[0]
    return exits, u, p


def assemble_result(setup: Any, controller: Controller, rec: dict[str, np.ndarray],
                    diverged: int) -> ControlResult:
    """Turn the recorded histories of plant 0 into a :class:`ControlResult` (the settling
    pre-roll, steps before ``setup.k0``, is dropped)."""
    robot, dyn, ctx, k0 = setup.robot, setup.dyn, setup.ctx, setup.k0
    n_all = len(setup.times)
    end = n_all
    if diverged >= 0:
        end = min(n_all, _first_bad(setup, rec["xc"][:diverged + 1]))
    end = max(end, k0 + 1)
    sl = slice(k0, end)
    n = end - k0
    times = setup.times[sl]
    xc, R, T = rec["xc"][sl], rec["R"][sl], rec["T"][sl]
    tau, speed = rec["tau"][sl], rec["speed"][sl]
    exits, u, p = _cable_geometry(setup, xc, R, sl)
    poses = np.column_stack([p, rpy_from_matrices(R)])
    ref = ctx.ref_poses[sl]
    err = np.linalg.norm(p - ref[:, :3], axis=1)
    E = ctx.R_ref[sl] @ np.swapaxes(R, 1, 2)
    ang = np.arccos(np.clip((np.einsum("tii->t", E) - 1.0) / 2.0, -1.0, 1.0))
    base_poses = setup.geo.base_poses[sl]
    tips = tipping_margins(robot, exits, u, T, base_poses)
    names = [c.name for c in robot.cables]
    enames = _edge_names(robot)
    ev = _events(times, T, tau, speed, tips, robot, dyn, names, enames)
    tol = EVENT_TENSION_TOL
    slack_time = float(np.sum(np.any(T < robot.t_min - tol, axis=1)) * ctx.dt)
    over = float(np.max(T - robot.t_max))
    under = float(np.max(robot.t_min - T))
    if diverged >= 0:
        status = "diverged"
        t_bad = float(setup.times[min(end, n_all - 1)])
        msg = (f"the plant diverged at t = {t_bad:.3f} s"
               + (" (during the settling pre-roll)" if t_bad < 0 else "")
               + " (the platform left the frame or a value became non-finite)")
    elif ev:
        status = "infeasible"
        kinds = sorted({e.kind for e in ev})
        msg = (f"{len(ev)} limit episode(s) ({', '.join(kinds)}); slack {slack_time:.3f} s, "
               f"worst over-tension {max(over, 0.0):.2f} N; max tracking error "
               f"{1e3 * float(err.max()):.2f} mm")
    else:
        status = "ok"
        msg = (f"every cable within [t_min, t_max], no tipping, no saturation; max tracking "
               f"error {1e3 * float(err.max()):.3f} mm")
    del n
    return ControlResult(times, poses, ref, err, ang, T, tau, speed, tips, base_poses,
                         tuple(ev), robot.t_min, robot.t_max, tuple(names), enames,
                         describe_controller(controller), slack_time, over, under, status == "ok",
                         status, msg)


def _events(times: np.ndarray, T: np.ndarray, tau: np.ndarray, speed: np.ndarray,
            tips: np.ndarray, robot: Any, dyn: Any, names: list[str],
            enames: tuple[str, ...]) -> list[ControlEvent]:
    """Every monitor's episodes, sorted by start time."""
    tol = EVENT_TENSION_TOL
    lim_t = np.full(robot.m, dyn.peak_torque)
    lim_w = np.full(robot.m, dyn.motor_speed_limit)
    ev = (episodes(times, T, T < robot.t_min - tol, "slack", names, robot.t_min, "min")
          + episodes(times, T, T > robot.t_max + tol, "over_tension", names, robot.t_max, "max")
          + episodes(times, -tips, tips < -tol, "tipping", list(enames),
                     np.zeros(len(enames)), "max")
          + episodes(times, np.abs(tau), np.abs(tau) >= lim_t * (1 - SATURATION_REL),
                     "torque_saturation", names, lim_t, "max")
          + episodes(times, np.abs(speed), np.abs(speed) > lim_w, "speed_saturation", names,
                     lim_w, "max"))
    # the drive's time rule: above the rated torque for at most dyn.peak_duration at a time
    lim_r = np.full(robot.m, dyn.rated_torque)
    ev += [e for e in episodes(times, np.abs(tau), np.abs(tau) > lim_r, "above_rated", names,
                               lim_r, "max") if e.end - e.start > dyn.peak_duration]
    ev.sort(key=lambda e: (e.start, e.kind, e.index))
    return ev


class summarise:
    """Running per-run reductions for :func:`taut.cdpr.monte_carlo` (no full histories)."""

    def __init__(self, setup: Any) -> None:
        self.setup = setup
        B = setup.plant.B
        self.err_max = np.zeros(B)
        self.err_sq = np.zeros(B)
        self.t_lo = np.full(B, np.inf)
        self.t_hi = np.full(B, -np.inf)
        self.slack = np.zeros(B)
        self.tip = np.full(B, np.inf)
        self.sat = np.zeros(B, dtype=bool)
        self.count = 0

    def record(self, k: int, T: np.ndarray, tau: np.ndarray, snap: tuple) -> None:
        """Fold control step ``k`` (tensions T and torques tau, (B, m), the state ``snap`` =
        (x_c, R, speeds) they belong to) into the summary."""
        ctx, robot, pl = self.setup.ctx, self.setup.robot, self.setup.plant
        if k < self.setup.k0:
            return
        xc, R = snap[0], snap[1]
        p = xc - (R @ pl.com_local[:, :, None])[:, :, 0]
        e = np.linalg.norm(p - ctx.ref_poses[k, :3], axis=1)
        self.err_max = np.fmax(self.err_max, e)
        self.err_sq += e * e
        self.t_lo = np.fmin(self.t_lo, T.min(axis=1))
        self.t_hi = np.fmax(self.t_hi, T.max(axis=1))
        self.slack += np.any(T < robot.t_min - EVENT_TENSION_TOL, axis=1)
        self.sat |= np.any(np.abs(tau) >= self.setup.dyn.peak_torque, axis=1)
        self.count += 1
        if robot.n_edges and k % 10 == 0:                       # tipping every 10 ms
            exits = self.setup.geo.exits[k][None] + np.swapaxes(pl.exit_offsets, 1, 2)
            att = np.swapaxes(xc[:, :, None] + R @ pl.attach_c, 1, 2)
            vec = exits - att
            u = vec / np.linalg.norm(vec, axis=2, keepdims=True)
            bp = np.repeat(self.setup.geo.base_poses[k][None], pl.B, axis=0)
            self.tip = np.fmin(self.tip, tipping_margins(robot, exits, u, T, bp).min(axis=1))

    def from_kernel(self, rec: np.ndarray, summ: np.ndarray, every: int) -> None:
        """Take the compiled loop's summaries (B, 6) and its every-``every``-th states
        (n_rec, B, 12 + 3m) for the tipping monitor."""
        setup, robot, pl = self.setup, self.setup.robot, self.setup.plant
        m = robot.m
        self.err_max, self.err_sq = summ[:, 0], summ[:, 1]
        self.t_lo, self.t_hi = summ[:, 2], summ[:, 3]
        self.slack, self.sat = summ[:, 4], summ[:, 5] > 0
        self.count = len(setup.times) - setup.k0
        if not robot.n_edges:
            return
        ks = np.arange(rec.shape[0]) * every
        keep = (ks >= setup.k0) & np.all(np.isfinite(rec[:, :, 0]), axis=1)
        for i in np.nonzero(keep)[0]:
            xc, R = rec[i, :, :3], rec[i, :, 3:12].reshape(-1, 3, 3)
            T = rec[i, :, 12:12 + m]
            exits = setup.geo.exits[ks[i]][None] + np.swapaxes(pl.exit_offsets, 1, 2)
            att = np.swapaxes(xc[:, :, None] + R @ pl.attach_c, 1, 2)
            vec = exits - att
            u = vec / np.linalg.norm(vec, axis=2, keepdims=True)
            bp = np.repeat(setup.geo.base_poses[ks[i]][None], pl.B, axis=0)
            self.tip = np.fmin(self.tip, tipping_margins(robot, exits, u, T, bp).min(axis=1))

    def result(self, diverged: np.ndarray, name: str) -> MonteCarloResult:
        """The :class:`MonteCarloResult`."""
        robot, dt = self.setup.robot, self.setup.ctx.dt
        over = self.t_hi - robot.t_max.max()
        ok_lim = (self.t_lo >= robot.t_min.min() - EVENT_TENSION_TOL) & (
            over <= EVENT_TENSION_TOL) & (self.tip >= -EVENT_TENSION_TOL) & ~self.sat
        status = np.where(diverged >= 0, "diverged", np.where(ok_lim, "ok", "infeasible"))
        B = len(status)
        msg = (f"{int((status == 'ok').sum())} of {B} runs kept every monitor clean, "
               f"{int((status == 'diverged').sum())} diverged")
        return MonteCarloResult(self.err_max, np.sqrt(self.err_sq / max(self.count, 1)),
                                self.t_lo, self.t_hi, self.slack * dt, over, self.tip,
                                status == "ok", status, name, msg)
