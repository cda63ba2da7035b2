"""The compiled clearance of the SE(2) search against shapely (an independent geometry
library), and its motion check against dense re-sampling."""

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.geometry import Point, Polygon

from taut.plan import _tol
from taut.plan._kernels.clearance import (OBST_COLS, morph_clear, motion_clear,
    poses_clearance)

#: Circles in shapely: a 256-gon inscribed in the circle (the kernel's circle is exact), so
#: shapely's distances exceed the kernel's by at most r (1 - cos(pi / 256)) < 7.6e-5 r,
#: below 2e-5 m for the radii drawn (<= 0.2 m).
QUAD = 64
TOL = 2e-5


def _world(rng, kind):
    if kind == 0:
        walls = np.array([[0, 0], [6, 0], [6, 2], [0, 2]], float)
    else:                                    # an L-shaped corridor (a reflex vertex)
        walls = np.array([[0, 0], [5, 0], [5, 4], [3.5, 4], [3.5, 1.5], [0, 1.5]], float)
    rows, verts, geoms = [], [], []
    for _ in range(rng.integers(0, 5)):
        c = rng.uniform([0.5, 0.3], [4.5, 1.2])
        r = rng.uniform(0.03, 0.2)
        blocked = float(rng.random() < 0.5)
        keep = float(rng.uniform(0.0, 0.01))          # hull margin from a blocked obstacle
        if rng.random() < 0.5:
            rows.append([*c, r, blocked, 0, 0, 0, keep])
            geoms.append((Point(c).buffer(r, quad_segs=QUAD), blocked, keep))
        else:
            t = np.sort(rng.uniform(0, 2 * np.pi, rng.integers(3, 7)))
            pts = c + r * np.column_stack([np.cos(t), np.sin(t)])
            g = Polygon(pts)
            if not g.is_valid or g.area <= 1e-6:
                continue
            rows.append([*c, r, blocked, 1, sum(len(v) for v in verts), len(pts), keep])
            verts.append(pts)
            geoms.append((g, blocked, keep))
    obst = np.array(rows, float).reshape(-1, OBST_COLS)
    vv = np.concatenate(verts) if verts else np.zeros((0, 2))
    return walls, obst, np.ascontiguousarray(vv), geoms


def _oracle(robots, walls, geoms, clearance):
    """The rules' slack computed with shapely: robots vs walls and obstacles (minus the
    clearance), hull vs walls and blocked obstacles."""
    world = Polygon(walls)
    pts = shapely.points(robots)
    inside = shapely.contains(world, pts) | shapely.touches(world, pts)
    d = shapely.distance(world.exterior, pts)
    best = float(np.min(np.where(inside, d, -d))) - clearance
    hull = shapely.convex_hull(shapely.multipoints(robots))
    if not world.covers(hull):
        best = min(best, 0.0)
    else:
        best = min(best, float(world.exterior.distance(hull)))
    for g, blocked, keep in geoms:
        dd = shapely.distance(g, pts)
        dd = np.where(shapely.contains(g, pts), -shapely.distance(g.exterior, pts), dd)
        best = min(best, float(dd.min()) - clearance)
        if blocked:
            best = min(best, float(g.distance(hull)) - keep)
    return best


formations = st.integers(3, 9).flatmap(lambda n: st.tuples(
    st.just(n), st.integers(0, 2**32 - 1)))


@settings(max_examples=150, deadline=None)
@given(formations, st.integers(0, 1), st.integers(0, 2**32 - 1))
def test_clearance_matches_shapely(form, kind, seed):
    n, fseed = form
    rng = np.random.default_rng(seed)
    walls, obst, verts, geoms = _world(rng, kind)
    local = np.random.default_rng(fseed).uniform(-0.5, 0.5, (n, 2))
    radius = float(np.linalg.norm(local, axis=1).max())
    states = np.column_stack([rng.uniform([0, 0], [6, 4], (40, 2)),
                              rng.uniform(-np.pi, np.pi, 40)])
    out = np.empty(len(states))
    poses_clearance(local, radius, walls, obst, verts, 0.14, states, out)
    for s, k in zip(states, out):
        c, sn = np.cos(s[2]), np.sin(s[2])
        robots = local @ np.array([[c, sn], [-sn, c]]) + s[:2]
        exact = _oracle(robots, walls, geoms, 0.14)
        # Same sign wherever the rules are not within round-off of the boundary ...
        if abs(exact) > TOL:
            assert (k > 0) == (exact > 0), (k, exact)
        # ... and the same value where they hold (the kernel's value is exact there).
        if exact > TOL:
            assert k == pytest.approx(exact, abs=TOL)


@settings(max_examples=60, deadline=None)
@given(formations, st.integers(0, 1), st.integers(0, 2**32 - 1))
def test_motion_check_is_a_proof_for_the_continuous_motion(form, kind, seed):
    """An accepted motion keeps MOTION_MARGIN at 4000 poses along it; a refused one has
    a pose with less than STATE_CLEARANCE (up to the sampling of the re-check)."""
    n, fseed = form
    rng = np.random.default_rng(seed)
    walls, obst, verts, geoms = _world(rng, kind)
    local = np.random.default_rng(fseed).uniform(-0.4, 0.4, (n, 2))
    radius = float(np.linalg.norm(local, axis=1).max())
    a = np.array([*rng.uniform([0.5, 0.5], [1.5, 1.0]), rng.uniform(-np.pi, np.pi)])
    b = np.array([*rng.uniform([0.5, 0.5], [5.0, 1.0]), rng.uniform(-2 * np.pi, 2 * np.pi)])
    res = motion_clear(local, radius, walls, obst, verts, 0.14, a, b, _tol.MOTION_MARGIN,
                       _tol.MIN_ADVANCE)
    t = np.linspace(0, 1, 4001)
    states = a + t[:, None] * (b - a)
    out = np.empty(len(t))
    poses_clearance(local, radius, walls, obst, verts, 0.14, states, out)
    step = (np.hypot(*(b[:2] - a[:2])) + radius * abs(b[2] - a[2])) / 4000
    if res > 0:
        assert out.min() >= _tol.MOTION_MARGIN - 1e-12
    else:
        assert out.min() < _tol.STATE_CLEARANCE + step


@pytest.mark.slow  # ~12 s of CPU: the slow target (CI runs it)
def test_morph_check_is_a_proof_for_the_continuous_change():
    rng = np.random.default_rng(11)
    walls, _, verts, _ = _world(rng, 1)
    # A tall (blocked) post beside the centre and a low one ahead of it.
    obst = np.array([[1.9, 0.9, 0.05, 1, 0, 0, 0, 0.005], [2.4, 0.6, 0.05, 0, 0, 0, 0, 0.005]],
                    float)
    geoms = [(Point(c).buffer(0.05, quad_segs=QUAD), b, 0.005) for c, b in
             (([1.9, 0.9], 1.0), ([2.4, 0.6], 0.0))]
    accepted = refused = 0
    for _ in range(200):
        n = int(rng.integers(3, 8))
        A = rng.uniform(-0.6, 0.6, (n, 2)) + [1.8, 0.75]
        B = rng.uniform(-0.6, 0.6, (n, 2)) + [1.8, 0.75]
        radius = float(np.linalg.norm(np.concatenate([A, B]) - [1.8, 0.75], axis=1).max())
        res = morph_clear(A, B, 1.8, 0.75, radius, walls, obst, verts, 0.14,
                          _tol.MOTION_MARGIN, _tol.MIN_ADVANCE)
        slack = [_oracle(A + s * (B - A), walls, geoms, 0.14) for s in np.linspace(0, 1, 300)]
        if res > 0:
            accepted += 1
            assert min(slack) >= _tol.MOTION_MARGIN - 1e-5
        else:
            refused += 1
    assert accepted and refused
