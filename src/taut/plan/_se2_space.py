"""Validity of a rigid formation's pose in SE(2): the state space of the SE(2) planner.

A state ``(x, y, psi)`` places formation ``f`` with the object's projection at ``(x, y)``,
turned by ``psi`` (rad). It is *valid* when

1. every robot centre is at least ``robot_radius + lateral_safety`` from every wall and
   every obstacle (robots drive on the ground: they never pass over an obstacle);
2. the robots' convex hull (the sheet's projection when every cable is taut) lies in the
   free space (walls are tall) and meets only obstacles the formation can hold the object
   above: ``height <= f.max_height`` (eq. 2: object height minus the height safety). With
   crossing disabled it meets no obstacle at all.

An obstacle passing under the sheet between two robots is then automatically narrower than
the gap it passes through: it would otherwise violate rule 1 on the way in.

Motions between two states are checked at states ``MOTION_RESOLUTION`` of robot motion
apart, against the rules tightened by half a resolution plus ``INFLATION``: every point of
the continuous motion is within half a resolution of a checked state (robot positions and
hence hull points move at most that far), so the continuous motion keeps the rules with
``INFLATION`` to spare. This is the per-interval proof the verifier relies on for rigid
motions.
"""

from __future__ import annotations

import numpy as np
import shapely
import shapely.affinity
from shapely.ops import unary_union

from . import _tol
from shapely.geometry.polygon import orient

from .formation import Formation
from .world import Scenario

__all__ = ["PoseChecker", "SLICES"]

#: Heading slices of the free-space sampler.
SLICES = 72


class PoseChecker:
    """Batched validity of states ``(K, 3)`` of one formation (see module docstring).

    Parameters
    ----------
    scenario : Scenario
    formation : Formation
    allow_crossing : bool
        False: no obstacle may meet the robots' hull (the SE(2) bypass baseline).
    resolution : float
        Largest robot displacement between checked states of a motion, m.
    """

    def __init__(self, scenario: Scenario, formation: Formation, *, allow_crossing: bool,
                 resolution: float = _tol.MOTION_RESOLUTION) -> None:
        world, team = scenario.world, scenario.team
        self.formation = formation
        self.resolution = float(resolution)
        pad = self.pad = 0.5 * self.resolution + _tol.INFLATION
        c = team.clearance + pad
        robots_free = world.geometry.buffer(-c, quad_segs=16)
        grown = [o.geometry.buffer(c, quad_segs=16) for o in world.obstacles]
        if grown:
            robots_free = robots_free.difference(unary_union(grown))
        self.robot_region = robots_free
        self.hull_region = world.geometry.buffer(-pad, quad_segs=16)
        blocked = [o.geometry.buffer(pad, quad_segs=16) for o in world.obstacles
                   if not allow_crossing or o.height > formation.max_height + _tol.GEOMETRY_TOL]
        self.blocked = unary_union(blocked) if blocked else None
        for g in (self.robot_region, self.hull_region, self.blocked):
            if g is not None:
                shapely.prepare(g)
        self.radius = float(np.linalg.norm(formation.robots, axis=1).max())
        self.checks = 0
        self._near_sets(scenario, allow_crossing)
        self.passages = self._passages(scenario, c) if allow_crossing else []
        self._blocked_geoms = [o.geometry for o in world.obstacles
                               if not allow_crossing
                               or o.height > formation.max_height + _tol.GEOMETRY_TOL]
        self._slices: dict[int, object] = {}
        hull = orient(shapely.convex_hull(shapely.multipoints(formation.robots)), 1.0)
        self.hull_idx = np.array([int(np.argmin(np.linalg.norm(formation.robots - q, axis=1)))
                                  for q in np.asarray(hull.exterior.coords)[:-1]])
        self.headings = 2 * np.pi * np.arange(SLICES) / SLICES - np.pi

    def _slice(self, k: int):
        """The object positions valid at heading ``headings[k]`` (a shapely geometry):
        every robot in the robot region, the hull clear of blocked obstacles (Minkowski
        sums of convex shapes) and of reflex wall vertices."""
        if k in self._slices:
            return self._slices[k]
        psi = float(self.headings[k])
        d = self.formation.placed(np.zeros(2), psi)
        region = self.robot_region
        for off in d:
            region = region.intersection(shapely.affinity.translate(self.robot_region,
                                                                    -off[0], -off[1]))
            if region.is_empty:
                break
        hull = d[self.hull_idx]
        cuts = []
        for g in self._blocked_geoms:
            v = np.asarray(shapely.convex_hull(g).exterior.coords)[:-1]
            cuts.append(shapely.convex_hull(shapely.multipoints(
                (v[:, None] - hull[None]).reshape(-1, 2))))
        for v in self.near_c[len(self.near_c) - self._n_reflex:]:
            cuts.append(shapely.Polygon(v - hull))
        if cuts and not region.is_empty:
            region = region.difference(unary_union(cuts).buffer(self.pad + _tol.INFLATION))
        shapely.prepare(region)
        self._slices[k] = region
        return region

    def free_sample(self, rng: np.random.Generator, tries: int = 4) -> np.ndarray | None:
        """A state sampled in the free part of a random heading slice (narrow corridors
        are sampled where they are; None when the slice drawn is empty)."""
        k = int(rng.integers(SLICES))
        region = self._slice(k)
        if region.is_empty:
            return None
        lo, hi = np.asarray(region.bounds[:2]), np.asarray(region.bounds[2:])
        for _ in range(tries):
            p = rng.uniform(lo, hi, (32, 2))
            inside = shapely.contains_xy(region, p[:, 0], p[:, 1])
            if inside.any():
                q = p[int(np.argmax(inside))]
                return np.array([q[0], q[1], self.headings[k]])
        return None

    def _passages(self, scenario: Scenario, c: float) -> list[tuple[np.ndarray, np.ndarray]]:
        """Per crossable obstacle: its centre and the points of the formation frame where
        it could be (inside the robots' hull, clear of every robot): where the narrow
        passages of crossing are."""
        f = self.formation
        lo, hi = f.robots.min(axis=0), f.robots.max(axis=0)
        g = np.stack(np.meshgrid(np.linspace(lo[0], hi[0], 25), np.linspace(lo[1], hi[1], 25)),
                     axis=-1).reshape(-1, 2)
        hull = shapely.convex_hull(shapely.multipoints(f.robots))
        g = g[shapely.covers(hull, shapely.points(g))]
        dist = np.linalg.norm(g[:, None] - f.robots[None], axis=2).min(axis=1)
        out = []
        for o in scenario.world.obstacles:
            if o.height > f.max_height + _tol.GEOMETRY_TOL:
                continue
            pts = g[dist >= o.mec_radius + c]
            if len(pts):
                out.append((o.mec_center, pts))
        return out

    def passage_sample(self, rng: np.random.Generator) -> np.ndarray | None:
        """A random state with a crossable obstacle under the sheet, clear of the robots
        (None when the formation can cross nothing)."""
        if not self.passages:
            return None
        centre, pts = self.passages[int(rng.integers(len(self.passages)))]
        p = pts[int(rng.integers(len(pts)))]
        psi = float(rng.uniform(-np.pi, np.pi))
        cs, sn = np.cos(psi), np.sin(psi)
        return np.array([centre[0] - (cs * p[0] - sn * p[1]),
                         centre[1] - (sn * p[0] + cs * p[1]), psi])

    def _near_sets(self, scenario: Scenario, allow_crossing: bool) -> None:
        """Points near which the hull test can fail: blocked obstacles (centre, radius)
        and reflex vertices of the walls (a convex world never cuts a hull whose robots
        are inside it)."""
        world, f = scenario.world, self.formation
        blocked = [o for o in world.obstacles
                   if not allow_crossing or o.height > f.max_height + _tol.GEOMETRY_TOL]
        ring = orient(world.geometry, 1.0).exterior
        p = np.asarray(ring.coords)[:-1]
        a, b = p - np.roll(p, 1, axis=0), np.roll(p, -1, axis=0) - p
        reflex = p[a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0] < 0]
        self.near_c = np.concatenate([np.array([o.mec_center for o in blocked]).reshape(-1, 2),
                                      reflex])
        self.near_r = np.concatenate([[o.mec_radius for o in blocked], np.zeros(len(reflex))])
        self.near_r = self.near_r + self.radius + 2 * self.resolution
        self._near_r2 = self.near_r ** 2
        self._n_reflex = len(reflex)

    def robots(self, states: np.ndarray) -> np.ndarray:
        """Robot positions ``(K, N, 2)`` of states ``(K, 3)``."""
        s = np.asarray(states, dtype=float).reshape(-1, 3)
        return self.formation.placed(s[:, :2], s[:, 2])

    def valid(self, states: np.ndarray) -> np.ndarray:
        """Bool ``(K,)``: which states are valid. The hull test runs only for states whose
        object is near a blocked obstacle or a reflex wall vertex (elsewhere the hull,
        within ``radius`` of the object, cannot meet either)."""
        r = self.robots(states)
        K, N = r.shape[:2]
        self.checks += K
        p = r.reshape(-1, 2)                     # point-in-region without point objects
        ok = shapely.intersects_xy(self.robot_region, p[:, 0], p[:, 1])
        ok = ok.reshape(K, N).all(axis=1)
        if not ok.any():
            return ok
        idx = np.flatnonzero(ok)
        if len(self.near_r):
            s = np.asarray(states, dtype=float).reshape(-1, 3)[idx, :2]
            d2 = ((s[:, None] - self.near_c[None]) ** 2).sum(axis=-1)
            idx = idx[(d2 <= self._near_r2[None]).any(axis=1)]
        else:
            idx = idx[:0]
        if not len(idx):
            return ok
        hulls = shapely.convex_hull(shapely.multipoints(r[idx]))
        good = shapely.covers(self.hull_region, hulls)
        if self.blocked is not None:
            good &= ~shapely.intersects(self.blocked, hulls)
        ok[idx] = good
        return ok

    def steps(self, a: np.ndarray, b: np.ndarray) -> int:
        """Number of intervals that keep every robot within ``resolution`` per interval on
        the straight SE(2) motion from ``a`` to ``b``."""
        move = float(np.hypot(b[0] - a[0], b[1] - a[1]) + abs(b[2] - a[2]) * self.radius)
        return max(1, int(np.ceil(move / self.resolution)))

    def motion_valid(self, a: np.ndarray, b: np.ndarray) -> bool:
        """Is the straight SE(2) motion from ``a`` to ``b`` (position and heading linear in
        a common parameter) valid? Checked from both ends inward, coarse to fine."""
        k = self.steps(a, b)
        s = np.arange(1, k) / k
        if not len(s):
            return True
        pts = a[None, :] + s[:, None] * (b - a)[None, :]
        for stride in (16, 4, 1):                       # coarse to fine: fail early
            if not self.valid(pts[stride - 1::stride] if stride > 1 else pts).all():
                return False
        return True

