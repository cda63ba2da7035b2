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

Phases without cable motion (navigation with the platform locked, deploy and retract of
the stabilisers) are static for the cables: their margins come from the tension
distribution that holds the locked platform (:func:`taut.cdpr.distribute_tensions`,
minimum-norm QP with tipping and sliding) with the stabilisers in each state the phase
passes through (quasi-static: the bases' own accelerations are not in the moments).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely

from ..control.controllers import TorqueController
from ..control.dynamics import DynamicsModel
from ..control.simulate import simulate
from ..kinematics.cables import cable_state
from ..model.robot import CableRobot
from ..statics.sliding import sliding_rows
from ..statics.tension import distribute_tensions
from .timing import TimedPath
from .warehouse import Warehouse, to_world_frame

__all__ = ["PhaseRun", "run_motion", "hold_margins"]

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


def run_motion(warehouse: Warehouse, site_pose: np.ndarray, robot: CableRobot,
               law: TimedPath, dynamics: DynamicsModel) -> PhaseRun:
    """Simulate one platform motion ``law`` of the deployed ``robot`` (payload = the box
    carried) at ``site_pose`` and monitor it (module docstring)."""
    run = simulate(robot, law.reference(), TorqueController(), dynamics=dynamics)
    T = run.tensions
    ten = float(np.minimum(T - run.t_min, run.t_max - T).min())
    tip = float(run.tipping_margin.min()) if run.tipping_margin.size else float("inf")
    sel = slice(None, None, RECORD_EVERY)
    idx = np.r_[np.arange(len(run.times))[sel], len(run.times) - 1]
    slide = _sliding_margin(robot, run.poses[idx], T[idx])
    clear = _clearance(warehouse, site_pose, run.poses[idx, :3])
    ok = bool(run.success and ten >= 0 and tip >= 0 and slide >= 0 and clear >= 0)
    msg = run.message if ok or not run.success else (
        f"margins: tension {ten:.2f} N, tipping {tip:.2f} N m, sliding {slide:.2f} N, "
        f"clearance {clear:.3f} m")
    return PhaseRun(ok, msg, float(law.duration), ten, tip, slide, clear,
                    float(run.tracking_error.max()), run.times[idx],
                    to_world_frame(site_pose, run.poses[idx, :3]))


def hold_margins(robots: tuple[CableRobot, ...], position: np.ndarray, duration: float,
                 warehouse: Warehouse, site_pose: np.ndarray) -> PhaseRun:
    """Margins of the platform held at ``position`` (robot frame) by each of ``robots``
    (the stabiliser states a static phase passes through) for ``duration`` s."""
    pose = np.r_[position, 0.0, 0.0, 0.0]
    ten, tip, slide, ok, why = np.inf, np.inf, np.inf, True, ""
    for r in robots:
        res = distribute_tensions(r, pose, "qp_min_norm", tipping=True, sliding=True)
        if not res.success:
            ok, why = False, res.message
            ten = min(ten, float(np.nan_to_num(np.minimum(res.tensions - r.t_min,
                                                          r.t_max - res.tensions).min(),
                                               nan=-np.inf)))
            continue
        ten = min(ten, float(np.minimum(res.tensions - r.t_min, r.t_max - res.tensions).min()))
        if res.tipping_moments.size:
            tip = min(tip, float(-res.tipping_moments.max()))
        slide = min(slide, _sliding_margin(r, pose[None], res.tensions[None]))
    world = to_world_frame(site_pose, position[None])
    return PhaseRun(ok, why or "platform held within every limit", float(duration), ten, tip,
                    slide, float("inf"), 0.0, np.array([0.0, duration]),
                    np.repeat(world, 2, axis=0))
