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
``retract`` hold the locked platform, monitored along their time line: every sample of the
verified route with the bases' acceleration as an inertial load, every stabiliser state a
deploy or retract passes through. Every phase monitors the cables against the shelves
(solid to their height) and the bases' footprint against walls and shelves.

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
from typing import Any, Callable

import numpy as np

from ..._outcome import check_status
from ..._validate import (MAX_CDPR_LENGTH_M, as_array, as_bounded, as_flag, check_range,
                          require_instance)
from ...errors import InvalidInputError
from ..control.dynamics import DynamicsModel
from ..model.robot import CableRobot, with_friction, with_stabilisers
from ..statics.tension import distribute_tensions
from .._tol import NAV_TOL
from ..deployment.moving_base import _stabilisers
from ._execute import (PhaseRun, footprint_gap, hold_margins, navigate_run, run_motion,
                       switch_stabilisers)
from ._reposition import Reposition, active_index, drive_time, shifted
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
    min_cable_clearance : float
        m, least gap between any cable and any shelf (solid to its height).
    min_footprint_clearance : float
        m, least gap between the coupled bases' footprint and any wall or shelf.
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
    min_cable_clearance: float
    min_footprint_clearance: float
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
    repositions : tuple of Reposition
        Per task, the active base's offset chosen and what it saves and costs (empty
        unless ``active_base_offsets`` were given).
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
    repositions: tuple[Reposition, ...] = ()

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
                                 run.min_sliding_margin, run.min_cable_clearance,
                                 run.min_footprint_clearance, run.success, run.message))
        self.times.append(self.t + np.r_[run.times, dur])
        self.platform.append(np.vstack([run.platform, run.platform[-1:]]))
        self.bases.append(np.broadcast_to(bases, (len(run.times) + 1, 3))
                          if bases.ndim == 1 else bases)
        self.t += dur
        self.baseline += baseline + extra
        if kind not in ("navigate", "deploy"):
            self.motion += run.duration
            self.baseline_motion += baseline


#: The monitors of a :class:`~._execute.PhaseRun`, in its field order.
_MONITORS = ("min_tension_margin", "min_tipping_margin", "min_sliding_margin",
             "min_clearance", "max_tracking_error", "min_cable_clearance",
             "min_footprint_clearance")


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
                        np.nan, np.nan, np.array([0.0]),
                        to_world_frame(site.pose, wp[:1])), base
    if not simulate_runs:
        return PhaseRun(True, law.message, law.duration, np.nan, np.nan, np.nan, np.inf,
                        0.0, np.nan, np.nan, law.times[::50],
                        to_world_frame(site.pose, law.positions[::50])), base
    return run_motion(wh, site.pose, robot, law, dyn), base


def _worst(a: PhaseRun, b: PhaseRun) -> PhaseRun:
    """The monitors of motion ``a`` and static hold ``b`` combined (``a``'s track)."""
    worst = {f: (max if f == "max_tracking_error" else min)(getattr(a, f), getattr(b, f))
             for f in _MONITORS}
    return replace(a, success=a.success and b.success,
                   message=a.message if not a.success else b.message, **worst)


def _task_motions(down: CableRobot, mass: float, here: np.ndarray, pick: np.ndarray,
                  place: np.ndarray) -> list[tuple[str, CableRobot, list[np.ndarray], float]]:
    """The pick, carry and place motions of one task: kind, robot, waypoints, dwell s."""
    lift = np.array([0.0, 0.0, LIFT_M])
    empty, loaded = with_box(down, 0.0), with_box(down, mass)
    return [("pick", empty, [here, pick], GRIP_S),
            ("carry", loaded, [pick, pick + lift, place + lift], 0.0),
            ("place", loaded, [place + lift, place], GRIP_S)]


def _plan_time(motions: list[tuple[str, CableRobot, list[np.ndarray], float]],
               dyn: DynamicsModel) -> float:
    """Time-optimal duration of ``motions`` (inf when one is infeasible), s."""
    total = 0.0
    for _, robot, pts, _ in motions:
        wp = _waypoints(pts)
        if len(wp) > 1:
            law = time_optimal_path(robot, wp, dynamics=dyn)
            if not law.success:
                return float("inf")
            total += law.duration
    return total


def _choose_offset(wh: Warehouse, site: Site, offsets: tuple[float, ...], current: float,
                   name: str, motions: Callable[[CableRobot], list[Any]],
                   dyn: DynamicsModel) -> Reposition:
    """The active-base offset for one task (:mod:`._reposition`)."""
    times = {}
    for d in sorted(set(offsets) | {current}):
        robot = shifted(site.robot, d)
        if d != current and footprint_gap(wh, robot, site.pose) < wh.clearance - NAV_TOL:
            continue
        times[d] = _plan_time(motions(robot), dyn)
    cost = {d: t + drive_time(abs(d - current), wh.max_accel, STABILISER_S)
            for d, t in times.items()}
    best = min(cost, key=lambda d: (cost[d], abs(d - current)))
    fastest = min(times.values())
    return Reposition(name, best, times[best] - times[current],
                      cost[best] - times[best],
                      max(0.0, times[current] - fastest) if np.isfinite(fastest) else 0.0)


def _drive(wh: Warehouse, site: Site, a: float, b: float, here: np.ndarray) -> PhaseRun:
    """Monitors of a move of the active base from offset ``a`` to ``b`` (m) with the
    platform held empty at ``here``: on its wheels at both ends, then every stabiliser
    down."""
    k = active_index(site.robot)
    flags = [bb.stabilisers_deployed and j != k for j, bb in enumerate(site.robot.bases)]
    robots = (_stabilisers(shifted(site.robot, a), flags),
              _stabilisers(shifted(site.robot, b), flags), shifted(site.robot, b))
    return hold_margins(tuple(with_box(r, 0.0) for r in robots), here, 0.0, wh, site.pose)


def _site_tasks(wh: Warehouse, site: Site, k: int, park: np.ndarray, log: _Log,
                dyn: DynamicsModel, simulate_runs: bool, tick: Callable[[], None],
                offsets: tuple[float, ...] = (), repos: list[Reposition] | None = None
                ) -> None:
    """Deploy, every task of the site (moving the active base between tasks when that
    pays off, :mod:`._reposition`), retract."""
    down = site.robot
    log.add("deploy", "", k, switch_stabilisers(with_box(down, 0.0), True, park,
                                                STABILISER_S, wh, site.pose),
            0.0, STABILISER_S, site.pose)
    here, offset = park, 0.0
    masses = {t.name: t.mass for t in wh.tasks}
    for name, pick, place in zip(site.task_names, site.picks, site.places):
        def motions(robot: CableRobot, m: float = masses[name], h: np.ndarray = here,
                    p: np.ndarray = pick, q: np.ndarray = place) -> list[Any]:
            return _task_motions(robot, m, h, p, q)
        move, drive = 0.0, None
        if offsets:
            choice = _choose_offset(wh, site, offsets, offset, name, motions, dyn)
            if repos is not None:
                repos.append(choice)
            if choice.offset != offset:
                move, drive = choice.move_time, _drive(wh, site, offset, choice.offset, here)
                offset = choice.offset
        for kind, robot, pts, extra in motions(shifted(down, offset)):
            run, base = _motion(wh, site, robot, pts, dyn, simulate_runs)
            if kind == "pick" and drive is not None:
                run, extra = _worst(run, drive), extra + move
            log.add(kind, name, k, run, extra, base, site.pose)
            tick()
        here = place
    run, base = _motion(wh, site, with_box(shifted(down, offset), 0.0), [here, park], dyn,
                        simulate_runs)
    held = switch_stabilisers(with_box(down, 0.0), False, park, STABILISER_S, wh, site.pose)
    back = drive_time(abs(offset), wh.max_accel, STABILISER_S)
    if offset != 0.0:
        held = _worst(held, _drive(wh, site, offset, 0.0, park))
    log.add("retract", "", k, _worst(run, held), STABILISER_S + back, base, site.pose)


def plan_mission(warehouse: Warehouse, *, dynamics: DynamicsModel | None = None,
                 simulate_runs: bool = True, site_step: float = 0.25,
                 active_base_offsets: Any = (),
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
    active_base_offsets : array_like (k,), default ()
        Offsets the active base may move to along the shelf face between tasks, m
        (:mod:`taut.cdpr.mission._reposition`); empty: it stays at the site's placement.
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
    offsets = tuple(float(v) for v in check_range(
        as_array(active_base_offsets, "active_base_offsets", shape=(None,)),
        "active_base_offsets", MAX_CDPR_LENGTH_M, "m"))
    repos: list[Reposition] = []
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
        held = navigate_run(warehouse, with_box(free, 0.0), park, nav)
        held = replace(held, times=held.times[:-1], platform=held.platform[:-1])
        log.add("navigate", "", k, held, 0.0, nav.duration, nav.poses)
        tick()
        _site_tasks(warehouse, site, k, park, log, dyn, simulate_runs, tick, offsets, repos)
        served += list(site.task_names)
        pose = site.pose
    return replace(_result(log, status, chosen, tuple(routes), tuple(served),
                           tuple(unserved)), repositions=tuple(repos))


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
