"""Steepest descent of the nonsmooth rest-state function (docs/sheet_kinematics.md §1):
where the object rolls when its branch ends in a quasi-static simulation.

:math:`F(x) = q(x) + \\max_i (\\mathbf{a}_i \\cdot x + b_i)` with :math:`q(x) = |\\mathbf{r}_o|^2
- |\\mathbf{v}_o|^2` is a maximum of quadratics; its descent uses epsilon-steepest-descent
directions (minimum-norm element of the convex hull of the epsilon-active gradients) with
Armijo backtracking.
"""

from __future__ import annotations

from typing import Callable, TypeVar

import numpy as np

from .._tol import (ARMIJO_C1, ARRIVAL_ACTIVE_TOL, DESCENT_EPS0, DESCENT_GRAD2_TOL,
    DESCENT_MIN_EPS, DESCENT_MIN_STEP)

__all__ = ["min_norm_combination", "descend"]

_J = np.array([1.0, 1.0, -1.0, -1.0])
_Arrival = TypeVar("_Arrival")


def min_norm_combination(G: np.ndarray) -> np.ndarray:
    """Point of minimum norm in the convex hull of the rows of ``G`` (k, 4)."""
    if len(G) == 1:
        return G[0]
    from scipy.optimize import nnls     # not at import: FK imports this module, rarely calls it

    M = 1e3 * max(1.0, float(np.abs(G).max()))
    A = np.vstack([G.T, M * np.ones(len(G))])
    b = np.zeros(A.shape[0])
    b[-1] = M
    lam, _ = nnls(A, b)
    total = lam.sum()
    if total <= 0:
        return G[np.argmin(np.linalg.norm(G, axis=1))]
    return (lam / total) @ G


def descend(P: np.ndarray, x0: np.ndarray,
            arrive: Callable[[np.ndarray, np.ndarray], _Arrival | None], floor: float,
            maxit: int = 3000, active_tol: float = ARRIVAL_ACTIVE_TOL
            ) -> np.ndarray | _Arrival | None:
    """Steepest descent of F(x) = q(x) + max_i (a_i . x + b_i) from ``x0`` (normalised
    units; P (N, 5) lifted points): epsilon-steepest-descent directions (minimum-norm
    element of the gradients of the epsilon-active pieces) with Armijo backtracking, eps
    shrinking as the method stalls. Every few iterations ``arrive(active, x)`` is asked
    whether the pieces active at ``x`` already identify a stable minimum (it returns a
    result or None); otherwise the descent ends at a (Clarke) stationary point and
    returns ``x``. Returns None when F drops below ``floor`` (the object reaches the
    ground, :math:`d \\ge z_r`)."""
    A, b = P[:, :4], P[:, 4]

    def F(x: np.ndarray) -> float:
        return float(x @ (_J * x) + (A @ x + b).max())

    x = x0.copy()
    f = F(x)
    eps, t = DESCENT_EPS0, 1.0
    for it in range(maxit):
        vals = x @ (_J * x) + A @ x + b
        top = vals.max()
        if it % 4 == 0:
            found = arrive(np.flatnonzero(vals >= top - active_tol), x)
            if found is not None:
                return found
        active = vals >= top - eps
        g = min_norm_combination(2 * _J * x + A[active])
        gn2 = float(g @ g)
        if gn2 < DESCENT_GRAD2_TOL:
            if eps < DESCENT_MIN_EPS:
                break
            eps *= 0.1
            continue
        t = min(1.0, 4.0 * t)
        while True:
            trial = x - t * g
            ft = F(trial)
            if ft <= f - ARMIJO_C1 * t * gn2:
                break
            t *= 0.5
            if t < DESCENT_MIN_STEP:
                break
        if t < DESCENT_MIN_STEP:
            t = 1.0
            if eps < DESCENT_MIN_EPS:
                break
            eps *= 0.1
            continue
        x, f = trial, ft
        if f < floor:
            return None
    return x

