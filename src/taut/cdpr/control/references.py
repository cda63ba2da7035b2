"""Platform references for the control simulation: pick-and-place trajectories between
waypoints at a set speed (FASTKIT paper §2: 1 m/s platform speed) with smooth profiles, and
references from sampled poses (e.g. a CSV file, see :mod:`taut.io.cdpr_reference`).

A reference is sampled in time; velocities are ``[v; omega]`` (m/s, rad/s, world frame) and
accelerations ``[a; alpha]`` in the same order as the wrench ``[f; m]`` of FASTKIT eq. 18.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal, get_args

import numpy as np
from numpy.typing import ArrayLike

from ..._validate import (MAX_ACCELERATION, MAX_CONTROL_STEPS, MAX_DURATION_S,
                          MAX_RATE_HZ, MAX_SPEED, as_array, as_bounded, as_choice,
                          as_nonnegative, as_positive)
from ...errors import InvalidInputError, InvalidTrajectoryError
from .._tol import MAX_REFERENCE_SPEED, WAYPOINT_SAME
from ..kinematics.cables import as_poses
from ..model.robot import CableRobot
from ..._repr import CompactRepr

__all__ = ["Reference", "pick_and_place", "reference_from_samples"]

Profile = Literal["quintic", "trapezoidal"]


@dataclass(frozen=True, repr=False)
class Reference(CompactRepr):
    """A sampled platform reference.

    Attributes
    ----------
    times : (T,)
        s, strictly increasing, from 0.
    poses : (T, 6)
        ``(x, y, z, roll, pitch, yaw)``, m and rad.
    velocities : (T, 6)
        ``[v; omega]``, m/s and rad/s (world frame).
    accelerations : (T, 6)
        ``[a; alpha]``, m/s^2 and rad/s^2.
    """

    times: np.ndarray
    poses: np.ndarray
    velocities: np.ndarray
    accelerations: np.ndarray

    @property
    def duration(self) -> float:
        """s."""
        return float(self.times[-1])

    def sample(self, times: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Poses, velocities and accelerations linearly interpolated at ``times`` (held
        constant after the end)."""
        t = np.clip(times, self.times[0], self.times[-1])

        def interp(a: np.ndarray) -> np.ndarray:
            return np.column_stack([np.interp(t, self.times, a[:, j])
                                    for j in range(a.shape[1])])
        return interp(self.poses), interp(self.velocities), interp(self.accelerations)


def euler_rate_matrices(rpy: np.ndarray) -> np.ndarray:
    """``E`` (T, 3, 3) with ``omega = E (roll, pitch, yaw)_dot`` for ``R = Rz Ry Rx``."""
    r, p, y = rpy.T
    E = np.zeros((len(rpy), 3, 3))
    E[:, 0, 0] = np.cos(y) * np.cos(p)
    E[:, 1, 0] = np.sin(y) * np.cos(p)
    E[:, 2, 0] = -np.sin(p)
    E[:, 0, 1] = -np.sin(y)
    E[:, 1, 1] = np.cos(y)
    E[:, 2, 2] = 1.0
    return E


def _segment_time(d: float, speed: float, acceleration: float, profile: str) -> float:
    """Duration (s) of one segment of length ``d`` (m) of :func:`_profile`."""
    if profile == "quintic":
        return 15.0 * d / (8.0 * speed)                # peak of s_dot is 15/8 d/T
    v = min(speed, np.sqrt(d * acceleration))          # triangular when too short
    ta = v / acceleration
    return float(2 * ta + (d - v * ta) / v)


def _samples(T: float, rate: float) -> int:
    """Samples of a segment of ``T`` s at ``rate`` Hz, both ends included."""
    return max(int(np.ceil(T * rate)), 1) + 1


def _profile(d: float, speed: float, acceleration: float, profile: str,
             rate: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Path parameter s (m), s_dot, s_ddot of one segment of length d at the given rate."""
    T = _segment_time(d, speed, acceleration, profile)
    if profile == "quintic":
        tau = np.linspace(0.0, 1.0, _samples(T, rate))
        s = d * (10 * tau**3 - 15 * tau**4 + 6 * tau**5)
        sd = d / T * (30 * tau**2 - 60 * tau**3 + 30 * tau**4)
        sdd = d / T**2 * (60 * tau - 180 * tau**2 + 120 * tau**3)
        return s, sd, sdd
    v = min(speed, np.sqrt(d * acceleration))          # triangular when too short
    ta = v / acceleration
    t = np.linspace(0.0, T, _samples(T, rate))
    acc = t < ta
    dec = t > T - ta
    s = np.where(acc, 0.5 * acceleration * t**2,
                 np.where(dec, d - 0.5 * acceleration * (T - t) ** 2, 0.5 * v * ta + v * (t - ta)))
    sd = np.where(acc, acceleration * t, np.where(dec, acceleration * (T - t), v))
    sdd = np.where(acc, acceleration, np.where(dec, -acceleration, 0.0))
    return s, sd, sdd



def waypoint_segments(wp: np.ndarray) -> list[tuple[float, np.ndarray]]:
    """Length (m) and unit direction (3,) of each straight segment between consecutive
    waypoints ``wp`` (W, 3); a waypoint within ``WAYPOINT_SAME`` of the previous one is an
    input error naming it."""
    out = []
    for k in range(len(wp) - 1):
        seg = wp[k + 1] - wp[k]
        d = float(np.linalg.norm(seg))
        if d <= WAYPOINT_SAME:
            raise InvalidInputError(f"waypoints[{k + 1}]", "repeats the previous waypoint")
        out.append((d, seg / d))
    return out


def pick_and_place(robot: CableRobot, waypoints: ArrayLike, speed: float = 1.0, *,
                   profile: Profile = "quintic", acceleration: float = 3.0,
                   dwell: float = 0.3, rate: float = 1000.0) -> Reference:
    """Straight-line moves between waypoints, each at peak speed ``speed``, resting
    ``dwell`` s at every waypoint (pick, place), level orientation.

    Parameters
    ----------
    robot : CableRobot
        Used to check that every waypoint lies inside the frame box.
    waypoints : array_like (W, 3)
        Platform positions, m (W >= 2).
    speed : float
        Peak platform speed on every segment, m/s (FASTKIT: 1 m/s).
    profile : {"quintic", "trapezoidal"}
        Quintic (zero velocity and acceleration at the ends, peak speed ``speed``) or
        trapezoidal velocity (acceleration ``acceleration``, m/s^2, cruise at ``speed``).
    dwell : float
        Rest at each waypoint, s (also before the first move and after the last).
    rate : float
        Samples per second, Hz.

    Returns
    -------
    Reference

    Raises
    ------
    InfeasiblePoseError
        A waypoint outside the frame box.
    InvalidInputError
        Fewer than two waypoints, a zero-length segment, NaN, non-positive speed, rate or
        acceleration, unknown profile; ``dwell`` (or ``speed``, whichever gives more of
        them): more than :data:`taut._validate.MAX_CONTROL_STEPS` samples (more than a
        simulation may step through), refused before any is allocated (a day's dwell at
        1 kHz took ``taut cdpr simulate`` past 3 GB before its step count was refused).

    Examples
    --------
    >>> from taut.io.cdpr_model import load_cdpr_model
    >>> ref = pick_and_place(load_cdpr_model("fastkit"), [[-1, 0, 0.8], [1, 0, 0.8]])
    >>> round(float(np.abs(ref.velocities[:, 0]).max()), 3), round(ref.duration, 3)
    (1.0, 4.35)
    """
    speed = as_bounded(speed, "speed", MAX_SPEED, "m/s")
    acceleration = as_bounded(acceleration, "acceleration", MAX_ACCELERATION, "m/s^2")
    rate = as_bounded(rate, "rate", MAX_RATE_HZ, "Hz")
    dwell = as_bounded(dwell, "dwell", MAX_DURATION_S, "s", positive=False)
    as_choice(profile, get_args(Profile), "profile")
    wp = as_array(waypoints, "waypoints")
    if wp.ndim != 2 or wp.shape[1] != 3 or wp.shape[0] < 2:
        raise InvalidInputError("waypoints", "must be at least two (x, y, z) positions, m")
    as_poses(robot, wp, "waypoints")
    segments = waypoint_segments(wp)
    dt = 1.0 / rate
    n_dwell = int(round(dwell * rate))
    # the sample count in closed form, refused before any array is allocated
    moving = sum(_samples(_segment_time(d, speed, acceleration, profile), rate) - 1
                 for d, _ in segments)
    resting = n_dwell * len(wp) + 1
    if moving + resting > MAX_CONTROL_STEPS:
        raise InvalidInputError(
            "dwell" if resting > moving else "speed",
            f"the reference would hold {moving + resting:.3g} samples at {rate:g} Hz "
            f"({(moving + resting - 1) * dt:.3g} s: {resting * dt:.3g} s resting), more "
            f"than {MAX_CONTROL_STEPS}")
    pos, vel, acc = [np.repeat(wp[:1], n_dwell + 1, axis=0)], [np.zeros((n_dwell + 1, 3))], \
        [np.zeros((n_dwell + 1, 3))]
    for k, (d, e) in enumerate(segments):
        s, sd, sdd = _profile(d, speed, acceleration, profile, rate)
        pos.append(wp[k] + s[1:, None] * e)
        vel.append(sd[1:, None] * e)
        acc.append(sdd[1:, None] * e)
        pos.append(np.repeat(wp[k + 1:k + 2], n_dwell, axis=0))
        vel.append(np.zeros((n_dwell, 3)))
        acc.append(np.zeros((n_dwell, 3)))
    P, V, A = (np.concatenate(x) for x in (pos, vel, acc))
    T = len(P)
    z = np.zeros((T, 3))
    return Reference(np.arange(T) * dt, np.hstack([P, z]), np.hstack([V, z]),
                     np.hstack([A, z]))


def reference_from_samples(robot: CableRobot, times: ArrayLike, poses: ArrayLike
                           ) -> Reference:
    """A reference through sampled poses; velocities and accelerations by second-order
    finite differences (``numpy.gradient``), angular rates through the Euler-rate map.

    Parameters
    ----------
    times : array_like (T,)
        s, strictly increasing (shifted to start at 0), T >= 3.
    poses : array_like (T, 6) or (T, 3)
        m and rad.

    Raises
    ------
    InvalidTrajectoryError
        Wrong shapes, NaN, non-increasing times, or implied speeds above 20 m/s (rad/s),
        which suggests mm or degrees.
    InfeasiblePoseError
        A pose outside the frame box (the first one is named).
    """
    t = as_array(times, "times")
    if t.ndim != 1 or t.size < 3:
        raise InvalidTrajectoryError("times", "need at least 3 samples")
    if np.any(np.diff(t) <= 0):
        i = int(np.argmax(np.diff(t) <= 0)) + 1
        raise InvalidTrajectoryError(f"times[{i}]", "times must be strictly increasing")
    P = as_poses(robot, poses, "poses")
    if P.shape[0] != t.size:
        raise InvalidTrajectoryError("poses", f"{P.shape[0]} poses for {t.size} times")
    t = t - t[0]
    V = np.gradient(P, t, axis=0, edge_order=2)
    V[:, 3:] = np.einsum("tij,tj->ti", euler_rate_matrices(P[:, 3:]), V[:, 3:])
    fast = np.abs(V).max(axis=1) > MAX_REFERENCE_SPEED
    if np.any(fast):
        i = int(np.argmax(fast))
        raise InvalidTrajectoryError(f"poses[{i}]", f"implies a speed above "
                                     f"{MAX_REFERENCE_SPEED:g} m/s or rad/s at t = {t[i]:.3f} s "
                                     "(units must be m and rad)")
    A = np.gradient(V, t, axis=0, edge_order=2)
    return Reference(t, P, V, A)
