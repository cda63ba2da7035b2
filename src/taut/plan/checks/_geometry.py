"""The geometric rules of a plan proved for the continuous motion between its samples
(:func:`taut.plan.checks.verify.verify_motion`, check 4).

The rules, as checked at the samples: every robot centre inside the free space and at least
``team.clearance`` from walls and obstacles; the robots' convex hull inside the free space
(walls are tall); the hull clear of every obstacle too tall for the object
(``height > z_object - height_safety``). Each is a *slack*, m, that is non-negative when
the rule holds (within the tolerance ``TOLERANCE``, which (a)-(c) include; (d) must stay
positive, the hull may not touch a too-tall obstacle):

(a) each robot's signed distance to the walls (negative outside) minus the clearance,
(b) each robot's distance to each obstacle minus the clearance (negative when inside),
(c) the hull's distance to the boundary of the free space grown by ``TOLERANCE`` (negative
    when the grown free space does not cover it),
(d) the hull's distance to each obstacle too tall for the object.

A robot distance is 1-Lipschitz in that robot's position, and a hull distance 1-Lipschitz
in the largest robot displacement (a hull point is a convex combination of robots, so it
moves no more than the farthest robot). So if no robot travels more than ``L`` between
samples ``t`` and ``t + 1``, at a fraction ``u`` of the way the slack is at least
``max(s_t - u L, s_{t+1} - (1 - u) L)``, which is non-negative everywhere when
``s_t + s_{t+1} >= L`` (both ends checked; ``>`` for the hull terms, so that (d) stays
positive): the interval is *proved*.

For the robot terms an interval is also proved by the robots' paths themselves: each
robot's chord (the segment between its positions at the ends) is measured exactly with
shapely, and its path strays from it by at most ``rho_i theta**2 / 8`` (none on straight
motions), so a chord keeping the clearance by that much proves the robot's path: a robot
gliding along a wall at the clearance is proved at once, where the slacks would need
pieces as short as its slack. Likewise for the hull terms: on straight motions the hull
stays in the convex hull of both ends' robots (turning strays from it by at most the
robots' bow), which is measured exactly.

The travel bound: on a rigid interval the team turns by the fitted angle ``theta`` about
its centroid while the centroid moves straight (as :func:`taut.plan.checks.verify.resample_motion`
interpolates), so robot ``i`` travels at most ``|dc| + rho_i |theta|`` (``rho_i`` its
distance to the centroid) plus the fit residual; elsewhere (formation changes) robots move
straight and travel ``|dr_i|``. The rigid bound also covers a straight motion between the
same samples (a chord is no longer than its arc).

The too-tall class of an interval uses its lowest object height: the object is carried
rigidly (constant height) on rigid intervals; on formation changes it is the lowest of the
model's samples in the interval minus the largest object step allowed between model
samples (the object may move that much between them). The model samples of formation
changes also keep the height safety above the ground.

Intervals not proved are bisected (rigidly or linearly, as the motion is), all at once,
until every piece is proved, an inserted pose breaks a rule, or ``_tol.PROOF_DEPTH``
bisections (or ``_tol.MAX_PROOF_POSES`` inserted poses) are reached: then the motion could
not be proved and the plan fails.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial
from typing import Callable

import numpy as np
import shapely

from .. import _tol
from ..world import Scenario

#: Absolute tolerance of the geometric checks, m (as in :mod:`taut.plan.checks.verify`).
TOLERANCE = _tol.GEOMETRY_TOL


#: Shapely points (P * N,) and convex hulls (P,) of P poses of N robots.
Shapes = tuple[np.ndarray, np.ndarray]


def beneath_height(scenario: Scenario, robots: np.ndarray) -> np.ndarray:
    """Height of the tallest obstacle whose footprint meets the convex hull of ``robots``
    (T, N, 2), m, per sample (0 when none)."""
    hulls = shapely.convex_hull(shapely.multipoints(robots))
    out = np.zeros(len(robots))
    for o in scenario.world.obstacles:
        out = np.where(shapely.intersects(hulls, o.geometry), np.maximum(out, o.height), out)
    return out


def pair_slack(scenario: Scenario, robots: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Sheet slack (sheet distance less robot distance) of every robot pair of ``robots``
    (T, N, 2), m: shape (T, P), and the pairs' robots ``i`` and ``j`` (P,), ``i < j``."""
    V = scenario.team.sheet.vertices
    iu, ju = np.triu_indices(V.shape[0], 1)
    slack = (np.linalg.norm(V[iu] - V[ju], axis=1)[None]
             - np.linalg.norm(robots[:, iu] - robots[:, ju], axis=2))
    return slack, iu, ju


def shapes_of(robots: np.ndarray) -> Shapes:
    """The robots' points and hulls of poses ``robots`` (P, N, 2), m, as shapely arrays."""
    return (shapely.points(robots.reshape(-1, 2)),
            shapely.convex_hull(shapely.multipoints(robots)))


@dataclass(frozen=True)
class _Terms:
    """Slack terms of P poses (module docstring), m."""

    inside: np.ndarray   # (P, N) bool: robot centre inside the free space
    robot: np.ndarray    # (P, N): terms (a)-(b), least per robot
    clear: np.ndarray    # (P, N): least distance to a wall or obstacle
    hull: np.ndarray     # (P,): term (c), -inf when not covered
    under: np.ndarray    # (P, M): hull distance to each obstacle (0: meets it)

    def take(self, idx: np.ndarray) -> _Terms:
        """The terms of poses ``idx``."""
        return _Terms(self.inside[idx], self.robot[idx], self.clear[idx], self.hull[idx],
                      self.under[idx])

    def hull_slack(self, tall: np.ndarray) -> np.ndarray:
        """Least of terms (c)-(d) per pose, (P,), with ``tall`` (P, M) the too-tall
        obstacles, m."""
        d = np.where(tall, self.under, np.inf).min(axis=1, initial=np.inf)
        return np.minimum(self.hull, d)


class _Space:
    """The scenario's geometry, vectorised over poses."""

    def __init__(self, scenario: Scenario) -> None:
        world, team = scenario.world, scenario.team
        # Prepared copies (faster predicates and distances; the world's own are left as is).
        self.free, self.grown, *self.obstacles = shapely.from_wkb(shapely.to_wkb(
            [world.geometry, world.geometry.buffer(TOLERANCE),
             *(o.geometry for o in world.obstacles)]))
        shapely.prepare([self.free, self.grown, *self.obstacles])
        self.walls, self.grown_edge = self.free.exterior, self.grown.boundary
        self.ids = [o.id for o in world.obstacles]
        self.heights = np.array([o.height for o in world.obstacles], dtype=float)
        self.clearance, self.safety = team.clearance, team.height_safety

    def distance(self, geoms: np.ndarray) -> np.ndarray:
        """Least distance of each geometry (points or paths) to a wall or obstacle, m."""
        clear = shapely.distance(self.walls, geoms)
        for g in self.obstacles:
            clear = np.minimum(clear, shapely.distance(g, geoms))
        return clear

    def terms(self, robots: np.ndarray, shapes: Shapes | None = None) -> _Terms:
        """Slack terms of poses ``robots`` (P, N, 2), m (``shapes``: their points and hulls
        when already built)."""
        P, N = robots.shape[:2]
        pts, hulls = shapes if shapes is not None else shapes_of(robots)
        inside = shapely.contains(self.free, pts).reshape(P, N)
        walls = shapely.distance(self.walls, pts).reshape(P, N)
        clear = walls
        for g in self.obstacles:
            clear = np.minimum(clear, shapely.distance(g, pts).reshape(P, N))
        robot = np.where(inside, clear, -walls) - self.clearance + TOLERANCE
        hull = np.where(shapely.covers(self.grown, hulls),
                        shapely.distance(self.grown_edge, hulls), -np.inf)
        under = np.empty((P, len(self.obstacles)))
        for m, g in enumerate(self.obstacles):
            under[:, m] = shapely.distance(g, hulls)
        return _Terms(inside, robot, clear, hull, under)

    def tall(self, z: np.ndarray) -> np.ndarray:
        """(len(z), M): obstacles too tall for an object at heights ``z``, m."""
        return self.heights[None, :] > z[:, None] - self.safety + TOLERANCE

    def broken(self, t: _Terms, tall: np.ndarray, z: np.ndarray, key: np.ndarray,
               where: Callable[[int], str]) -> str | None:
        """Message for the pose of least ``key`` breaking a rule (``tall`` (P, M), object
        heights ``z`` (P,), m; ``where(p)`` names pose ``p``), or None."""
        bad = (~t.inside.all(axis=1) | (t.hull < 0) | (tall & (t.under <= 0)).any(axis=1)
               | (t.robot < 0).any(axis=1))
        if not bad.any():
            return None
        p = int(np.flatnonzero(bad)[np.argmin(key[bad])])
        if not t.inside[p].all():
            return f"robot {int(np.argmin(t.inside[p])) + 1} leaves the free space {where(p)}"
        if t.hull[p] < 0:
            return f"the sheet crosses a wall {where(p)}"
        hit = tall[p] & (t.under[p] <= 0)
        if hit.any():
            m = int(np.argmax(hit))
            return (f"object only {z[p] - self.heights[m]:.3g} m above obstacle "
                    f"{self.ids[m]!r} {where(p)} (height safety {self.safety:.3g} m)")
        i = int(np.argmin(t.robot[p]))
        return f"robot {i + 1} only {t.clear[p, i]:.3g} m from a wall or obstacle {where(p)}"

    def margin(self, t: _Terms, z: np.ndarray) -> float:
        """Least (object height ``z`` (P,) - obstacle height) over poses with an obstacle
        beneath the hull, m (inf when none)."""
        m = np.where(t.under <= 0, z[:, None] - self.heights[None, :], np.inf)
        return float(m.min(initial=np.inf))


class _Motion:
    """The continuous motion between samples: rigid or straight per interval."""

    def __init__(self, robots: np.ndarray, rigid: np.ndarray) -> None:
        a, b = robots[:-1], robots[1:]
        ca, cb = a.mean(axis=1), b.mean(axis=1)
        rel = a - ca[:, None]
        self.angle, fit = rigid_fits(a, b)
        resid = np.linalg.norm(fit - b, axis=2).max(axis=1)
        turn = np.linalg.norm(cb - ca, axis=1) + (np.linalg.norm(rel, axis=2).max(axis=1)
                                                  * np.abs(self.angle)) + resid
        straight = np.linalg.norm(b - a, axis=2).max(axis=1)
        self.robots, self.rigid, self.centre, self.move = robots, rigid, ca, cb - ca
        self.radius, self.resid = np.linalg.norm(rel, axis=2), resid    # (T-1, N), (T-1,)
        self.travel = np.where(rigid, turn, straight)   # (T-1,) travel bound, m

    def bow(self, k: np.ndarray, width: np.ndarray) -> np.ndarray:
        """(P, N): how far each robot's path strays from the chord between its positions
        at the ends of pieces ``width`` (P,) long (fractions) of intervals ``k`` (P,), m.
        The turning part ``R(u theta) v`` has second derivative ``theta**2 |v|``, so it
        strays at most ``|v| (theta w)**2 / 8`` from its chord; the straight part none."""
        bend = self.radius[k] * ((self.angle[k] * width) ** 2 / 8)[:, None] \
            + self.resid[k][:, None]
        return np.where(self.rigid[k][:, None], bend, 0.0)

    def at(self, k: np.ndarray, u: np.ndarray) -> np.ndarray:
        """Poses (P, N, 2) a fraction ``u`` (P,) of the way through intervals ``k`` (P,)."""
        a, b = self.robots[k], self.robots[k + 1]
        c = self.centre[k][:, None]
        turned = _turn(a - c, u * self.angle[k]) + c + (u[:, None] * self.move[k])[:, None]
        lin = a + u[:, None, None] * (b - a)
        return np.where(self.rigid[k][:, None, None], turned, lin)


def rigid_fits(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Best rigid motions (Kabsch without reflection) mapping each ``a[k]`` (K, N, 2) onto
    ``b[k]``: their angles (K,), rad, and ``a`` so moved (K, N, 2)."""
    ca, cb = a.mean(axis=1, keepdims=True), b.mean(axis=1, keepdims=True)
    rel = a - ca
    h = np.einsum("kni,knj->kij", rel, b - cb)
    angle = np.arctan2(h[:, 0, 1] - h[:, 1, 0], h[:, 0, 0] + h[:, 1, 1])
    return angle, _turn(rel, angle) + cb


def pair_closest(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Least distance of every robot pair (``triu_indices`` order) while the robots move
    straight from ``a`` to ``b`` (..., N, 2) at the same time, m (..., P): a pair's
    relative position is linear in time, so the least distance has a closed form."""
    iu, ju = np.triu_indices(a.shape[-2], 1)
    d0 = a[..., iu, :] - a[..., ju, :]
    e = (b[..., iu, :] - b[..., ju, :]) - d0
    ee = (e * e).sum(axis=-1)
    t = np.clip(-(d0 * e).sum(axis=-1) / np.where(ee > 0, ee, 1.0), 0.0, 1.0)
    return np.linalg.norm(d0 + t[..., None] * e, axis=-1)


def _turn(rel: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Points ``rel`` (P, N, 2) turned by ``angle`` (P,) rad about the origin."""
    c, s = np.cos(angle)[:, None], np.sin(angle)[:, None]
    return np.stack([c * rel[..., 0] - s * rel[..., 1], s * rel[..., 0] + c * rel[..., 1]],
                    axis=-1)


def prove_between(scenario: Scenario, robots: np.ndarray, z_model: np.ndarray,
                  rigid: np.ndarray, object_step: float, shapes: Shapes | None = None
                  ) -> tuple[float, float, str | None]:
    """Prove the geometric rules between samples (module docstring) and find the least
    clearance of the continuous motion.

    Parameters
    ----------
    scenario : Scenario
    robots : ndarray, shape (T, N, 2)
        Robot positions per sample, m (each sample already meets the rules).
    z_model : ndarray, shape (T - 1,)
        Lowest object height over the model samples of each interval, m.
    rigid : ndarray of bool, shape (T - 1,)
        Intervals that are rigid motions of the team.
    object_step : float
        Largest object step between model samples on formation changes, m.
    shapes : tuple, optional
        :func:`shapes_of` the samples, when already built.

    Returns
    -------
    min_height_margin : float
        Least (object height - obstacle height) over inserted poses with an obstacle
        beneath the hull (the interval's lowest object height), m (inf when none).
    min_clearance : float
        Least robot-centre distance to a wall or obstacle over the continuous motion, m,
        to ``_tol.CLEARANCE_ACCURACY`` (:func:`_least_clearance`; inf for one sample).
    message : str or None
        The first rule broken between samples, or why the motion could not be proved.
    """
    if len(robots) < 2:
        return np.inf, np.inf, None
    space, motion = _Space(scenario), _Motion(robots, rigid)
    k = np.arange(len(robots) - 1)
    low = np.flatnonzero(z_model < space.safety - TOLERANCE)
    if len(low):
        return -np.inf, -np.inf, ("object closer to the ground than the height safety "
                                  + _between(k, int(low[0])))
    z_low = np.where(rigid, z_model, z_model - object_step)
    tall = space.tall(z_low)
    ends = space.terms(robots, shapes)
    # Each sample is an end of two intervals, whose too-tall classes may differ.
    head, tail = ends.take(k), ends.take(k + 1)
    for t in (head, tail):
        why = space.broken(t, tall, z_low, k.astype(float), partial(_between, k))
        if why is not None:
            return -np.inf, -np.inf, why
    whole = _Pieces(k, np.zeros(len(k)), np.ones(len(k)), robots[:-1], robots[1:])
    slack = (head.robot.min(axis=1), tail.robot.min(axis=1), head.hull_slack(tall),
             tail.hull_slack(tall))
    margin, why = _bisect(space, motion, tall, z_low, whole, slack)
    if why is not None:
        return margin, -np.inf, why
    return margin, _least_clearance(space, motion, ends.clear.min(axis=1)), None


def _between(k: np.ndarray, p: int) -> str:
    """Names the interval of pose ``p`` (``k`` the interval of each pose)."""
    return f"between samples {k[p]} and {k[p] + 1}"


@dataclass(frozen=True)
class _Pieces:
    """P pieces ``[lo, hi]`` (fractions) of intervals ``k``, with the robots at their ends
    ``a``, ``b`` (P, N, 2), m."""

    k: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    a: np.ndarray
    b: np.ndarray

    def take(self, idx: np.ndarray) -> _Pieces:
        """The pieces ``idx``."""
        return _Pieces(self.k[idx], self.lo[idx], self.hi[idx], self.a[idx], self.b[idx])

    def halves(self, motion: _Motion) -> tuple[_Pieces, np.ndarray]:
        """The first halves, then the second halves, and the poses between (P, N, 2)."""
        mid = (self.lo + self.hi) / 2
        m = motion.at(self.k, mid)
        cat = np.concatenate
        return _Pieces(cat([self.k, self.k]), cat([self.lo, mid]), cat([mid, self.hi]),
                       cat([self.a, m]), cat([m, self.b])), m

    def chords(self, space: _Space, motion: _Motion) -> tuple[np.ndarray, np.ndarray]:
        """(P, N) each robot's chord distance to walls and obstacles and how far its path
        strays from the chord, m: its clearance on the piece is within the latter of the
        former's (exact on straight motions)."""
        P, N = self.a.shape[:2]
        lines = shapely.linestrings(np.stack([self.a, self.b], axis=2).reshape(P * N, 2, 2))
        return space.distance(lines).reshape(P, N), motion.bow(self.k, self.hi - self.lo)

    def swept_clear(self, space: _Space, motion: _Motion, tall: np.ndarray) -> np.ndarray:
        """(P,) pieces whose hull keeps terms (c)-(d) all along: on straight motions every
        hull point is a convex combination of the robots' chord points, so the hull stays
        in the convex hull of both ends' robots; turning strays from it by at most the
        robots' bow (:meth:`chords`), which the distances must exceed."""
        swept = shapely.convex_hull(shapely.multipoints(np.concatenate([self.a, self.b],
                                                                       axis=1)))
        bow = motion.bow(self.k, self.hi - self.lo).max(axis=1)
        ok = shapely.covers(space.grown, swept) & (shapely.distance(space.grown_edge, swept)
                                                    >= bow)
        for m, g in enumerate(space.obstacles):
            ok &= ~tall[:, m] | (shapely.distance(g, swept) > bow)
        return ok


def _proved(space: _Space, motion: _Motion, pieces: _Pieces, slack: tuple,
            tall: np.ndarray) -> np.ndarray:
    """(P,) pieces on which no rule can break: the hull terms' end slacks (m) add up to the
    robots' travel or the swept hull keeps them (:meth:`_Pieces.swept_clear`; ``tall``
    (P, M) the too-tall obstacles), and so do the robot terms' or the robots' chords keep
    the clearance (then each path stays inside the free space too)."""
    r0, r1, h0, h1 = slack
    travel = (pieces.hi - pieces.lo) * motion.travel[pieces.k]
    robot, hull = r0 + r1 >= travel, h0 + h1 > travel
    ask = np.flatnonzero(~hull)
    if len(ask):
        hull[ask] = pieces.take(ask).swept_clear(space, motion, tall[ask])
    ask = np.flatnonzero(hull & ~robot)
    if len(ask):
        d, bow = pieces.take(ask).chords(space, motion)
        least = (d - bow).min(axis=1)
        robot[ask] = (least > 0) & (least - space.clearance + TOLERANCE >= 0)
    return robot & hull


def _bisect(space: _Space, motion: _Motion, tall: np.ndarray, z_low: np.ndarray,
            pieces: _Pieces, slack: tuple) -> tuple[float, str | None]:
    """Bisect the pieces not proved by their end slacks ``slack`` (robot terms at either
    end, hull terms at either end: four arrays (P,), m), all at once, level by level
    (:func:`prove_between`): (least height margin over inserted poses, m, message or
    None)."""
    keep = ~_proved(space, motion, pieces, slack, tall[pieces.k])
    pieces, slack = pieces.take(keep), tuple(x[keep] for x in slack)
    margin, budget = np.inf, _tol.MAX_PROOF_POSES
    for _ in range(_tol.PROOF_DEPTH):
        k = pieces.k
        if not len(k) or len(k) > budget:
            break
        budget -= len(k)
        pieces, mid = pieces.halves(motion)
        t = space.terms(mid)
        margin = min(margin, space.margin(t, z_low[k]))
        why = space.broken(t, tall[k], z_low[k], k + pieces.hi[:len(k)],
                           partial(_between, k))
        if why is not None:
            return margin, why
        r0, r1, h0, h1 = slack
        rm, hm = t.robot.min(axis=1), t.hull_slack(tall[k])
        cat = np.concatenate
        slack = (cat([r0, rm]), cat([rm, r1]), cat([h0, hm]), cat([hm, h1]))
        keep = ~_proved(space, motion, pieces, slack, tall[pieces.k])
        pieces, slack = pieces.take(keep), tuple(x[keep] for x in slack)
    if len(pieces.k):
        first = int(pieces.k.min())
        return margin, (f"the motion could not be proved clear of walls and obstacles "
                        f"between samples {first} and {first + 1} (bisected "
                        f"{_tol.PROOF_DEPTH} times, or more than {_tol.MAX_PROOF_POSES} "
                        "poses inserted)")
    return margin, None


def _least_clearance(space: _Space, motion: _Motion, ends: np.ndarray) -> float:
    """Least robot-centre clearance of the continuous motion, m: a lower bound within
    ``_tol.CLEARANCE_ACCURACY`` of it (branch and bound over pieces of intervals).

    ``ends`` (T,) is the least clearance at each sample, m. An interval's clearance is at
    least ``(c_t + c_{t+1} - travel) / 2`` (1-Lipschitz); an interval that bound cannot set
    aside is measured along each robot's chord (:meth:`_Pieces.chords`): exact on straight
    motions, and bisected where turning leaves the bound too loose."""
    acc = _tol.CLEARANCE_ACCURACY
    best = float(ends.min())                       # an upper bound of the least clearance
    bound = (ends[:-1] + ends[1:] - motion.travel) / 2
    open_ = bound < best - acc
    lower = float(bound[~open_].min(initial=best))
    k = np.flatnonzero(open_)
    pieces = _Pieces(k, np.zeros(len(k)), np.ones(len(k)), motion.robots[k],
                     motion.robots[k + 1])
    bound, budget = bound[k], _tol.MAX_PROOF_POSES
    for _ in range(_tol.PROOF_DEPTH):
        if not len(pieces.k) or len(pieces.k) > budget:
            break
        budget -= len(pieces.k)
        d, bow = pieces.chords(space, motion)
        bound = (d - bow).min(axis=1)
        best = min(best, float((d + bow).min(axis=1).min()))
        done = bound >= best - acc
        lower = min(lower, float(bound[done].min(initial=np.inf)))
        pieces, _ = pieces.take(~done).halves(motion)
        bound = np.tile(bound[~done], 2)
    return min(lower, float(bound.min(initial=np.inf)))
