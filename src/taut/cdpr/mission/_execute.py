"""The mission's phases executed in the control simulation (issue 30, part 5), with the
monitors the mission reports.

Platform motions (pick, carry, place, the return before a retract) run through
:func:`taut.cdpr.simulate` with the built-in :class:`~taut.cdpr.TorqueController` (task-space
PD on the reference tension distribution, pose estimated from the encoders: the default
:class:`~taut.cdpr.Sensing`) at 1 kHz on the FASTKIT winch and cable dynamics, the
robot deployed at its site (stabilisers down, the warehouse's friction), the carried box
as the payload. Each run starts from the closed-loop rest state at its first waypoint
(the gripper grips and releases at rest, so the payload changes between runs).
Monitors along every recorded instant: tension margin ``min(t - t_min, t_max - t)`` (N),
tipping margin ``-m_C`` of eqs. 21-23 from the actual tensions (N m), sliding margin
``s - S t`` of the friction pyramid (N), the platform's clearance to every shelf seen from
above (m, the platform's reference point in the world) and the run's own limit episodes
(slack, over-tension, torque and speed saturation).

Every phase also monitors collisions: each cable (exit point to attachment point) against
each shelf's solid ``footprint x [0, height]`` (:func:`~._monitors.cable_clearance`, m) and
the coupled bases' footprint against the walls and shelves (m; with the stabiliser feet
while they are down).

Phases without cable motion hold the locked platform; their margins come from the tension
distribution that holds it (:func:`taut.cdpr.distribute_tensions`, minimum-norm QP with
tipping and sliding), evaluated along the phase's time line:

``navigate``
    at every sample of the verified route (0.1 s apart): the rigid footprint's gap to walls
    and shelves, the cables' gap to the shelves, and the tensions, tipping and sliding with
    the platform's inertial load ``-m a`` of the bases' acceleration ``a`` and the bases' own
    d'Alembert forces ``-m_b a`` at their centres of mass in the tipping moments and the
    sliding condition (:func:`~taut.cdpr.with_base_acceleration`; stabilisers up; ``a`` is
    the translational acceleration of the coupled bases' origin, rounded to 1 mm/s^2,
    one tension distribution per distinct value; the yaw rate's centripetal and angular
    terms are neglected, at most 0.2 rad/s);
``deploy`` / ``retract``
    the stabilisers switch base by base (:func:`~._monitors.stabiliser_sequence`), each
    state held for an equal share of the phase, monitored in each.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import shapely

from ..control._setup import BaseMotion
from ..control.controllers import TorqueController
from ..control.dynamics import DynamicsModel
from ..control.simulate import simulate
from ..kinematics.cables import cable_state
from ..model.robot import CableRobot, with_base_acceleration
from ..statics.sliding import sliding_rows
from ..statics.tipping import tipping_moments
from ..statics.tension import distribute_tensions
from ..deployment.moving_base import _stabilisers
from ._monitors import (cable_clearance, cable_segments, segments_clearance,
                        stabiliser_sequence)
from ._navigate import footprint_slack
from .navigation import NavigationResult
from .timing import TimedPath
from .warehouse import Warehouse, coupled_footprint, to_world_frame

__all__ = ["PhaseRun", "run_motion", "hold_margins", "footprint_gap", "switch_stabilisers", "navigate_run"]

#: Recorded instants kept in a run's track (every RECORD_EVERY-th control step).
RECORD_EVERY = 50


@dataclass(frozen=True)
class PhaseRun:
    """One phase's monitors.

    Attributes
    ----------
    success : bool
        Every monitor clean (every margin >= 0, no limit episode).
    message : str
    duration : float
        s (the motion, without the pre-roll).
    min_tension_margin : float
        N.
    min_tipping_margin : float
        N m (``inf`` without mobile bases).
    min_sliding_margin : float
        N (``inf`` without friction).
    min_clearance : float
        m, platform to the nearest shelf seen from above (``inf`` for static phases).
    max_tracking_error : float
        m (0 for static phases).
    min_cable_clearance : float
        m, any cable to the nearest shelf (solid to its height).
    min_footprint_clearance : float
        m, the coupled bases' footprint to the nearest wall or shelf.
    times : (T,)
        s from the phase's start, every RECORD_EVERY-th step.
    platform : (T, 3)
        Platform reference point in the world, m.
    """

    success: bool
    message: str
    duration: float
    min_tension_margin: float
    min_tipping_margin: float
    min_sliding_margin: float
    min_clearance: float
    max_tracking_error: float
    min_cable_clearance: float
    min_footprint_clearance: float
    times: np.ndarray
    platform: np.ndarray


def _sliding_margin(robot: CableRobot, poses: np.ndarray, tensions: np.ndarray) -> float:
    if not robot.has_sliding:
        return float("inf")
    S, s, _ = sliding_rows(robot, cable_state(robot, poses, validated=True).unit)
    return float((s[None] - np.einsum("bfm,bm->bf", S, tensions)).min())


def _clearance(warehouse: Warehouse, pose: np.ndarray, points: np.ndarray) -> float:
    world = to_world_frame(pose, points)
    pts = shapely.points(world[:, :2])
    return float(min((shapely.distance(sh.footprint, pts).min() for sh in warehouse.shelves),
                     default=np.inf))


def footprint_gap(warehouse: Warehouse, robot: CableRobot, poses: np.ndarray) -> float:
    """Least gap between the coupled bases (stabiliser feet included when any is down) at
    ``poses`` (P, 3) and the walls and shelves, m."""
    down = any(b.stabilisers_deployed for b in robot.bases)
    gap, _ = footprint_slack(warehouse, coupled_footprint(robot, deployed=down),
                             np.atleast_2d(poses))
    return float(gap.min())


def run_motion(warehouse: Warehouse, site_pose: np.ndarray, robot: CableRobot,
               law: TimedPath, dynamics: DynamicsModel, bases: BaseMotion | None = None,
               base_acc: np.ndarray | None = None) -> PhaseRun:
    """Simulate one platform motion ``law`` of the deployed ``robot`` (payload = the box
    carried) at ``site_pose`` and monitor it (module docstring). With ``bases`` (the bases'
    poses over the law's time) and ``base_acc`` (K, T, 3) (each base's acceleration at the
    law's times, robot frame, m/s^2) the bases move during the run: tipping, sliding and
    the collision gaps are evaluated with the bases where they are at each recorded instant
    and their d'Alembert forces (:func:`~taut.cdpr.with_base_acceleration`)."""
    run = simulate(robot, law.reference(), TorqueController(), dynamics=dynamics,
                   base_motion=bases)
    T = run.tensions
    ten = float(np.minimum(T - run.t_min, run.t_max - T).min())
    tip = float(run.tipping_margin.min()) if run.tipping_margin.size else float("inf")
    sel = slice(None, None, RECORD_EVERY)
    idx = np.r_[np.arange(len(run.times))[sel], len(run.times) - 1]
    if bases is None or base_acc is None:
        robots = [robot]
        slide = _sliding_margin(robot, run.poses[idx], T[idx])
    else:
        robots = _robots_along(robot, bases, law.times, base_acc, run.times[idx])
        tip_b, slide = _moving_margins(robots, run.poses[idx], T[idx])
        tip = min(tip, tip_b)
    clear = _clearance(warehouse, site_pose, run.poses[idx, :3])
    cab = min(cable_clearance(warehouse, r, site_pose, run.poses[idx[i:i + 1]])
              for i, r in enumerate(robots)) if len(robots) > 1 else \
        cable_clearance(warehouse, robot, site_pose, run.poses[idx])
    foot = min(footprint_gap(warehouse, r, site_pose) for r in robots)
    ok = bool(run.success and min(ten, tip, slide, clear, cab, foot) >= 0)
    msg = run.message if ok or not run.success else (
        f"margins: tension {ten:.2f} N, tipping {tip:.2f} N m, sliding {slide:.2f} N, "
        f"clearance {clear:.3f} m, cables to shelves {cab:.3f} m, bases to shelves and "
        f"walls {foot:.3f} m")
    return PhaseRun(ok, msg, float(law.duration), ten, tip, slide, clear,
                    float(run.tracking_error.max()), cab, foot, run.times[idx],
                    to_world_frame(site_pose, run.poses[idx, :3]))


def _robots_along(robot: CableRobot, bases: BaseMotion, law_times: np.ndarray,
                  base_acc: np.ndarray, times: np.ndarray) -> list[CableRobot]:
    """``robot`` with its bases where ``bases`` puts them at ``times`` (s) and accelerating
    as ``base_acc`` (K, T_law, 3) m/s^2 says (held outside the law's span)."""
    poses = bases.at(times)
    acc = np.stack([[np.interp(times, law_times, base_acc[k, :, j]) for j in range(3)]
                    for k in range(len(robot.bases))])              # (K, 3, S)
    out = []
    for i in range(len(times)):
        moved = replace(robot, bases=tuple(
            replace(b, exit_points=dict(b.exit_points), pose=poses[i, k])
            for k, b in enumerate(robot.bases)))
        out.append(with_base_acceleration(moved, acc[:, :, i]))
    return out


def _moving_margins(robots: list[CableRobot], poses: np.ndarray, tensions: np.ndarray
                    ) -> tuple[float, float]:
    """Least tipping margin (N m) and sliding margin (N) of the actual ``tensions``
    (S, m) at platform ``poses`` (S, 6), the bases of sample ``i`` as ``robots[i]``."""
    tip = min((float(-tipping_moments(r, poses[i], tensions[i]).moments.max())
               for i, r in enumerate(robots) if r.has_tipping), default=float("inf"))
    slide = min(_sliding_margin(r, poses[i:i + 1], tensions[i:i + 1])
                for i, r in enumerate(robots))
    return tip, slide


def _held(robot: CableRobot, position: np.ndarray, wrench: np.ndarray | None
          ) -> tuple[float, float, float, str]:
    """Tension (N), tipping (N m) and sliding (N) margins of the platform held at
    ``position`` (3,) (robot frame) under the extra ``wrench`` (B, 6) (or none), and why
    it is not held ("" when it is)."""
    B = 1 if wrench is None else len(wrench)
    poses = np.tile(np.r_[position, 0.0, 0.0, 0.0], (B, 1))
    res = distribute_tensions(robot, poses, "qp_min_norm", external_wrench=wrench,
                              tipping=True, sliding=True)
    t = res.tensions
    ten = float(np.nan_to_num(np.minimum(t - robot.t_min, robot.t_max - t).min(),
                              nan=-np.inf))
    if not np.all(res.success):
        return ten, -np.inf, -np.inf, res.message
    tip = float(-res.tipping_moments.max()) if res.tipping_moments.size else float("inf")
    return ten, tip, _sliding_margin(robot, poses, t), ""


def _static_run(checks: list[tuple[float, float, float, str]], duration: float, cab: float,
                foot: float, times: np.ndarray, platform: np.ndarray) -> PhaseRun:
    why = next((c[3] for c in checks if c[3]), "")
    ten, tip, slide = (min(c[0] for c in checks), min(c[1] for c in checks),
                       min(c[2] for c in checks))
    ok = not why and min(ten, tip, slide, cab, foot) >= 0
    msg = why or ("platform held within every limit" if ok else
                  f"margins: tension {ten:.2f} N, tipping {tip:.2f} N m, sliding "
                  f"{slide:.2f} N, cables to shelves {cab:.3f} m, bases to shelves and "
                  f"walls {foot:.3f} m")
    return PhaseRun(bool(ok), msg, float(duration), ten, tip, slide, float("inf"), 0.0, cab,
                    foot, times, platform)


def hold_margins(robots: tuple[CableRobot, ...], position: np.ndarray, duration: float,
                 warehouse: Warehouse, site_pose: np.ndarray) -> PhaseRun:
    """Margins of the platform held at ``position`` (robot frame) by each of ``robots``
    (the stabiliser states a static phase passes through, in order, each for an equal
    share of ``duration`` s)."""
    checks = [_held(r, position, None) for r in robots]
    pose6 = np.r_[position, 0.0, 0.0, 0.0][None]
    cab = min(cable_clearance(warehouse, r, site_pose, pose6) for r in robots)
    foot = min(footprint_gap(warehouse, r, site_pose) for r in robots)
    k = len(robots)
    times = np.linspace(0.0, duration, k + 1)
    world = to_world_frame(site_pose, position[None])
    return _static_run(checks, duration, cab, foot, times, np.repeat(world, k + 1, axis=0))


def switch_stabilisers(robot: CableRobot, deploy: bool, position: np.ndarray,
                       duration: float, warehouse: Warehouse, site_pose: np.ndarray
                       ) -> PhaseRun:
    """A deploy (``deploy``) or retract of ``robot``'s stabilisers in ``duration`` s, the
    platform held at ``position`` (robot frame), monitored in every state it passes
    through (module docstring)."""
    states = stabiliser_sequence(robot, deploy)
    return hold_margins(tuple(_stabilisers(robot, s) for s in states), position, duration,
                        warehouse, site_pose)


def _base_accel(nav: NavigationResult) -> np.ndarray:
    """Acceleration (T, 2) of the coupled bases' origin along ``nav``, robot frame,
    m/s^2 (finite differences of the sampled route)."""
    t, p = nav.times, nav.poses
    if len(t) < 3:
        return np.zeros((len(t), 2))
    a = np.column_stack([np.gradient(np.gradient(p[:, j], t), t) for j in range(2)])
    c, s = np.cos(p[:, 2]), np.sin(p[:, 2])
    return np.column_stack([c * a[:, 0] + s * a[:, 1], -s * a[:, 0] + c * a[:, 1]])


def navigate_run(warehouse: Warehouse, robot: CableRobot, position: np.ndarray,
                 nav: NavigationResult) -> PhaseRun:
    """The locked platform (at ``position``, robot frame) of ``robot`` (stabilisers up)
    carried along the verified route ``nav``, monitored at every sample (module
    docstring)."""
    checks = [_held(with_base_acceleration(robot, np.r_[a, 0.0]), position,
                    np.r_[-robot.total_mass * a, np.zeros(4)][None])
              for a in np.unique(np.round(_base_accel(nav), 3), axis=0)]
    pose6 = np.r_[position, 0.0, 0.0, 0.0][None]
    ex, at = cable_segments(robot, np.zeros(3), pose6)          # robot frame, (1, m, 3)
    c, s = np.cos(nav.poses[:, 2]), np.sin(nav.poses[:, 2])
    rot = np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)   # (P, 2, 2)

    def world(q: np.ndarray) -> np.ndarray:
        out = np.broadcast_to(q, (len(rot),) + q.shape[1:]).copy()
        out[..., :2] = np.einsum("pij,pmj->pmi", rot, q[..., :2]) + nav.poses[:, None, :2]
        return out

    cab = segments_clearance(warehouse, world(ex), world(at))
    foot = footprint_gap(warehouse, robot, nav.poses)
    platform = np.array([to_world_frame(q, position) for q in nav.poses])
    return _static_run(checks, nav.duration, cab, foot, nav.times - nav.times[0], platform)
