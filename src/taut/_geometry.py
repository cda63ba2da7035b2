"""The convex hull of points in the plane, written once for every family.

:func:`convex_hull` is Andrew's monotone chain (A. M. Andrew, "Another efficient algorithm
for convex hulls in two dimensions", Information Processing Letters 9(5), 1979) as a
kernel of :mod:`taut._jit`: compiled kernels call it on their own scratch arrays (the
planner's clearance, :mod:`taut.plan._kernels.clearance`), and the numpy fallback is the
same function run as plain Python. :func:`convex_hull_2d` gives Python callers (the cable
robots' support polygons, the planner's squeezed formations, the app's platform outline)
the same hull as a new array.

The hull has no tolerance: its vertices are the distinct extreme points, counter-clockwise
from the smallest ``(x, y)`` in lexicographic order, the first not repeated. A repeated
point, and a point on an edge (its orientation, a floating-point cross product, exactly 0),
are dropped; a point whose orientation is positive, however small, is kept. Points on one
line give the two ends of their segment, points that all coincide give that point, no
points give none.
Coordinates are in any length unit; the hull is in the same unit.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ._jit import jit

__all__ = ["convex_hull", "convex_hull_2d"]


@jit
def _turn(o, a, b):
    """Twice the signed area of triangle ``o, a, b`` (> 0 for a left turn)."""
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


@jit
def convex_hull(points, order, hull):
    """Convex hull of ``points`` (N, 2) into the first rows of ``hull`` (module docstring).

    Parameters
    ----------
    points : ndarray, shape (N, 2)
        Points, any length unit.
    order : ndarray of int64, shape (N,)
        Scratch: the points' indices, sorted here by ``(x, y)`` (insertion sort, linear
        on sorted input; the teams it serves have a dozen points or so).
    hull : ndarray, shape (>= N + 1, 2)
        Receives the vertices, counter-clockwise (same unit as ``points``).

    Returns
    -------
    int
        The number of vertices written: 0 for no points, 1 when all coincide, 2 when all
        lie on one line, else at least 3.
    """
    N = points.shape[0]
    if N == 0:
        return 0
    for i in range(N):
        order[i] = i
    for i in range(1, N):
        k = order[i]
        j = i - 1
        while j >= 0 and (points[order[j], 0] > points[k, 0] or (
                points[order[j], 0] == points[k, 0] and points[order[j], 1] > points[k, 1])):
            order[j + 1] = order[j]
            j -= 1
        order[j + 1] = k
    first, last = order[0], order[N - 1]
    if points[first, 0] == points[last, 0] and points[first, 1] == points[last, 1]:
        hull[0, 0], hull[0, 1] = points[first, 0], points[first, 1]     # all coincide
        return 1
    m = 0
    for i in range(N):                         # lower chain, left to right
        p = points[order[i]]
        while m >= 2 and _turn(hull[m - 2], hull[m - 1], p) <= 0.0:
            m -= 1
        hull[m, 0], hull[m, 1] = p[0], p[1]
        m += 1
    low = m + 1
    for i in range(N - 2, -1, -1):             # upper chain, right to left
        p = points[order[i]]
        while m >= low and _turn(hull[m - 2], hull[m - 1], p) <= 0.0:
            m -= 1
        hull[m, 0], hull[m, 1] = p[0], p[1]
        m += 1
    return m - 1                               # the last row repeats the first vertex


def convex_hull_2d(points: Any) -> np.ndarray:
    """Convex hull of ``points`` as a new array (module docstring).

    Parameters
    ----------
    points : array_like, shape (N, 2)
        Points, any length unit, already validated by the caller (finite numbers; this
        private helper does not check them again).

    Returns
    -------
    ndarray, shape (k, 2)
        The hull's vertices, counter-clockwise from the smallest ``(x, y)``, same unit;
        ``k`` is 0 for no points, 1 when all coincide, 2 when all lie on one line.

    Examples
    --------
    >>> convex_hull_2d([[0, 0], [2, 0], [1, 0], [2, 2], [0, 2], [1, 1], [0, 0]]).tolist()
    [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]]
    """
    p = np.asarray(points, dtype=float)
    # A sorted copy (new, so writable and contiguous: the types the compiled kernel is
    # cached for), on which the kernel's insertion sort is linear.
    p = p[np.lexsort((p[:, 1], p[:, 0]))]
    out = np.empty((p.shape[0] + 1, 2))
    return out[:convex_hull(p, np.empty(p.shape[0], np.int64), out)].copy()
