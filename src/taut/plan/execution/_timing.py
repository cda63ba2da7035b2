"""Timing a robot path under speed, acceleration and yaw-rate limits.

The path's samples are given (:mod:`taut.plan.execution._drives`); timing chooses each
interval's duration. Within interval ``j`` every robot moves straight at constant velocity
``d_ij / dt_j`` (``d_ij`` its displacement) and turns at a constant rate; the *speed* of
the interval, ``w_j = D_j / dt_j`` with ``D_j = max_i |d_ij|``, is that of its fastest robot
(robots far from the team's rotation centre move faster, so the limit binds on them).
Limits, per robot and interval or sample:

* speed ``|d_ij| / dt_j <= max_speed`` (``reform_speed`` on formation changes);
* yaw rate ``|dtheta_ij| / dt_j <= max_yaw_rate``;
* acceleration at sample ``j`` between intervals ``a`` and ``b``:
  ``|v_ib - v_ia| / ((dt_a + dt_b) / 2) <= max_accel`` (the velocity change over the mean
  duration of the two intervals: it holds tangential and centripetal acceleration). The
  trajectory starts and ends at rest, and a turn in place is a stop;
* yaw acceleration, the same for the yaw rates ``omega_ij = dtheta_ij / dt_j``:
  ``|omega_ib - omega_ia| / ((dt_a + dt_b) / 2) <= max_yaw_accel``, from and to rest. It
  holds when every interval has ``|omega_ij| <= max_yaw_accel dt_j / 2``, i.e.
  ``dt_j >= sqrt(2 |dtheta_ij| / max_yaw_accel)``: a speed cap on moving intervals and
  the least duration of a turn in place (which otherwise takes
  ``max_i |dtheta_i| / max_yaw_rate``).

With ``u_ij = d_ij / D_j`` and ``c`` the largest ``|u_ib - u_ia|`` at a sample, the change
of velocity is at most ``c min(w) + |w_b - w_a|`` and the mean duration at least
``S / max(w)``, ``S = (D_a + D_b) / 2``, so two sufficient conditions are used: a
curvature cap ``c max(w)^2 <= max_accel S / 2`` on both intervals, and a forward and a
backward pass bounding ``max(w) (max(w) - min(w)) <= max_accel S / 2`` (the classical
velocity-limit and acceleration passes of time-optimal path timing, here for the
discrete model; not time-optimal, within about a factor of two of it where acceleration
binds). This sufficient timing is then *tightened*: starting from every interval at its
speed and yaw-rate caps, the speeds of the intervals next to a sample whose (yaw) acceleration exceeds
its limit are lowered, in rounds (at most ``TIMING_ROUNDS``), until no sample does, by the
exact discrete definitions above (:func:`measured_limits`); the faster of the two timings
that meets every limit is kept (the sufficient one always does).
"""

from __future__ import annotations

import numpy as np

from .. import _tol

__all__ = ["time_path", "measured_limits"]


def _speed_caps(D: np.ndarray, H: np.ndarray, reform: np.ndarray, vmax: float, wmax: float,
                vreform: float, alpha: float) -> np.ndarray:
    """Per-interval speed caps (M-1,), m/s, from the speed, yaw-rate and yaw-acceleration
    limits (module docstring); ``D``: fastest robot's step, m; ``H``: largest turn, rad."""
    cap = np.where(reform, min(vmax, vreform), vmax)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.minimum(cap, np.where(H > 0, np.minimum(wmax * D / H,
                                                          D * np.sqrt(alpha / (2 * H))),
                                        np.inf))


def _caps(step: np.ndarray, dturn: np.ndarray, reform: np.ndarray, vmax: float, amax: float,
          wmax: float, vreform: float, alpha: float) -> tuple[np.ndarray, np.ndarray]:
    """Per-interval speed caps (M-1,) from the speed, yaw and curvature limits, m/s, and
    ``D`` (M-1,), m."""
    dist = np.linalg.norm(step, axis=2)
    D = dist.max(axis=1)
    H = np.abs(dturn).max(axis=1)
    cap = _speed_caps(D, H, reform, vmax, wmax, vreform, alpha)
    with np.errstate(divide="ignore", invalid="ignore"):
        u = np.where(D[:, None, None] > 0, step / D[:, None, None], 0.0)
        c = np.linalg.norm(np.diff(u, axis=0), axis=2).max(axis=1)          # (M-2,)
        S = (D[:-1] + D[1:]) / 2
        curv = np.where(c > 0, np.sqrt(amax * S / (2 * c)), np.inf)
    cap[:-1] = np.minimum(cap[:-1], curv)
    cap[1:] = np.minimum(cap[1:], curv)
    return np.where(D > 0, cap, 0.0), D


def _pass(w: np.ndarray, D: np.ndarray, amax: float) -> np.ndarray:
    """One acceleration pass (module docstring) in the direction of increasing index, from
    rest: each speed at most ``(w + sqrt(w^2 + 2 a S)) / 2`` after the previous ``w``."""
    out = w.copy()
    prev_w, prev_d = 0.0, 0.0
    for j in range(len(out)):
        if D[j] > 0:
            S = (prev_d + D[j]) / 2
            out[j] = min(out[j], (prev_w + np.sqrt(prev_w ** 2 + 2 * amax * S)) / 2)
        prev_w, prev_d = out[j], D[j]
    return out


def time_path(robots: np.ndarray, heading: np.ndarray, reform: np.ndarray, *,
              max_speed: float, max_accel: float, max_yaw_rate: float,
              reform_speed: float, max_yaw_accel: float = _tol.MAX_YAW_ACCEL) -> np.ndarray:
    """Sample times (M,), s, of the path ``robots`` (M, N, 2), m, with headings ``heading``
    (M, N), rad, under the limits (module docstring); ``reform`` (M-1,) marks formation
    changes. Consecutive samples differ in a position or a heading."""
    step = np.diff(robots, axis=0)
    dturn = np.diff(heading, axis=0)
    cap, D = _caps(step, dturn, reform, max_speed, max_accel, max_yaw_rate, reform_speed,
                   max_yaw_accel)
    w = _pass(cap, D, max_accel)
    w = _pass(w[::-1], D[::-1], max_accel)[::-1]
    H = np.abs(dturn).max(axis=1)
    turn = np.maximum(H / max_yaw_rate, np.sqrt(2 * H / max_yaw_accel))
    safe = _durations(D, w, turn)
    tight = _tighten(robots, heading, D, _speed_caps(D, H, reform, max_speed, max_yaw_rate,
                                                     reform_speed, np.inf),
                     H / max_yaw_rate, max_accel, max_yaw_accel)
    dt = tight if tight is not None and tight.sum() < safe.sum() else safe
    return np.concatenate([[0.0], np.cumsum(dt)])


def _durations(D: np.ndarray, w: np.ndarray, turn: np.ndarray) -> np.ndarray:
    """Interval durations (M-1,), s: ``D / w`` moving, ``turn`` in place."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(D > 0, D / np.where(w > 0, w, 1.0), turn)


def _accels(dt: np.ndarray, robots: np.ndarray, heading: np.ndarray
            ) -> tuple[np.ndarray, np.ndarray]:
    """Largest robot acceleration (m/s^2) and yaw acceleration (rad/s^2) at every sample
    (M,) by the discrete definitions of the module docstring, from and to rest."""
    v = np.diff(robots, axis=0) / dt[:, None, None]
    om = np.diff(heading, axis=0) / dt[:, None]
    tt = np.concatenate([[0.0], dt, [0.0]])
    mean = ((tt[:-1] + tt[1:]) / 2)[:, None]
    vv = np.concatenate([np.zeros((1, *v.shape[1:])), v, np.zeros((1, *v.shape[1:]))])
    oo = np.concatenate([np.zeros((1, om.shape[1])), om, np.zeros((1, om.shape[1]))])
    acc = np.linalg.norm(np.diff(vv, axis=0), axis=2) / mean
    return acc.max(axis=1), (np.abs(np.diff(oo, axis=0)) / mean).max(axis=1)


def _tighten(robots: np.ndarray, heading: np.ndarray, D: np.ndarray, cap: np.ndarray,
             turn: np.ndarray, amax: float, alpha: float) -> np.ndarray | None:
    """Durations (M-1,), s, from every interval at its speed cap ``cap`` (turns in place
    at ``turn``, at the yaw rate limit), the intervals next to a sample over a limit slowed
    down round by round until no sample is (module
    docstring); None if ``TIMING_ROUNDS`` rounds do not reach that."""
    dt = _durations(D, cap, turn)
    for _ in range(_tol.TIMING_ROUNDS):
        acc, yaw = _accels(dt, robots, heading)
        over = np.maximum(acc / amax, yaw / alpha)                       # (M,)
        if over.max() <= 1.0:
            return dt
        # The acceleration at a sample scales as 1 / dt^2 when both its intervals stretch.
        f = np.where(over > 1.0, np.sqrt(over) * 1.02, 1.0)
        dt = dt * np.maximum(f[:-1], f[1:])                              # per interval
    return None


def measured_limits(times: np.ndarray, robots: np.ndarray, heading: np.ndarray
                    ) -> tuple[float, float, float, float]:
    """Largest robot speed (m/s), acceleration (m/s^2, the discrete definition of the
    module docstring, starting and ending at rest), yaw rate (rad/s) and yaw acceleration
    (rad/s^2, the same definition) of a timed path."""
    dt = np.diff(times)
    if not len(dt):
        return 0.0, 0.0, 0.0, 0.0
    v = np.diff(robots, axis=0) / dt[:, None, None]                       # (M-1, N, 2)
    yaw = np.abs(np.diff(heading, axis=0)) / dt[:, None]
    acc, yaw_acc = _accels(dt, robots, heading)
    return (float(np.linalg.norm(v, axis=2).max()), float(acc.max()), float(yaw.max()),
            float(yaw_acc.max()))
