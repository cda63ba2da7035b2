"""Small dense linear algebra and geometry for the compiled FK kernel (numba):
LU with partial pivoting, extreme singular values by one-sided Jacobi, the paper's
projection test, and the reduced Hessian's smallest eigenvalue (docs/sheet_kinematics.md
§3, §5). Plain loops over arrays of at most 6 x 6."""

from __future__ import annotations

import math

import numpy as np

from ..._jit import jit, jit_inline
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


@jit_inline
def _lu_solve4(r0, r1, r2, r3):
    """:func:`_lu_solve` for ``n = 4`` on the rows ``(K[i, 0], ..., K[i, 3], rhs[i])`` as
    tuples (kept in registers, no loop): the same pivots, operations and order, hence
    bit-identical results (tested). Returns ``(det, ok_solved, y0, y1, y2, y3)``; the
    ``y`` are meaningless when not ``ok_solved``."""
    det = 1.0
    # Step 0: pivot on column 0 (the first largest magnitude, as _lu_solve).
    p, best = 0, abs(r0[0])
    if abs(r1[0]) > best:
        p, best = 1, abs(r1[0])
    if abs(r2[0]) > best:
        p, best = 2, abs(r2[0])
    if abs(r3[0]) > best:
        p, best = 3, abs(r3[0])
    if best == 0.0:
        return 0.0, False, 0.0, 0.0, 0.0, 0.0
    if p == 1:
        r0, r1, det = r1, r0, -det
    elif p == 2:
        r0, r2, det = r2, r0, -det
    elif p == 3:
        r0, r3, det = r3, r0, -det
    piv = r0[0]
    det *= piv
    r1 = _eliminate5(r1, r0, r1[0] / piv)
    r2 = _eliminate5(r2, r0, r2[0] / piv)
    r3 = _eliminate5(r3, r0, r3[0] / piv)
    # Step 1: column 1 of rows 1-3.
    p, best = 1, abs(r1[1])
    if abs(r2[1]) > best:
        p, best = 2, abs(r2[1])
    if abs(r3[1]) > best:
        p, best = 3, abs(r3[1])
    if best == 0.0:
        return 0.0, False, 0.0, 0.0, 0.0, 0.0
    if p == 2:
        r1, r2, det = r2, r1, -det
    elif p == 3:
        r1, r3, det = r3, r1, -det
    piv = r1[1]
    det *= piv
    r2 = _eliminate5(r2, r1, r2[1] / piv)
    r3 = _eliminate5(r3, r1, r3[1] / piv)
    # Step 2: column 2 of rows 2-3.
    p, best = 2, abs(r2[2])
    if abs(r3[2]) > best:
        p, best = 3, abs(r3[2])
    if best == 0.0:
        return 0.0, False, 0.0, 0.0, 0.0, 0.0
    if p == 3:
        r2, r3, det = r3, r2, -det
    piv = r2[2]
    det *= piv
    r3 = _eliminate5(r3, r2, r3[2] / piv)
    # Step 3.
    if abs(r3[3]) == 0.0:
        return 0.0, False, 0.0, 0.0, 0.0, 0.0
    det *= r3[3]
    y3 = r3[4] / r3[3]
    y2 = (r2[4] - r2[3] * y3) / r2[2]
    y1 = ((r1[4] - r1[2] * y2) - r1[3] * y3) / r1[1]
    y0 = (((r0[4] - r0[1] * y1) - r0[2] * y2) - r0[3] * y3) / r0[0]
    return det, True, y0, y1, y2, y3


@jit
def _eliminate5(ri, rk, f):
    """Row ``ri`` minus ``f`` times row ``rk`` (5-tuples), unchanged when ``f == 0`` (as
    :func:`_lu_solve`, which skips that row). Entries left of the pivot column are
    updated too but never read again (the lower triangle)."""
    if f == 0.0:
        return ri
    return (ri[0] - f * rk[0], ri[1] - f * rk[1], ri[2] - f * rk[2], ri[3] - f * rk[3],
            ri[4] - f * rk[4])


@jit_inline
def _lu_solve5(r0, r1, r2, r3, r4):
    """:func:`_lu_solve4` for ``n = 5`` (rows ``(K[i, 0], ..., K[i, 4], rhs[i])``):
    bit-identical to :func:`_lu_solve`. Returns ``(det, ok_solved, y0, ..., y4)``.

    Long because it is unrolled: five pivot steps written out on values held in
    registers (no loop, no array), which is what makes it faster than the looped solve
    for the 4-robot candidates of the batch (1.91 -> 1.64 us per formation at N = 4)."""
    det = 1.0
    # Step 0: pivot on column 0 of rows 0-4 (the first largest magnitude).
    p, best = 0, abs(r0[0])
    if abs(r1[0]) > best:
        p, best = 1, abs(r1[0])
    if abs(r2[0]) > best:
        p, best = 2, abs(r2[0])
    if abs(r3[0]) > best:
        p, best = 3, abs(r3[0])
    if abs(r4[0]) > best:
        p, best = 4, abs(r4[0])
    if best == 0.0:
        return 0.0, False, 0.0, 0.0, 0.0, 0.0, 0.0
    if p == 1:
        r0, r1, det = r1, r0, -det
    elif p == 2:
        r0, r2, det = r2, r0, -det
    elif p == 3:
        r0, r3, det = r3, r0, -det
    elif p == 4:
        r0, r4, det = r4, r0, -det
    piv = r0[0]
    det *= piv
    r1 = _eliminate6(r1, r0, r1[0] / piv)
    r2 = _eliminate6(r2, r0, r2[0] / piv)
    r3 = _eliminate6(r3, r0, r3[0] / piv)
    r4 = _eliminate6(r4, r0, r4[0] / piv)
    # Step 1: pivot on column 1 of rows 1-4 (the first largest magnitude).
    p, best = 1, abs(r1[1])
    if abs(r2[1]) > best:
        p, best = 2, abs(r2[1])
    if abs(r3[1]) > best:
        p, best = 3, abs(r3[1])
    if abs(r4[1]) > best:
        p, best = 4, abs(r4[1])
    if best == 0.0:
        return 0.0, False, 0.0, 0.0, 0.0, 0.0, 0.0
    if p == 2:
        r1, r2, det = r2, r1, -det
    elif p == 3:
        r1, r3, det = r3, r1, -det
    elif p == 4:
        r1, r4, det = r4, r1, -det
    piv = r1[1]
    det *= piv
    r2 = _eliminate6(r2, r1, r2[1] / piv)
    r3 = _eliminate6(r3, r1, r3[1] / piv)
    r4 = _eliminate6(r4, r1, r4[1] / piv)
    # Step 2: pivot on column 2 of rows 2-4 (the first largest magnitude).
    p, best = 2, abs(r2[2])
    if abs(r3[2]) > best:
        p, best = 3, abs(r3[2])
    if abs(r4[2]) > best:
        p, best = 4, abs(r4[2])
    if best == 0.0:
        return 0.0, False, 0.0, 0.0, 0.0, 0.0, 0.0
    if p == 3:
        r2, r3, det = r3, r2, -det
    elif p == 4:
        r2, r4, det = r4, r2, -det
    piv = r2[2]
    det *= piv
    r3 = _eliminate6(r3, r2, r3[2] / piv)
    r4 = _eliminate6(r4, r2, r4[2] / piv)
    # Step 3: pivot on column 3 of rows 3-4 (the first largest magnitude).
    p, best = 3, abs(r3[3])
    if abs(r4[3]) > best:
        p, best = 4, abs(r4[3])
    if best == 0.0:
        return 0.0, False, 0.0, 0.0, 0.0, 0.0, 0.0
    if p == 4:
        r3, r4, det = r4, r3, -det
    piv = r3[3]
    det *= piv
    r4 = _eliminate6(r4, r3, r4[3] / piv)
    # Step 4.
    if abs(r4[4]) == 0.0:
        return 0.0, False, 0.0, 0.0, 0.0, 0.0, 0.0
    det *= r4[4]
    y4 = r4[5] / r4[4]
    y3 = (r3[5] - r3[4] * y4) / r3[3]
    y2 = ((r2[5] - r2[3] * y3) - r2[4] * y4) / r2[2]
    y1 = (((r1[5] - r1[2] * y2) - r1[3] * y3) - r1[4] * y4) / r1[1]
    y0 = ((((r0[5] - r0[1] * y1) - r0[2] * y2) - r0[3] * y3) - r0[4] * y4) / r0[0]
    return det, True, y0, y1, y2, y3, y4


@jit
def _eliminate6(ri, rk, f):
    """:func:`_eliminate5` for 6-tuples."""
    if f == 0.0:
        return ri
    return (ri[0] - f * rk[0], ri[1] - f * rk[1], ri[2] - f * rk[2], ri[3] - f * rk[3],
            ri[4] - f * rk[4], ri[5] - f * rk[5])


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


#: Sines of the angular margins of :func:`_surely_outside`: another robot counts as
#: strictly counter-clockwise of robot ``j`` within a quarter turn when the sine exceeds
#: ``_CCW_SIN``, and beyond a quarter turn when it exceeds ``_ARC_SIN`` (so short of a
#: half turn by more than 2e-6 rad). Both far above the rounding of the cross products
#: (~1e-16 relative) and, for the latter, of ``atan2`` and ``ANGLE_TOL``.
_CCW_SIN, _ARC_SIN = 1e-12, 2e-6


@jit_inline
def _in_hull(Rn, taut, N, px, py, ang):
    """The paper's projection test (``_kernel.in_hull_2d``) for the robots in ``taut``:
    True when the projected object ``(px, py)`` sits on a taut robot, else when no angular
    gap between the taut robots seen from it exceeds pi (``ANGLE_TOL``). The gaps come
    from ``atan2``, unless :func:`_surely_outside` already answers False or
    :func:`_surely_inside` True."""
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
    if _surely_outside(Rn, taut, N, px, py):
        return False
    if _surely_inside(Rn, taut, N, px, py):
        return True
    for j in range(N):                             # none at the point (above)
        if taut[j]:
            ang[m] = math.atan2(Rn[j, 1] - py, Rn[j, 0] - px)
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
def _surely_outside(Rn, taut, N, px, py):
    """True when the robots in ``taut`` (none at ``(px, py)``), seen from ``(px, py)``,
    lie in a closed arc shorter than a half turn by more than 2e-6 rad: some taut robot
    ``j`` has every other one strictly counter-clockwise of it and less than that far
    round (cross and dot products against the margins ``_CCW_SIN``, ``_ARC_SIN``; no
    square root, no ``atan2``). The complementary gap then exceeds pi + 2e-6, and
    :func:`_in_hull`'s ``atan2`` gaps (rounding ~1e-15) would answer False as well: a
    cheap sure answer, False when unsure (then ``atan2`` decides)."""
    for j in range(N):
        if not taut[j]:
            continue
        ax = Rn[j, 0] - px
        ay = Rn[j, 1] - py
        a2 = ax * ax + ay * ay
        arc = True
        for k in range(N):
            if k == j or not taut[k]:
                continue
            bx = Rn[k, 0] - px
            by = Rn[k, 1] - py
            cross = ax * by - ay * bx
            sin = _CCW_SIN if ax * bx + ay * by > 0.0 else _ARC_SIN
            if not (cross > 0.0 and cross * cross > (sin * sin) * (a2 * (bx * bx + by * by))):
                arc = False
                break
        if arc:
            return True
    return False


@jit_inline
def _surely_inside(Rn, taut, N, px, py):
    """True when ``(px, py)`` (no taut robot at it) lies inside a triangle of three robots
    in ``taut``, each seen from it turning the same way to the next by a sine above
    ``_CCW_SIN`` (cross products, no ``atan2``). The three directions then leave no gap
    above pi - 1e-12 (rounding ~1e-15), and neither do all of them: :func:`_in_hull`'s
    ``atan2`` gaps would answer True as well (within pi + ``ANGLE_TOL``). False when
    unsure (then ``atan2`` decides)."""
    s2 = _CCW_SIN * _CCW_SIN
    for j in range(N):
        if not taut[j]:
            continue
        ax = Rn[j, 0] - px
        ay = Rn[j, 1] - py
        a2 = ax * ax + ay * ay
        for k in range(j + 1, N):
            if not taut[k]:
                continue
            bx = Rn[k, 0] - px
            by = Rn[k, 1] - py
            b2 = bx * bx + by * by
            ab = ax * by - ay * bx
            if not ab * ab > s2 * (a2 * b2):
                continue
            for m in range(k + 1, N):
                if not taut[m]:
                    continue
                cx = Rn[m, 0] - px
                cy = Rn[m, 1] - py
                c2 = cx * cx + cy * cy
                bc = bx * cy - by * cx
                ca = cx * ay - cy * ax
                if ((ab > 0.0) == (bc > 0.0) and (ab > 0.0) == (ca > 0.0)
                        and bc * bc > s2 * (b2 * c2) and ca * ca > s2 * (c2 * a2)):
                    return True
    return False


#: Rows of the work array of :func:`_reduced_min_eig_ws` (4 columns).
EIG_WORK_ROWS = 3


@jit
def _reduced_min_eig(P, members, s):
    """Smallest eigenvalue of diag(1, 1, -1, -1) on the face's tangent space
    (``_kernel.reduced_hessian_min_eig``): +inf for 5 members, the generalised cross
    product for 4, a 2 x 2 closed form for 3, -1 for 2 (docs/sheet_kinematics.md §5)."""
    return _reduced_min_eig_ws(P, members, s, np.empty((EIG_WORK_ROWS, 4)))


@jit_inline
def _reduced_min_eig_ws(P, members, s, work):
    """:func:`_reduced_min_eig` on a caller's work array ``work`` (``EIG_WORK_ROWS``, 4):
    no allocation (the per-call path of the small-team kernel)."""
    if s >= 5:
        return np.inf
    if s <= 2:
        # A 3-space: by Cauchy interlacing against diag(1, 1, -1, -1) the smallest
        # eigenvalue is exactly -1 (such rows never get here: a 2-cable taut set fails
        # the paper's test, larger ones are weight families).
        return -1.0
    if s == 3:
        return _min_eig_three(P, members[0], members[1], members[2])
    D = work[0:3]
    for a in range(1, s):
        for c in range(4):
            D[a - 1, c] = P[members[a], c] - P[members[0], c]
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


@jit_inline
def _min_eig_three(P, i, j, k):
    """The 3-member case of :func:`_reduced_min_eig_ws`: the face's tangent space is the
    orthogonal complement of the plane spanned by ``d1 = P_j - P_i`` and ``d2 = P_k - P_i``
    (first 4 coordinates). J = diag(1, 1, -1, -1) is symmetric and orthogonal, so in an
    orthonormal basis (plane, complement) its blocks A (plane) and C (complement) satisfy
    A^2 + B B' = I, C^2 + B' B = I and trace A + trace C = trace J = 0 (CS decomposition):
    with both blocks 2 x 2 the spectrum of C is minus that of A, and the smallest
    eigenvalue on the tangent space is minus the largest of A, a symmetric 2 x 2 from one
    Gram-Schmidt step on d1, d2 (re-orthogonalised once). No work array, no loop over
    axes."""
    a0 = P[j, 0] - P[i, 0]
    a1 = P[j, 1] - P[i, 1]
    a2 = P[j, 2] - P[i, 2]
    a3 = P[j, 3] - P[i, 3]
    n = math.sqrt(a0 * a0 + a1 * a1 + a2 * a2 + a3 * a3)
    a0, a1, a2, a3 = a0 / n, a1 / n, a2 / n, a3 / n
    b0 = P[k, 0] - P[i, 0]
    b1 = P[k, 1] - P[i, 1]
    b2 = P[k, 2] - P[i, 2]
    b3 = P[k, 3] - P[i, 3]
    for _ in range(2):                             # "twice is enough"
        d = a0 * b0 + a1 * b1 + a2 * b2 + a3 * b3
        b0, b1, b2, b3 = b0 - d * a0, b1 - d * a1, b2 - d * a2, b3 - d * a3
    n = math.sqrt(b0 * b0 + b1 * b1 + b2 * b2 + b3 * b3)
    b0, b1, b2, b3 = b0 / n, b1 / n, b2 / n, b3 / n
    h00 = a0 * a0 + a1 * a1 - a2 * a2 - a3 * a3
    h11 = b0 * b0 + b1 * b1 - b2 * b2 - b3 * b3
    h01 = a0 * b0 + a1 * b1 - a2 * b2 - a3 * b3
    half = 0.5 * (h00 - h11)
    return -(0.5 * (h00 + h11) + math.sqrt(half * half + h01 * h01))
