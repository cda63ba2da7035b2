"""The numpy engine of sheet forward kinematics: validated inputs in, result objects out.

Runs :func:`taut.sheet.fk._solve.solve` (vectorised over formations) and turns its
normalised solutions into :class:`FKResult` / :class:`BatchFKResult` in the caller's
units. The front end (:mod:`taut.sheet.fk.forward`) and the compiled engine
(:class:`taut.sheet.FKSolver`, for the cases its kernel does not take) call it; it calls
neither.
"""

from __future__ import annotations

import weakref

import numpy as np
from numpy.typing import ArrayLike

from ..._units import GRAVITY
from ..._validate import MAX_SHEET_LENGTH, as_array, check_range, require_nonempty
from ...errors import InvalidInputError
from ._batch_result import padded_batch
from ._finalize import Classified
from .._lifted import KIND_NAMES, KIND_NOT_EQUILIBRIUM, Frame
from ._solve import solve
from .._tol import FAST_CHECK_RTOL
from ..model import Sheet, check_formations, feasible_formations
from .results import BatchFKResult, Equilibrium, FKResult, Funnel

__all__ = ["forward_numpy", "forward_numpy_batch"]

#: Squared sheet side lengths, shrunk by FAST_CHECK_RTOL, per sheet (see _formations).
_SIDES2: "weakref.WeakKeyDictionary[Sheet, np.ndarray]" = weakref.WeakKeyDictionary()


def _formations(sheet: Sheet, formations: ArrayLike, field: str, single: bool
                ) -> tuple[np.ndarray, np.ndarray]:
    """Formations as shape (B, N, 2) and which of them the sheet can span (B,), with a fast
    path: formations whose robots are all clearly closer than their sheet vertices
    (squared distances below the cached squared side lengths) are accepted at once;
    anything else gets the full check (:func:`~taut.sheet.model.feasible_formations`),
    which decides borderline cases. A single formation the sheet cannot span raises the
    usual :class:`~taut.errors.InfeasibleFormationError`."""
    r = require_nonempty(as_array(formations, field, ndim=2 if single else 3), field)
    check_range(r, field, MAX_SHEET_LENGTH, "sheet units")
    rb = r[None] if single else r
    if rb.shape[1:] == (sheet.n, 2):
        sides2 = _SIDES2.get(sheet)
        if sides2 is None:
            sides2 = _SIDES2[sheet] = sheet.side_lengths() ** 2 * (1.0 - FAST_CHECK_RTOL)
        d = rb[:, :, None, :] - rb[:, None, :, :]
        if np.all(d[..., 0] * d[..., 0] + d[..., 1] * d[..., 1] <= sides2):
            return rb, np.ones(len(rb), dtype=bool)
    if single:
        return check_formations(sheet, rb, field), np.ones(1, dtype=bool)
    return rb, feasible_formations(sheet, rb, field)


def _user_units(frame: Frame, c: Classified, hold_height: float, mass: float | None
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]:
    """Object positions (M, 3), contact points (M, 2), cable lengths (M, N) in the
    caller's frame and units; tensions (M, N) in N (None without a mass)."""
    ro = c.ro * frame.scale + frame.r_centre[c.form]
    vo = c.vo * frame.scale + frame.v_centre
    obj = np.empty((len(ro), 3))
    obj[:, :2] = ro
    obj[:, 2] = hold_height - c.depth * frame.scale
    d = frame.V[None, :, :] - c.vo[:, None, :]
    lengths = np.sqrt(d[..., 0] * d[..., 0] + d[..., 1] * d[..., 1])       # normalised
    tensions = None
    if mass is not None:
        # Only equilibria have tensions: elsewhere the "tension" would be negative (a push).
        tensions = c.weights * (mass * GRAVITY) * lengths / c.depth[:, None]
        held = c.taut & (c.kind != KIND_NOT_EQUILIBRIUM)[:, None]
        tensions = np.where(held, tensions, np.where(c.taut, np.nan, 0.0))
    return obj, vo, lengths * frame.scale, tensions


def _funnel(counts: dict[str, int], force_closure: int) -> Funnel:
    return Funnel(counts["combinations"], counts["form_closure"], counts["cqp_feasible"],
                  counts["height_feasible"], force_closure)


def forward_numpy(sheet: Sheet, formation: ArrayLike, z: float, mass: float | None,
                  method: str) -> FKResult:
    """:func:`~taut.sheet.forward_kinematics` on the numpy path (``sheet``, ``z``,
    ``mass``, ``method`` already validated; ``formation`` checked here)."""
    Rb, _ = _formations(sheet, formation, "formation", single=True)
    R = Rb[0]
    frame, c, counts = solve(sheet, Rb, z, method)
    obj, vo, lengths, tensions = _user_units(frame, c, z, mass)
    # Per-equilibrium slices of the flat taut entries (row-major order of c.taut).
    rows, cols = np.nonzero(c.taut)
    w = c.weights[rows, cols]
    ln = lengths[rows, cols]
    tn = tensions[rows, cols] if tensions is not None else None
    ends = np.cumsum(c.taut.sum(axis=1)).tolist()
    starts = [0] + ends[:-1]
    idx = cols.tolist()
    eqs = [Equilibrium(tuple(idx[a:e]), obj[k], vo[k], w[a:e],
                       None if tn is None or kind == KIND_NOT_EQUILIBRIUM else tn[a:e],
                       ln[a:e], KIND_NAMES[kind])  # type: ignore[arg-type]
           for k, (a, e, kind) in enumerate(zip(starts, ends, c.kind.tolist()))]
    funnel = _funnel(counts, len(eqs)) if counts is not None else None
    return FKResult(tuple(eqs), funnel, method, sheet, R, z, mass)


def forward_numpy_batch(sheet: Sheet, formations: ArrayLike, z: float, mass: float | None,
                        method: str) -> BatchFKResult:
    """:func:`~taut.sheet.forward_kinematics_batch` on the numpy path (inputs but
    ``formations`` validated); formations the sheet cannot span are flagged, not solved."""
    if method == "exhaustive":
        raise InvalidInputError("method", "the batched form supports 'fast' and 'subsets'")
    R, feasible = _formations(sheet, formations, "formations", single=False)
    ok = np.flatnonzero(feasible)
    if not len(ok):
        N = sheet.n
        return padded_batch(sheet, R, z, mass, method, feasible, ok, np.zeros((0, N), bool),
                            np.zeros((0, 3)), np.zeros((0, 2)), np.zeros((0, N)),
                            None if mass is None else np.zeros((0, N)), np.zeros(0, np.int8))
    frame, c, _ = solve(sheet, R if len(ok) == len(R) else R[ok], z, method)
    obj, vo, _, tensions = _user_units(frame, c, z, mass)
    return padded_batch(sheet, R, z, mass, method, feasible, ok[c.form], c.taut, obj, vo,
                        c.weights, tensions, c.kind)
