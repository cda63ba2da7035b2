"""Solutions of many formations as one padded :class:`BatchFKResult` (both engines)."""

from __future__ import annotations

import numpy as np

from ..._units import GRAVITY
from ...errors import InfeasibleFormationError
from .._lifted import KIND_NOT_EQUILIBRIUM, KIND_STABLE
from ..model import Sheet, check_formation
from .results import BatchFKResult

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
    starts = np.concatenate([[0], np.cumsum(count)[:-1]]).astype(np.intp)
    slot = np.arange(len(form)) - starts[form]

    def pad(values: np.ndarray, fill: float | bool | int, dtype: type = np.float64
            ) -> np.ndarray:
        out: np.ndarray = np.full((B, K) + values.shape[1:], fill, dtype=dtype)
        out[form, slot] = values
        return out

    valid = pad(np.ones(len(form), dtype=bool), False, bool)
    kinds = pad(kind, -1, np.int8)
    ten = None if tensions is None else pad(tensions, 0.0)
    success, status, message = _outcome(sheet, formations, kinds, feasible)
    return BatchFKResult(count, valid, pad(taut, False, bool), pad(obj, np.nan),
                         pad(contact, np.nan), pad(weights, 0.0), ten, kinds, feasible,
                         success, status, message, sheet, formations, hold_height, mass,
                         method)


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
