"""The compiled projection test (``_kernels.linalg._in_hull``, the FK paper's test that the
projected object lies in the taut robots' polygon) answers exactly as its ``atan2`` gaps
do, now that ``_surely_outside`` / ``_surely_inside`` answer the clear "outside" /
"inside" cases without ``atan2``:
against the ``atan2`` algorithm written out here, on random points and on points placed
a hair (1e-15 .. 1e-3 of the size) either side of a half turn, where the sure answer must
step aside."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import example, given, settings
from hypothesis import strategies as st

from taut.sheet._kernels import linalg as la
from taut.sheet._tol import ANGLE_TOL, COINCIDE_RTOL2


def _atan2_gaps(Rn, taut, px, py):
    """``_in_hull`` before the sure answer: every taut robot's angle by ``atan2``, the
    widest gap at most pi (``ANGLE_TOL``), a robot at the point counts as inside."""
    d = [(Rn[j, 0] - px, Rn[j, 1] - py) for j in range(len(taut)) if taut[j]]
    scale2 = max([1.0] + [dx * dx + dy * dy for dx, dy in d])
    if any(dx * dx + dy * dy <= COINCIDE_RTOL2 * scale2 for dx, dy in d):
        return True
    a = sorted(math.atan2(dy, dx) for dx, dy in d)
    gap = a[0] + 2.0 * math.pi - a[-1]
    for k in range(len(a) - 1):
        gap = max(gap, a[k + 1] - a[k])
    return gap <= math.pi + ANGLE_TOL


def _case(seed, m, near, eps):
    """Robots (5, 2), a taut mask of ``m`` of them and a point: random, or (``near``) the
    point on the line through two taut robots, moved ``eps`` (relative) off it, the
    others on one side (a widest gap of about pi +- eps)."""
    rng = np.random.default_rng(seed)
    Rn = rng.uniform(-1.0, 1.0, (5, 2))
    taut = np.zeros(5, dtype=np.bool_)
    taut[rng.choice(5, m, replace=False)] = True
    p = rng.uniform(-1.0, 1.0, 2)
    if near and m >= 2:
        i, j = np.flatnonzero(taut)[:2]
        t = rng.uniform(0.1, 0.9)
        p = (1 - t) * Rn[i] + t * Rn[j]
        edge = Rn[j] - Rn[i]
        normal = np.array([-edge[1], edge[0]]) / np.linalg.norm(edge)
        for k in np.flatnonzero(taut)[2:]:         # the others on one side of the line
            side = (Rn[k] - p) @ normal
            Rn[k] -= (side - abs(side) - rng.uniform(0.01, 0.5)) * normal
        p = p + eps * rng.choice([-1.0, 1.0]) * normal
    return Rn, taut, float(p[0]), float(p[1])


@settings(max_examples=300, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), m=st.integers(1, 5), near=st.booleans(),
       log_eps=st.floats(-15.0, -3.0))
@example(seed=0, m=3, near=True, log_eps=-15.0)
@example(seed=1, m=4, near=True, log_eps=-9.0)
@example(seed=2, m=5, near=True, log_eps=-6.0)
def test_projection_test_answers_as_its_atan2_gaps(seed, m, near, log_eps):
    Rn, taut, px, py = _case(seed, m, near, 10.0 ** log_eps)
    expected = _atan2_gaps(Rn, taut, px, py)
    assert la._in_hull(Rn, taut, 5, px, py, np.empty(5)) == expected
    if la._surely_outside(Rn, taut, 5, px, py):    # the sure answers are never wrong
        assert not expected
    if la._surely_inside(Rn, taut, 5, px, py):
        assert expected


def test_the_sure_answer_takes_the_clear_cases():
    """Clearly outside (all robots in a quarter turn): answered without ``atan2``; inside
    or a hair outside a half turn: left to ``atan2``."""
    Rn = np.array([[1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [-1.0, 0.0], [-1.0, -1e-12]])
    taut = np.array([True, True, True, False, False])
    assert la._surely_outside(Rn, taut, 5, 0.0, 0.0)
    assert not la._in_hull(Rn, taut, 5, 0.0, 0.0, np.empty(5))
    half = np.array([True, False, False, True, False])        # exactly a half turn
    assert not la._surely_outside(Rn, half, 5, 0.0, 0.0)
    assert la._in_hull(Rn, half, 5, 0.0, 0.0, np.empty(5))
    hair = np.array([True, True, False, False, True])        # pi + 1e-12: atan2 decides
    assert not la._surely_outside(Rn, hair, 5, 0.0, 0.0)
    assert la._in_hull(Rn, hair, 5, 0.0, 0.0, np.empty(5)) == _atan2_gaps(Rn, hair, 0.0, 0.0)


def test_the_sure_inside_answer_takes_the_clear_cases():
    """Inside a triangle of taut robots by more than the margin: answered without
    ``atan2``; on an edge, a hair inside it, or with fewer than three taut robots: left to
    ``atan2``."""
    Rn = np.array([[1.0, 0.0], [-1.0, 1.0], [-1.0, -1.0], [5.0, 5.0], [0.0, 3.0]])
    three = np.array([True, True, True, False, False])
    for taut in (three, np.array([False, True, True, False, True])):
        assert la._surely_inside(Rn, taut, 5, -0.2, 0.1) == bool(taut[0])
    assert la._in_hull(Rn, three, 5, -0.2, 0.1, np.empty(5))
    two = np.array([True, True, False, False, False])
    assert not la._surely_inside(Rn, two, 5, 0.0, 0.0)
    # The edge (1, 0)-(-1, 1) passes (0, 0.5); the triangle lies below it.
    for eps, sure in ((0.0, False), (1e-15, False), (-1e-15, False), (1e-3, False),
                      (-1e-3, True)):
        px, py = 0.0, 0.5 + eps
        assert la._surely_inside(Rn, three, 5, px, py) == sure
        assert la._in_hull(Rn, three, 5, px, py, np.empty(5)) == _atan2_gaps(Rn, three, px, py)
