"""The whole kitting mission planned and simulated (issue 30, parts 4-6): navigate to each
deployment site, deploy the stabilisers, pick, carry and place every box served there
along time-optimal laws, retract, go on; and the same mission with the paper's fixed
1 m/s profile as the baseline.

Sequence (documented choice; the paper gives none): the sites in the order
:func:`~taut.cdpr.mission.sites.choose_sites` chose them; at each site the platform,
locked at the park position during navigation, does the site's tasks in the warehouse's
order, each as three platform motions with the gripper's dwell at rest in between:

``pick``
    empty, from where the platform is to the pick target, then ``GRIP_S`` to grip;
``carry``
    with the box, up ``LIFT_M`` off the shelf and across to ``LIFT_M`` above the place
    target;
``place``
    with the box, down to the place target, then ``GRIP_S`` to release.

Before the first task the stabilisers deploy (``STABILISER_S``); after the last the platform
returns empty to the park position and they retract (the ``retract`` phase holds both).
Every motion follows :func:`~taut.cdpr.mission.timing.time_optimal_path` and runs in the
control simulation (:mod:`taut.cdpr.mission._execute`); ``navigate``, ``deploy`` and
``retract`` hold the platform statically.

Baseline (``baseline_total_time``): the same sites, routes, dwells and stabiliser times,
every platform motion on a fixed trapezoidal profile through the same waypoints: cruise
at the paper's 1 m/s (``BASELINE_SPEED``), accelerate and brake at the largest constant
rate the same constraints (tensions with inertia, margins, tipping, sliding, winch torque)
admit on the whole segment, the same smoothing window
(:func:`~taut.cdpr.mission.timing.fixed_profile_duration`; not simulated). A profile that
ignores the constraints is no baseline: the quintic at 1 m/s peak needs 16 m/s^2 on a
0.1 m lift, beyond what the cables hold. The sites are those of the site search (the
nearest feasible placements it finds); only the motion law differs.

Assumed times (the paper gives none): ``GRIP_S`` = 0.5 s to grip or release a box,
``STABILISER_S`` = 3 s to deploy or retract the stabilisers; ``LIFT_M`` = 0.1 m lift off a
shelf. Units: SI (m, s, N, N m).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Callable

import numpy as np

from ..._outcome import check_status
from ..._validate import MAX_CDPR_LENGTH_M, as_bounded, as_flag, require_instance
from ...errors import InvalidInputError
from ..control.dynamics import DynamicsModel
from ..model.robot import CableRobot, with_friction, with_stabilisers
from ..statics.tension import distribute_tensions
from ._execute import PhaseRun, hold_margins, run_motion
from .navigation import NavigationResult, plan_navigation
from .sites import Site, SitesResult, UnservedTask, choose_sites
from .timing import fixed_profile_duration, time_optimal_path, with_box
from .warehouse import Warehouse, to_world_frame

__all__ = ["Phase", "MissionResult", "plan_mission", "PHASE_KINDS"]

#: The kinds of phase, in the order a site uses them.
PHASE_KINDS = ("navigate", "deploy", "pick", "carry", "place", "retract")
GRIP_S = 0.5
STABILISER_S = 3.0
LIFT_M = 0.1
#: The baseline's cruise speed, the paper's 1 m/s (FASTKIT §2.1), m/s.
BASELINE_SPEED = 1.0
#: Park heights tried for the locked platform (robot frame, above the origin), m: the
#: first one holding the platform with the stabilisers retracted is used.
PARK_HEIGHTS = (0.5, 0.6, 0.4, 0.7, 0.3, 0.8)


@dataclass(frozen=True)
class Phase:
    """One phase of the mission.

    Attributes
    ----------
    kind : str
        One of :data:`PHASE_KINDS`.
    task : str
        The box moved (``""`` for navigate, deploy, retract).
    site : int
        Index of the site (0-based; -1 while navigating away from the start).
    start, end : float
        s from the mission's start.
    min_tension_margin : float
        N, ``min(t - t_min, t_max - t)`` over cables and time.
    min_tipping_margin : float
        N m, ``-m_C`` (eqs. 21-23) over base edges and time.
    min_sliding_margin : float
        N, friction pyramid (inf without friction).
    success : bool
    message : str
    """

    kind: str
    task: str
    site: int
    start: float
    end: float
    min_tension_margin: float
    min_tipping_margin: float
    min_sliding_margin: float
    success: bool
    message: str


@dataclass(frozen=True, eq=False)
class MissionResult:
    """Outcome of :func:`plan_mission`.

    Attributes
    ----------
    success : bool
        Every served task done with every monitor clean (tasks no site serves are
        reported, not failures: the mission goes on without them).
    status : str
        ``"ok"``; ``"no_route"`` when a site could not be reached; ``"infeasible"`` when a
        phase broke a limit.
    message : str
        One line; names the unserved tasks and why.
    phases : tuple of Phase
    total_time, baseline_total_time : float
        s (baseline: module docstring).
    motion_time, baseline_motion_time : float
        s, the platform motions alone (pick, carry, place and the return before a
        retract; no dwell, navigation or stabiliser time): where the two laws differ.
    served : tuple of str
        Tasks done.
    unserved : tuple of UnservedTask
    sites : tuple of Site
    routes : tuple of NavigationResult
    track_times : (T,)
        s.
    track_bases : (T, 3)
        Pose ``(x, y, yaw)`` of the coupled bases, m and rad.
    track_platform : (T, 3)
        Platform reference point in the world, m.
    """

    success: bool
    status: str
    message: str
    phases: tuple[Phase, ...]
    total_time: float
    baseline_total_time: float
    motion_time: float
    baseline_motion_time: float
    served: tuple[str, ...]
    unserved: tuple[UnservedTask, ...]
    sites: tuple[Site, ...]
    routes: tuple[NavigationResult, ...]
    track_times: np.ndarray
    track_bases: np.ndarray
    track_platform: np.ndarray

    def __post_init__(self) -> None:
        check_status(self.status)

    @property
    def speedup(self) -> float:
        """``baseline_total_time / total_time``."""
        return self.baseline_total_time / self.total_time if self.total_time > 0 else np.nan


class _Log:
    """Phases and track under construction (private)."""

    def __init__(self) -> None:
        self.t = 0.0
        self.baseline = 0.0
        self.motion = 0.0
        self.baseline_motion = 0.0
        self.phases: list[Phase] = []
        self.times: list[np.ndarray] = []
        self.bases: list[np.ndarray] = []
        self.platform: list[np.ndarray] = []

    def add(self, kind: str, task: str, site: int, run: PhaseRun, extra: float,
            baseline: float, bases: np.ndarray) -> None:
        dur = run.duration + extra
        self.phases.append(Phase(kind, task, site, self.t, self.t + dur,
                                 run.min_tension_margin, run.min_tipping_margin,
                                 run.min_sliding_margin, run.success, run.message))
        self.times.append(self.t + np.r_[run.times, dur])
        self.platform.append(np.vstack([run.platform, run.platform[-1:]]))
        self.bases.append(np.broadcast_to(bases, (len(run.times) + 1, 3))
                          if bases.ndim == 1 else bases)
        self.t += dur
        self.baseline += baseline + extra
        if kind != "navigate":
            self.motion += run.duration
            self.baseline_motion += baseline


def _park(robot: CableRobot) -> np.ndarray:
    """Park position of the locked platform (robot frame), m."""
    for z in PARK_HEIGHTS:
        if distribute_tensions(robot, [0.0, 0.0, z], "qp_min_norm").success:
            return np.array([0.0, 0.0, z])
    raise InvalidInputError("robot", "cannot hold its empty platform with the stabilisers "
                                     "retracted at any park height "
                                     f"{list(PARK_HEIGHTS)} m above its centre")


def _waypoints(points: list[np.ndarray]) -> np.ndarray:
    keep = [points[0]]
    for p in points[1:]:
        if np.linalg.norm(p - keep[-1]) > 1e-6:
            keep.append(p)
    return np.array(keep)


def _motion(wh: Warehouse, site: Site, robot: CableRobot, points: list[np.ndarray],
            dyn: DynamicsModel, simulate_runs: bool) -> tuple[PhaseRun, float]:
    """Plan, simulate and monitor one platform motion; and its baseline duration, s."""
    wp = _waypoints(points)
    if len(wp) < 2:
        return hold_margins((robot,), wp[0], 0.0, wh, site.pose), 0.0
    law = time_optimal_path(robot, wp, dynamics=dyn)
    base = fixed_profile_duration(law, BASELINE_SPEED)
    if not law.success:
        return PhaseRun(False, law.message, 0.0, np.nan, np.nan, np.nan, np.nan, np.nan,
                        np.array([0.0]), to_world_frame(site.pose, wp[:1])), base
    if not simulate_runs:
        return PhaseRun(True, law.message, law.duration, np.nan, np.nan, np.nan, np.inf,
                        0.0, law.times[::50],
                        to_world_frame(site.pose, law.positions[::50])), base
    return run_motion(wh, site.pose, robot, law, dyn), base


def _site_tasks(wh: Warehouse, site: Site, k: int, park: np.ndarray, log: _Log,
                dyn: DynamicsModel, simulate_runs: bool, tick: Callable[[], None]) -> None:
    """Deploy, every task of the site, retract."""
    down = site.robot
    up = with_stabilisers(down, deployed=False)
    log.add("deploy", "", k, hold_margins((with_box(up, 0.0), with_box(down, 0.0)), park,
                                          0.0, wh, site.pose), STABILISER_S, 0.0, site.pose)
    here = park
    masses = {t.name: t.mass for t in wh.tasks}
    lift = np.array([0.0, 0.0, LIFT_M])
    for name, pick, place in zip(site.task_names, site.picks, site.places):
        empty, loaded = with_box(down, 0.0), with_box(down, masses[name])
        for kind, robot, pts, extra in (
                ("pick", empty, [here, pick], GRIP_S),
                ("carry", loaded, [pick, pick + lift, place + lift], 0.0),
                ("place", loaded, [place + lift, place], GRIP_S)):
            run, base = _motion(wh, site, robot, pts, dyn, simulate_runs)
            log.add(kind, name, k, run, extra, base, site.pose)
            tick()
        here = place
    run, base = _motion(wh, site, with_box(down, 0.0), [here, park], dyn, simulate_runs)
    held = hold_margins((with_box(down, 0.0), with_box(up, 0.0)), park, 0.0, wh, site.pose)
    worst = PhaseRun(run.success and held.success, run.message if not run.success else
                     held.message, run.duration,
                     min(run.min_tension_margin, held.min_tension_margin),
                     min(run.min_tipping_margin, held.min_tipping_margin),
                     min(run.min_sliding_margin, held.min_sliding_margin),
                     run.min_clearance, run.max_tracking_error, run.times, run.platform)
    log.add("retract", "", k, worst, STABILISER_S, base, site.pose)


def plan_mission(warehouse: Warehouse, *, dynamics: DynamicsModel | None = None,
                 simulate_runs: bool = True, site_step: float = 0.25,
                 progress: Callable[[int, int], None] | None = None) -> MissionResult:
    """Plan and simulate the warehouse's kitting mission (module docstring).

    Parameters
    ----------
    warehouse : Warehouse
    dynamics : DynamicsModel, optional
        Winches and cables (default the FASTKIT values).
    simulate_runs : bool, default True
        Run every platform motion in the control simulation (False: plan only; the
        motion phases then carry NaN margins).
    site_step : float
        Spacing of the candidate sites along the shelf faces, m
        (:func:`~taut.cdpr.mission.sites.choose_sites`).
    progress : callable(done, total), optional
        Called after each site search, route and motion phase.

    Returns
    -------
    MissionResult

    Examples
    --------
    >>> from taut.io import load_warehouse
    >>> res = plan_mission(load_warehouse("examples/cdpr/warehouse.yaml"))  # doctest: +SKIP
    >>> res.success, res.total_time < res.baseline_total_time               # doctest: +SKIP
    (True, True)
    """
    require_instance(warehouse, Warehouse, "warehouse")
    dyn = DynamicsModel() if dynamics is None else dynamics
    require_instance(dyn, DynamicsModel, "dynamics")
    simulate_runs = as_flag(simulate_runs, "simulate_runs")
    if progress is not None and not callable(progress):
        raise InvalidInputError("progress", "must be a callable(done, total) or None")
    site_step = as_bounded(site_step, "site_step", MAX_CDPR_LENGTH_M, "m")
    chosen: SitesResult = choose_sites(warehouse, step=site_step)
    ntasks = sum(len(s.task_names) for s in chosen.sites)
    total, done = 1 + len(chosen.sites) + 3 * ntasks, [1]

    def tick() -> None:
        done[0] += 1
        if progress is not None:
            progress(done[0], total)

    if progress is not None:
        progress(1, total)
    free = with_stabilisers(with_friction(warehouse.robot, warehouse.friction), deployed=False)
    park = _park(with_box(free, 0.0))
    log, routes, served = _Log(), [], []
    unserved = list(chosen.unserved)
    pose, status = np.asarray(warehouse.start, dtype=float), "ok"
    for k, site in enumerate(chosen.sites):
        nav = plan_navigation(warehouse, pose, site.pose)
        routes.append(nav)
        if not nav.success:
            status = "no_route"
            unserved += [UnservedTask(n, f"site {k + 1} not reached: {nav.message}")
                         for n in site.task_names]
            continue
        held = hold_margins((with_box(free, 0.0),), park, nav.duration, warehouse, pose)
        platform = np.array([to_world_frame(p, park) for p in nav.poses])
        held = replace(held, times=nav.times[:-1] - nav.times[0], platform=platform[:-1])
        log.add("navigate", "", k, held, 0.0, nav.duration, nav.poses)
        tick()
        _site_tasks(warehouse, site, k, park, log, dyn, simulate_runs, tick)
        served += list(site.task_names)
        pose = site.pose
    return _result(log, status, chosen, tuple(routes), tuple(served), tuple(unserved))


def _result(log: _Log, status: str, chosen: SitesResult, routes: tuple[NavigationResult, ...],
            served: tuple[str, ...], unserved: tuple[UnservedTask, ...]) -> MissionResult:
    bad = [p for p in log.phases if not p.success]
    if bad and status == "ok":
        status = "infeasible"
    parts = [f"{len(served)} task(s) done in {log.t:.1f} s (baseline {log.baseline:.1f} s)"]
    if bad:
        b = bad[0]
        parts.append(f"{len(bad)} phase(s) broke a limit, first {b.kind} "
                     f"{b.task or ''} at {b.start:.1f} s: {b.message}")
    if unserved:
        parts.append("unserved: " + "; ".join(f"{u.name} ({u.reason})" for u in unserved))
    empty3 = np.zeros((0, 3))
    return MissionResult(status == "ok", status, "; ".join(parts), tuple(log.phases), log.t,
                         log.baseline, log.motion, log.baseline_motion, served, unserved,
                         chosen.sites, routes,
                         np.concatenate(log.times) if log.times else np.zeros(0),
                         np.vstack(log.bases) if log.bases else empty3,
                         np.vstack(log.platform) if log.platform else empty3)
