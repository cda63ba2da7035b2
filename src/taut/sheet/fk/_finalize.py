"""From solved candidate sets to classified equilibria: de-duplication, the paper's
force-closure test, exact weights, stability and tensions (docs/sheet_kinematics.md §3-§5)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._lifted import (KIND_NOT_EQUILIBRIUM, KIND_SADDLE, KIND_STABLE, Frame, Solved,
    in_hull_2d, reduced_hessian_min_eig)
from .._tol import CURVATURE_TOL, FAMILY_FTOL, FAMILY_RESIDUAL, INSIDE_WEIGHT, RANK_TOL, WEIGHT_TOL
from .._util import q_hessian


@dataclass
class Classified:
    """Final solutions, flat over formations, in output order.

    ``form`` (K,), ``taut`` (K, N) bool, ``ro``/``vo`` (K, 2) normalised, ``depth`` (K,)
    normalised, ``weights`` (K, N) (0 on slack cables), ``kind`` (K,) int8 (``KIND_*``).
    """

    form: np.ndarray
    taut: np.ndarray
    ro: np.ndarray
    vo: np.ndarray
    depth: np.ndarray
    weights: np.ndarray
    kind: np.ndarray


def _output_order(form: np.ndarray, taut: np.ndarray, tsize: np.ndarray,
                  prefer: np.ndarray) -> np.ndarray:
    """One row per (formation, taut set), in output order.

    Rows are sorted by formation, number of taut cables, then taut set (ascending index
    lists compare like the bit strings of ``~taut``, most significant bit first). Among
    rows with the same key the first one with ``prefer`` set wins, else the first one.
    Returns the chosen row indices, in output order.
    """
    first = np.argsort(~prefer, kind="stable")
    M, N = taut.shape
    if N <= 40 and (int(form.max()) + 1) * (N + 1) < 1 << (62 - N):
        # Small teams: the same key packed into one integer; stable sort, first of each run.
        code = (~taut[first]) @ (1 << np.arange(N - 1, -1, -1, dtype=np.int64))
        key = (form[first] * (N + 1) + tsize[first]) << N | code
        order = np.argsort(key, kind="stable")
        key = key[order]
        head = np.ones(M, dtype=bool)
        np.not_equal(key[1:], key[:-1], out=head[1:])
        return first[order[head]]
    keys = np.concatenate([form[first].astype(">i8").view(np.uint8).reshape(M, 8),
                           tsize[first].astype(">i4").view(np.uint8).reshape(M, 4),
                           np.packbits(~taut[first], axis=1)], axis=1)
    keys = np.ascontiguousarray(keys).view(np.dtype((np.void, keys.shape[1]))).ravel()
    _, pick = np.unique(keys, return_index=True)       # stable: first occurrence wins
    return first[pick]


def _weights_family(frame: Frame, f: int, idx: np.ndarray, ro: np.ndarray, vo: np.ndarray
                    ) -> tuple[np.ndarray, float]:
    """Weights when more cables are taut than the state determines.

    Returns the minimum-norm weights (non-negative when possible) and the largest
    achievable minimum weight ``t*`` (an LP solved with HiGHS): ``t* >= 0`` iff some
    non-negative weights balance the object (docs/sheet_kinematics.md §3).
    """
    from scipy.optimize import linprog               # rare: imported here, not with FK

    from ..._qp import solve_qp

    k = len(idx)
    E = np.vstack([frame.R[f, idx].T, frame.V[idx].T, np.ones(k)])
    rhs = np.concatenate([ro, vo, [1.0]])
    # Dependent taut sets (e.g. Lemma 2: every lifted point on a 2-plane) make E rank
    # deficient; rounding then leaves the 5 equations inconsistent at ~1e-12 and the LP
    # infeasible. Keep the equations along E's significant singular directions.
    U, S, _ = np.linalg.svd(E, full_matrices=False)
    rank = int(np.sum(S > RANK_TOL * S[0]))
    E, rhs = U[:, :rank].T @ E, U[:, :rank].T @ rhs
    c = np.zeros(k + 1)
    c[-1] = -1.0
    A_ub = np.hstack([-np.eye(k), np.ones((k, 1))])
    lp = linprog(c, A_ub=A_ub, b_ub=np.zeros(k), A_eq=np.hstack([E, np.zeros((rank, 1))]),
                 b_eq=rhs, bounds=[(None, None)] * (k + 1), method="highs")
    w_min_norm = np.linalg.pinv(E, rcond=RANK_TOL) @ rhs
    if not lp.success:
        return w_min_norm, -np.inf
    t_star = float(lp.x[-1])
    if t_star < -WEIGHT_TOL or w_min_norm.min() >= -WEIGHT_TOL:
        return w_min_norm, t_star
    # min |w|^2 / 2 s.t. E w = rhs, w >= 0: DAQP (taut._qp), or SLSQP from the LP's point.
    x = solve_qp(np.eye(k), A_eq=E, b_eq=rhs, lb=np.zeros(k), x0=np.maximum(lp.x[:k], 0.0),
                 ftol=FAMILY_FTOL)
    w = x if x is not None and np.abs(E @ x - rhs).max() < FAMILY_RESIDUAL else lp.x[:k]
    return w, t_star


def _min_eig_family(frame: Frame, f: int, idx: np.ndarray) -> float:
    A = frame.P[f, idx, :4]
    D = A[1:] - A[:1]
    _, sv, vt = np.linalg.svd(D, full_matrices=True)
    r = int(np.sum(sv > RANK_TOL * max(1.0, sv[0] if len(sv) else 1.0)))
    Z = vt[r:]
    if len(Z) == 0:
        return np.inf
    Hr = Z @ q_hessian() @ Z.T
    return float(np.linalg.eigvalsh(Hr)[0])


def classify(frame: Frame, solved: Solved, taut: np.ndarray,
             projection_checked: np.ndarray | None = None,
             curvature: np.ndarray | None = None) -> Classified:
    """Turn candidate solutions (already feasible: pieces maximal, depth real, object
    above ground) into the final, de-duplicated, classified solution list.

    Steps: keep one solution per (formation, taut set), preferring one whose candidate
    *is* the taut set, in output order; apply the paper's projection test; compute weights (unique
    when the taut set is affinely independent, otherwise by LP/QP); kind from the
    weights' signs and the reduced Hessian; sort by formation, taut-set size, taut set.
    ``projection_checked`` (M,) marks rows that already passed the projection test on
    their exact taut set; ``curvature`` (M,) holds rows' reduced-Hessian eigenvalues
    already known (NaN where not).
    """
    N = taut.shape[1]
    if len(taut) == 0:
        return _empty(N)
    tsize = taut.sum(axis=1)
    pick = _output_order(solved.form, taut, tsize, tsize == solved.size)
    taut, tsize = taut[pick], tsize[pick]
    form, subset = solved.form[pick], solved.subset[pick]
    is_rare = tsize != solved.size[pick]
    ro = solved.x[pick, :2]
    w = solved.w[pick]
    members = subset >= 0
    min_w = np.where(members, w, np.inf).min(axis=1, initial=np.inf)
    paper_ok = tsize >= 3
    todo = paper_ok if projection_checked is None else paper_ok & ~projection_checked[pick]
    # r_o = sum w_i r_i over the candidate's robots (a subset of the taut ones): with
    # every weight clearly positive it lies inside their polygon, the test can only pass.
    todo = todo & ~(min_w > INSIDE_WEIGHT)
    if np.any(todo):
        todo = np.flatnonzero(todo)
        if np.any(is_rare[todo]):
            cols, inside = taut_indices(taut[todo], tsize[todo], int(tsize[todo].max()))
        else:                                     # the candidates are the taut sets
            cols, inside = subset[todo], members[todo]
        paper_ok[todo] = in_hull_2d(frame.R[form[todo, None], np.clip(cols, 0, N - 1)],
                                    inside, ro[todo])
    if not paper_ok.all():
        pick, taut, tsize, is_rare = pick[paper_ok], taut[paper_ok], tsize[paper_ok], is_rare[paper_ok]
        form, subset, members = form[paper_ok], subset[paper_ok], members[paper_ok]
        w, min_w = w[paper_ok], min_w[paper_ok]
    x = solved.x[pick]
    K = len(tsize)
    weights = np.zeros((K, N))
    rows = np.nonzero(members)[0]
    weights[rows, subset[members]] = w[members]
    # Curvature decides stable vs saddle only: not needed where a weight is negative
    # (not an equilibrium) nor for rare rows (their own computation below).
    min_eig = np.full(K, np.nan) if curvature is None else curvature[pick]
    unknown = np.flatnonzero(np.isnan(min_eig) & (min_w >= -WEIGHT_TOL) & ~is_rare)
    if len(unknown):
        min_eig[unknown] = reduced_hessian_min_eig(frame, form[unknown], subset[unknown])
    for k in np.flatnonzero(is_rare):
        idx = np.flatnonzero(taut[k])
        weights[k] = 0.0
        weights[k, idx], min_w[k] = _weights_family(frame, int(form[k]), idx, x[k, :2], x[k, 2:])
        min_eig[k] = _min_eig_family(frame, int(form[k]), idx)
    kind = np.where(min_w < -WEIGHT_TOL, KIND_NOT_EQUILIBRIUM,
                    np.where(min_eig > CURVATURE_TOL, KIND_STABLE, KIND_SADDLE)
                    ).astype(np.int8)
    return Classified(form, taut, x[:, :2], x[:, 2:], np.sqrt(solved.depth2[pick]), weights,
                      kind)


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
