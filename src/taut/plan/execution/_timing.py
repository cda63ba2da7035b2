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
  trajectory starts and ends at rest, and a turn in place is a stop.

With ``u_ij = d_ij / D_j`` and ``c`` the largest ``|u_ib - u_ia|`` at a sample, the change
of velocity is at most ``c min(w) + |w_b - w_a|`` and the mean duration at least
``S / max(w)``, ``S = (D_a + D_b) / 2``, so two sufficient conditions are used: a
curvature cap ``c max(w)^2 <= max_accel S / 2`` on both intervals, and a forward and a
backward pass bounding ``max(w) (max(w) - min(w)) <= max_accel S / 2`` (the classical
velocity-limit and acceleration passes of time-optimal path timing, here for the
discrete model; not time-optimal, within about a factor of two of it where acceleration
binds). Turns in place take ``max_i |dtheta_i| / max_yaw_rate``.
"""

from __future__ import annotations

import numpy as np

__all__ = ["time_path", "measured_limits"]


def _caps(step: np.ndarray, dturn: np.ndarray, reform: np.ndarray, vmax: float, amax: float,
          wmax: float, vreform: float) -> tuple[np.ndarray, np.ndarray]:
    """Per-interval speed caps (M-1,) from the speed, yaw and curvature limits, m/s, and
    ``D`` (M-1,), m."""
    dist = np.linalg.norm(step, axis=2)
    D = dist.max(axis=1)
    H = np.abs(dturn).max(axis=1)
    cap = np.where(reform, min(vmax, vreform), vmax)
    with np.errstate(divide="ignore", invalid="ignore"):
        cap = np.minimum(cap, np.where(H > 0, wmax * D / H, np.inf))
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
              reform_speed: float) -> np.ndarray:
    """Sample times (M,), s, of the path ``robots`` (M, N, 2), m, with headings ``heading``
    (M, N), rad, under the limits (module docstring); ``reform`` (M-1,) marks formation
    changes. Consecutive samples differ in a position or a heading."""
    step = np.diff(robots, axis=0)
    dturn = np.diff(heading, axis=0)
    cap, D = _caps(step, dturn, reform, max_speed, max_accel, max_yaw_rate, reform_speed)
    w = _pass(cap, D, max_accel)
    w = _pass(w[::-1], D[::-1], max_accel)[::-1]
    turn = np.abs(dturn).max(axis=1) / max_yaw_rate
    with np.errstate(divide="ignore", invalid="ignore"):
        dt = np.where(D > 0, D / np.where(w > 0, w, 1.0), turn)
    return np.concatenate([[0.0], np.cumsum(dt)])


def measured_limits(times: np.ndarray, robots: np.ndarray, heading: np.ndarray
                    ) -> tuple[float, float, float]:
    """Largest robot speed (m/s), acceleration (m/s^2, the discrete definition of the
    module docstring, starting and ending at rest) and yaw rate (rad/s) of a timed path."""
    dt = np.diff(times)
    if not len(dt):
        return 0.0, 0.0, 0.0
    v = np.diff(robots, axis=0) / dt[:, None, None]                       # (M-1, N, 2)
    yaw = np.abs(np.diff(heading, axis=0)) / dt[:, None]
    rest = np.zeros((1, *v.shape[1:]))
    vv = np.concatenate([rest, v, rest])
    tt = np.concatenate([[0.0], dt, [0.0]])
    acc = np.linalg.norm(np.diff(vv, axis=0), axis=2) / ((tt[:-1] + tt[1:]) / 2)[:, None]
    return (float(np.linalg.norm(v, axis=2).max()), float(acc.max()), float(yaw.max()))
