"""Compiled branch following for quasi-static simulation: one taut set (a *support* of
3..5 cables) re-solved on one formation or along a sequence of formations, in one numba
call (docs/sheet_kinematics.md §1-§5; FK paper eqs. 10-15).

The same decisions as the numpy tracker (``_branch.solve_taut_sets`` with
``independent=True``, and ``_branch.solve_support_one``): the bordered Lagrange system
``[G 1; 1' 0] [w; mu] = [b_S; 1]`` by LU with partial pivoting, rejected when a pivot is
zero or the solution exceeds ``MAX_SOLUTION``; a real depth above the ground
(``TAUT_TOL`` < d^2 < z_r^2, normalised); weights >= ``-WEIGHT_TOL``; no cable
over-stretched (``TAUT_TOL``); the reduced Hessian's smallest eigenvalue above
``CURVATURE_TOL`` (``_small_linalg._reduced_min_eig``, closed forms).

Output rows (float64, width ``5 + 2 N``; see ``step_width``): object ``r_o`` (2) and
``v_o`` (2) and ``z_o`` in the caller's units, weights (N), exact taut mask (N, 0/1).
"""

from __future__ import annotations

import math

import numpy as np

from ..._jit import jit
from .small import centroid
from .linalg import _lu_solve, _reduced_min_eig
from .._tol import CURVATURE_TOL, MAX_SOLUTION, TAUT_TOL, WEIGHT_TOL

__all__ = ["step_width", "solve_support", "follow_support", "feasible_step"]


def step_width(N: int) -> int:
    """Width of an output row of :func:`solve_support` for ``N`` robots."""
    return 5 + 2 * N


@jit
def solve_support(R, Xv, vcx, vcy, size, z, support, k, out):
    """Re-solve the support ``support[:k]`` (3..5 cable indices) on formation ``R``
    (N, 2, caller's units) into ``out`` (``step_width(N)``,). ``Xv`` (N, 2) are the sheet
    vertices centred at ``(vcx, vcy)`` and divided by ``size``; ``z`` the hold height.
    Returns True when the support gives a stable state there (module docstring)."""
    N = R.shape[0]
    cx, cy = centroid(R)
    P = np.empty((N, 5))
    for i in range(N):
        rx = (R[i, 0] - cx) / size
        ry = (R[i, 1] - cy) / size
        P[i, 0] = -2.0 * rx
        P[i, 1] = -2.0 * ry
        P[i, 2] = 2.0 * Xv[i, 0]
        P[i, 3] = 2.0 * Xv[i, 1]
        P[i, 4] = (rx * rx + ry * ry) - (Xv[i, 0] * Xv[i, 0] + Xv[i, 1] * Xv[i, 1])
    K = np.empty((6, 6))
    rhs = np.empty(6)
    for a in range(k):
        ia = support[a]
        for c in range(k):
            ic = support[c]
            # G_ij = 2 (r_i . r_j - v_i . v_j) from the lifted points (a = (-2r, 2v)).
            K[a, c] = 0.5 * ((P[ia, 0] * P[ic, 0] + P[ia, 1] * P[ic, 1])
                             - (P[ia, 2] * P[ic, 2] + P[ia, 3] * P[ic, 3]))
        K[a, k] = 1.0
        K[k, a] = 1.0
        rhs[a] = P[ia, 4]
    K[k, k] = 0.0
    rhs[k] = 1.0
    _, solved = _lu_solve(K, rhs, k + 1)
    if not solved:
        return False
    wmin = np.inf
    for a in range(k + 1):
        if not abs(rhs[a]) < MAX_SOLUTION:
            return False
        if a < k and rhs[a] < wmin:
            wmin = rhs[a]
    mu = rhs[k]
    x0 = x1 = x2 = x3 = 0.0
    for a in range(k):
        m = support[a]
        x0 -= 0.5 * rhs[a] * P[m, 0]
        x1 -= 0.5 * rhs[a] * P[m, 1]
        x2 += rhs[a] * Xv[m, 0]
        x3 += rhs[a] * Xv[m, 1]
    depth2 = -((x0 * x0 + x1 * x1) - (x2 * x2 + x3 * x3) + mu)
    zn = z / size
    if not (depth2 > TAUT_TOL and depth2 < zn * zn) or wmin < -WEIGHT_TOL:
        return False
    worst = -np.inf
    for j in range(N):
        e = (x0 * P[j, 0] + x1 * P[j, 1] + x2 * P[j, 2] + x3 * P[j, 3]) + (P[j, 4] - mu)
        out[5 + N + j] = 1.0 if e >= -TAUT_TOL else 0.0
        out[5 + j] = 0.0
        if e > worst:
            worst = e
    if not worst <= TAUT_TOL:
        return False
    if k < 5 and not _reduced_min_eig(P, support, k) > CURVATURE_TOL:
        return False
    for a in range(k):
        out[5 + support[a]] = rhs[a]
    out[0] = x0 * size + cx
    out[1] = x1 * size + cy
    out[2] = x2 * size + vcx
    out[3] = x3 * size + vcy
    out[4] = z - math.sqrt(max(depth2, 0.0)) * size
    return True


@jit
def follow_support(Rs, Xv, vcx, vcy, size, z, support, k, out):
    """:func:`solve_support` on each formation of ``Rs`` (T, N, 2) in order, rows into
    ``out`` (T, width), stopping at the first formation where the support fails.
    Returns the number of leading formations with a valid state."""
    for t in range(Rs.shape[0]):
        if not solve_support(Rs[t], Xv, vcx, vcy, size, z, support, k, out[t]):
            return t
    return Rs.shape[0]


@jit
def feasible_step(R0, V, dt, lim2, R1):
    """``R1 = R0 + V * dt`` (N, 2); True when finite and no robot pair is farther apart
    than its (tolerant) sheet distance, ``lim2`` (N, N) the squared limits (the test of
    ``model.check_formation``). Returns ``(ok, largest coordinate motion)``."""
    N = R0.shape[0]
    motion = 0.0
    for i in range(N):
        for c in range(2):
            R1[i, c] = R0[i, c] + V[i, c] * dt
            d = abs(R1[i, c] - R0[i, c])
            if not math.isfinite(R1[i, c]):
                return False, 0.0
            if d > motion:
                motion = d
    for i in range(N):
        for j in range(i + 1, N):
            dx = R1[i, 0] - R1[j, 0]
            dy = R1[i, 1] - R1[j, 1]
            if dx * dx + dy * dy > lim2[i, j]:
                return False, 0.0
    return True, motion
