"""Compiled forward kinematics of one small team: many formations in one numba call with
one workspace for the whole batch, and the per-call path of ``FKSolver.solve`` (one call
on a packed solver, nothing allocated but the work arrays). The per-formation decisions
are those of ``_small_kernel.solve_formation`` (the same function, ``solve_into``), so the
rows are identical (tested in tests/sheet/fk/test_solver_batch.py and
tests/sheet/fk/test_solver_fastpath.py)."""

from __future__ import annotations

import numpy as np

from ..._jit import jit
from .small import (INFEASIBLE, append_rows, borrowed, shaped, similar_fit, solve_carved,
    solve_into, work_floats, work_views)

__all__ = ["solve_formations_ws", "solve_one", "pack", "out_rows", "decode", "snap_screen_batch",
           "HEADER", "FLAGS_SHIFT", "HAS_STABLE", "HAS_PENDING", "NEAR_COPY", "TORN"]


@jit
def solve_formations_ws(Rb, Vn, table, sizes, scale, vcx, vcy, hold, lim2):
    """As ``_small_kernel.solve_formations``: rows (M, width) of every formation of
    ``Rb`` (B, N, 2), their formation index (M,), and the first infeasible formation's
    index (or -1). One workspace for the whole batch; the formations are solved by
    :func:`_solve_formations`, which returns here only to size or grow the output."""
    B, N = Rb.shape[0], Rb.shape[1]
    C = table.shape[0]
    W = 12 + 3 * N
    buf = np.empty((C, W))
    fw = np.empty(work_floats(N, C))
    iw = np.empty(2 * C, dtype=np.int64)
    taut = np.empty((C, N), dtype=np.bool_)
    # No room until the first formation with rows: it sizes the output (below).
    rows = np.empty((0, W))
    form = np.empty(0, dtype=np.int64)
    M = 0
    b = 0
    while True:
        M, b, k = _solve_formations(Rb, b, Vn, table, sizes, scale, vcx, vcy, hold, lim2, buf,
                                    fw, iw, taut, rows, form, M)
        if k <= 0:                                 # done, or formation b infeasible
            return rows[:M], form[:M], (b if k < 0 else -1)
        if M == 0:
            # Room for the rest at this formation's k rows each, plus 1/8 (a batch of
            # similar formations has similar counts; a team with several rest states
            # per formation then fills its output without regrowing), at least 2 per
            # formation; a later overflow doubles (append_rows).
            left = B - b
            cap = max(16, 2 * left, k * left + left // 8 + 16)
            rows = np.empty((cap, W))
            form = np.empty(cap, dtype=np.int64)
        rows, form = append_rows(rows, form, M, buf, k, b)    # grows when full
        M += k
        b += 1


@jit
def _solve_formations(Rb, b0, Vn, table, sizes, scale, vcx, vcy, hold, lim2, buf, fw, iw,
                      taut, rows, form, M):
    """Solve formations ``b0, b0 + 1, ...`` of ``Rb`` on the work arrays ``buf`` (C,
    width), ``fw``, ``iw`` (``solve_into``) and ``taut`` (C, N), appending their rows to
    ``rows`` / ``form`` after the first ``M``. Returns ``(M, b, k)``: ``k = 0`` all done;
    ``k < 0`` formation ``b`` is infeasible; ``k > 0`` formation ``b``'s ``k`` rows are in
    ``buf`` and do not fit. Every array is used borrowed (``borrowed``: no reference
    counting in the per-formation loop; the caller owns them for the call)."""
    Rb, Vn, table, sizes, lim2 = borrowed(Rb), borrowed(Vn), borrowed(table), borrowed(sizes), \
        borrowed(lim2)
    buf, fw, iw, taut = borrowed(buf), borrowed(fw), borrowed(iw), borrowed(taut)
    rows, form = borrowed(rows), borrowed(form)
    B, N = Rb.shape[0], Rb.shape[1]
    W = rows.shape[1]
    Rn, P, G, bvec, ang, sol, lin, eig, key, order = work_views(fw, iw, N, table.shape[0])
    for b in range(b0, B):
        k, _, _ = solve_carved(Rb[b], Vn, table, sizes, scale, vcx, vcy, hold, lim2, buf, Rn,
                               P, G, bvec, ang, sol, lin, eig, key, order, taut)
        if k < 0 or M + k > rows.shape[0]:
            return M, b, k
        for i in range(k):
            for j in range(W):
                rows[M + i, j] = buf[i, j]
            form[M + i] = b
        M += k
    return M, B, 0


#: Leading floats of a pack (:func:`pack`): N, C, scale, vcx, vcy, hold, three snap bounds.
HEADER = 9
#: :func:`solve_one`'s return code when the caller has work left: ``-1 - (rows | flags <<
#: FLAGS_SHIFT)`` (rows < 2**20: the candidates of at most ``COMPILED_MAX_N`` robots).
FLAGS_SHIFT = 20
#: Flags: a stable row; a row with a weight family to resolve; next to a similar copy;
#: the formation is torn or not finite (no rows).
HAS_STABLE, HAS_PENDING, NEAR_COPY, TORN = 1, 2, 4, 8


def pack(Vn, A, lim2, table, sizes, scale, vcx, vcy, hold, snap):
    """The solver argument of :func:`solve_one`: one flat float64 array holding ``N, C,
    scale, vcx, vcy, hold`` and the three snap-screen bounds ``snap``, then ``Vn`` and
    ``A`` (N, 2) each and ``lim2`` (N, N), then the int64 ``table`` (C, 5) and ``sizes``
    (C,) as raw 8-byte words (read back with ``view``, never converted). One argument
    instead of nine: numba's dispatch costs ~0.1-0.3 us per array."""
    N, C = len(Vn), len(table)
    head = np.array([N, C, scale, vcx, vcy, hold, *snap], dtype=np.float64)
    floats = np.concatenate([head, np.ravel(Vn), np.ravel(A), np.ravel(lim2)])
    ints = np.concatenate([np.ravel(table), np.ravel(sizes)]).astype(np.int64)
    out = np.empty(len(floats) + len(ints), dtype=np.float64)
    out[:len(floats)] = floats
    out[len(floats):].view(np.int64)[:] = ints
    return out


def out_rows(N: int, C: int) -> int:
    """Rows of :func:`solve_one`'s ``out`` for ``N`` robots and ``C`` candidates: ``C``
    result rows, then the float, int64 and bool work arrays of ``solve_into``, then one
    row whose first ``2 N`` floats hold the copy of the formation."""
    work = work_floats(N, C) + 2 * C + (C * N + 7) // 8
    return C + -(-work // (12 + 3 * N)) + 1


def decode(code: int) -> tuple[int, int]:
    """``(rows, flags)`` of a :func:`solve_one` return code (``rows`` is ``INFEASIBLE``
    for a torn or non-finite formation)."""
    if code >= 0:
        return code, 0
    v = -1 - code
    if v >> FLAGS_SHIFT & TORN:
        return INFEASIBLE, TORN
    return v & ((1 << FLAGS_SHIFT) - 1), v >> FLAGS_SHIFT


@jit
def solve_one(R, solver, out):
    """``_small_kernel.solve_formation`` of formation ``R`` (N, 2) on a packed solver
    (:func:`pack`), and the screen of ``FKSolver._snap`` (``_small_kernel.similar_fit``:
    within the snap distance of a similar copy of the sheet, not larger than it; next to
    one the formation is answered as the copy, stable states or not:
    docs/sheet_fk_solver.md). ``out`` (C + extra, width): rows in ``out[:C]``, the work
    arrays after them, and ``R`` copied into the first ``2 N`` floats of the last row
    (:func:`out_rows` rows in all): the caller keeps that copy, whatever the layout of
    ``R`` (any strides), and everything here reads it.

    Returns one int (the cheapest value to return to Python): the number of rows when
    they are the answer (no state, or a stable one and no weight family, and not next to
    a similar copy), else ``-1 - (rows | flags << FLAGS_SHIFT)`` (:func:`decode`; the
    flag ``TORN`` for a torn or non-finite ``R``)."""
    R, solver, out = borrowed(R), borrowed(solver), borrowed(out)   # see ``borrowed``
    N = R.shape[0]
    last = out.shape[0] - 1
    for i in range(N):
        out[last, 2 * i] = R[i, 0]
        out[last, 2 * i + 1] = R[i, 1]
    Rc = shaped(out[last, 0:2 * N], (N, 2))
    C = int(solver[1])
    g = HEADER
    Vn = shaped(solver[g:g + 2 * N], (N, 2))
    A = shaped(solver[g + 2 * N:g + 4 * N], (N, 2))
    lim2 = shaped(solver[g + 4 * N:g + 4 * N + N * N], (N, N))
    h = g + 4 * N + N * N
    ints = solver[h:h + 6 * C].view(np.int64)
    table = shaped(ints[0:5 * C], (C, 5))
    sizes = ints[5 * C:6 * C]
    flat = shaped(out, (out.size,))
    o = C * out.shape[1]
    fw = flat[o:o + work_floats(N, C)]
    o += work_floats(N, C)
    iw = flat[o:o + 2 * C].view(np.int64)
    o += 2 * C
    taut = shaped(flat[o:o + (C * N + 7) // 8].view(np.bool_)[:C * N], (C, N))
    k, stable, pending = solve_into(Rc, Vn, table, sizes, solver[2], solver[3], solver[4],
                                    solver[5], lim2, out, fw, iw, taut)
    if k < 0:
        return -1 - (TORN << FLAGS_SHIFT)
    flags = (HAS_STABLE if stable else 0) | (HAS_PENDING if pending else 0)
    scale, dist = similar_fit(Rc, A)
    if solver[6] < dist <= solver[7] and scale <= solver[8]:
        flags |= NEAR_COPY
    if k == 0 and flags == 0 or flags == HAS_STABLE:
        return k
    return -1 - (k | flags << FLAGS_SHIFT)


@jit
def snap_screen_batch(Rb, A, low, high, top):
    """The snap screen of ``solve_one`` on every formation of ``Rb`` (B, N, 2): within
    ``(low, high]`` of a similar copy of the sheet (centred vertices ``A``), scale at most
    ``top`` -> (B,) bool (``FKSolver._snap`` makes the exact test on those)."""
    B = Rb.shape[0]
    out = np.zeros(B, dtype=np.bool_)
    for b in range(B):
        scale, dist = similar_fit(Rb[b], A)
        out[b] = low < dist <= high and scale <= top
    return out
