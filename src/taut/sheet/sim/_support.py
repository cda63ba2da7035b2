"""One branch of the quasi-static simulation: its state and the re-solve of its support.

A branch is the rest state of the object on one taut set; it is followed by re-solving
its *support* (3..5 taut cables with affinely independent lifted points) on each new
formation with the same tests as forward kinematics (docs/sheet_kinematics.md §1-§5; FK
paper Sec. II). The tracker that strings these solves together is :mod:`._branch`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import linprog

from .._lifted import (CURVATURE_TOL, TAUT_TOL, WEIGHT_TOL, Frame, height_ok,
    reduced_hessian_min_eig, solve_candidates, taut_masks)
from .._tol import SUPPORT_RANK_RTOL
from ..fk.forward import forward_kinematics
from ..model import Sheet
from ..fk.results import Equilibrium

__all__ = ["State", "SetSolution", "from_equilibrium", "solve_taut_sets", "solve_support_one",
           "members", "branch", "neighbour_sets", "nearest"]

_J = np.array([1.0, 1.0, -1.0, -1.0])


@dataclass
class State:
    """Object state; ``support`` (3..5 cables, affinely independent lifted points, the
    set that is re-solved along the branch) is a subset of ``taut`` (the exact maximiser
    set, reported; larger only at degenerate states such as all-taut IK formations)."""

    support: tuple[int, ...]
    taut: tuple[int, ...]
    ro: np.ndarray
    vo: np.ndarray
    z: float
    w: np.ndarray                          # (N,)

    @property
    def point(self) -> np.ndarray:
        """(r_o, v_o, z_o), shape (5,)."""
        return np.concatenate([self.ro, self.vo, [self.z]])


def _support(sheet: Sheet, R: np.ndarray, z: float, e: Equilibrium) -> tuple[int, ...]:
    """A subset of the taut set to follow: at most 5 cables whose lifted points are
    affinely independent and span the same face, carrying non-negative weights for the
    same state (a basic solution of the weight equations, Caratheodory), so that solving
    it reproduces the state."""
    T = np.array(e.taut, dtype=np.intp)
    frame = Frame.build(sheet.vertices, R[None], z, sheet.size)
    P = frame.P[0, T]

    def rank(rows: np.ndarray) -> int:
        if len(rows) < 2:
            return len(rows)
        sv = np.linalg.svd(P[rows[1:]] - P[rows[:1]], compute_uv=False)
        return 1 + int(np.sum(sv > SUPPORT_RANK_RTOL * max(1.0, sv[0])))

    everything = np.arange(len(T))
    full = rank(everything)
    if len(T) <= 5 and full == len(T):
        return tuple(int(i) for i in T)
    E = np.vstack([np.ones(len(T)), frame.R[0, T].T, frame.V[T].T])
    lp = linprog(-np.asarray(e.weights), A_eq=E, b_eq=E @ e.weights,
                 bounds=[(0, None)] * len(T), method="highs-ds")
    w = lp.x if lp.success else np.asarray(e.weights)
    chosen: list[int] = []
    for i in np.argsort(-w):
        if len(chosen) == full:
            break
        if rank(np.array(chosen + [int(i)])) == len(chosen) + 1:
            chosen.append(int(i))
    return tuple(sorted(int(T[i]) for i in chosen))


def from_equilibrium(e: Equilibrium, sheet: Sheet, R: np.ndarray, z: float) -> State:
    """The tracker's state for the FK equilibrium ``e`` of formation ``R``."""
    w = np.zeros(sheet.n)
    w[list(e.taut)] = e.weights
    return State(_support(sheet, R, z, e), e.taut, e.object[:2].copy(), e.contact.copy(),
                 float(e.object[2]), w)


#: valid (M,), ro (M, 2), vo (M, 2), zo (M,), w (M, N), exact taut sets (M, N).
SetSolution = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]


def solve_taut_sets(sheet: Sheet, R: np.ndarray, z: float, form: np.ndarray,
                    idx: np.ndarray) -> SetSolution:
    """Solve taut sets ``idx`` (M, 5), padded with -1, 3..5 cables each, on formations
    ``R[form]`` (R (B, N, 2)), with the tests of :func:`forward_kinematics`.

    Returns valid (M,), ro (M, 2), vo (M, 2), zo (M,), w (M, N) in world units, and the
    exact taut sets (M, N) (NaN/0/False on rows whose system is singular)."""
    M, N = len(form), R.shape[1]
    frame = Frame.build(sheet.vertices, R, z, sheet.size)
    sol = solve_candidates(frame, form, idx, independent=True)
    valid = np.zeros(M, dtype=bool)
    ro = np.full((M, 2), np.nan)
    vo = np.full((M, 2), np.nan)
    zo = np.full(M, np.nan)
    w = np.zeros((M, N))
    tight = np.zeros((M, N), dtype=bool)
    if len(sol.form) == 0:
        return valid, ro, vo, zo, w, tight
    ok = height_ok(frame, sol)
    ok_taut, tight_sol = taut_masks(frame, sol)
    members = sol.subset >= 0
    ok &= ok_taut & (np.where(members, sol.w, np.inf).min(axis=1) >= -WEIGHT_TOL)
    ok &= reduced_hessian_min_eig(frame, sol.form, sol.subset) > CURVATURE_TOL
    src, f = sol.source, sol.form
    valid[src] = ok
    ro[src] = sol.ro * frame.scale + frame.r_centre[f]
    vo[src] = sol.vo * frame.scale + frame.v_centre
    zo[src] = z - np.sqrt(np.maximum(sol.depth2, 0.0)) * frame.scale
    rows, slots = np.nonzero(members)
    w[src[rows], sol.subset[rows, slots]] = sol.w[rows, slots]
    tight[src] = tight_sol
    return valid, ro, vo, zo, w, tight


def _tangent_min_eig(D: np.ndarray) -> float:
    """Smallest eigenvalue of diag(1,1,-1,-1) on the null space of the rows D (k-1, 4),
    k = 3 or 4 affinely independent members (docs/sheet_kinematics.md §5)."""
    _, _, vt = np.linalg.svd(D, full_matrices=True)
    Z = vt[len(D):]
    return float(np.linalg.eigvalsh((Z * _J) @ Z.T)[0])


def solve_support_one(Xv: np.ndarray, v_centre: np.ndarray, size: float, z: float,
                      R: np.ndarray, support: tuple[int, ...]
                      ) -> tuple[np.ndarray, np.ndarray, float, np.ndarray, np.ndarray] | None:
    """One formation R (N, 2), one support (3..5 cables): the kernel's Lagrange solve and
    its tests (real depth above the ground, every cable admissible, weights >= 0, reduced
    Hessian positive; docs/sheet_kinematics.md §1-§5) without batching.

    ``Xv`` (N, 2) are the vertices centred at ``v_centre`` and divided by ``size``.
    Returns ro (2,), vo (2,), zo, w (N,), exact taut mask (N,) in world units, or None
    when the support does not give a stable state."""
    S = list(support)
    k = len(S)
    r_centre = R.mean(axis=0)
    Xr = (R - r_centre) / size
    b = (Xr * Xr).sum(axis=1) - (Xv * Xv).sum(axis=1)
    rs, vs = Xr[S], Xv[S]
    K = np.ones((k + 1, k + 1))
    K[:k, :k] = 2.0 * (rs @ rs.T - vs @ vs.T)
    K[k, k] = 0.0
    rhs = np.append(b[S], 1.0)
    try:
        sol = np.linalg.solve(K, rhs)
    except np.linalg.LinAlgError:
        return None
    if not np.all(np.abs(sol) < 1e9):
        return None
    w, mu = sol[:k], sol[k]
    x = np.concatenate([w @ rs, w @ vs])
    depth2 = -(x[0] * x[0] + x[1] * x[1] - x[2] * x[2] - x[3] * x[3] + mu)
    zn = z / size
    if not (depth2 > TAUT_TOL and depth2 < zn * zn) or w.min() < -WEIGHT_TOL:
        return None
    excess = (-2.0 * Xr) @ x[:2] + (2.0 * Xv) @ x[2:] + b - mu
    if excess.max() > TAUT_TOL:
        return None
    if k < 5:
        A = np.hstack([-2.0 * rs, 2.0 * vs])
        if not _tangent_min_eig(A[1:] - A[:1]) > CURVATURE_TOL:
            return None
    w_full = np.zeros(len(Xv))
    w_full[S] = w
    return (x[:2] * size + r_centre, x[2:] * size + v_centre,
            float(z - np.sqrt(max(depth2, 0.0)) * size), w_full, excess >= -TAUT_TOL)


def members(mask_or_idx: np.ndarray) -> tuple[int, ...]:
    a = np.asarray(mask_or_idx)
    idx = np.flatnonzero(a) if a.dtype == bool else a
    return tuple(sorted(int(i) for i in idx))


def branch(sheet: Sheet, R: np.ndarray, z: float, taut: tuple[int, ...]) -> SetSolution:
    """One taut set (3..5 cables) on every formation of ``R`` (C, N, 2); see
    :func:`solve_taut_sets`."""
    C = R.shape[0]
    idx = np.full((C, 5), -1, dtype=np.intp)
    idx[:, :len(taut)] = taut
    return solve_taut_sets(sheet, R, z, np.arange(C), idx)


def neighbour_sets(taut: tuple[int, ...], N: int) -> np.ndarray:
    """Taut sets one cable away from ``taut`` (drop one, add one, or swap one), 3..5
    cables, as rows padded with -1: the candidates for a continuous taut-set change."""
    cur = set(taut)
    out = []
    for i in taut:
        if len(cur) - 1 >= 3:
            out.append(sorted(cur - {i}))
    others = [j for j in range(N) if j not in cur]
    for j in others:
        if len(cur) + 1 <= 5:
            out.append(sorted(cur | {j}))
        for i in taut:
            if len(cur) >= 3:
                out.append(sorted((cur - {i}) | {j}))
    idx = np.full((len(out), 5), -1, dtype=np.intp)
    for k, row in enumerate(out):
        idx[k, :len(row)] = row
    return idx


def nearest(stable: tuple[Equilibrium, ...], point: np.ndarray) -> tuple[int, float]:
    """Index and distance of the state nearest to ``point`` = (r_o, v_o, z_o) (5,)."""
    pts = np.array([np.concatenate([e.object[:2], e.contact, [e.object[2]]]) for e in stable])
    d = np.linalg.norm(pts - point, axis=1)
    j = int(np.argmin(d))
    return j, float(d[j])
