"""Small dense linear algebra and geometry for the compiled FK kernel (numba):
LU with partial pivoting, extreme singular values by one-sided Jacobi, the paper's
projection test, and the reduced Hessian's smallest eigenvalue (docs/sheet_kinematics.md
§3, §5). Plain loops over arrays of at most 6 x 6."""

from __future__ import annotations

import math

import numpy as np

from ..._jit import jit
from .._tol import ANGLE_TOL, COINCIDE_RTOL2, JACOBI_TOL

#: Columns of the 3 x 3 minors giving the null vector of a 3 x 4 matrix (signs +-+-).
_MINOR_COLS = np.array([[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]])

@jit
def _lu_solve(K, rhs, n):
    """Solve ``K[:n, :n] y = rhs[:n]`` in place by LU with partial pivoting (as LAPACK's
    getrf). Returns ``(det, ok_solved)``; ``rhs`` holds the solution; ``K`` is destroyed.
    A zero pivot leaves ``det = 0`` (the caller then rejects the system)."""
    det = 1.0
    for k in range(n):
        p = k
        best = abs(K[k, k])
        for i in range(k + 1, n):
            if abs(K[i, k]) > best:
                best = abs(K[i, k])
                p = i
        if best == 0.0:
            return 0.0, False
        if p != k:
            for j in range(n):
                t = K[k, j]
                K[k, j] = K[p, j]
                K[p, j] = t
            t = rhs[k]
            rhs[k] = rhs[p]
            rhs[p] = t
            det = -det
        piv = K[k, k]
        det *= piv
        for i in range(k + 1, n):
            f = K[i, k] / piv
            if f != 0.0:
                for j in range(k + 1, n):
                    K[i, j] -= f * K[k, j]
                rhs[i] -= f * rhs[k]
    for k in range(n - 1, -1, -1):
        s = rhs[k]
        for j in range(k + 1, n):
            s -= K[k, j] * rhs[j]
        rhs[k] = s / K[k, k]
    return det, True


@jit
def _singular_extremes(W, n):
    """Largest and smallest singular value of ``W[:n, :n]`` (destroyed) by one-sided
    Jacobi rotations of its columns (Hestenes): accurate small singular values, and far
    less to compile than LAPACK's SVD."""
    for _ in range(60):
        rotated = False
        for p in range(n - 1):
            for q in range(p + 1, n):
                alpha = beta = gamma = 0.0
                for i in range(n):
                    alpha += W[i, p] * W[i, p]
                    beta += W[i, q] * W[i, q]
                    gamma += W[i, p] * W[i, q]
                if abs(gamma) <= JACOBI_TOL * math.sqrt(alpha * beta):
                    continue
                rotated = True
                zeta = (beta - alpha) / (2.0 * gamma)
                t = math.copysign(1.0, zeta) / (abs(zeta) + math.sqrt(1.0 + zeta * zeta))
                c = 1.0 / math.sqrt(1.0 + t * t)
                s = c * t
                for i in range(n):
                    wp, wq = W[i, p], W[i, q]
                    W[i, p] = c * wp - s * wq
                    W[i, q] = s * wp + c * wq
        if not rotated:
            break
    top = 0.0
    bottom = np.inf
    for j in range(n):
        norm = 0.0
        for i in range(n):
            norm += W[i, j] * W[i, j]
        norm = math.sqrt(norm)
        top = max(top, norm)
        bottom = min(bottom, norm)
    return top, bottom


@jit
def _in_hull(Rn, taut, N, px, py, ang):
    """The paper's projection test (``_kernel.in_hull_2d``) for the robots in ``taut``."""
    m = 0
    scale2 = 1.0
    for j in range(N):
        if taut[j]:
            dx = Rn[j, 0] - px
            dy = Rn[j, 1] - py
            d2 = dx * dx + dy * dy
            if d2 > scale2:
                scale2 = d2
    for j in range(N):
        if taut[j]:
            dx = Rn[j, 0] - px
            dy = Rn[j, 1] - py
            if dx * dx + dy * dy <= COINCIDE_RTOL2 * scale2:
                return True
            ang[m] = math.atan2(dy, dx)
            m += 1
    a = ang[:m]
    for k in range(1, m):                          # insertion sort (m <= N is small)
        v = a[k]
        i = k - 1
        while i >= 0 and a[i] > v:
            a[i + 1] = a[i]
            i -= 1
        a[i + 1] = v
    gap = a[0] + 2.0 * math.pi - a[m - 1]
    for k in range(m - 1):
        if a[k + 1] - a[k] > gap:
            gap = a[k + 1] - a[k]
    return gap <= math.pi + ANGLE_TOL


@jit
def _project_out(v, Q, q):
    """Remove from ``v`` (4,) its components along the first ``q`` rows of ``Q`` (twice:
    "twice is enough" for Gram-Schmidt); returns the residual norm."""
    for _ in range(2):
        for k in range(q):
            dot = v[0] * Q[k, 0] + v[1] * Q[k, 1] + v[2] * Q[k, 2] + v[3] * Q[k, 3]
            for c in range(4):
                v[c] -= dot * Q[k, c]
    return math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + v[3] * v[3])


@jit
def _orthonormal_complement(D, nrows, Q):
    """Orthonormal rows ``Q[nrows:4]`` spanning the null space of the ``nrows`` (affinely
    independent, so linearly independent) rows of ``D`` (4 columns), which are first
    orthonormalised into ``Q[:nrows]``; each further row is the coordinate axis with the
    largest residual (no threshold needed)."""
    v = np.empty(4)
    for r in range(nrows):
        for c in range(4):
            v[c] = D[r, c]
        nv = _project_out(v, Q, r)
        for c in range(4):
            Q[r, c] = v[c] / nv
    best = np.empty(4)
    for q in range(nrows, 4):
        top = -1.0
        for axis in range(4):
            for c in range(4):
                v[c] = 0.0
            v[axis] = 1.0
            nv = _project_out(v, Q, q)
            if nv > top:
                top = nv
                for c in range(4):
                    best[c] = v[c] / nv
        for c in range(4):
            Q[q, c] = best[c]


@jit
def _reduced_min_eig(P, members, s):
    """Smallest eigenvalue of diag(1, 1, -1, -1) on the face's tangent space
    (``_kernel.reduced_hessian_min_eig``): +inf for 5 members, the generalised cross
    product for 4, a 2 x 2 closed form for 3, a 3 x 3 one for 2 (docs/sheet_kinematics.md
    §5)."""
    if s >= 5:
        return np.inf
    if s <= 2:
        # A 3-space: by Cauchy interlacing against diag(1, 1, -1, -1) the smallest
        # eigenvalue is exactly -1 (such rows never get here: a 2-cable taut set fails
        # the paper's test, larger ones are weight families).
        return -1.0
    D = np.empty((4, 4))
    for a in range(1, s):
        for c in range(4):
            D[a - 1, c] = P[members[a], c] - P[members[0], c]
    if s == 4:
        num = 0.0
        den = 0.0
        for k in range(4):
            c0, c1, c2 = _MINOR_COLS[k, 0], _MINOR_COLS[k, 1], _MINOR_COLS[k, 2]
            m3 = (D[0, c0] * (D[1, c1] * D[2, c2] - D[1, c2] * D[2, c1])
                  - D[0, c1] * (D[1, c0] * D[2, c2] - D[1, c2] * D[2, c0])
                  + D[0, c2] * (D[1, c0] * D[2, c1] - D[1, c1] * D[2, c0]))
            nk2 = m3 * m3
            num += nk2 if k < 2 else -nk2
            den += nk2
        return num / den
    Q = np.zeros((4, 4))
    _orthonormal_complement(D, s - 1, Q)
    nz = 5 - s
    H = np.zeros((3, 3))
    for i in range(nz):
        for j in range(nz):
            zi, zj = s - 1 + i, s - 1 + j
            H[i, j] = (Q[zi, 0] * Q[zj, 0] + Q[zi, 1] * Q[zj, 1]
                       - Q[zi, 2] * Q[zj, 2] - Q[zi, 3] * Q[zj, 3])
    if nz == 2:
        half = 0.5 * (H[0, 0] - H[1, 1])
        return 0.5 * (H[0, 0] + H[1, 1]) - math.sqrt(half * half + H[0, 1] * H[0, 1])
    return H[0, 0]                                 # not reached: nz is 1 or 2
