"""Validity of a rigid formation's pose in SE(2): the state space of the SE(2) planner.

A state ``(x, y, psi)`` places formation ``f`` with the object's projection at ``(x, y)``,
turned by ``psi`` (rad). It is *valid* when

1. every robot centre is at least ``robot_radius + lateral_safety`` from every wall and
   every obstacle (robots drive on the ground: they never pass over an obstacle);
2. the robots' convex hull (the sheet's projection when every cable is taut) lies in the
   free space (walls are tall) and meets only obstacles the formation can hold the object
   above: ``height <= f.max_height`` (eq. 2: object height minus the height safety), and
   keeps ``POSITION_ACCURACY`` from the others (so that robots off their places by that
   much cannot bring the sheet onto them). With crossing disabled it meets no obstacle at
   all;

each with ``STATE_CLEARANCE`` to spare. An obstacle passing under the sheet between two
robots is then automatically narrower than the gap it passes through: it would otherwise
violate rule 1 on the way in.

The rules are evaluated by compiled code (:mod:`taut.plan._kernels.clearance`) as a
*clearance*: how far the robots may move before a rule breaks. Motions between two
states (and in-place formation changes) are proved valid by conservative advancement on
that clearance: every pose of the continuous motion keeps the rules with
``MOTION_MARGIN`` to spare. This is the per-interval proof the verifier relies on for
rigid motions. Shapely geometry is kept only for the samplers (free parts of heading
slices, passages under the sheet).
"""

from __future__ import annotations

import numpy as np
import shapely
import shapely.affinity
from shapely.geometry.polygon import orient
from shapely.ops import unary_union

from .. import _tol
from .._kernels.clearance import morph_clear
from ._body import BodyChecker, kernel_world
from ..formations.optimal import Formation
from ..world import Scenario

__all__ = ["PoseChecker", "SLICES", "morph_valid"]

#: Heading slices of the free-space sampler.
SLICES = 72


class PoseChecker(BodyChecker):
    """Batched validity of states ``(K, 3)`` of one formation (see module docstring).

    Parameters
    ----------
    scenario : Scenario
    formation : Formation
    allow_crossing : bool
        False: no obstacle may meet the robots' hull (the SE(2) bypass baseline).
    """

    def __init__(self, scenario: Scenario, formation: Formation, *,
                 allow_crossing: bool) -> None:
        world, team = scenario.world, scenario.team
        self.formation = formation
        self.allow_crossing = bool(allow_crossing)
        blocked = [not allow_crossing or o.height > formation.max_height + _tol.GEOMETRY_TOL
                   for o in world.obstacles]
        super().__init__(formation.robots,
                         *kernel_world(world, blocked, _tol.POSITION_ACCURACY),
                         team.clearance)
        # Shapely geometry of the samplers only (validity is decided by the kernel).
        pad = self.pad = _tol.STATE_CLEARANCE
        c = team.clearance + pad
        robots_free = world.geometry.buffer(-c, quad_segs=16)
        grown = [o.geometry.buffer(c, quad_segs=16) for o in world.obstacles]
        if grown:
            robots_free = robots_free.difference(unary_union(grown))
        self.robot_region = robots_free
        shapely.prepare(self.robot_region)
        self._blocked_geoms = [o.geometry for o, bl in zip(world.obstacles, blocked) if bl]
        self._reflex = _reflex_vertices(scenario)
        self.passages = self._passages(scenario, c) if allow_crossing else []
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
        for v in self._reflex:
            cuts.append(shapely.Polygon(v - hull))
        if cuts and not region.is_empty:
            region = region.difference(unary_union(cuts).buffer(self.pad))
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

    def robots(self, states: np.ndarray) -> np.ndarray:
        """Robot positions ``(K, N, 2)`` of states ``(K, 3)``."""
        s = np.asarray(states, dtype=float).reshape(-1, 3)
        return self.formation.placed(s[:, :2], s[:, 2])


def _reflex_vertices(scenario: Scenario) -> np.ndarray:
    """Reflex vertices of the walls (a convex world never cuts a hull whose robots are
    inside it)."""
    ring = orient(scenario.world.geometry, 1.0).exterior
    p = np.asarray(ring.coords)[:-1]
    a, b = p - np.roll(p, 1, axis=0), np.roll(p, -1, axis=0) - p
    return p[a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0] < 0]


def morph_valid(ca: PoseChecker, cb: PoseChecker, state: np.ndarray) -> bool:
    """Is the in-place change from ``ca``'s formation to ``cb``'s at ``state`` valid (every
    robot moving straight to its new place; robots clear of walls and obstacles, the hull
    in the free space and over obstacles low enough for both formations), with
    ``MOTION_MARGIN`` to spare at every instant?"""
    strict = ca if ca.formation.max_height <= cb.formation.max_height else cb
    a, b = ca.robots(state)[0], cb.robots(state)[0]
    n = morph_clear(np.ascontiguousarray(a), np.ascontiguousarray(b), float(state[0]),
                    float(state[1]), max(ca.radius, cb.radius), strict._walls, strict._obst,
                    strict._verts, strict.clearance_rule, _tol.MOTION_MARGIN,
                    _tol.MIN_ADVANCE)
    return n > 0
