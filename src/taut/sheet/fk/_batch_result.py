"""Solutions of many formations as one padded :class:`BatchFKResult` (both engines)."""

from __future__ import annotations

from functools import partial
from typing import Callable

import numpy as np

from ..._units import GRAVITY
from .._lifted import KIND_NOT_EQUILIBRIUM, KIND_STABLE
from .._tol import MERGE_RTOL
from ..model import Sheet
from .results import (BatchFKResult, _has_kind, _merge_equilibria, _Padded, _row_states,
                      _write_row)

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
    count, pad = _padder(form, formations.shape[0])
    arrays = (count, pad(np.ones(len(form), dtype=bool), False, bool), pad(taut, False, bool),
              pad(obj, np.nan), pad(contact, np.nan), pad(weights, 0.0),
              None if tensions is None else pad(tensions, 0.0), pad(kind, -1, np.int8))
    return _batch(sheet, formations, hold_height, mass, method, feasible, arrays[3],
                  arrays[7], arrays)


def _batch(sheet: Sheet, formations: np.ndarray, hold_height: float, mass: float | None,
           method: str, feasible: np.ndarray, obj: np.ndarray, kinds: np.ndarray,
           padded: _Padded | Callable[[], _Padded]) -> BatchFKResult:
    """The :class:`BatchFKResult` of the padded arrays ``padded`` (:data:`_Padded`), or of
    a function building them (``batch_from_rows``: built when a field first needs them),
    whose object points and kinds are ``obj`` (B, K, 3) and ``kinds`` (B, K): coinciding
    states merged (the arrays built at once for that, as rarely needed), and the direct
    minimisation's candidates found."""
    if obj.shape[1] > 1:
        close = _close_states(obj, MERGE_RTOL * sheet.size)
        if len(close):
            if callable(padded):
                padded = padded()
            _merge_batch(sheet, formations, hold_height, mass, padded, close)
    # The direct minimisation of the lowest state runs on these when a field needs it.
    missing = np.flatnonzero(feasible & ~_has_kind(kinds, KIND_STABLE))
    return BatchFKResult(padded, kinds, missing, feasible, sheet, formations, hold_height,
                         mass, method)


def _padder(form: np.ndarray, B: int
            ) -> tuple[np.ndarray, Callable[..., np.ndarray]]:
    """``count`` (B,), the solutions of each of ``B`` formations, and ``pad(values, fill,
    dtype=float64)``: the flat per-solution ``values`` (M, ...) placed in fresh padded
    (B, K, ...) arrays (K = ``count.max()``), slot ``j`` of row ``b`` holding formation
    ``b``'s ``j``-th solution. When every formation has ``K`` solutions (``form`` is then
    ``0,..,0, 1,..``: the common case of a batch of similar formations) this is a
    reshaped copy; else one flat index, computed once, places them (a fraction of the cost
    of indexing by (formation, slot) pairs for every array)."""
    count = np.bincount(form, minlength=B) if len(form) else np.zeros(B, dtype=np.intp)
    K = int(count.max()) if B else 0
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
    return count, pad


def _merge_batch(sheet: Sheet, formations: np.ndarray, hold_height: float,
                 mass: float | None, arrays: _Padded, close: np.ndarray) -> None:
    """Report coinciding states of each formation once, in place (as
    :class:`FKResult` does, :mod:`taut.sheet.fk._merge`): the merge itself only on the
    (rare) formations ``close`` that pass the vectorised screen (:func:`_close_states`)."""
    for b in close:
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
    taut-set size, object, contact, depth, taut mask, weights, lengths, ...). Only the
    kinds are copied out at once (``success`` needs no more) and the object points read
    by the merge screen (in place when every formation has ``K`` rows); the padded
    arrays (most of the cost of copying out the rows) when a field first needs them, at
    once only when some states coincide."""
    B = formations.shape[0]
    count, pad = _padder(form, B)
    kinds = pad(rows[:, 0], -1, np.int8)
    K = kinds.shape[1]
    obj = (rows.reshape(B, K, rows.shape[1])[:, :, 2:5] if len(form) == B * K
           else pad(rows[:, 2:5], np.nan))
    build = partial(_row_arrays, sheet, mass, rows, form, count, kinds)
    return _batch(sheet, formations, hold_height, mass, method, feasible, obj, kinds, build)


def _row_arrays(sheet: Sheet, mass: float | None, rows: np.ndarray, form: np.ndarray,
                count: np.ndarray, kinds: np.ndarray) -> _Padded:
    """The padded arrays (:data:`_Padded`) of kernel ``rows`` of formations ``form``,
    with their ``count`` and padded ``kinds`` already made (:func:`batch_from_rows`; a
    module function, so that a result pickles)."""
    N = sheet.n
    pad = _padder(form, len(count))[1]
    taut = rows[:, 8:8 + N] > 0.5
    weights = rows[:, 8 + N:8 + 2 * N]
    tensions = None
    if mass is not None:
        lengths_n = rows[:, 8 + 2 * N:8 + 3 * N] / sheet.size
        t = weights * (mass * GRAVITY) * lengths_n / rows[:, 7:8]
        # Only equilibria have tensions: elsewhere the "tension" would be a push.
        held = taut & (rows[:, :1] != KIND_NOT_EQUILIBRIUM)
        tensions = pad(np.where(held, t, np.where(taut, np.nan, 0.0)), 0.0)
    return (count, pad(np.ones(len(form), dtype=bool), False, bool), pad(taut, False, bool),
            pad(rows[:, 2:5], np.nan), pad(rows[:, 5:7], np.nan), pad(weights, 0.0), tensions,
            kinds)
