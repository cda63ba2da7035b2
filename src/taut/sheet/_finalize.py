"""From solved candidate sets to classified equilibria: de-duplication, the paper's
force-closure test, exact weights, stability and tensions (DESIGN.md Sec. 3-5)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import linprog, minimize

from ._kernel import (CURVATURE_TOL, STATUS_NOT_EQUILIBRIUM, STATUS_SADDLE, STATUS_STABLE,
                      WEIGHT_TOL, Frame, Solved, in_hull_2d, reduced_hessian_min_eig)


@dataclass
class Classified:
    """Final solutions, flat over formations, in output order.

    ``form`` (K,), ``taut`` (K, N) bool, ``ro``/``vo`` (K, 2) normalised, ``depth`` (K,)
    normalised, ``weights`` (K, N) (0 on slack cables), ``status`` (K,) int8.
    """

    form: np.ndarray
    taut: np.ndarray
    ro: np.ndarray
    vo: np.ndarray
    depth: np.ndarray
    weights: np.ndarray
    status: np.ndarray


def _row_keys(form: np.ndarray, taut: np.ndarray) -> np.ndarray:
    packed = np.packbits(taut, axis=1)
    keys = np.ascontiguousarray(np.concatenate(
        [form.astype(">i8").view(np.uint8).reshape(-1, 8), packed], axis=1))
    return keys.view(np.dtype((np.void, keys.shape[1]))).ravel()


def _weights_family(frame: Frame, f: int, idx: np.ndarray, ro: np.ndarray, vo: np.ndarray
                    ) -> tuple[np.ndarray, float]:
    """Weights when more cables are taut than the state determines.

    Returns the minimum-norm weights (non-negative when possible) and the largest
    achievable minimum weight ``t*`` (an LP solved with HiGHS): ``t* >= 0`` iff some
    non-negative weights balance the object (DESIGN.md Sec. 3).
    """
    k = len(idx)
    E = np.vstack([frame.R[f, idx].T, frame.V[idx].T, np.ones(k)])
    rhs = np.concatenate([ro, vo, [1.0]])
    c = np.zeros(k + 1)
    c[-1] = -1.0
    A_ub = np.hstack([-np.eye(k), np.ones((k, 1))])
    lp = linprog(c, A_ub=A_ub, b_ub=np.zeros(k), A_eq=np.hstack([E, np.zeros((5, 1))]),
                 b_eq=rhs, bounds=[(None, None)] * (k + 1), method="highs")
    w_min_norm = np.linalg.pinv(E) @ rhs
    if not lp.success:
        return w_min_norm, -np.inf
    t_star = float(lp.x[-1])
    if t_star < -WEIGHT_TOL or w_min_norm.min() >= -WEIGHT_TOL:
        return w_min_norm, t_star
    res = minimize(lambda w: 0.5 * w @ w, np.maximum(lp.x[:k], 0.0), jac=lambda w: w,
                   method="SLSQP", bounds=[(0.0, None)] * k,
                   constraints=[{"type": "eq", "fun": lambda w: E @ w - rhs, "jac": lambda w: E}],
                   options={"ftol": 1e-15, "maxiter": 200})
    w = res.x if res.success and np.abs(E @ res.x - rhs).max() < 1e-9 else lp.x[:k]
    return w, t_star


def _min_eig_family(frame: Frame, f: int, idx: np.ndarray) -> float:
    A = frame.P[f, idx, :4]
    D = A[1:] - A[:1]
    _, sv, vt = np.linalg.svd(D, full_matrices=True)
    r = int(np.sum(sv > 1e-9 * max(1.0, sv[0] if len(sv) else 1.0)))
    Z = vt[r:]
    if len(Z) == 0:
        return np.inf
    Hr = Z @ np.diag([1.0, 1.0, -1.0, -1.0]) @ Z.T
    return float(np.linalg.eigvalsh(Hr)[0])


def classify(frame: Frame, solved: Solved, taut: np.ndarray,
             projection_checked: np.ndarray | None = None) -> Classified:
    """Turn candidate solutions (already feasible: pieces maximal, depth real, object
    above ground) into the final, de-duplicated, classified solution list.

    Steps: keep one solution per (formation, taut set), preferring one whose candidate
    *is* the taut set; apply the paper's projection test; compute weights (unique
    when the taut set is affinely independent, otherwise by LP/QP); status from the
    weights' signs and the reduced Hessian; sort by formation, taut-set size, taut set.
    ``projection_checked`` (M,) marks rows that already passed the projection test on
    their exact taut set.
    """
    N = taut.shape[1]
    tsize = taut.sum(axis=1)
    if len(tsize) == 0:
        return _empty(N)
    keys = _row_keys(solved.form, taut)
    _, inverse = np.unique(keys, return_inverse=True)
    inverse = inverse.ravel()
    is_rare = (tsize != solved.size).astype(np.int8)
    order = np.lexsort((is_rare, inverse))
    first_mask = np.ones(len(order), dtype=bool)
    first_mask[1:] = inverse[order][1:] != inverse[order][:-1]
    pick = order[first_mask]
    sol = solved.take(pick)
    taut = taut[pick]
    tsize = tsize[pick]
    is_rare = is_rare[pick].astype(bool)

    width = int(tsize.max())
    cols, inside = taut_indices(taut, tsize, width)
    pts = frame.R[sol.form[:, None], np.minimum(cols, N - 1)]
    paper_ok = tsize >= 3
    todo = paper_ok if projection_checked is None else paper_ok & ~projection_checked[pick]
    if np.any(todo):
        paper_ok[todo] = in_hull_2d(pts[todo], inside[todo], sol.ro[todo])
    sol = sol.take(paper_ok)
    taut, tsize, is_rare = taut[paper_ok], tsize[paper_ok], is_rare[paper_ok]
    K = len(tsize)
    weights = np.zeros((K, N))
    min_w = np.empty(K)
    min_eig = np.empty(K)
    common = np.flatnonzero(~is_rare)
    if len(common):
        rows = np.repeat(common, 5)
        cols = sol.subset[common].ravel()
        valid = cols >= 0
        weights[rows[valid], cols[valid]] = sol.w[common].ravel()[valid]
        min_w[common] = np.where(sol.subset[common] >= 0, sol.w[common], np.inf).min(axis=1)
        min_eig[common] = reduced_hessian_min_eig(frame, sol.form[common], sol.subset[common])
    for k in np.flatnonzero(is_rare):
        idx = np.flatnonzero(taut[k])
        w, t_star = _weights_family(frame, int(sol.form[k]), idx, sol.ro[k], sol.vo[k])
        weights[k, idx] = w
        min_w[k] = t_star
        min_eig[k] = _min_eig_family(frame, int(sol.form[k]), idx)
    status = np.where(min_w < -WEIGHT_TOL, STATUS_NOT_EQUILIBRIUM,
                      np.where(min_eig > CURVATURE_TOL, STATUS_STABLE, STATUS_SADDLE)
                      ).astype(np.int8)

    # Output order: formation, number of taut cables, taut set (lexicographic).
    width = int(tsize.max()) if K else 0
    sorted_idx = taut_indices(taut, tsize, width)[0]
    order = np.lexsort(tuple(sorted_idx[:, c] for c in range(width - 1, -1, -1))
                       + (tsize, sol.form))
    sol = sol.take(order)
    return Classified(sol.form, taut[order], sol.ro, sol.vo,
                      np.sqrt(sol.depth2), weights[order], status[order])


def taut_indices(taut: np.ndarray, tsize: np.ndarray, width: int
                 ) -> tuple[np.ndarray, np.ndarray]:
    """Ascending indices of each row's True entries, padded to ``width`` with ``N``;
    and the mask of real entries. ``taut`` (K, N) bool; O(number of True entries)."""
    K, N = taut.shape
    rows, cols = np.nonzero(taut)
    starts = np.concatenate([[0], np.cumsum(tsize)[:-1]])
    pos = np.arange(len(rows)) - starts[rows]
    out = np.full((K, width), N, dtype=np.intp)
    out[rows, pos] = cols
    return out, out < N


def _empty(N: int) -> Classified:
    z2 = np.zeros((0, 2))
    return Classified(np.zeros(0, np.intp), np.zeros((0, N), bool), z2, z2.copy(),
                      np.zeros(0), np.zeros((0, N)), np.zeros(0, np.int8))
