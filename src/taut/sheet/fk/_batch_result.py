"""Solutions of many formations as one padded :class:`BatchFKResult` (both engines)."""

from __future__ import annotations

from typing import Callable

import numpy as np

from ..._units import GRAVITY
from .._lifted import KIND_NOT_EQUILIBRIUM, KIND_STABLE
from .._tol import MERGE_RTOL
from ..model import Sheet
from .results import BatchFKResult, _has_kind, _merge_equilibria, _row_states, _write_row

__all__ = ["padded_batch", "batch_from_rows"]


def padded_batch(sheet: Sheet, formations: np.ndarray, hold_height: float,
                 mass: float | None, method: str, feasible: np.ndarray, form: np.ndarray,
                 taut: np.ndarray, obj: np.ndarray, contact: np.ndarray,
                 weights: np.ndarray, tensions: np.ndarray | None, kind: np.ndarray
                 ) -> BatchFKResult:
    """A :class:`BatchFKResult` from flat solutions grouped by formation, in output order.

    Parameters
    ----------
    formations : ndarray, shape (B, N, 2)
    feasible : ndarray of bool, shape (B,)
        Which formations the sheet can span (the others have no solutions).
    form : ndarray of int, shape (M,)
        Formation of each solution (non-decreasing).
    taut : ndarray of bool, shape (M, N)
    obj, contact : ndarray, shapes (M, 3) and (M, 2)
        Object and contact point, caller's units.
    weights : ndarray, shape (M, N)
    tensions : ndarray, shape (M, N), or None
        In N, when a mass was given.
    kind : ndarray of int, shape (M,)
        ``KIND_*`` codes.
    """
    B, N = formations.shape[:2]
    count = np.bincount(form, minlength=B) if len(form) else np.zeros(B, dtype=np.intp)
    K = int(count.max()) if B else 0
    pad = _padder(form, count, B, K)

    valid = pad(np.ones(len(form), dtype=bool), False, bool)
    kinds = pad(kind, -1, np.int8)
    ten = None if tensions is None else pad(tensions, 0.0)
    arrays = (count, valid, pad(taut, False, bool), pad(obj, np.nan), pad(contact, np.nan),
              pad(weights, 0.0), ten, kinds)
    if K > 1:
        _merge_batch(sheet, formations, hold_height, mass, arrays)
    # The direct minimisation of the lowest state runs on these when a field needs it.
    missing = np.flatnonzero(feasible & ~_has_kind(kinds, KIND_STABLE))
    return BatchFKResult(arrays, missing, feasible, sheet, formations, hold_height, mass,
                         method)


def _padder(form: np.ndarray, count: np.ndarray, B: int, K: int
            ) -> Callable[..., np.ndarray]:
    """``pad(values, fill, dtype=float64)``: the flat per-solution ``values`` (M, ...)
    placed in fresh padded (B, K, ...) arrays, slot ``j`` of row ``b`` holding formation
    ``b``'s ``j``-th solution. When every formation has ``K`` solutions (``form`` is then
    ``0,..,0, 1,..``: the common case of a batch of similar formations) this is a
    reshaped copy; else one flat index, computed once, places them (a fraction of the cost
    of indexing by (formation, slot) pairs for every array)."""
    full = len(form) == B * K

    if not full:
        starts = np.concatenate([[0], np.cumsum(count)[:-1]]).astype(np.intp)
        flat = form.astype(np.intp) * K + (np.arange(len(form)) - starts[form])

    def pad(values: np.ndarray, fill: float | bool | int, dtype: type = np.float64
            ) -> np.ndarray:
        shape = (B, K) + values.shape[1:]
        if full:
            return np.array(values, dtype=dtype).reshape(shape)
        out: np.ndarray = np.full((B * K,) + values.shape[1:], fill, dtype=dtype)
        out[flat] = values
        return out.reshape(shape)
    return pad


def _merge_batch(sheet: Sheet, formations: np.ndarray, hold_height: float,
                 mass: float | None, arrays: tuple) -> None:
    """Report coinciding states of each formation once, in place (as
    :class:`FKResult` does, :mod:`taut.sheet.fk._merge`): one vectorised screen over all
    formations (:func:`_close_states`), the merge itself only on the (rare) formations
    that pass it."""
    for b in _close_states(arrays[3], MERGE_RTOL * sheet.size):
        eqs = _row_states(sheet, arrays, int(b))
        merged = _merge_equilibria(eqs, sheet, formations[b], hold_height, mass)
        if len(merged) < len(eqs):
            _write_row(int(b), merged, *arrays)


def _close_states(obj: np.ndarray, tol: float) -> np.ndarray:
    """Formations (indices, increasing) with two object points ``obj`` (B, K, 3), K >= 2,
    within ``tol`` (same unit) of each other in every coordinate; padding is NaN and never
    close. The x coordinates of every pair first (one column each, ~30 x cheaper than all
    coordinates of all pairs at once), all three only where some x are close."""
    iu, ju = np.triu_indices(obj.shape[1], 1)
    x = obj[:, :, 0]
    with np.errstate(invalid="ignore"):
        close_x = np.abs(x[:, iu[0]] - x[:, ju[0]]) <= tol
        for i, j in zip(iu[1:].tolist(), ju[1:].tolist()):
            close_x |= np.abs(x[:, i] - x[:, j]) <= tol
        maybe = np.flatnonzero(close_x)
        o = obj[maybe]
        return maybe[np.any(np.abs(o[:, iu] - o[:, ju]).max(axis=2) <= tol, axis=1)]


def batch_from_rows(sheet: Sheet, formations: np.ndarray, hold_height: float,
                    mass: float | None, method: str, feasible: np.ndarray,
                    rows: np.ndarray, form: np.ndarray) -> BatchFKResult:
    """:func:`padded_batch` of compiled-kernel rows (layout of ``_kernels.small``: kind,
    taut-set size, object, contact, depth, taut mask, weights, lengths, ...)."""
    N = formations.shape[1]
    taut = rows[:, 8:8 + N] > 0.5
    weights = rows[:, 8 + N:8 + 2 * N]
    tensions = None
    if mass is not None:
        lengths_n = rows[:, 8 + 2 * N:8 + 3 * N] / sheet.size
        t = weights * (mass * GRAVITY) * lengths_n / rows[:, 7:8]
        # Only equilibria have tensions: elsewhere the "tension" would be a push.
        held = taut & (rows[:, :1] != KIND_NOT_EQUILIBRIUM)
        tensions = np.where(held, t, np.where(taut, np.nan, 0.0))
    return padded_batch(sheet, formations, hold_height, mass, method, feasible, form, taut,
                        rows[:, 2:5], rows[:, 5:7], weights, tensions,
                        rows[:, 0].astype(np.int8))
