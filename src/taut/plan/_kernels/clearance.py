"""Compiled clearance of a rigid formation's pose and exact checks of continuous SE(2)
motions (numba; the hot path of the SE(2) search).

The *clearance* of a pose ``(x, y, psi)`` is a lower bound, in metres, of how far every
robot and the robots' convex hull may move before a rule of
:mod:`taut.plan.se2._space` breaks:

* per robot: its signed distance to the walls (positive inside the free space) and to
  every obstacle (negative inside), minus ``clearance`` (robot radius + lateral safety);
* the hull against every wall: the distance from each wall edge to the hull (zero when
  they meet: walls are tall);
* the hull against every *blocked* obstacle (too tall for the formation, or every
  obstacle when crossing is disabled): their distance less the obstacle's hull margin
  (the caller's ``POSITION_ACCURACY``: robots that far off their places cannot bring the
  sheet onto an obstacle it must not pass over).

Each term is 1-Lipschitz in the robots' displacement (the hull's points are convex
combinations of the robots), so a pose whose clearance is ``s`` stays valid while no
robot moves more than ``s``. Far terms are bounded from the object's distance without
computing them (the bound is all the motion check needs).

A straight SE(2) motion from ``a`` to ``b`` (position and heading linear in a parameter
``t``) moves every robot at most ``L = |b_xy - a_xy| + R |b_psi - a_psi|`` per unit ``t``
(``R`` the largest robot distance from the object). :func:`motion_clear` advances by
*conservative advancement*: from a pose of clearance ``s >= margin + min_step`` the next
pose checked is ``(s - margin) / L`` further, so every pose in between has clearance at
least ``margin`` — a proof for the continuous motion, not a check of samples. A pose
with clearance below ``margin + min_step`` fails the motion (so every advance is at
least ``min_step`` of robot motion and the loop ends). :func:`morph_clear` does the same
for an in-place formation change, where every robot moves straight to its new place (the
hull's points then move at most as far as the farthest robot).

Obstacles are rows of ``obst`` (``OBST_COLS`` columns): centre x, y, enclosing radius,
blocked flag, kind (0 a disc of that radius, 1 a polygon), first vertex and vertex count
in ``verts``, and the distance the hull keeps from the obstacle when it is blocked (m). A disc is the circle circumscribing the obstacle's 64-gon footprint (its
``mec_radius``), so it contains that footprint: the clearance is never overstated.
"""

from __future__ import annotations

import math

import numpy as np

from ..._geometry import convex_hull
from ..._jit import jit

__all__ = ["OBST_COLS", "robots_clearance", "poses_clearance", "motion_clear", "morph_clear",
           "segment_point_distance", "convex_point_signed_distance"]

#: Columns of an obstacle row (module docstring).
OBST_COLS = 8


@jit
def segment_point_distance(ax, ay, bx, by, px, py):
    """Distance from point p to segment ab."""
    dx = bx - ax
    dy = by - ay
    L2 = dx * dx + dy * dy
    t = 0.0
    if L2 > 0.0:
        t = ((px - ax) * dx + (py - ay) * dy) / L2
        if t < 0.0:
            t = 0.0
        elif t > 1.0:
            t = 1.0
    ex = ax + t * dx - px
    ey = ay + t * dy - py
    return math.sqrt(ex * ex + ey * ey)


@jit
def _inside_polygon(P, start, count, px, py):
    """Even-odd point-in-polygon test on vertices ``P[start:start + count]``."""
    inside = False
    j = start + count - 1
    for i in range(start, start + count):
        yi = P[i, 1]
        yj = P[j, 1]
        if (yi > py) != (yj > py):
            xc = P[i, 0] + (py - yi) * (P[j, 0] - P[i, 0]) / (yj - yi)
            if px < xc:
                inside = not inside
        j = i
    return inside


@jit
def _polygon_point_distance(P, start, count, px, py):
    """Distance from p to the boundary of polygon ``P[start:start + count]``."""
    best = np.inf
    j = start + count - 1
    for i in range(start, start + count):
        d = segment_point_distance(P[j, 0], P[j, 1], P[i, 0], P[i, 1], px, py)
        if d < best:
            best = d
        j = i
    return best


@jit
def convex_point_signed_distance(H, px, py):
    """Signed distance from p to the convex polygon ``H`` (counter-clockwise rows):
    negative inside."""
    k = H.shape[0]
    inside = True
    best = np.inf
    j = k - 1
    for i in range(k):
        ax, ay = H[j, 0], H[j, 1]
        bx, by = H[i, 0], H[i, 1]
        if (bx - ax) * (py - ay) - (by - ay) * (px - ax) < 0.0:
            inside = False
        d = segment_point_distance(ax, ay, bx, by, px, py)
        if d < best:
            best = d
        j = i
    return -best if inside else best


@jit
def _segments_cross(ax, ay, bx, by, cx, cy, dx, dy):
    """Do closed segments ab and cd meet?"""
    d1 = (dx - cx) * (ay - cy) - (dy - cy) * (ax - cx)
    d2 = (dx - cx) * (by - cy) - (dy - cy) * (bx - cx)
    d3 = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
    d4 = (bx - ax) * (dy - ay) - (by - ay) * (dx - ax)
    if ((d1 > 0.0 and d2 < 0.0) or (d1 < 0.0 and d2 > 0.0)) and \
            ((d3 > 0.0 and d4 < 0.0) or (d3 < 0.0 and d4 > 0.0)):
        return True
    # Touching or collinear cases: an endpoint on the other segment.
    return (segment_point_distance(cx, cy, dx, dy, ax, ay) == 0.0
            or segment_point_distance(cx, cy, dx, dy, bx, by) == 0.0
            or segment_point_distance(ax, ay, bx, by, cx, cy) == 0.0
            or segment_point_distance(ax, ay, bx, by, dx, dy) == 0.0)


@jit
def _convex_segment_distance(H, ax, ay, bx, by):
    """Distance between the convex polygon ``H`` (solid) and segment ab (0 when they
    meet)."""
    da = convex_point_signed_distance(H, ax, ay)
    db = convex_point_signed_distance(H, bx, by)
    if da <= 0.0 or db <= 0.0:
        return 0.0
    best = min(da, db)
    k = H.shape[0]
    j = k - 1
    for i in range(k):
        if _segments_cross(H[j, 0], H[j, 1], H[i, 0], H[i, 1], ax, ay, bx, by):
            return 0.0
        d = segment_point_distance(ax, ay, bx, by, H[i, 0], H[i, 1])
        if d < best:
            best = d
        j = i
    return best


@jit
def _convex_polygon_distance(H, P, start, count):
    """Distance between the convex polygon ``H`` and the simple polygon
    ``P[start:start + count]`` (both solid; 0 when they meet)."""
    for i in range(H.shape[0]):
        if _inside_polygon(P, start, count, H[i, 0], H[i, 1]):
            return 0.0
    best = np.inf
    j = start + count - 1
    for i in range(start, start + count):
        d = _convex_segment_distance(H, P[j, 0], P[j, 1], P[i, 0], P[i, 1])
        if d < best:
            best = d
            if best <= 0.0:
                return 0.0
        j = i
    return best


@jit
def robots_clearance(robots, walls, obst, verts, clearance, cx, cy, radius, order, scratch):
    """Clearance (m, module docstring) of robots ``robots`` (N, 2), all within ``radius``
    of ``(cx, cy)``; ``walls`` (M, 2) is the free-space polygon; ``order`` (N,) and
    ``scratch`` (N + 1, 2) are scratch arrays. A negative value means a rule is broken."""
    N = robots.shape[0]
    M = walls.shape[0]
    best = np.inf
    # Robots against the walls: signed distance to the free-space boundary.
    for i in range(N):
        d = _polygon_point_distance(walls, 0, M, robots[i, 0], robots[i, 1])
        if not _inside_polygon(walls, 0, M, robots[i, 0], robots[i, 1]):
            d = -d
        d -= clearance
        if d < best:
            best = d
    if best < 0.0:
        return best
    nh = convex_hull(robots, order, scratch)
    hull = scratch[:nh]
    # The hull against each wall edge (bounded from the centre's distance when far).
    j = M - 1
    for i in range(M):
        far = segment_point_distance(walls[j, 0], walls[j, 1], walls[i, 0], walls[i, 1],
                                     cx, cy) - radius
        if far < best:
            d = _convex_segment_distance(hull, walls[j, 0], walls[j, 1], walls[i, 0],
                                         walls[i, 1])
            if d < best:
                best = d
        j = i
    # Obstacles: every robot keeps the clearance; the hull keeps off blocked ones.
    for o in range(obst.shape[0]):
        ox, oy, orad = obst[o, 0], obst[o, 1], obst[o, 2]
        far = math.sqrt((cx - ox) ** 2 + (cy - oy) ** 2) - radius - orad
        if far - clearance >= best:
            continue
        disc = obst[o, 4] < 0.5
        start, count = int(obst[o, 5]), int(obst[o, 6])
        for i in range(N):
            px, py = robots[i, 0], robots[i, 1]
            if disc:
                d = math.sqrt((px - ox) ** 2 + (py - oy) ** 2) - orad
            else:
                d = _polygon_point_distance(verts, start, count, px, py)
                if _inside_polygon(verts, start, count, px, py):
                    d = -d
            d -= clearance
            if d < best:
                best = d
        if obst[o, 3] > 0.5 and far - obst[o, 7] < best:             # blocked
            if disc:
                d = convex_point_signed_distance(hull, ox, oy) - orad
            else:
                d = _convex_polygon_distance(hull, verts, start, count)
            d -= obst[o, 7]
            if d < best:
                best = d
        if best < 0.0:
            return best
    return best


@jit
def _place(local, x, y, psi, out):
    c = math.cos(psi)
    s = math.sin(psi)
    for i in range(local.shape[0]):
        out[i, 0] = c * local[i, 0] - s * local[i, 1] + x
        out[i, 1] = s * local[i, 0] + c * local[i, 1] + y


@jit
def poses_clearance(local, radius, walls, obst, verts, clearance, states, out):
    """Clearance of formation ``local`` (N, 2; robots relative to the object, all within
    ``radius`` of it) at every pose of ``states`` (K, 3) into ``out`` (K,)."""
    N = local.shape[0]
    robots = np.empty((N, 2))
    order = np.empty(N, np.int64)
    scratch = np.empty((N + 1, 2))
    for k in range(states.shape[0]):
        _place(local, states[k, 0], states[k, 1], states[k, 2], robots)
        out[k] = robots_clearance(robots, walls, obst, verts, clearance, states[k, 0],
                                  states[k, 1], radius, order, scratch)


@jit
def _advance(clear, t, rate, margin, min_step):
    """Next parameter of conservative advancement from ``t`` where the clearance is
    ``clear`` and robots move at most ``rate`` per unit parameter: -1 when the pose has
    less than ``margin + min_step``; 1 or more when the motion's end is reached."""
    if clear < margin + min_step:
        return -1.0
    if rate <= 0.0:
        return 1.0
    return t + (clear - margin) / rate


@jit
def motion_clear(local, radius, walls, obst, verts, clearance, a, b, margin, min_step):
    """Conservative advancement along the straight SE(2) motion of formation ``local``
    from pose ``a`` to pose ``b`` (module docstring). Returns the number of poses
    checked, negated when the motion fails."""
    N = local.shape[0]
    robots = np.empty((N, 2))
    order = np.empty(N, np.int64)
    scratch = np.empty((N + 1, 2))
    dx, dy, dpsi = b[0] - a[0], b[1] - a[1], b[2] - a[2]
    rate = math.sqrt(dx * dx + dy * dy) + radius * abs(dpsi)
    t = 0.0
    checks = 0
    while True:
        x, y = a[0] + t * dx, a[1] + t * dy
        _place(local, x, y, a[2] + t * dpsi, robots)
        s = robots_clearance(robots, walls, obst, verts, clearance, x, y, radius, order,
                             scratch)
        checks += 1
        t = _advance(s, t, rate, margin, min_step)
        if t < 0.0 or t >= 1.0:
            return checks if t >= 1.0 else -checks


@jit
def morph_clear(A, B, cx, cy, radius, walls, obst, verts, clearance, margin, min_step):
    """Conservative advancement along the straight motion of every robot from ``A`` to
    ``B`` (N, 2) (an in-place formation change; every robot within ``radius`` of
    ``(cx, cy)`` throughout). The rate is the largest robot displacement; the hull is
    recomputed at every pose. Returns the poses checked, negated when it fails."""
    N = A.shape[0]
    robots = np.empty((N, 2))
    order = np.empty(N, np.int64)
    scratch = np.empty((N + 1, 2))
    rate = 0.0
    for i in range(N):
        rate = max(rate, math.sqrt((B[i, 0] - A[i, 0]) ** 2 + (B[i, 1] - A[i, 1]) ** 2))
    t = 0.0
    checks = 0
    while True:
        for i in range(N):
            robots[i, 0] = A[i, 0] + t * (B[i, 0] - A[i, 0])
            robots[i, 1] = A[i, 1] + t * (B[i, 1] - A[i, 1])
        s = robots_clearance(robots, walls, obst, verts, clearance, cx, cy, radius, order,
                             scratch)
        checks += 1
        t = _advance(s, t, rate, margin, min_step)
        if t < 0.0 or t >= 1.0:
            return checks if t >= 1.0 else -checks
