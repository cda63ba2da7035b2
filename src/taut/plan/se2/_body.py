"""A rigid body in SE(2) for the compiled clearance kernels: the footprint-agnostic part of
the SE(2) search's state space (:mod:`taut.plan.se2._space` adds the sheet team's rules and
samplers; :mod:`taut.cdpr.mission.navigation` uses it for the coupled bases of a mobile
cable robot).

The body is a set of points ``local`` (N, 2) placed by a pose ``(x, y, psi)``; the rules of
:mod:`taut.plan._kernels.clearance` hold at a pose when every point keeps
``clearance_rule`` from the walls and every obstacle, and the points' convex hull lies in
the free space and keeps each *blocked* obstacle's margin from it. The world is given as
the kernel's arrays (:func:`kernel_world`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .. import _tol
from .._kernels.clearance import OBST_COLS, motion_clear, poses_clearance
from ..world import World

__all__ = ["BodyChecker", "kernel_world"]


def kernel_world(world: World, blocked: Sequence[bool], margin: float
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Walls (M, 2), obstacle rows (``OBST_COLS``) and polygon vertices for the kernel;
    ``blocked[k]``: the hull must keep off obstacle ``k`` by ``margin`` (m)."""
    walls = np.ascontiguousarray(world.free_space, dtype=float)
    rows, verts = [], []
    count = 0
    for o, bl in zip(world.obstacles, blocked):
        if o.polygon is None:
            rows.append([*o.mec_center, o.mec_radius, float(bl), 0.0, 0.0, 0.0, margin])
        else:
            v = np.asarray(o.polygon, dtype=float)
            rows.append([*o.mec_center, o.mec_radius, float(bl), 1.0, count, len(v), margin])
            verts.append(v)
            count += len(v)
    obst = np.array(rows, dtype=float).reshape(-1, OBST_COLS)
    vv = np.concatenate(verts) if verts else np.zeros((0, 2))
    return walls, obst, np.ascontiguousarray(vv)


class BodyChecker:
    """Batched validity of poses ``(K, 3)`` of a rigid body (module docstring).

    Parameters
    ----------
    local : ndarray (N, 2)
        The body's points relative to its reference point, m.
    walls, obst, verts : ndarray
        The world, as :func:`kernel_world` returns it.
    clearance_rule : float
        Least distance from every point to walls and obstacles, m.
    """

    def __init__(self, local: np.ndarray, walls: np.ndarray, obst: np.ndarray,
                 verts: np.ndarray, clearance_rule: float) -> None:
        self._local = np.ascontiguousarray(local, dtype=float)
        self._walls, self._obst, self._verts = walls, obst, verts
        self.clearance_rule = float(clearance_rule)
        self.radius = float(np.linalg.norm(self._local, axis=1).max())
        self.checks = 0

    def clearance(self, states: np.ndarray) -> np.ndarray:
        """Float ``(K,)``: how far (m) every point may move from each state before a rule
        breaks (negative: broken); :mod:`taut.plan._kernels.clearance`."""
        s = np.ascontiguousarray(np.asarray(states, dtype=float).reshape(-1, 3))
        out = np.empty(len(s))
        poses_clearance(self._local, self.radius, self._walls, self._obst, self._verts,
                        self.clearance_rule, s, out)
        self.checks += len(s)
        return out

    def valid(self, states: np.ndarray) -> np.ndarray:
        """Bool ``(K,)``: which states keep every rule with ``STATE_CLEARANCE`` to
        spare."""
        return self.clearance(states) >= _tol.STATE_CLEARANCE

    def motion_valid(self, a: np.ndarray, b: np.ndarray) -> bool:
        """Is the straight SE(2) motion from ``a`` to ``b`` (position and heading linear in
        a common parameter) valid at every pose, with ``MOTION_MARGIN`` to spare?"""
        n = motion_clear(self._local, self.radius, self._walls, self._obst, self._verts,
                         self.clearance_rule, np.asarray(a, dtype=float),
                         np.asarray(b, dtype=float), _tol.MOTION_MARGIN, _tol.MIN_ADVANCE)
        self.checks += abs(n)
        return n > 0
