"""Solutions of many formations as one padded :class:`BatchFKResult` (both engines)."""

from __future__ import annotations

from typing import Callable

import numpy as np

from ..._units import GRAVITY
from ...errors import InfeasibleFormationError
from .._lifted import KIND_NAMES, KIND_NOT_EQUILIBRIUM, KIND_STABLE
from .._tol import MERGE_RTOL
from ..model import Sheet, check_formation
from .results import (BatchFKResult, Equilibrium, _equilibrium, _merge_equilibria,
                      _with_lowest)

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
        _merge_batch(sheet, formations, hold_height, mass, *arrays)
    missing = np.flatnonzero(feasible & ~np.any(arrays[-1] == KIND_STABLE, axis=1))
    direct = np.zeros(B, dtype=bool)
    if len(missing):
        arrays = _lowest_batch(sheet, formations, hold_height, mass, missing, direct,
                               *arrays)
    success, status, message = _outcome(sheet, formations, arrays[-1], feasible)
    # A lowest rest state found directly but not strict: reported, status "not_strict".
    status = np.where(direct & ~success, "not_strict", status)
    return BatchFKResult(*arrays, feasible, success, status, message, sheet, formations,
                         hold_height, mass, method)


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


def _row_states(sheet: Sheet, taut: np.ndarray, obj: np.ndarray, contact: np.ndarray,
                weights: np.ndarray, kind: np.ndarray, b: int, k: int
                ) -> tuple[Equilibrium, ...]:
    """The first ``k`` states of formation ``b`` of the padded arrays (without tensions)."""
    return tuple(_equilibrium(tuple(int(i) for i in np.flatnonzero(taut[b, j])),
                              obj[b, j].copy(), contact[b, j].copy(),
                              weights[b, j, taut[b, j]], None,
                              np.zeros(0), KIND_NAMES[int(kind[b, j])])
                 for j in range(k))


def _write_row(b: int, states: tuple[Equilibrium, ...], count: np.ndarray,
               valid: np.ndarray, taut: np.ndarray, obj: np.ndarray, contact: np.ndarray,
               weights: np.ndarray, tensions: np.ndarray | None, kind: np.ndarray) -> None:
    """Replace formation ``b``'s states in the padded arrays by ``states``."""
    m = len(states)
    count[b] = m
    valid[b] = False
    valid[b, :m] = True
    taut[b] = False
    obj[b] = np.nan
    contact[b] = np.nan
    weights[b] = 0.0
    kind[b] = -1
    if tensions is not None:
        tensions[b] = 0.0
    for j, e in enumerate(states):
        idx = np.array(e.taut, dtype=np.intp)
        taut[b, j, idx] = True
        obj[b, j] = e.object
        contact[b, j] = e.contact
        weights[b, j, idx] = e.weights
        kind[b, j] = KIND_NAMES.index(e.kind)
        if tensions is not None:
            tensions[b, j, idx] = np.nan if e.tensions is None else e.tensions


def _lowest_batch(sheet: Sheet, formations: np.ndarray, hold_height: float,
                  mass: float | None, missing: np.ndarray, direct: np.ndarray,
                  count: np.ndarray,
                  valid: np.ndarray, taut: np.ndarray, obj: np.ndarray, contact: np.ndarray,
                  weights: np.ndarray, tensions: np.ndarray | None, kind: np.ndarray
                  ) -> tuple:
    """The lowest rest state by direct minimisation for the feasible formations
    ``missing`` without a stable state (as :class:`FKResult` does); one more slot per
    formation where needed; ``direct`` (B,) marks the formations it supplied. Returns
    the (possibly widened) arrays."""
    found = {}
    for b in missing:
        eqs, supplied, _ = _with_lowest(_row_states(sheet, taut, obj, contact, weights, kind,
                                                 int(b), int(count[b])),
                                     sheet, formations[b], hold_height, mass)
        if supplied:
            found[int(b)] = eqs
            direct[b] = True
    if not found:
        return count, valid, taut, obj, contact, weights, tensions, kind
    K = max(valid.shape[1], max(len(e) for e in found.values()))
    if K > valid.shape[1]:
        def widen(a: np.ndarray, fill: float | bool | int) -> np.ndarray:
            extra = np.full((a.shape[0], K - a.shape[1]) + a.shape[2:], fill, dtype=a.dtype)
            return np.concatenate([a, extra], axis=1)
        valid, taut, obj, contact = (widen(valid, False), widen(taut, False),
                                     widen(obj, np.nan), widen(contact, np.nan))
        weights, kind = widen(weights, 0.0), widen(kind, -1)
        tensions = None if tensions is None else widen(tensions, 0.0)
    for b, eqs in found.items():
        _write_row(b, eqs, count, valid, taut, obj, contact, weights, tensions, kind)
    return count, valid, taut, obj, contact, weights, tensions, kind


def _merge_batch(sheet: Sheet, formations: np.ndarray, hold_height: float,
                 mass: float | None, count: np.ndarray, valid: np.ndarray, taut: np.ndarray,
                 obj: np.ndarray, contact: np.ndarray, weights: np.ndarray,
                 tensions: np.ndarray | None, kind: np.ndarray) -> None:
    """Report coinciding states of each formation once, in place (as
    :class:`FKResult` does, :mod:`taut.sheet.fk._merge`): one vectorised screen over all
    formations (any two object points of a formation within the tolerance; padding is NaN
    and never close), the merge itself only on the (rare) formations that pass it."""
    tol = MERGE_RTOL * sheet.size
    iu, ju = np.triu_indices(obj.shape[1], 1)
    with np.errstate(invalid="ignore"):
        near = np.any(np.abs(obj[:, iu] - obj[:, ju]).max(axis=2) <= tol, axis=1)
    for b in np.flatnonzero(near):
        eqs = _row_states(sheet, taut, obj, contact, weights, kind, int(b), int(count[b]))
        merged = _merge_equilibria(eqs, sheet, formations[b], hold_height, mass)
        if len(merged) < len(eqs):
            _write_row(int(b), merged, count, valid, taut, obj, contact, weights, tensions,
                       kind)


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


def _outcome(sheet: Sheet, formations: np.ndarray, kind: np.ndarray, feasible: np.ndarray
             ) -> tuple[np.ndarray, np.ndarray, str]:
    """``success`` (B,), ``status`` (B,) and the one-line ``message`` of a batch from the
    padded kinds (B, K) and the feasibility of each formation (B,)."""
    success = feasible & np.any(kind == KIND_STABLE, axis=1)
    status = np.where(success, "ok", "infeasible")
    message = (f"{int(np.count_nonzero(success))} of {len(success)} formation(s) hold the "
               "object in a stable state")
    torn = np.flatnonzero(~feasible)
    if len(torn):
        b = int(torn[0])
        try:
            check_formation(sheet, formations[b])
            why = "the sheet cannot span it"                   # pragma: no cover
        except InfeasibleFormationError as exc:
            why = exc.problem
        message += f"; {len(torn)} infeasible, the first is formation {b}: {why}"
    return success, status, message
