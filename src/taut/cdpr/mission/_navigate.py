"""Engine of :func:`taut.cdpr.mission.navigation.plan_navigation` (private): the route on the
sheet planner's lattice, its timing, and the independent verification."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import shapely

from ..._outcome import check_status
from ...plan.se2._rigid import rigid_route
from ...plan.world import Obstacle, World
from .._tol import NAV_PROOF_DEPTH, NAV_TOL
from .warehouse import Warehouse

__all__ = ["NavigationCertificate", "NavigationResult", "navigate", "grown",
           "footprint_slack", "nav_world"]


@dataclass(frozen=True, eq=False)
class NavigationCertificate:
    """Why no route was returned, and what is proven.

    Attributes
    ----------
    kind : {"start_collides", "goal_collides", "disconnected", "budget"}
    proven : bool
        True for a proof (a colliding end pose; the lattice's free space disconnected, a
        proof at ``spacing`` only), False for a diagnosis (budget).
    spacing : float
        Lattice spacing of the search, m (NaN when no search ran).
    headings : int
        Headings of the lattice (0 when no search ran).
    expanded : int
        Lattice nodes expanded.
    blockers : tuple of str
        Shelves (or ``"walls"``) the colliding footprint meets.
    message : str
        The statement in one sentence: what is proven, what is not.
    """

    kind: str
    proven: bool
    spacing: float
    headings: int
    expanded: int
    blockers: tuple[str, ...]
    message: str


@dataclass(frozen=True, eq=False)
class NavigationResult:
    """Outcome of :func:`plan_navigation`.

    Attributes
    ----------
    success : bool
    status : str
        ``"ok"``; ``"unreachable"`` (an end pose collides), ``"no_route"`` (no lattice
        route), ``"budget_exhausted"``, or ``"unverified"`` (the verifier refused the
        timed motion).
    message : str
    times : ndarray (T,)
        Sample times, s, from 0 (empty when refused).
    poses : ndarray (T, 3)
        ``(x, y, yaw)`` of the coupled bases at ``times``, m and rad (yaw unwrapped).
    duration : float
        s (NaN when refused).
    waypoints : ndarray (K, 3)
        Corners of the route (straight SE(2) segments between them), m and rad.
    length : float
        Travelled distance of the footprint's origin, m.
    min_clearance : float
        Least gap between the footprint and any wall or shelf over the verified samples, m
        (at least the warehouse's ``clearance`` on success).
    spacing : float
        Lattice spacing used, m.
    certificate : NavigationCertificate or None
        When refused: what is proven (a certificate) or not (a diagnosis).
    """

    success: bool
    status: str
    message: str
    times: np.ndarray
    poses: np.ndarray
    duration: float
    waypoints: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    length: float = float("nan")
    min_clearance: float = float("nan")
    spacing: float = float("nan")
    certificate: NavigationCertificate | None = None

    def __post_init__(self) -> None:
        check_status(self.status)



def grown(body: np.ndarray, margin: float) -> np.ndarray:
    """The convex polygon ``body`` (p, 2), counter-clockwise, with every edge moved out by
    ``margin`` m (sharp corners: it contains the body's ``margin`` buffer)."""
    e = np.roll(body, -1, axis=0) - body
    n = np.column_stack([e[:, 1], -e[:, 0]]) / np.linalg.norm(e, axis=1)[:, None]
    n_in, n_out = np.roll(n, 1, axis=0), n           # edges into and out of each vertex
    return body + margin * (n_in + n_out) / (1.0 + np.sum(n_in * n_out, axis=1))[:, None]


def nav_world(warehouse: Warehouse) -> World:
    """The warehouse as the sheet planner's world: the floor, every shelf an obstacle."""
    return World(np.asarray(warehouse.floor.exterior.coords)[:-1],
                 tuple(Obstacle(s.name, 1.0, polygon=np.asarray(s.footprint.exterior.coords)[:-1])
                       for s in warehouse.shelves))


def _placed(body: np.ndarray, poses: np.ndarray) -> np.ndarray:
    """Body vertices (P, p, 2) at poses (P, 3)."""
    c, s = np.cos(poses[:, 2]), np.sin(poses[:, 2])
    x = c[:, None] * body[None, :, 0] - s[:, None] * body[None, :, 1] + poses[:, :1]
    y = s[:, None] * body[None, :, 0] + c[:, None] * body[None, :, 1] + poses[:, 1:2]
    return np.stack([x, y], axis=-1)


def footprint_slack(warehouse: Warehouse, body: np.ndarray, poses: np.ndarray
                    ) -> tuple[np.ndarray, list[tuple[str, ...]]]:
    """Least gap (P,) between the footprint ``body`` at ``poses`` and any wall or shelf,
    m (negative when outside the floor or overlapping a shelf: minus the overlap's
    extent), measured with shapely, and the names it comes closer than ``clearance`` to."""
    polys = shapely.polygons(_placed(body, np.atleast_2d(poses)))
    floor = warehouse.floor
    inside = shapely.covers(floor, polys)
    gap = np.where(inside, shapely.distance(floor.exterior, polys), -1.0)
    near: list[list[str]] = [[] if g >= warehouse.clearance - NAV_TOL else ["walls"]
                             for g in gap]
    for sh in warehouse.shelves:
        d = shapely.distance(sh.footprint, polys)
        hit = shapely.intersects(sh.footprint, polys)
        d = np.where(hit, -shapely.area(shapely.intersection(sh.footprint, polys)) - NAV_TOL,
                     d)
        for k in np.flatnonzero(d < warehouse.clearance - NAV_TOL):
            near[k].append(sh.name)
        gap = np.minimum(gap, d)
    return gap, [tuple(n) for n in near]


def _rates(a: np.ndarray, b: np.ndarray, limits: tuple[float, float, float],
           radius: float) -> tuple[np.ndarray, np.ndarray]:
    """Largest rate (1/s) and acceleration (1/s^2) of the segment parameter ``s`` in [0, 1]
    of straight SE(2) segments from ``a`` to ``b`` (K, 3) under the speed, acceleration and
    turning-rate ``limits`` (the acceleration also for a point at ``radius`` m turning)."""
    v, acc, om = limits
    d = np.linalg.norm(b[:, :2] - a[:, :2], axis=1)
    th = np.abs(b[:, 2] - a[:, 2])
    rate = np.minimum(np.where(d > 0, v / np.maximum(d, 1e-300), np.inf),
                      np.where(th > 0, om / np.maximum(th, 1e-300), np.inf))
    most = np.minimum(np.where(d > 0, acc / np.maximum(d, 1e-300), np.inf),
                      np.where(th > 0, acc / np.maximum(radius * th, 1e-300), np.inf))
    return rate, most


def _profile(w: np.ndarray, limits: tuple[float, float, float], radius: float
             ) -> np.ndarray:
    """Durations (K-1,) of rest-to-rest trapezoidal profiles along the straight SE(2)
    segments of ``w`` (K, 3): speed <= v, turn rate <= omega, acceleration <= a for the
    reference point and (turning) for the farthest footprint point at ``radius``."""
    rate, acc = _rates(w[:-1], w[1:], limits, radius)
    tri = rate ** 2 >= acc                         # never reaches the top rate
    with np.errstate(invalid="ignore", divide="ignore"):     # zero-length segments: 0 s
        return np.where(tri, 2.0 * np.sqrt(1.0 / acc), 1.0 / rate + rate / acc)


def _pose_at(w: np.ndarray, ends: np.ndarray, t: np.ndarray,
             limits: tuple[float, float, float], radius: float) -> np.ndarray:
    """Poses (T, 3) at times ``t`` of the timed route (segment end times ``ends``)."""
    dur = np.diff(np.concatenate([[0.0], ends]))
    seg = np.clip(np.searchsorted(ends, t, side="left"), 0, len(dur) - 1)
    tau = np.clip(t - (ends[seg] - dur[seg]), 0.0, dur[seg])
    T = dur[seg]
    rate, acc = _rates(w[seg], w[seg + 1], limits, radius)
    rate = np.minimum(rate, np.sqrt(acc))          # triangular profiles peak lower
    ta = rate / acc
    s = np.where(tau < ta, 0.5 * acc * tau ** 2,
                 np.where(tau > T - ta, 1.0 - 0.5 * acc * (T - tau) ** 2,
                          0.5 * acc * ta ** 2 + rate * (tau - ta)))
    s = np.clip(s, 0.0, 1.0)
    return w[seg] + s[:, None] * (w[seg + 1] - w[seg])


def _verify(warehouse: Warehouse, body: np.ndarray, pose_at, times: np.ndarray
            ) -> tuple[bool, float, str]:
    """Every instant of the timed motion keeps the clearance: samples measured with
    shapely, intervals proved by the 1-Lipschitz bound (a footprint point moves at most
    ``|dxy| + R |dyaw|`` between two samples of one straight segment), unproved intervals
    bisected. Returns (proved, least gap m, message)."""
    radius = float(np.linalg.norm(body, axis=1).max())
    t = np.asarray(times, float)
    gap, _ = footprint_slack(warehouse, body, pose_at(t))
    least = float(gap.min())
    for _ in range(NAV_PROOF_DEPTH):
        slack = gap - warehouse.clearance + NAV_TOL
        if slack.min() < 0:
            k = int(np.argmin(slack))
            return False, least, (f"the footprint comes {gap[k]:.3g} m from a wall or shelf "
                                  f"at t = {t[k]:.3g} s (clearance {warehouse.clearance:.3g} m)")
        p = pose_at(t)
        travel = (np.linalg.norm(np.diff(p[:, :2], axis=0), axis=1)
                  + radius * np.abs(np.diff(p[:, 2])))
        bad = slack[:-1] + slack[1:] < travel
        if not bad.any():
            return True, least, "verified at every instant"
        mid = 0.5 * (t[:-1][bad] + t[1:][bad])
        g, _ = footprint_slack(warehouse, body, pose_at(mid))
        least = min(least, float(g.min()))
        order = np.argsort(np.concatenate([t, mid]), kind="stable")
        t = np.concatenate([t, mid])[order]
        gap = np.concatenate([gap, g])[order]
    return False, least, f"not proved after {NAV_PROOF_DEPTH} bisections"


def _refusal(status: str, kind: str, proven: bool, message: str, spacing: float = np.nan,
             headings: int = 0, expanded: int = 0, blockers: tuple[str, ...] = ()
             ) -> NavigationResult:
    cert = NavigationCertificate(kind, proven, spacing, headings, expanded, blockers, message)
    return NavigationResult(False, status, message, np.zeros(0), np.zeros((0, 3)), np.nan,
                            spacing=spacing, certificate=cert)


def navigate(warehouse: Warehouse, start: np.ndarray, goal: np.ndarray,
             limits: tuple[float, float, float], spacing: float, expansions: int,
             dt: float) -> NavigationResult:
    """:func:`~taut.cdpr.mission.navigation.plan_navigation` on validated inputs."""
    body = np.asarray(warehouse.body)
    for name, pose in (("start", start), ("goal", goal)):
        gap, near = footprint_slack(warehouse, body, pose[None])
        if gap[0] < warehouse.clearance - NAV_TOL:
            who = ", ".join(near[0])
            how = (f"overlaps or leaves {who}" if gap[0] < 0 else
                   f"comes {gap[0]:.3g} m from {who}")
            return _refusal("unreachable", f"{name}_collides", True,
                            f"no route: the coupled bases' footprint at the {name} "
                            f"({pose[0]:.3g}, {pose[1]:.3g}) m, {pose[2]:.3g} rad {how} "
                            f"(clearance {warehouse.clearance:.3g} m): proven, the pose "
                            "itself is invalid", blockers=near[0])
    radius = float(np.linalg.norm(body, axis=1).max())
    route = rigid_route(grown(body, warehouse.clearance), nav_world(warehouse), 0.0, start,
                        goal, spacing=spacing, speed=limits[0], rotation_speed=limits[2],
                        expansions=expansions, rng=np.random.default_rng(0))
    where = f"a lattice of {route.spacing:.3g} m and {route.headings} headings"
    if route.waypoints is None:
        if not (route.start_valid and route.goal_valid and route.goal_linked):
            end = "start" if not route.start_valid else "goal"
            return _refusal("no_route", "end_tight", False,
                            f"no route found: the {end} keeps the clearance only with "
                            f"rounded corners, not with the lattice's sharp-cornered margin "
                            f"or from {where}; a route is not ruled out", route.spacing,
                            route.headings)
        if route.exhausted:
            return _refusal("budget_exhausted", "budget", False,
                            f"no route within {expansions} lattice expansions on {where}: "
                            "nothing proven", route.spacing, route.headings, route.expanded)
        return _refusal("no_route", "disconnected", True,
                        f"no route: on {where} the start and goal poses are not connected "
                        f"(all {route.expanded} reachable lattice poses searched); proven at "
                        "this resolution only: no route keeps about a lattice spacing of "
                        "footprint motion to spare, a tighter one is not ruled out",
                        route.spacing, route.headings, route.expanded)
    w = route.waypoints
    w = w[np.concatenate([[True], np.abs(np.diff(w, axis=0)).max(axis=1) > 0.0])]
    if len(w) < 2:
        w = np.vstack([w, w])
    dur = _profile(w, limits, radius)
    dur = np.where(np.isfinite(dur), dur, 0.0)
    ends = np.cumsum(dur)
    total = float(ends[-1])

    def pose_at(t: np.ndarray) -> np.ndarray:
        return _pose_at(w, ends, np.asarray(t, float), limits, radius) if total > 0 else \
            np.repeat(w[:1], len(np.atleast_1d(t)), axis=0)

    times = np.union1d(np.arange(0.0, total, dt), np.concatenate([[0.0], ends]))
    ok, least, why = _verify(warehouse, body, pose_at, times)
    poses = pose_at(times)
    length = float(np.linalg.norm(np.diff(w[:, :2], axis=0), axis=1).sum())
    if not ok:
        return NavigationResult(False, "unverified", f"route rejected by verification: {why}",
                                times, poses, total, w, length, least, route.spacing)
    return NavigationResult(True, "ok", f"route of {length:.3g} m in {total:.3g} s "
                            f"({len(w) - 1} straight segments, least gap {least:.3g} m), "
                            "verified at every instant", times, poses, total, w, length,
                            least, route.spacing)
