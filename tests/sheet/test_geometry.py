"""Formation metrics of the planning paper (eqs. 1-4) on shapes with known answers."""

from itertools import combinations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from taut.errors import InvalidInputError
from taut.sheet import (formation_metrics, formation_size, max_obstacle_diameter,
                                 max_obstacle_height, min_robot_distance,
                                 minimum_enclosing_circle)


def regular(n, r=1.0, phase=0.3, centre=(2.0, -1.0)):
    t = phase + 2 * np.pi * np.arange(n) / n
    return np.column_stack([r * np.cos(t), r * np.sin(t)]) + centre


def brute_force_mec(p):
    """Smallest circle through 2 or 3 of the points that contains all of them."""
    best = (None, np.inf)
    cands = []
    for i, j in combinations(range(len(p)), 2):
        cands.append(((p[i] + p[j]) / 2, np.linalg.norm(p[i] - p[j]) / 2))
    for i, j, k in combinations(range(len(p)), 3):
        a, b, c = p[i], p[j], p[k]
        d = 2 * ((b - a)[0] * (c - a)[1] - (b - a)[1] * (c - a)[0])
        if abs(d) < 1e-12:
            continue
        ab2, ac2 = (b - a) @ (b - a), (c - a) @ (c - a)
        ux = ((c - a)[1] * ab2 - (b - a)[1] * ac2) / d
        uy = ((b - a)[0] * ac2 - (c - a)[0] * ab2) / d
        cands.append((a + np.array([ux, uy]), np.hypot(ux, uy)))
    for c, r in cands:
        if r < best[1] and np.all(np.linalg.norm(p - c, axis=1) <= r * (1 + 1e-9) + 1e-12):
            best = (c, r)
    return best


def test_equilateral_triangle():
    a = 1.7
    p = np.array([[0, 0], [a, 0], [a / 2, a * np.sqrt(3) / 2]])
    m = formation_metrics(p, margin=0.1, object_height=0.6, height_margin=0.05)
    assert m.enclosing_diameter == pytest.approx(2 * a / np.sqrt(3), rel=1e-12)
    np.testing.assert_allclose(m.centre, [a / 2, a / (2 * np.sqrt(3))], atol=1e-12)
    assert m.size == pytest.approx(2 * a / np.sqrt(3) + 0.2, rel=1e-12)
    assert m.min_distance == pytest.approx(a, rel=1e-12)
    assert m.max_obstacle_diameter == pytest.approx(a - 0.2, rel=1e-12)
    assert m.max_obstacle_height == pytest.approx(0.55, rel=1e-12)


def test_square():
    p = np.array([[0, 0], [2, 0], [2, 2], [0, 2]], dtype=float)
    assert formation_size(p) == pytest.approx(2 * np.sqrt(2), rel=1e-12)
    assert formation_size(p, margin=0.5) == pytest.approx(2 * np.sqrt(2) + 1.0, rel=1e-12)
    d, pair = min_robot_distance(p)
    assert d == pytest.approx(2.0) and pair in {(0, 1), (1, 2), (2, 3), (0, 3)}
    assert max_obstacle_diameter(p, margin=0.25) == pytest.approx(1.5)


@pytest.mark.parametrize("n", [3, 5, 6, 8, 12, 20])
def test_regular_polygons(n):
    p = regular(n, r=0.9)
    c, r = minimum_enclosing_circle(p)
    assert r == pytest.approx(0.9, rel=1e-12)
    np.testing.assert_allclose(c, [2.0, -1.0], atol=1e-12)
    assert min_robot_distance(p)[0] == pytest.approx(2 * 0.9 * np.sin(np.pi / n), rel=1e-12)


def test_obtuse_triangle_uses_longest_side():
    p = np.array([[0, 0], [4, 0], [2, 0.5]])
    c, r = minimum_enclosing_circle(p)
    assert r == pytest.approx(2.0, rel=1e-12)
    np.testing.assert_allclose(c, [2, 0], atol=1e-12)


@pytest.mark.parametrize("eps", [0.0, 1e-15, 1e-9, 1e-6])
def test_near_collinear_team(eps):
    x = np.array([0.0, 0.3, 1.1, 2.0, 2.5])
    p = np.column_stack([x, eps * np.array([0, 1, -1, 1, 0])])
    m = formation_metrics(p)
    assert m.enclosing_diameter == pytest.approx(2.5, rel=1e-9)
    assert m.min_distance == pytest.approx(0.3, rel=1e-6)
    assert m.closest_pair == (0, 1)
    assert np.all(np.linalg.norm(p - m.centre, axis=1) <= m.enclosing_diameter / 2 + 1e-12)


def test_coincident_robots_give_zero_distance():
    p = np.array([[0, 0], [1, 0], [1, 0], [0, 1]], dtype=float)
    assert min_robot_distance(p) == (0.0, (1, 2))
    assert max_obstacle_diameter(p, margin=0.1) == pytest.approx(-0.2)


def test_max_obstacle_height_is_object_height_minus_margin():
    assert max_obstacle_height(0.8, 0.15) == pytest.approx(0.65)
    assert formation_metrics(regular(4)).max_obstacle_height is None


@settings(max_examples=60, deadline=None)
@given(arrays(np.float64, st.tuples(st.integers(2, 9), st.just(2)),
              elements=st.floats(-10, 10, allow_nan=False, width=64)))
def test_enclosing_circle_is_minimal(p):
    c, r = minimum_enclosing_circle(p)
    scale = max(1.0, np.abs(p).max())
    assert np.all(np.linalg.norm(p - c, axis=1) <= r + 1e-9 * scale)
    bc, br = brute_force_mec(p)
    if bc is not None:
        assert r <= br + 1e-9 * scale
    # No circle is smaller than half the diameter of the point set.
    diam = max((np.linalg.norm(a - b) for a, b in combinations(p, 2)), default=0.0)
    assert r >= diam / 2 - 1e-9 * scale


@given(st.floats(0.1, 100), st.floats(-np.pi, np.pi), st.integers(3, 10))
@settings(max_examples=30, deadline=None)
def test_metrics_are_rigid_motion_invariant(scale, angle, n):
    p = regular(n, r=scale, phase=0.0)
    p[0] *= 0.8
    c, s = np.cos(angle), np.sin(angle)
    q = p @ np.array([[c, s], [-s, c]]) + [5.0, -3.0]
    a, b = formation_metrics(p), formation_metrics(q)
    assert b.enclosing_diameter == pytest.approx(a.enclosing_diameter, rel=1e-9)
    assert b.min_distance == pytest.approx(a.min_distance, rel=1e-9)


@pytest.mark.parametrize("bad, field", [
    ([[0, 0]], "formation"),
    ([[0, 0, 1], [1, 1, 1]], "formation"),
    ([[0, 0], [np.nan, 1], [1, 1]], "formation"),
    ("abc", "formation"),
])
def test_bad_formations(bad, field):
    with pytest.raises(InvalidInputError) as exc:
        formation_metrics(bad)
    assert exc.value.field == field


def test_negative_margins_are_rejected():
    with pytest.raises(InvalidInputError) as exc:
        formation_size(regular(3), margin=-1)
    assert exc.value.field == "margin"
    with pytest.raises(InvalidInputError) as exc:
        max_obstacle_height(1.0, height_margin=-0.1)
    assert exc.value.field == "height_margin"
