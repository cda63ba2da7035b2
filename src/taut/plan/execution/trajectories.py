"""Per-robot trajectories of a plan (issue 28): :func:`robot_trajectories`.

A plan (:func:`taut.plan.plan`) is a rigid motion of the team in SE(2) with in-place
formation changes, sampled along its path at the team's speed; no robot can execute it
as it stands. :func:`robot_trajectories` keeps the plan's path (every robot goes where the
plan says, in the same order: the verified geometry and quasi-static model are unchanged)
and gives it the robots' headings and timing:

1. headings for the drive (:mod:`taut.plan.execution._drives`): holonomic robots turn with
   the formation; differential-drive robots face their direction of motion and stop to
   turn in place where it turns sharply;
2. timing under the limits of every robot (:mod:`taut.plan.execution._timing`): speed,
   acceleration (from rest to rest), yaw rate and yaw acceleration, and during formation changes a speed
   of at most ``reform_speed`` (default ``taut.plan._tol.REFORM_MAX_SPEED``, 5 cm/s) so
   that the object settles as the quasi-static model assumes;
3. re-verification of the executed motion by the plan's own verifier
   (:func:`taut.plan.checks.verify.verify_motion`'s engine): every robot pair
   ``sheet_margin`` inside its sheet distance, the object (the rest state followed along the
   trajectories) above the ground and what it passes over by the height safety, no robot
   collision with walls, obstacles or another robot, proved between samples.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..._outcome import check_status
from ..._repr import CompactRepr
from ..._validate import as_bounded, as_choice, require_instance
from .. import _tol
from ..checks.verify import Verification, _rigid_mask, _verify_motion
from ..result import PlanResult
from ._drives import DRIVES, drive_path
from ._timing import measured_limits, time_path

__all__ = ["RobotTrajectories", "robot_trajectories"]


@dataclass(frozen=True, eq=False, repr=False)
class RobotTrajectories(CompactRepr):
    """Per-robot trajectories of a plan (:func:`robot_trajectories`).

    Attributes
    ----------
    success : bool
        True when the plan had a path and its executed motion passed re-verification.
    status : {"ok", "unverified", "no_route", "refuted", "budget_exhausted"}
        ``unverified``: the executed motion failed re-verification (``message`` says
        why); otherwise the plan's own failure status.
    message : str
    times : ndarray, shape (T,)
        Sample times, s, strictly increasing from 0 (a turn in place is an interval
        in which no robot moves).
    poses : ndarray, shape (T, N, 3)
        Per robot ``x`` (m), ``y`` (m), heading (rad, unwrapped along time). Between
        samples robots move straight at constant speed and turn at a constant rate.
    object : ndarray, shape (T, 3)
        The object (x_o, y_o, z_o), m: the quasi-static rest state followed along the
        trajectories (forward kinematics from the first sample on).
    drive : {"holonomic", "differential"}
    duration : float
        ``times[-1]``, s.
    plan_duration : float
        The rigid plan's duration at the team's speed, s (for comparison).
    turns : int
        Turns in place (differential drives).
    peak_speed, peak_accel, peak_yaw_rate, peak_yaw_accel : float
        The largest robot speed (m/s), acceleration (m/s^2), yaw rate (rad/s) and yaw
        acceleration (rad/s^2) of the trajectories
        (:func:`taut.plan.execution._timing.measured_limits`).
    limits : tuple of float
        The limits asked for: max speed (m/s), max acceleration (m/s^2), max yaw rate
        (rad/s), max speed during formation changes (m/s).
    max_yaw_accel : float
        The yaw acceleration limit asked for, rad/s^2.
    verification : Verification or None
        The re-verification of the executed motion.
    """

    success: bool
    status: str
    message: str
    times: np.ndarray
    poses: np.ndarray
    object: np.ndarray
    drive: str
    duration: float
    plan_duration: float
    turns: int = 0
    peak_speed: float = 0.0
    peak_accel: float = 0.0
    peak_yaw_rate: float = 0.0
    limits: tuple[float, float, float, float] = (np.inf, np.inf, np.inf, np.inf)
    verification: Verification | None = None
    peak_yaw_accel: float = 0.0
    max_yaw_accel: float = _tol.MAX_YAW_ACCEL

    def __post_init__(self) -> None:
        check_status(self.status)


def robot_trajectories(result: PlanResult, *, drive: str = "holonomic", max_speed: float,
                       max_accel: float, max_yaw_rate: float,
                       reform_speed: float = _tol.REFORM_MAX_SPEED,
                       max_yaw_accel: float = _tol.MAX_YAW_ACCEL) -> RobotTrajectories:
    """One time-parameterised trajectory per robot executing ``result`` (module docstring).

    Parameters
    ----------
    result : PlanResult
        A plan of :func:`taut.plan.plan`.
    drive : {"holonomic", "differential"}
        Holonomic robots keep their heading in the formation; differential-drive robots
        face their direction of motion and turn in place where it turns by more than
        ``taut.plan._tol.TURN_IN_PLACE`` (0.1 rad) between samples.
    max_speed : float
        Largest speed of every robot, m/s, in (0, 100].
    max_accel : float
        Largest acceleration of every robot, m/s^2, in (0, 100].
    max_yaw_rate : float
        Largest turn rate of every robot, rad/s, in (0, 100].
    reform_speed : float
        Largest robot speed during a formation change, m/s, in (0, 100] (default 0.05:
        quasi-static, the object settles).
    max_yaw_accel : float
        Largest yaw acceleration of every robot, rad/s^2, in (0, 100] (default
        ``taut.plan._tol.MAX_YAW_ACCEL``, 2 rad/s^2).

    Returns
    -------
    RobotTrajectories
        ``success`` False when the plan has no path or the executed motion fails
        re-verification.

    Raises
    ------
    InvalidInputError
        A limit out of its range, an unknown drive, or ``result`` not a PlanResult.

    Examples
    --------
    >>> from taut.io import load_plan_scenario                     # doctest: +SKIP
    >>> from taut.plan import plan, robot_trajectories            # doctest: +SKIP
    >>> r = plan(load_plan_scenario("examples/plan/paper_corridor.yaml"))  # doctest: +SKIP
    >>> tr = robot_trajectories(r, drive="differential", max_speed=0.2, max_accel=0.5,
    ...                         max_yaw_rate=1.0)                 # doctest: +SKIP
    >>> tr.success, tr.poses.shape[1:], tr.peak_speed <= 0.2      # doctest: +SKIP
    (True, (4, 3), True)
    """
    require_instance(result, PlanResult, "result")
    return _robot_trajectories(result, *trajectory_options(
        drive, max_speed, max_accel, max_yaw_rate, reform_speed, max_yaw_accel))


def trajectory_options(drive: str, max_speed: float, max_accel: float, max_yaw_rate: float,
                       reform_speed: float = _tol.REFORM_MAX_SPEED,
                       max_yaw_accel: float = _tol.MAX_YAW_ACCEL
                       ) -> tuple[str, tuple[float, float, float, float], float]:
    """The one validation of :func:`robot_trajectories`' options (also what ``taut plan``
    validates before planning): the drive, the limits (m/s, m/s^2, rad/s, m/s) and the
    yaw acceleration limit (rad/s^2)."""
    lim = _tol.MAX_ROBOT_LIMIT
    return as_choice(drive, DRIVES, "drive"), (
        as_bounded(max_speed, "max_speed", lim, "m/s"),
        as_bounded(max_accel, "max_accel", lim, "m/s^2"),
        as_bounded(max_yaw_rate, "max_yaw_rate", lim, "rad/s"),
        as_bounded(reform_speed, "reform_speed", lim, "m/s")), as_bounded(
        max_yaw_accel, "max_yaw_accel", lim, "rad/s^2")


def _robot_trajectories(result: PlanResult, drive: str,
                        limits: tuple[float, float, float, float],
                        max_yaw_accel: float = _tol.MAX_YAW_ACCEL) -> RobotTrajectories:
    """:func:`robot_trajectories` on validated inputs."""
    n = result.robots.shape[1]
    if not result.success or result.scenario is None or len(result.times) < 1:
        return RobotTrajectories(False, result.status, f"no plan to execute: "
                                 f"{result.message}", np.zeros(0), np.zeros((0, n, 3)),
                                 np.zeros((0, 3)), drive, float("nan"), result.duration,
                                 limits=limits, max_yaw_accel=max_yaw_accel)
    robots, heading, obj = _distinct(result)
    sc = result.scenario
    reform = ~_rigid_mask(robots, _tol.RIGID_RTOL * sc.team.sheet.size * 10)
    path = drive_path(robots, heading, obj, reform, drive)
    vmax, amax, wmax, vref = limits
    times = time_path(path.robots, path.heading, path.reform, max_speed=vmax,
                      max_accel=amax, max_yaw_rate=wmax, reform_speed=vref,
                      max_yaw_accel=max_yaw_accel)
    poses = np.concatenate([path.robots, path.heading[..., None]], axis=2)
    check = _verify_motion(sc, path.robots, path.object, result.sheet_margin)
    speed, accel, yaw, yaw_acc = measured_limits(times, path.robots, path.heading)
    ok = check.success
    msg = (f"{drive} trajectories: {times[-1]:.2f} s ({times[-1] / result.duration:.2f}x "
           f"the rigid plan's {result.duration:.2f} s), {path.turns} turn(s) in place; "
           f"peak speed {speed:.3g} m/s, acceleration {accel:.3g} m/s^2, yaw rate "
           f"{yaw:.3g} rad/s, yaw acceleration {yaw_acc:.3g} rad/s^2; re-verified at {len(times)} samples" if ok else
           f"executed motion failed re-verification: {check.message}")
    return RobotTrajectories(ok, "ok" if ok else "unverified", msg, times, poses,
                             check.object, drive, float(times[-1]), result.duration,
                             path.turns, speed, accel, yaw, limits, check, yaw_acc,
                             max_yaw_accel)


def _distinct(result: PlanResult) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The plan's robots (T, N, 2), heading (T,) and object (T, 3) without samples that
    repeat the one before (no motion between them)."""
    r, h, o = result.robots, np.unwrap(result.heading), result.object
    same = np.all(np.abs(np.diff(r, axis=0)) <= _tol.GEOMETRY_TOL * 1e-3, axis=(1, 2))
    keep = np.concatenate([[True], ~same])
    return r[keep], h[keep], o[keep]
