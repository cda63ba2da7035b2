"""Geometry of the deformed sheet surface (triangles over node positions), no MuJoCo.

Used to read the object's position off the simulation the way the virtual variable cables
model defines it: the point object rests *on* the sheet, so the physics' object position
is the sheet point under the ball's centre (this accounts for the ball radius whatever the
sheet's slope around it), and its contact point is that point's place in the flat sheet.
"""

from __future__ import annotations

import numpy as np

from . import _tol

__all__ = ["point_triangle_distance", "surface_below"]


def _segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    d = b - a
    t = np.clip(np.einsum("tk,tk->t", p - a, d) / np.einsum("tk,tk->t", d, d), 0.0, 1.0)
    return np.linalg.norm(p - (a + t[:, None] * d), axis=1)


def point_triangle_distance(p: np.ndarray, A: np.ndarray, B: np.ndarray, C: np.ndarray
                            ) -> np.ndarray:
    """Distance from point ``p`` (3,) to each triangle ``(A, B, C)`` (each (T, 3)).

    Examples
    --------
    >>> import numpy as np
    >>> A, B, C = np.array([[0., 0, 0]]), np.array([[1., 0, 0]]), np.array([[0., 1, 0]])
    >>> float(point_triangle_distance(np.array([0.2, 0.2, 0.5]), A, B, C)[0])
    0.5
    >>> float(point_triangle_distance(np.array([2.0, 0.0, 0.0]), A, B, C)[0])
    1.0
    """
    P = np.broadcast_to(p, A.shape)
    n = np.cross(B - A, C - A)
    n = n / np.linalg.norm(n, axis=1)[:, None]
    dp = np.einsum("tk,tk->t", P - A, n)
    q = P - dp[:, None] * n
    inside = np.ones(len(A), dtype=bool)
    for u, v in ((A, B), (B, C), (C, A)):
        inside &= np.einsum("tk,tk->t", np.cross(v - u, q - u), n) >= 0
    d = np.where(inside, np.abs(dp), np.inf)
    for u, v in ((A, B), (B, C), (C, A)):
        d = np.minimum(d, _segment_distance(P, u, v))
    return d


def surface_below(nodes: np.ndarray, triangles: np.ndarray, point: np.ndarray
                  ) -> tuple[float, int, np.ndarray] | None:
    """Highest sheet point straight below ``point`` (3,): (z, triangle, barycentric (3,)),
    or None when no triangle lies below it."""
    A, B, C = (nodes[triangles[:, k]] for k in range(3))
    e1, e2 = (B - A)[:, :2], (C - A)[:, :2]
    det = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    ok = np.abs(det) > _tol.FLAT_TRIANGLE
    rel = point[None, :2] - A[:, :2]
    with np.errstate(divide="ignore", invalid="ignore"):
        u = (rel[:, 0] * e2[:, 1] - rel[:, 1] * e2[:, 0]) / det
        v = (e1[:, 0] * rel[:, 1] - e1[:, 1] * rel[:, 0]) / det
    eps = _tol.BARYCENTRIC_SLACK
    hit = ok & (u >= -eps) & (v >= -eps) & (u + v <= 1 + eps)
    z = A[:, 2] + u * (B - A)[:, 2] + v * (C - A)[:, 2]
    hit &= z <= point[2] + _tol.BELOW_SLACK
    if not np.any(hit):
        return None
    k = int(np.flatnonzero(hit)[np.argmax(z[hit])])
    return float(z[k]), k, np.array([1 - u[k] - v[k], u[k], v[k]])
