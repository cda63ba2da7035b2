"""Compiled forward kinematics for small teams: every taut-set candidate of at most five
cables, solved and classified in one numba function per formation.

The same decisions as the numpy path (``fk._solve._solve_as_given`` with a subset table, then
``_finalize.classify``), in the same order (docs/sheet_kinematics.md §1-§5):

1. normalised frame (formation and sheet centred, lengths over the sheet size);
2. per candidate ``S`` (table order): the bordered Lagrange system ``[G 1; 1' 0] [w; mu] =
   [b_S; 1]`` by LU with partial pivoting; a small relative determinant sends it to the
   condition-number test (``SINGULAR_RTOL``, ``MAX_CONDITION``);
3. real depth below the hold height (FK paper eq. 15), no cable over-stretched and the
   exact taut set (``TAUT_TOL``);
4. one row per taut set (the candidate that *is* the taut set preferred), ordered by
   taut-set size then taut set; the paper's projection test (``INSIDE_WEIGHT``,
   ``ANGLE_TOL``); kind (stable, saddle, not an equilibrium) from the weights' signs
   (``WEIGHT_TOL``) and the reduced Hessian (``CURVATURE_TOL``).

Rows whose taut set is larger than their candidate (a weight *family*, e.g. Lemma 2) get
kind ``PENDING``: their weights need an LP, done by the caller in Python exactly as the
numpy path does. Every function here is plain Python over scalars and small arrays, so
it also runs (slowly) without numba; ``jit`` compiles it when numba is installed.

Output rows (float64, width ``8 + 3 N + 4``; see ``COL_*``): kind, taut-set size,
object (3, user units), contact (2, user units), normalised depth, taut mask (N, 0/1),
weights (N), cable lengths (N, user units), the normalised point ``x = (r_o, v_o)`` (4).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..._jit import HAVE_NUMBA, jit, jit_inline
from .linalg import (EIG_WORK_ROWS, _in_hull, _lu_solve, _lu_solve4, _lu_solve5,
    _reduced_min_eig_ws, _singular_extremes)
from .._tol import CURVATURE_TOL, INSIDE_WEIGHT, MAX_CONDITION, SINGULAR_RTOL, TAUT_TOL, WEIGHT_TOL

__all__ = ["HAVE_NUMBA", "solve_formation", "solve_into", "solve_carved", "work_views",
           "solve_formations", "append_rows",
           "lifted_points", "similar_fit", "feasible", "row_width", "work_floats", "borrowed",
           "shaped"]


def _same(arr: Any) -> Any:
    """``arr`` itself: :data:`borrowed` without numba (no reference count to skip)."""
    return arr


#: ``borrowed(arr)`` in a kernel: ``arr`` without its reference count (numba's meminfo and
#: parent set to NULL), so that calls on it and views of it cost no atomic reference
#: counting. numba counts every array argument of a compiled call up on entry and down on
#: return, and every view; at N = 4 that was ~1/5 of the batch kernel's time (2.5 -> 2.0
#: us a formation). Only for an *argument* of the calling kernel (its caller owns it for
#: the whole call), never for a local (it would be freed after its last use) nor for an
#: array returned to Python. Without numba, the array itself.
borrowed: Any = _same


def _reshape(arr: Any, shape: Any) -> Any:
    """``arr.reshape(shape)``: :data:`_c_view` without numba."""
    return arr.reshape(shape)


#: ``_c_view(arr, shape)`` in a kernel: the C-contiguous ``arr`` as a C-contiguous view of
#: shape ``shape`` (same data, same reference count), built in place; no size check (see
#: :func:`shaped`). Without numba, ``arr.reshape(shape)``.
_c_view: Any = _reshape

if HAVE_NUMBA:
    from numba.core import cgutils, types
    from numba.extending import intrinsic

    def _borrow(typingctx: Any, arr: Any) -> Any:
        """numba typing and code of :data:`borrowed`."""
        if not isinstance(arr, types.Array):
            return None

        def codegen(context: Any, builder: Any, sig: Any, args: Any) -> Any:
            ary = context.make_array(sig.args[0])(context, builder, value=args[0])
            ary.meminfo = cgutils.get_null_value(ary.meminfo.type)
            ary.parent = cgutils.get_null_value(ary.parent.type)
            return ary._getvalue()
        return arr(arr), codegen

    borrowed = intrinsic(_borrow)

    def _view_c(typingctx: Any, arr: Any, shape: Any) -> Any:
        """numba typing and code of :data:`_c_view` (C-contiguous ``arr`` only)."""
        if not (isinstance(arr, types.Array) and arr.layout == "C"
                and isinstance(shape, types.UniTuple)
                and isinstance(shape.dtype, types.Integer)):
            return None
        ret = arr.copy(ndim=shape.count, layout="C")

        def codegen(context: Any, builder: Any, sig: Any, args: Any) -> Any:
            from numba.core.imputils import impl_ret_borrowed
            from numba.np.arrayobj import populate_array

            src = context.make_array(sig.args[0])(context, builder, value=args[0])
            dims = [context.cast(builder, d, shape.dtype, types.intp)
                    for d in cgutils.unpack_tuple(builder, args[1])]
            strides: list[Any] = []
            step = src.itemsize
            for d in reversed(dims):
                strides.insert(0, step)
                step = builder.mul(step, d)
            dst = context.make_array(sig.return_type)(context, builder)
            populate_array(dst, data=src.data, shape=dims, strides=strides,
                           itemsize=src.itemsize, meminfo=src.meminfo, parent=src.parent)
            return impl_ret_borrowed(context, builder, sig.return_type, dst._getvalue())
        return ret(arr, shape), codegen

    _c_view = intrinsic(_view_c)


@jit
def shaped(arr, shape):
    """``arr.reshape(shape)`` for a C-contiguous ``arr`` of exactly that many items, as a
    view made in place: numba's ``reshape`` calls a C helper for the general case (~20-30
    ns each; the per-call path of ``FKSolver.solve`` carves ~13 views)."""
    n = 1
    for d in shape:
        n *= d
    if n != arr.size:
        raise ValueError("shaped: size mismatch")
    return _c_view(arr, shape)


#: Row kind codes (the first three as ``_lifted.KIND_*``; ``PENDING``: weights to resolve).
STABLE, SADDLE, NOT_EQUILIBRIUM, PENDING = 0, 1, 2, 3
#: Kernel return codes.
OK, INFEASIBLE = 0, -1

COL_KIND, COL_TSIZE, COL_OBJECT, COL_CONTACT, COL_DEPTH, COL_TAUT = 0, 1, 2, 5, 7, 8


def row_width(N: int) -> int:
    """Width of an output row for ``N`` robots."""
    return 12 + 3 * N


#: Floats of :func:`solve_into`'s work array besides the per-robot and per-candidate
#: parts: the bordered system (13 x 6) and the reduced Hessian's work (``EIG_WORK_ROWS``
#: x 4).
_FIXED_WORK = 13 * 6 + EIG_WORK_ROWS * 4


@jit
def work_floats(N, C):
    """Length of :func:`solve_into`'s float work array for ``N`` robots and ``C``
    candidates."""
    return 2 * N + 5 * N + N * N + N + N + 11 * C + _FIXED_WORK


@jit
def _lagrange(G, bvec, members, s, K, rhs, work):
    """Solve candidate ``members[:s]``'s bordered system into ``rhs[:s+1]`` = (w, mu).
    Returns False where the system is singular (policy of ``_kernel._screen_and_solve``:
    relative determinant, then the condition number of the 6 x 6 padded form). Three and
    four members (most candidates of small teams) take :func:`_lu_solve4` /
    :func:`_lu_solve5` on registers, bit-identical to :func:`_lu_solve`."""
    n = s + 1
    if s == 3:
        det, solved, norms = _bordered3(G, bvec, members[0], members[1], members[2], rhs)
    elif s == 4:
        det, solved, norms = _bordered4(G, bvec, members[0], members[1], members[2],
                                        members[3], rhs)
    else:
        _fill_bordered(G, members, s, K)
        for a in range(s):
            rhs[a] = bvec[members[a]]
        rhs[s] = 1.0
        norms = 1.0
        for a in range(n):
            r2 = 0.0
            for c in range(n):
                r2 += K[a, c] * K[a, c]
            norms *= math.sqrt(r2)
        det, solved = _lu_solve(K, rhs, n)
    return _clear(det, solved, norms) or _conditioned(G, members, s, work, solved)


@jit_inline
def _clear(det, solved, norms):
    """The bordered system is solved and clearly regular (relative determinant)."""
    return solved and abs(det) > SINGULAR_RTOL * norms


@jit
def _conditioned(G, members, s, work, solved):
    """A suspect system (not :func:`_clear`) is accepted: solved and its condition
    number below ``MAX_CONDITION``. ``work`` (6, 6): work array."""
    # Condition number of the padded 6 x 6 form (extra singular values 1).
    _fill_bordered(G, members, s, work)
    top, bottom = _singular_extremes(work, s + 1)
    smax = max(top, 1.0)
    smin = min(bottom, 1.0)
    if not (smin > 0.0 and smax / smin < MAX_CONDITION):
        return False
    if not solved:
        return False
    return True


@jit
def _fill_bordered(G, members, s, K):
    """``K[:s+1, :s+1]`` = the bordered matrix ``[G_S 1; 1' 0]`` of ``members[:s]``."""
    for a in range(s):
        ia = members[a]
        for c in range(s):
            K[a, c] = G[ia, members[c]]
        K[a, s] = 1.0
        K[s, a] = 1.0
    K[s, s] = 0.0


@jit_inline
def _bordered3(G, bvec, i, j, k, rhs):
    """:func:`_lagrange`'s system for the members ``i, j, k``: rows as tuples, the
    product of the row norms in :func:`_lagrange`'s order, :func:`_lu_solve4`; the
    solution into ``rhs[:4]`` when solved. Returns ``(det, solved, norms)``."""
    r0 = (G[i, i], G[i, j], G[i, k], 1.0, bvec[i])
    r1 = (G[j, i], G[j, j], G[j, k], 1.0, bvec[j])
    r2 = (G[k, i], G[k, j], G[k, k], 1.0, bvec[k])
    r3 = (1.0, 1.0, 1.0, 0.0, 1.0)
    norms = 1.0
    norms *= math.sqrt(r0[0] * r0[0] + r0[1] * r0[1] + r0[2] * r0[2] + r0[3] * r0[3])
    norms *= math.sqrt(r1[0] * r1[0] + r1[1] * r1[1] + r1[2] * r1[2] + r1[3] * r1[3])
    norms *= math.sqrt(r2[0] * r2[0] + r2[1] * r2[1] + r2[2] * r2[2] + r2[3] * r2[3])
    norms *= math.sqrt(r3[0] * r3[0] + r3[1] * r3[1] + r3[2] * r3[2] + r3[3] * r3[3])
    det, solved, y0, y1, y2, y3 = _lu_solve4(r0, r1, r2, r3)
    if solved:
        rhs[0] = y0
        rhs[1] = y1
        rhs[2] = y2
        rhs[3] = y3
    return det, solved, norms


@jit_inline
def _bordered4(G, bvec, i, j, k, m, rhs):
    """:func:`_bordered3` for the four members ``i, j, k, m`` (:func:`_lu_solve5`)."""
    r0 = (G[i, i], G[i, j], G[i, k], G[i, m], 1.0, bvec[i])
    r1 = (G[j, i], G[j, j], G[j, k], G[j, m], 1.0, bvec[j])
    r2 = (G[k, i], G[k, j], G[k, k], G[k, m], 1.0, bvec[k])
    r3 = (G[m, i], G[m, j], G[m, k], G[m, m], 1.0, bvec[m])
    r4 = (1.0, 1.0, 1.0, 1.0, 0.0, 1.0)
    norms = 1.0
    norms *= math.sqrt(r0[0] * r0[0] + r0[1] * r0[1] + r0[2] * r0[2] + r0[3] * r0[3]
                       + r0[4] * r0[4])
    norms *= math.sqrt(r1[0] * r1[0] + r1[1] * r1[1] + r1[2] * r1[2] + r1[3] * r1[3]
                       + r1[4] * r1[4])
    norms *= math.sqrt(r2[0] * r2[0] + r2[1] * r2[1] + r2[2] * r2[2] + r2[3] * r2[3]
                       + r2[4] * r2[4])
    norms *= math.sqrt(r3[0] * r3[0] + r3[1] * r3[1] + r3[2] * r3[2] + r3[3] * r3[3]
                       + r3[4] * r3[4])
    norms *= math.sqrt(r4[0] * r4[0] + r4[1] * r4[1] + r4[2] * r4[2] + r4[3] * r4[3]
                       + r4[4] * r4[4])
    det, solved, y0, y1, y2, y3, y4 = _lu_solve5(r0, r1, r2, r3, r4)
    if solved:
        rhs[0] = y0
        rhs[1] = y1
        rhs[2] = y2
        rhs[3] = y3
        rhs[4] = y4
    return det, solved, norms


@jit_inline
def centroid(R):
    """Mean ``(x, y)`` of the points ``R`` (N, 2)."""
    N = R.shape[0]
    cx = 0.0
    cy = 0.0
    for i in range(N):
        cx += R[i, 0]
        cy += R[i, 1]
    return cx / N, cy / N


@jit_inline
def _frame(R, Vn, scale, Rn, P, G, bvec):
    """Normalised robots ``Rn``, lifted points ``P`` (N, 5), Gram matrix ``G`` and ``b``
    (``_kernel.Frame.build``); returns the formation centre (cx, cy)."""
    N = R.shape[0]
    cx, cy = centroid(R)
    for i in range(N):
        Rn[i, 0] = (R[i, 0] - cx) / scale
        Rn[i, 1] = (R[i, 1] - cy) / scale
        b = (Rn[i, 0] * Rn[i, 0] + Rn[i, 1] * Rn[i, 1]) - (Vn[i, 0] * Vn[i, 0] + Vn[i, 1] * Vn[i, 1])
        P[i, 0] = -2.0 * Rn[i, 0]
        P[i, 1] = -2.0 * Rn[i, 1]
        P[i, 2] = 2.0 * Vn[i, 0]
        P[i, 3] = 2.0 * Vn[i, 1]
        P[i, 4] = b
        bvec[i] = b
    for i in range(N):
        for j in range(N):
            G[i, j] = 2.0 * ((Rn[i, 0] * Rn[j, 0] + Rn[i, 1] * Rn[j, 1])
                             - (Vn[i, 0] * Vn[j, 0] + Vn[i, 1] * Vn[j, 1]))
    return cx, cy


@jit_inline
def feasible(R, lim2):
    """Finite coordinates and no robot pair farther apart than its (tolerant) sheet
    distance (``model.check_formations``); ``lim2`` (N, N) squared limits."""
    N = R.shape[0]
    for i in range(N):
        if not (math.isfinite(R[i, 0]) and math.isfinite(R[i, 1])):
            return False
    for i in range(N):
        for j in range(i + 1, N):
            dx = R[i, 0] - R[j, 0]
            dy = R[i, 1] - R[j, 1]
            if dx * dx + dy * dy > lim2[i, j]:
                return False
    return True


@jit
def _candidates(Rn, P, G, bvec, table, sizes, z2, sol, taut, key, lin):
    """Steps 2-3 for every candidate of ``table`` (C, 5): ``sol[c]`` = (w (5), x (4), mu,
    depth2), ``taut[c]`` the exact taut set and ``key[c]`` its sort key (taut-set size,
    then taut set, then the own-set preference, then table order), or -1 where the
    candidate fails. Returns the number of survivors. ``lin`` (13, 6): work array."""
    N = Rn.shape[0]
    C = table.shape[0]
    K = lin[0:6]
    work = lin[6:12]
    rhs = lin[12]
    found = 0
    for c in range(C):
        key[c] = -1
        s = sizes[c]
        members = table[c]
        if s == 3:         # _lagrange's s == 3 case inline: one call (~6 % of the batch) less
            det, solved, norms = _bordered3(G, bvec, members[0], members[1], members[2], rhs)
            if not (_clear(det, solved, norms) or _conditioned(G, members, s, work, solved)):
                continue
        elif not _lagrange(G, bvec, members, s, K, rhs, work):
            continue
        x0 = x1 = x2 = x3 = 0.0
        for a in range(s):
            m = members[a]
            w = rhs[a]
            x0 += w * Rn[m, 0]
            x1 += w * Rn[m, 1]
            x2 += w * (P[m, 2] * 0.5)
            x3 += w * (P[m, 3] * 0.5)
        mu = rhs[s]
        depth2 = -((x0 * x0 + x1 * x1) - (x2 * x2 + x3 * x3) + mu)
        if not (depth2 > TAUT_TOL and depth2 < z2):
            continue
        worst = -np.inf
        code = 0
        tsize = 0
        for j in range(N):
            e = (x0 * P[j, 0] + x1 * P[j, 1] + x2 * P[j, 2] + x3 * P[j, 3]) + (P[j, 4] - mu)
            if e > worst:
                worst = e
            t = e >= -TAUT_TOL
            taut[c, j] = t
            if t:
                tsize += 1
            else:
                code |= 1 << (N - 1 - j)
        if not worst <= TAUT_TOL:
            continue
        for a in range(5):
            sol[c, a] = rhs[a] if a < s else 0.0
        sol[c, 5] = x0
        sol[c, 6] = x1
        sol[c, 7] = x2
        sol[c, 8] = x3
        sol[c, 9] = mu
        sol[c, 10] = depth2
        prefer = 0 if tsize == s else 1
        key[c] = ((((tsize << N) | code) * 2 + prefer) * C + c)
        found += 1
    return found


@jit_inline
def _classify_row(Rn, P, table, sizes, c, sol, taut_c, tsize, ang, eig):
    """Step 4 for candidate ``c`` whose exact taut set is ``taut_c``: -1 when the paper's
    projection test fails, else the status (``PENDING`` for weight families). ``ang``
    (N,) and ``eig`` (``EIG_WORK_ROWS``, 4): work arrays."""
    N = Rn.shape[0]
    s = sizes[c]
    min_w = np.inf
    for a in range(s):
        if sol[c, a] < min_w:
            min_w = sol[c, a]
    if tsize < 3:
        return -1
    if not min_w > INSIDE_WEIGHT:
        if not _in_hull(Rn, taut_c, N, sol[c, 5], sol[c, 6], ang):
            return -1
    if tsize != s:
        return PENDING
    if min_w < -WEIGHT_TOL:
        return NOT_EQUILIBRIUM
    if _reduced_min_eig_ws(P, table[c], s, eig) > CURVATURE_TOL:
        return STABLE
    return SADDLE


@jit_inline
def _write_row(out, k, status, c, sol, taut_c, tsize, table, sizes, Vn, scale, cx, cy,
               vcx, vcy, hold):
    """Row ``k`` of ``out`` in the caller's units (layout in the module docstring)."""
    N = Vn.shape[0]
    out[k, 0] = status
    out[k, 1] = tsize
    depth = math.sqrt(sol[c, 10])
    out[k, 2] = sol[c, 5] * scale + cx
    out[k, 3] = sol[c, 6] * scale + cy
    out[k, 4] = hold - depth * scale
    out[k, 5] = sol[c, 7] * scale + vcx
    out[k, 6] = sol[c, 8] * scale + vcy
    out[k, 7] = depth
    wcol = 8 + N
    lcol = 8 + 2 * N
    for j in range(N):
        out[k, 8 + j] = 1.0 if taut_c[j] else 0.0
        out[k, wcol + j] = 0.0
        dx = Vn[j, 0] - sol[c, 7]
        dy = Vn[j, 1] - sol[c, 8]
        out[k, lcol + j] = math.sqrt(dx * dx + dy * dy) * scale
    for a in range(sizes[c]):
        out[k, wcol + table[c, a]] = sol[c, a]
    xcol = 8 + 3 * N
    for a in range(4):
        out[k, xcol + a] = sol[c, 5 + a]


@jit
def solve_formation(R, Vn, table, sizes, scale, vcx, vcy, hold, lim2, out):
    """Every rest state of one formation ``R`` (N, 2, caller's units) into rows of
    ``out`` (at least C rows of ``row_width(N)``). ``Vn`` (N, 2) normalised vertices,
    ``table`` (C, 5) / ``sizes`` (C,) the candidates, ``lim2`` (N, N) squared pair limits.
    Returns ``(rows, stable_rows, pending_rows)``, or ``(INFEASIBLE, 0, 0)`` for a
    non-finite or torn formation (nothing solved)."""
    N = R.shape[0]
    C = table.shape[0]
    return solve_into(R, Vn, table, sizes, scale, vcx, vcy, hold, lim2, out,
                      np.empty(work_floats(N, C)), np.empty(2 * C, dtype=np.int64),
                      np.empty((C, N), dtype=np.bool_))


@jit
def solve_into(R, Vn, table, sizes, scale, vcx, vcy, hold, lim2, out, fw, iw, taut):
    """:func:`solve_formation` on the caller's work arrays: ``fw`` float64
    (``work_floats(N, C)``,), ``iw`` int64 (2 C,), ``taut`` bool (C, N); nothing is
    allocated (the per-call path). ``taut`` needs no reset: only rows of surviving
    candidates are read, and ``_candidates`` writes those in full."""
    N = R.shape[0]
    Rn, P, G, bvec, ang, sol, lin, eig, key, order = work_views(fw, iw, N, table.shape[0])
    return solve_carved(R, Vn, table, sizes, scale, vcx, vcy, hold, lim2, out, Rn, P, G, bvec,
                        ang, sol, lin, eig, key, order, taut)


@jit
def work_views(fw, iw, N, C):
    """The work arrays of :func:`solve_carved` as views of ``fw`` (``work_floats(N, C)``,)
    and ``iw`` (2 C,): Rn (N, 2), P (N, 5), G (N, N), bvec (N,), ang (N,), sol (C, 11),
    lin (13, 6), eig (``EIG_WORK_ROWS``, 4), key (C,), order (C,). Made once per batch:
    each view costs reference counting."""
    Rn = shaped(fw[0:2 * N], (N, 2))
    o = 2 * N
    P = shaped(fw[o:o + 5 * N], (N, 5))
    o += 5 * N
    G = shaped(fw[o:o + N * N], (N, N))
    o += N * N
    bvec = fw[o:o + N]
    ang = fw[o + N:o + 2 * N]
    o += 2 * N
    sol = shaped(fw[o:o + 11 * C], (C, 11))
    o += 11 * C
    lin = shaped(fw[o:o + 78], (13, 6))
    eig = shaped(fw[o + 78:o + 78 + 4 * EIG_WORK_ROWS], (EIG_WORK_ROWS, 4))
    return Rn, P, G, bvec, ang, sol, lin, eig, iw[0:C], iw[C:2 * C]


@jit
def solve_carved(R, Vn, table, sizes, scale, vcx, vcy, hold, lim2, out, Rn, P, G, bvec, ang,
                 sol, lin, eig, key, order, taut):
    """:func:`solve_formation` on the work arrays of :func:`work_views` and ``taut``."""
    if not feasible(R, lim2):
        return INFEASIBLE, 0, 0
    C = table.shape[0]
    cx, cy = _frame(R, Vn, scale, Rn, P, G, bvec)
    z = hold / scale
    found = _candidates(Rn, P, G, bvec, table, sizes, z * z, sol, taut, key, lin)
    if found == 0:
        return 0, 0, 0
    m = sorted_survivors(key, C, found, order)
    return classify_survivors(order, 0, m, key, C, Rn, P, table, sizes, sol, taut, ang, eig,
                              out, Vn, scale, cx, cy, vcx, vcy, hold)


#: Up to this many survivors :func:`sorted_survivors` sorts by insertion (no allocation).
_INSERTION_MAX = 32


@jit
def sorted_survivors(key, C, found, order):
    """Indices of the ``found`` candidates with ``key >= 0`` into ``order``, by increasing
    key (the keys are distinct: they end in the table position); returns ``found``."""
    if found > _INSERTION_MAX:
        order[:found] = np.argsort(key)[C - found:]
        return found
    m = 0
    for c in range(C):
        k = key[c]
        if k < 0:
            continue
        i = m - 1
        while i >= 0 and key[order[i]] > k:
            order[i + 1] = order[i]
            i -= 1
        order[i + 1] = c
        m += 1
    return m


@jit
def classify_survivors(order, r0, r1, key, C, Rn, P, table, sizes, sol, taut, ang, eig, out,
                       Vn, scale, cx, cy, vcx, vcy, hold):
    """Classify the surviving candidates ``order[r0:r1]`` (sorted by ``key``; one per
    distinct stationary point, ``key // (2 C)``) and write their rows into ``out``.
    Returns ``(rows, stable_rows, pending_rows)``."""
    N = Rn.shape[0]
    k = 0
    stable = 0
    pending = 0
    last = -1
    for r in range(r0, r1):
        c = order[r]
        head = key[c] // (2 * C)
        if head == last:
            continue
        last = head
        tsize = 0
        for j in range(N):
            if taut[c, j]:
                tsize += 1
        status = _classify_row(Rn, P, table, sizes, c, sol, taut[c], tsize, ang, eig)
        if status < 0:
            continue
        _write_row(out, k, status, c, sol, taut[c], tsize, table, sizes, Vn, scale, cx, cy,
                   vcx, vcy, hold)
        if status == STABLE:
            stable += 1
        elif status == PENDING:
            pending += 1
        k += 1
    return k, stable, pending


@jit
def append_rows(rows, form, M, buf, k, b):
    """Append ``buf[:k]``, the rows of formation ``b``, to ``rows`` (cap, W) and ``form``
    (cap,) that hold ``M`` rows, doubling their capacity when full; returns the arrays
    (new ones when they grew)."""
    cap = rows.shape[0]
    if M + k > cap:
        cap = max(2 * cap, M + k)
        grown = np.empty((cap, rows.shape[1]))
        grown[:M] = rows[:M]
        rows = grown
        gform = np.empty(cap, dtype=np.int64)
        gform[:M] = form[:M]
        form = gform
    rows[M:M + k] = buf[:k]
    form[M:M + k] = b
    return rows, form


@jit
def solve_formations(Rb, Vn, table, sizes, scale, vcx, vcy, hold, lim2):
    """:func:`solve_formation` for each of ``Rb`` (B, N, 2). Returns the rows (M, width)
    with their formation index ``form`` (M,), and the first infeasible formation's index
    (or -1)."""
    B, N = Rb.shape[0], Rb.shape[1]
    C = table.shape[0]
    W = 12 + 3 * N
    buf = np.empty((C, W))
    cap = max(16, 2 * B)
    rows = np.empty((cap, W))
    form = np.empty(cap, dtype=np.int64)
    M = 0
    for b in range(B):
        k, _, _ = solve_formation(Rb[b], Vn, table, sizes, scale, vcx, vcy, hold, lim2, buf)
        if k < 0:
            return rows[:M], form[:M], b
        rows, form = append_rows(rows, form, M, buf, k, b)
        M += k
    return rows[:M], form[:M], -1


@jit
def lifted_points(R, Vn, scale):
    """Normalised lifted points :math:`P_i = (\\mathbf{a}_i, b_i)` (N, 5) of formation
    ``R`` (docs/sheet_kinematics.md §1), as ``_kernel.Frame.build``."""
    N = R.shape[0]
    Rn = np.empty((N, 2))
    P = np.empty((N, 5))
    G = np.empty((N, N))
    bvec = np.empty(N)
    _frame(R, Vn, scale, Rn, P, G, bvec)
    return P


@jit
def similar_fit(R, A):
    """Scale and largest robot displacement of the closest similar copy ``s Q A + c`` of
    the centred vertices ``A`` (N, 2) to formation ``R`` (rotation only, centroid kept;
    ``fk.similar_copy`` without building the copy). The displacement is +inf where the
    best orthogonal fit is a reflection (``det(A' R_c) < 0``), as there."""
    N = R.shape[0]
    cx = 0.0
    cy = 0.0
    for i in range(N):
        cx += R[i, 0]
        cy += R[i, 1]
    cx /= N
    cy /= N
    m00 = m01 = m10 = m11 = aa = 0.0
    for i in range(N):
        rx, ry = R[i, 0] - cx, R[i, 1] - cy
        m00 += A[i, 0] * rx
        m01 += A[i, 0] * ry
        m10 += A[i, 1] * rx
        m11 += A[i, 1] * ry
        aa += A[i, 0] * A[i, 0] + A[i, 1] * A[i, 1]
    if m00 * m11 - m01 * m10 < 0.0:
        return 0.0, np.inf
    # Best rotation for a 2 x 2 cross-covariance with det >= 0: angle from its rotation
    # part; the sum of its singular values is the norm of that part.
    c = m00 + m11
    s = m01 - m10
    nuc = math.sqrt(c * c + s * s)
    if nuc == 0.0:
        return 0.0, np.inf
    cos, sin = c / nuc, s / nuc
    scale = nuc / aa
    dist = 0.0
    for i in range(N):
        qx = scale * (cos * A[i, 0] - sin * A[i, 1]) + cx
        qy = scale * (sin * A[i, 0] + cos * A[i, 1]) + cy
        d = max(abs(qx - R[i, 0]), abs(qy - R[i, 1]))
        if d > dist:
            dist = d
    return scale, dist
