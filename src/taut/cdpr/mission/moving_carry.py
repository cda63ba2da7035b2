"""The active base driving *while* the platform carries a box (issue 30, part 4: FASTKIT's
kinematic redundancy in task mode, which the paper's conclusion leaves open).

What moving means physically (documented choice; the paper gives no model):

* the active base drives on its wheels, so its stabilisers are up for the whole carry
  (its tipping polygon is the wheel footprint; the passive base keeps its stabilisers
  down); it drives along its own x axis (parallel to the shelf face, in the cable plane:
  the direction :func:`~taut.cdpr.mission._reposition.shifted` uses), from offset ``a0``
  to ``a1`` m from the site's placement;
* it moves in step with the platform: on the carry's across segment (the last straight
  segment, length ``L``) its offset is ``a(s) = a0 + (a1 - a0) s / L`` with ``s`` the
  platform's path coordinate, so its velocity is ``delta s_d`` and its acceleration
  ``delta s_dd`` along its x axis (``delta = (a1 - a0) / L``), standing at ``a0`` on the
  earlier segments (the lift);
* the exits move with it: a cable's length rate is ``u_i . (e - exit_rate_i) s_d`` (its
  winch speed and the winding torque's cable acceleration use that relative direction);
* the base's d'Alembert force ``-m_b delta s_dd`` at its centre of mass loads its tipping
  edges and its friction (:attr:`taut.cdpr.Base.acceleration`), linear in ``s_dd``;
* the base's own limits: ``|delta s_d| <=`` ``base_speed`` (FASTKIT eq. 10: 0.2 m/s in
  task mode) and ``|delta s_dd| <=`` ``base_accel``.

The time law is the TOPP-RA of :mod:`taut.cdpr.mission.timing` with those constraints
(:class:`~taut.cdpr.mission.timing.AnchorMotion`); the geometry of every grid point is the
robot with the active base at ``a(s)``. 
:func:`run_moving_carry` executes it in the 1 kHz control simulation with the moving
base (:class:`~taut.cdpr.BaseMotion`) and the mission's monitors, tipping and sliding
re-evaluated with the base where it is and its d'Alembert force. Units: SI (m, s, N, N m).

Measured on ``examples/cdpr/warehouse.yaml`` (docs/mission.md, examples/cdpr/README.md): it
never shortens a carry there. The carries move the platform only 0.2-0.3 m in the cable
plane (the 1.9 m from rack to kitting table is across it, the gripper's reach), so a base
limited to 0.2 m/s and 0.25 m/s^2 moving any distance caps the platform's speed and
acceleration on that short segment, and raising the active base's stabilisers already
costs up to 0.12 s and most of the tipping margin. Not part of ``plan_mission``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from ..._validate import (MAX_CDPR_LENGTH_M, MAX_RATE_HZ, MAX_SPEED, as_array, as_bounded,
                         as_count, check_range)
from ..._validate import require_instance
from ...errors import InvalidInputError
from ..control._setup import BaseMotion
from ..control.dynamics import DynamicsModel
from ..control.references import waypoint_segments
from ..deployment.moving_base import _stabilisers
from ..kinematics.cables import as_poses
from ..kinematics.modes import fastkit_motion_limits
from ..model.robot import CableRobot, with_base_acceleration
from ..statics.sliding import sliding_rows
from ._execute import PhaseRun, run_motion
from ._reposition import active_index, shifted
from .warehouse import Warehouse
from .timing import (DEFAULT_MAX_ACCEL_MPS2, DEFAULT_MAX_SPEED_MPS, MAX_GRID, SMOOTHING_S,
                     TENSION_MARGIN_N, TIPPING_MARGIN_NM, AnchorMotion, TimedPath, _plan,
                     checked_limits)

__all__ = ["MovingCarry", "moving_carry", "run_moving_carry", "wheels_for_active"]


@dataclass(frozen=True)
class MovingCarry:
    """A carry with the active base driving along.

    Attributes
    ----------
    law : TimedPath
        The platform's time-optimal law (robot frame of the site's placement).
    offsets : (2,)
        Active base offset at the start and the end of the carry, m.
    base_motion : BaseMotion
        Poses (T, K, 3) of every base at the law's times (m, rad), for
        :func:`taut.cdpr.simulate`.
    base_acceleration : (K, T, 3)
        Every base's acceleration at the law's times, robot frame, m/s^2 (zero but for the
        active base).
    """

    law: TimedPath
    offsets: np.ndarray
    base_motion: BaseMotion | None
    base_acceleration: np.ndarray


def wheels_for_active(robot: CableRobot) -> CableRobot:
    """``robot`` with the active base's stabilisers up (it drives), the others as they
    are."""
    require_instance(robot, CableRobot, "robot")
    k = active_index(robot)
    return _stabilisers(robot, [b.stabilisers_deployed and j != k
                                for j, b in enumerate(robot.bases)])


def _direction(robot: CableRobot) -> np.ndarray:
    """Unit x axis (3,) of the active base, robot frame."""
    th = float(robot.bases[active_index(robot)].pose[2])
    return np.array([np.cos(th), np.sin(th), 0.0])


def _anchor_motion(robot: CableRobot, pts: np.ndarray, a0: float, a1: float,
                   base_speed: float, base_accel: float) -> AnchorMotion:
    """Moving exits of the across segment with grid points ``pts`` (G, 3) (module
    docstring)."""
    L = float(np.linalg.norm(pts[-1] - pts[0]))
    s = np.linalg.norm(pts - pts[0], axis=1)
    delta = (a1 - a0) / L
    k, f = active_index(robot), _direction(robot)
    robots = tuple(shifted(robot, a0 + delta * si) for si in s)
    exit_rate = np.where((robot.cable_base == k)[:, None], delta * f[None], 0.0)
    acc = np.zeros((len(robot.bases), 3))
    acc[k] = delta * f                          # base acceleration per unit s_dd
    moved = with_base_acceleration(robot, acc)
    tip_rate = moved.edge_weight_moment - robot.edge_weight_moment
    slide_rate = np.zeros(0)
    if robot.has_sliding:
        unit0 = np.zeros((1, robot.m, 3))
        slide_rate = sliding_rows(moved, unit0)[1] - sliding_rows(robot, unit0)[1]
    return AnchorMotion(robots, exit_rate, tip_rate, slide_rate, abs(delta), base_speed,
                        base_accel)


def _base_track(robot: CableRobot, law: TimedPath, wp: np.ndarray, a0: float, a1: float
                ) -> tuple[BaseMotion, np.ndarray]:
    """Base poses along ``law`` and every base's acceleration (K, T, 3), m/s^2."""
    k, f = active_index(robot), _direction(robot)
    start = wp[-2]
    L = float(np.linalg.norm(wp[-1] - start))
    e = (wp[-1] - start) / L
    on = law.grid_segment.max()
    t_seg = law.times >= law.times[-1] - law.segment_times[on] - 1e-12
    s = np.where(t_seg, np.clip((law.positions - start) @ e, 0.0, L), 0.0)
    off = a0 + (a1 - a0) * s / L
    poses = np.repeat(np.array([b.pose for b in robot.bases])[None], len(s), axis=0)
    poses[:, k] += off[:, None] * f
    acc = np.zeros((len(robot.bases), len(s), 3))
    acc[k] = np.where(t_seg[:, None], (law.accelerations @ e)[:, None] * (a1 - a0) / L * f,
                      0.0)
    return BaseMotion(law.times, poses), acc


def moving_carry(robot: CableRobot, waypoints: ArrayLike, offsets: ArrayLike, *,
                 base_accel: float, base_speed: float | None = None,
                 dynamics: DynamicsModel | None = None,
                 tension_margin: float = TENSION_MARGIN_N,
                 tipping_margin: float = TIPPING_MARGIN_NM,
                 max_speed: float | None = DEFAULT_MAX_SPEED_MPS,
                 max_accel: float = DEFAULT_MAX_ACCEL_MPS2,
                 smoothing: float = SMOOTHING_S, rate: float = 1000.0,
                 grid: int | None = None) -> MovingCarry:
    """Time-optimal carry through ``waypoints`` with the active base driving from
    ``offsets[0]`` to ``offsets[1]`` m on the last segment (module docstring).

    Parameters
    ----------
    robot : CableRobot
        At the site's placement, carrying the box (:func:`~taut.cdpr.with_box`); the active
        base's stabilisers are raised here (:func:`wheels_for_active`).
    waypoints : array_like (W, 3)
        Platform positions, m (robot frame), W >= 2.
    offsets : array_like (2,)
        ``(a0, a1)``: the active base's offset along its x axis at the start and at the
        end, m.
    base_accel : float
        The active base's acceleration limit, m/s^2 (the warehouse's ``max_accel``).
    base_speed : float, optional
        Its speed limit, m/s (default FASTKIT eq. 10's task-mode 0.2 m/s).
    dynamics, tension_margin, tipping_margin, max_speed, max_accel, smoothing, rate, grid
        As :func:`~taut.cdpr.time_optimal_path` (N, N m, m/s, m/s^2, s, Hz, intervals per
        segment).

    Returns
    -------
    MovingCarry
        ``law.success`` False when some grid point cannot rest (``base_motion`` None).
    """
    require_instance(robot, CableRobot, "robot")
    wp = as_array(waypoints, "waypoints")
    if wp.ndim != 2 or wp.shape[1] != 3 or wp.shape[0] < 2:
        raise InvalidInputError("waypoints", "must be at least two (x, y, z) positions, m")
    as_poses(robot, wp, "waypoints")
    waypoint_segments(wp)
    a0, a1 = check_range(as_array(offsets, "offsets", shape=(2,)), "offsets",
                         MAX_CDPR_LENGTH_M, "m")
    bacc = as_bounded(base_accel, "base_accel", MAX_SPEED, "m/s^2")
    bv = float(fastkit_motion_limits().base_max[0]) if base_speed is None else \
        as_bounded(base_speed, "base_speed", MAX_SPEED, "m/s")
    lim = checked_limits(robot, DynamicsModel() if dynamics is None else dynamics,
                         tension_margin, tipping_margin, max_speed, max_accel, smoothing)
    rate = as_bounded(rate, "rate", MAX_RATE_HZ, "Hz")
    wheels = wheels_for_active(robot)
    start = shifted(wheels, float(a0))
    last = len(wp) - 2

    def motion_for(k: int, pts: np.ndarray) -> AnchorMotion | None:
        if k != last or a1 == a0:
            return None
        return _anchor_motion(start, pts, 0.0, float(a1 - a0), bv, bacc)

    n = None if grid is None else as_count(grid, "grid", minimum=1, maximum=MAX_GRID)
    law = _plan(start, wp, lim, n, rate, motion_for)
    if not law.success:
        return MovingCarry(law, np.array([a0, a1]), None,
                           np.zeros((len(robot.bases), 0, 3)))
    track, acc = _base_track(start, law, wp, 0.0, float(a1 - a0))
    return MovingCarry(law, np.array([a0, a1]), track, acc)


def run_moving_carry(warehouse: Warehouse, site_pose: ArrayLike, robot: CableRobot,
                     carry: MovingCarry, dynamics: DynamicsModel | None = None) -> PhaseRun:
    """``carry`` executed in the control simulation (torque control on encoder-estimated
    states) with the active base driving, monitored as a mission phase
    (:mod:`taut.cdpr.mission._execute`): tensions at every step, tipping (with the base's
    d'Alembert force), sliding and collisions at every recorded instant with the bases
    where they are.

    Parameters
    ----------
    warehouse : Warehouse
    site_pose : array_like (3,)
        The coupled bases' pose at the site, m and rad (the robot frame in the world).
    robot : CableRobot
        As given to :func:`moving_carry` (the box as payload).
    carry : MovingCarry
        A successful :func:`moving_carry`.
    dynamics : DynamicsModel, optional
    """
    require_instance(warehouse, Warehouse, "warehouse")
    require_instance(carry, MovingCarry, "carry")
    if carry.base_motion is None:
        raise InvalidInputError("carry", f"has no law to run: {carry.law.message}")
    pose = as_array(site_pose, "site_pose", shape=(3,))
    dyn = DynamicsModel() if dynamics is None else dynamics
    require_instance(dyn, DynamicsModel, "dynamics")
    start = shifted(wheels_for_active(robot), float(carry.offsets[0]))
    return run_motion(warehouse, pose, start, carry.law, dyn, carry.base_motion,
                      carry.base_acceleration)
