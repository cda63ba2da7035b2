"""Compiled forward kinematics of many formations of one small team in one numba call,
with one workspace for the whole batch (``_small_kernel.solve_formations`` allocates
its per-formation arrays and sorts with ``np.argsort`` for every formation; at N = 4 that
is a third of the cost). The per-formation decisions are those of
``_small_kernel.solve_formation`` (the same helper functions, in the same order), so the
rows are identical (tested in tests/sheet/fk/test_solver_batch.py)."""

from __future__ import annotations

import numpy as np

from ..._jit import jit
from .small import (INFEASIBLE, _candidates, _frame, append_rows, classify_survivors, feasible,
    similar_fit, solve_formation)

__all__ = ["solve_formations_ws", "solve_packed", "pack"]


@jit
def _sorted_survivors(key, C, order):
    """Indices of the candidates with ``key >= 0`` into ``order``, by increasing key (the
    keys are distinct: they end in the table position); returns their count."""
    m = 0
    for c in range(C):
        k = key[c]
        if k < 0:
            continue
        i = m - 1
        while i >= 0 and key[order[i]] > k:            # insertion sort: C is small
            order[i + 1] = order[i]
            i -= 1
        order[i + 1] = c
        m += 1
    return m


@jit
def _one(R, Vn, table, sizes, scale, vcx, vcy, hold, lim2, out, Rn, P, G, bvec, sol,
         taut, key, order, ang):
    """``_small_kernel.solve_formation`` on preallocated work arrays; returns the number
    of rows written to ``out`` (or ``INFEASIBLE``). ``taut`` needs no reset: only rows of
    surviving candidates are read, and ``_candidates`` writes those in full."""
    if not feasible(R, lim2):
        return INFEASIBLE
    C = table.shape[0]
    cx, cy = _frame(R, Vn, scale, Rn, P, G, bvec)
    z = hold / scale
    found = _candidates(Rn, P, G, bvec, table, sizes, z * z, sol, taut, key)
    if found == 0:
        return 0
    m = _sorted_survivors(key, C, order)
    k, _stable, _pending = classify_survivors(order, 0, m, key, C, Rn, P, table, sizes, sol,
                                              taut, ang, out, Vn, scale, cx, cy, vcx, vcy,
                                              hold)
    return k


@jit
def solve_formations_ws(Rb, Vn, table, sizes, scale, vcx, vcy, hold, lim2):
    """As ``_small_kernel.solve_formations``: rows (M, width) of every formation of
    ``Rb`` (B, N, 2), their formation index (M,), and the first infeasible formation's
    index (or -1)."""
    B, N = Rb.shape[0], Rb.shape[1]
    C = table.shape[0]
    W = 12 + 3 * N
    buf = np.empty((C, W))
    Rn = np.empty((N, 2))
    P = np.empty((N, 5))
    G = np.empty((N, N))
    bvec = np.empty(N)
    sol = np.empty((C, 11))
    taut = np.zeros((C, N), dtype=np.bool_)
    key = np.empty(C, dtype=np.int64)
    order = np.empty(C, dtype=np.int64)
    ang = np.empty(N)
    cap = max(16, 2 * B)
    rows = np.empty((cap, W))
    form = np.empty(cap, dtype=np.int64)
    M = 0
    for b in range(B):
        k = _one(Rb[b], Vn, table, sizes, scale, vcx, vcy, hold, lim2, buf, Rn, P, G, bvec,
                 sol, taut, key, order, ang)
        if k < 0:
            return rows[:M], form[:M], b
        rows, form = append_rows(rows, form, M, buf, k, b)
        M += k
    return rows[:M], form[:M], -1


def pack(Vn, A, lim2, table, sizes, scale, vcx, vcy, hold, snap):
    """The arguments of :func:`solve_packed` for one solver: a flat float64 array (``Vn``
    and ``A`` (N, 2) each, ``lim2`` (N, N), then ``scale, vcx, vcy, hold`` and the three
    snap-screen bounds ``snap``) and a flat int64 array (``table`` (C, 5) then ``sizes``
    (C,)). Two arguments instead of nine: numba's dispatch costs ~0.3 us per array."""
    f = np.concatenate([np.ravel(Vn), np.ravel(A), np.ravel(lim2),
                        [scale, vcx, vcy, hold], np.asarray(snap, dtype=np.float64)])
    i = np.concatenate([np.ravel(table), np.ravel(sizes)]).astype(np.int64)
    return np.ascontiguousarray(f, dtype=np.float64), np.ascontiguousarray(i)


@jit
def solve_packed(R, fpack, ipack, out):
    """``_small_kernel.solve_formation`` of formation ``R`` (N, 2) on the packed solver
    arguments (:func:`pack`), and the screen of ``FKSolver._snap`` (next to a similar copy
    the formation is answered as the copy, stable states or not: docs/sheet_fk_solver.md)
    (``_small_kernel.similar_fit``: the formation is within the snap distance of a
    similar copy of the sheet, not larger than it). Returns ``(rows, stable_rows,
    pending_rows, near_copy)``; rows is ``INFEASIBLE`` for a torn or non-finite ``R``."""
    N = R.shape[0]
    C = ipack.shape[0] // 6
    Vn = fpack[0:2 * N].reshape(N, 2)
    A = fpack[2 * N:4 * N].reshape(N, 2)
    lim2 = fpack[4 * N:4 * N + N * N].reshape(N, N)
    g = 4 * N + N * N
    table = ipack[0:5 * C].reshape(C, 5)
    sizes = ipack[5 * C:6 * C]
    k, stable, pending = solve_formation(R, Vn, table, sizes, fpack[g], fpack[g + 1],
                                         fpack[g + 2], fpack[g + 3], lim2, out)
    near = False
    if k >= 0:
        scale, dist = similar_fit(R, A)
        near = fpack[g + 4] < dist <= fpack[g + 5] and scale <= fpack[g + 6]
    return k, stable, pending, near


@jit
def snap_screen_batch(Rb, A, low, high, top):
    """The snap screen of ``solve_packed`` on every formation of ``Rb`` (B, N, 2): within
    ``(low, high]`` of a similar copy of the sheet (centred vertices ``A``), scale at most
    ``top`` -> (B,) bool (``FKSolver._snap`` makes the exact test on those)."""
    B = Rb.shape[0]
    out = np.zeros(B, dtype=np.bool_)
    for b in range(B):
        scale, dist = similar_fit(Rb[b], A)
        out[b] = low < dist <= high and scale <= top
    return out
