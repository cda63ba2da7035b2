"""Small dense convex quadratic programs, by a QP solver when installed (private).

``minimise 1/2 x' H x + f' x`` subject to ``A_eq x = b_eq``, ``A_ub x <= b_ub`` and
``lb <= x <= ub``, with ``H`` symmetric positive definite: the minimum-norm tensions of a
cable robot with more than two redundant cables, its redundancy resolution and the
minimum-norm load shares of a sheet's dependent taut sets.

Backends
    ``"daqp"``: DAQP, a dual active-set solver for dense QPs (D. Arnström, A. Bemporad,
    D. Axehill, "A dual active-set solver for embedded quadratic programming using recursive
    LDL' updates", IEEE TAC 67(8), 2022): the optimum, or a proof of infeasibility, in
    microseconds for these sizes (a core dependency: one small binary wheel).
    ``"scipy"``: SciPy's SLSQP from a start point: the fallback when DAQP is missing; a
    general NLP method, so it may stop short (``None``) where DAQP answers.
    ``"auto"``: DAQP when installed, else SLSQP.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["solve_qp", "qp_backend", "QP_BACKENDS"]

#: Backends of :func:`solve_qp`.
QP_BACKENDS: tuple[str, ...] = ("auto", "daqp", "scipy")
#: Iterations of SLSQP (the fallback) before it gives up.
_SLSQP_MAXITER = 200
#: DAQP's primal tolerance (absolute, in the unit of the constraint rows: N, m/s, or a load
#: share): how far an inactive inequality may be violated at the answer. DAQP's default
#: (1e-6) would let a non-negative share come out at -1e-7; this keeps rows to round-off.
_DAQP_PRIMAL_TOL = 1e-10


def _daqp() -> Any:
    try:
        import daqp
    except ImportError:
        return None
    return daqp


def qp_backend(backend: str = "auto") -> str:
    """The backend ``backend`` resolves to: ``"daqp"`` or ``"scipy"``.

    Raises
    ------
    ModuleNotFoundError
        ``backend="daqp"`` without DAQP installed (the CLI names the extra).
    """
    if backend == "scipy":
        return "scipy"
    if _daqp() is not None:
        return "daqp"
    if backend == "daqp":
        raise ModuleNotFoundError("No module named 'daqp'", name="daqp")
    return "scipy"


def solve_qp(H: np.ndarray, f: np.ndarray | None = None, *, A_eq: np.ndarray | None = None,
             b_eq: np.ndarray | None = None, A_ub: np.ndarray | None = None,
             b_ub: np.ndarray | None = None, lb: np.ndarray | None = None,
             ub: np.ndarray | None = None, x0: np.ndarray | None = None,
             ftol: float = 1e-12, backend: str = "auto", unconverged: bool = False
             ) -> np.ndarray | None:
    """The minimiser, or ``None`` when the solver proves the QP infeasible or fails.

    ``x0`` is SLSQP's start point (default: zero, clipped to the bounds); ``ftol`` its
    function tolerance; with ``unconverged`` its last iterate is returned even when it
    reports failure. DAQP needs none of them. Callers check the answer against their own
    tolerances, whichever backend produced it.
    """
    n = H.shape[0]
    f = np.zeros(n) if f is None else np.asarray(f, float)
    A_eq = np.zeros((0, n)) if A_eq is None else np.asarray(A_eq, float).reshape(-1, n)
    b_eq = np.zeros(0) if b_eq is None else np.asarray(b_eq, float).reshape(-1)
    A_ub = np.zeros((0, n)) if A_ub is None else np.asarray(A_ub, float).reshape(-1, n)
    b_ub = np.zeros(0) if b_ub is None else np.asarray(b_ub, float).reshape(-1)
    lb = np.full(n, -np.inf) if lb is None else np.asarray(lb, float)
    ub = np.full(n, np.inf) if ub is None else np.asarray(ub, float)
    if qp_backend(backend) == "daqp":
        return _solve_daqp(np.asarray(H, float), f, A_eq, b_eq, A_ub, b_ub, lb, ub)
    x0 = np.clip(np.zeros(n) if x0 is None else np.asarray(x0, float), lb, ub)
    return _solve_slsqp(np.asarray(H, float), f, A_eq, b_eq, A_ub, b_ub, lb, ub, x0, ftol,
                        unconverged)


def _solve_daqp(H: np.ndarray, f: np.ndarray, A_eq: np.ndarray, b_eq: np.ndarray,
                A_ub: np.ndarray, b_ub: np.ndarray, lb: np.ndarray, ub: np.ndarray
                ) -> np.ndarray | None:
    """DAQP with the bounds as its simple bounds (the first ``n`` entries of the bound
    vectors), then the equality rows (sense 5) and the inequality rows."""
    daqp = _daqp()
    n = H.shape[0]
    A = np.ascontiguousarray(np.vstack([A_eq, A_ub]))
    upper = np.concatenate([ub, b_eq, b_ub])
    lower = np.concatenate([lb, b_eq, np.full(len(b_ub), -np.inf)])
    sense = np.zeros(len(upper), dtype=np.int32)
    sense[n:n + len(b_eq)] = 5
    x, _, exitflag, _ = daqp.solve(np.ascontiguousarray(H), f, A, upper, lower, sense,
                                   primal_tol=_DAQP_PRIMAL_TOL)
    return np.array(x, dtype=float) if exitflag >= 1 and np.all(np.isfinite(x)) else None


def _solve_slsqp(H: np.ndarray, f: np.ndarray, A_eq: np.ndarray, b_eq: np.ndarray,
                 A_ub: np.ndarray, b_ub: np.ndarray, lb: np.ndarray, ub: np.ndarray,
                 x0: np.ndarray, ftol: float, unconverged: bool) -> np.ndarray | None:
    from scipy.optimize import minimize

    cons = []
    if len(b_eq):
        cons.append({"type": "eq", "fun": lambda x: A_eq @ x - b_eq, "jac": lambda x: A_eq})
    if len(b_ub):
        cons.append({"type": "ineq", "fun": lambda x: b_ub - A_ub @ x, "jac": lambda x: -A_ub})
    bounds = None
    if np.any(np.isfinite(lb)) or np.any(np.isfinite(ub)):
        bounds = [(lo if np.isfinite(lo) else None, hi if np.isfinite(hi) else None)
                  for lo, hi in zip(lb, ub)]
    res = minimize(lambda x: 0.5 * x @ H @ x + f @ x, x0, jac=lambda x: H @ x + f,
                   bounds=bounds, constraints=cons, method="SLSQP",
                   options={"ftol": ftol, "maxiter": _SLSQP_MAXITER})
    return np.asarray(res.x, float) if res.success or unconverged else None
