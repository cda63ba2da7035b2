"""Compiled kernel rows of many formations as one padded :class:`BatchFKResult`."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .results import BatchFKResult

if TYPE_CHECKING:
    from .solver import FKSolver

__all__ = ["batch_result"]


def batch_result(solver: "FKSolver", Rb: np.ndarray, rows: np.ndarray, form: np.ndarray,
                 mass: float | None) -> BatchFKResult:
    """Kernel rows of many formations as a padded :class:`BatchFKResult`."""
    B, N = Rb.shape[:2]
    count = np.bincount(form, minlength=B) if len(form) else np.zeros(B, dtype=np.intp)
    K = int(count.max()) if B else 0
    starts = np.concatenate([[0], np.cumsum(count)[:-1]]).astype(np.intp)
    slot = np.arange(len(form)) - starts[form]
    valid = np.zeros((B, K), dtype=bool)
    valid[form, slot] = True
    taut = np.zeros((B, K, N), dtype=bool)
    taut[form, slot] = rows[:, 8:8 + N] > 0.5
    obj = np.full((B, K, 3), np.nan)
    obj[form, slot] = rows[:, 2:5]
    con = np.full((B, K, 2), np.nan)
    con[form, slot] = rows[:, 5:7]
    wts = np.zeros((B, K, N))
    wts[form, slot] = rows[:, 8 + N:8 + 2 * N]
    status = np.full((B, K), -1, dtype=np.int8)
    status[form, slot] = rows[:, 0].astype(np.int8)
    ten = None
    if mass is not None:
        from .._kernels import small as sk      # loaded (with numba) by the solver already
        from .results import GRAVITY
        lengths_n = rows[:, 8 + 2 * N:8 + 3 * N] / solver.sheet.size
        t = rows[:, 8 + N:8 + 2 * N] * (mass * GRAVITY) * lengths_n / rows[:, 7:8]
        held = taut[form, slot] & (rows[:, :1] != sk.NOT_EQUILIBRIUM)
        t = np.where(held, t, np.where(taut[form, slot], np.nan, 0.0))
        ten = np.zeros((B, K, N))
        ten[form, slot] = t
    return BatchFKResult(count, valid, taut, obj, con, wts, ten, status, solver.sheet, Rb,
                         solver.hold_height, mass, solver.method)
