"""Rest states in exact rational arithmetic, independent of taut's float64 solver (tests).

The data (float64 sheet vertices and robot positions) are taken as the exact rationals
they are; for a taut-cable subset ``S`` (3..5 cables) the stationary point of
``F(x) = max_i (|r_o - r_i|^2 - |v_o - v_i|^2)`` on the face where the cables of ``S`` are
equal is the solution of a linear system in the weights (docs/sheet_kinematics.md §3:
``r_o = sum w_i r_i``, ``v_o = sum w_i v_i``, ``sum w_i = 1``, the pieces of ``S`` equal),
solved with fractions. The state is a rest state when every weight is non-negative, no
other cable is longer than its sheet allows there and the object hangs above the floor;
a strict minimum when, in addition, every weight is positive and the Hessian
``diag(2, 2, -2, -2)`` restricted to the face's tangent space is positive definite
(Sylvester: every pivot of its LDL^T factorisation positive). Nothing is rounded.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction as Fr
from itertools import combinations

import numpy as np


@dataclass
class ExactState:
    subset: tuple[int, ...]
    weights: list[Fr]
    x: list[Fr]              # (r_o, v_o), the data's frame and unit
    depth2: Fr               # d^2 below the hold height
    slack: list[Fr]          # per cable: max_i F_i - F_j (0 on the taut ones)
    strict: bool

    def object(self, hold: float) -> np.ndarray:
        return np.array([float(self.x[0]), float(self.x[1]),
                         hold - float(self.depth2) ** 0.5])


def _solve(M: list[list[Fr]], y: list[Fr]) -> list[Fr] | None:
    n = len(M)
    A = [row[:] + [y[i]] for i, row in enumerate(M)]
    for c in range(n):
        p = next((r for r in range(c, n) if A[r][c] != 0), None)
        if p is None:
            return None
        A[c], A[p] = A[p], A[c]
        for r in range(n):
            if r != c and A[r][c] != 0:
                f = A[r][c] / A[c][c]
                A[r] = [a - f * b for a, b in zip(A[r], A[c])]
    return [A[i][n] / A[i][i] for i in range(n)]


def _null_space(rows: list[list[Fr]], dim: int = 4) -> list[list[Fr]]:
    A = [r[:] for r in rows]
    pivots: list[int] = []
    for c in range(dim):
        p = next((r for r in range(len(pivots), len(A)) if A[r][c] != 0), None)
        if p is None:
            continue
        k = len(pivots)
        A[k], A[p] = A[p], A[k]
        A[k] = [a / A[k][c] for a in A[k]]
        for r in range(len(A)):
            if r != k and A[r][c] != 0:
                f = A[r][c]
                A[r] = [a - f * b for a, b in zip(A[r], A[k])]
        pivots.append(c)
    basis = []
    for free in (c for c in range(dim) if c not in pivots):
        z = [Fr(0)] * dim
        z[free] = Fr(1)
        for i, pc in enumerate(pivots):
            z[pc] = -A[i][free]
        basis.append(z)
    return basis


def _positive_definite(H: list[list[Fr]]) -> bool:
    A = [r[:] for r in H]
    for k in range(len(A)):
        if A[k][k] <= 0:
            return False
        for i in range(k + 1, len(A)):
            f = A[i][k] / A[k][k]
            A[i] = [a - f * b for a, b in zip(A[i], A[k])]
    return True


def exact_state(V: np.ndarray, R: np.ndarray, hold: float, S: tuple[int, ...]
                ) -> ExactState | None:
    """The rest state on the taut cables ``S`` (3..5 indices), or None when the system is
    singular or the state is not a rest state above the floor."""
    v = [[Fr(float(a)) for a in p] for p in V]
    r = [[Fr(float(a)) for a in p] for p in R]
    pts = [r[i] + v[i] for i in S]               # (r_i, v_i) in R^4

    def grad_diff(i: int, j: int) -> tuple[list[Fr], Fr]:
        """F_i - F_j = c . x + k (affine: the quadratic parts cancel)."""
        c = [-2 * (r[i][0] - r[j][0]), -2 * (r[i][1] - r[j][1]),
             2 * (v[i][0] - v[j][0]), 2 * (v[i][1] - v[j][1])]
        k = (r[i][0] ** 2 + r[i][1] ** 2 - r[j][0] ** 2 - r[j][1] ** 2
             - v[i][0] ** 2 - v[i][1] ** 2 + v[j][0] ** 2 + v[j][1] ** 2)
        return c, k

    M, y = [], []
    for j in S[1:]:
        c, k = grad_diff(S[0], j)
        M.append([sum((c[m] * p[m] for m in range(4)), Fr(0)) for p in pts])
        y.append(-k)
    M.append([Fr(1)] * len(S))
    y.append(Fr(1))
    w = _solve(M, y)
    if w is None or min(w) < 0:
        return None
    x = [sum((w[a] * pts[a][m] for a in range(len(S))), Fr(0)) for m in range(4)]
    F = [(x[0] - r[i][0]) ** 2 + (x[1] - r[i][1]) ** 2 - (x[2] - v[i][0]) ** 2
         - (x[3] - v[i][1]) ** 2 for i in range(len(V))]
    top = max(F)
    if any(F[i] != top for i in S) or not 0 < -top < Fr(float(hold)) ** 2:
        return None
    Z = _null_space([grad_diff(S[0], j)[0] for j in S[1:]])
    H = [[sum((a[m] * (2 if m < 2 else -2) * b[m] for m in range(4)), Fr(0)) for b in Z]
         for a in Z]
    strict = min(w) > 0 and _positive_definite(H)
    return ExactState(tuple(S), w, x, -top, [top - f for f in F], strict)


def sharp_minimum(V: np.ndarray, R: np.ndarray, state: ExactState, w: dict[int, Fr]
                  ) -> bool:
    """Whether ``state`` is a strict (sharp) minimum, certified by weights ``w`` (cable ->
    weight) on cables exactly taut there: every weight positive, they balance the object
    exactly (``sum w_i (r_i, v_i) = x``, ``sum w_i = 1``), and the gradients of the taut
    pieces span R^4. Then F(x + z) - F(x) = max_i grad F_i . z + q(z) (exact: the pieces
    are quadratics with one Hessian) and the maximum is positive for every z != 0 (its
    w-weighted mean is 0 and not all terms vanish), so the minimum is strict."""
    v = [[Fr(float(a)) for a in p] for p in V]
    r = [[Fr(float(a)) for a in p] for p in R]
    if sum(w.values()) != 1 or min(w.values()) <= 0 or any(state.slack[i] for i in w):
        return False
    if any(sum((w[i] * (r[i] + v[i])[m] for i in w), Fr(0)) != state.x[m] for m in range(4)):
        return False
    x = state.x
    grads = [[2 * (x[0] - r[i][0]), 2 * (x[1] - r[i][1]), -2 * (x[2] - v[i][0]),
              -2 * (x[3] - v[i][1])] for i in w]
    return not _null_space(grads)


def exact_states(V: np.ndarray, R: np.ndarray, hold: float, cables=None
                 ) -> list[ExactState]:
    """Every rest state on 3..5 taut cables among ``cables`` (default: all), deepest
    (lowest object) first."""
    cables = range(len(V)) if cables is None else cables
    out = [s for k in (3, 4, 5) for S in combinations(sorted(cables), k)
           if (s := exact_state(V, R, hold, S)) is not None]
    return sorted(out, key=lambda s: -s.depth2)


def brute_lowest(V: np.ndarray, R: np.ndarray, hold: float, starts: int = 6
                 ) -> tuple[float, bool]:
    """The lowest object position by a generic constrained minimisation (scipy SLSQP,
    independent of taut's enumeration and descent): minimise ``t`` over ``(r_o, v_o, t)``
    subject to ``t >= F_i`` for every cable, the contact point on the (convex) sheet and
    ``t >= -hold^2`` (the floor), from the centroids and from ``starts`` points towards
    the vertices. Returns the lowest depth^2 reached (``-t``, the data's unit squared) and
    whether that point is a rest state: the contact point strictly inside the sheet and the
    object strictly above the floor (else the object slides to the edge or the floor)."""
    from scipy.optimize import minimize

    size = float(np.ptp(V, axis=0).max())
    v = (V - V.mean(axis=0)) / size
    r = (R - R.mean(axis=0)) / size
    z2 = (hold / size) ** 2
    E = np.roll(v, -1, axis=0) - v
    ccw = float(np.sum(E[:, 0] * (v[:, 1] + np.roll(v, -1, axis=0)[:, 1]))) < 0
    sign = 1.0 if ccw else -1.0

    def F(y):
        return ((y[:2] - r) ** 2).sum(axis=1) - ((y[2:4] - v) ** 2).sum(axis=1)

    def F_jac(y):
        J = np.zeros((len(v), 5))
        J[:, :2] = 2 * (y[:2] - r)
        J[:, 2:4] = -2 * (y[2:4] - v)
        return J

    def inside(y):
        return sign * (E[:, 0] * (y[3] - v[:, 1]) - E[:, 1] * (y[2] - v[:, 0]))

    def inside_jac(y):
        J = np.zeros((len(v), 5))
        J[:, 2], J[:, 3] = sign * E[:, 1] * -1, sign * E[:, 0]
        return J

    cons = [{"type": "ineq", "fun": lambda y: y[4] - F(y),
             "jac": lambda y: np.c_[-F_jac(y)[:, :4], np.ones(len(v))]},
            {"type": "ineq", "fun": inside, "jac": inside_jac},
            {"type": "ineq", "fun": lambda y: np.array([y[4] + z2]),
             "jac": lambda y: np.array([[0, 0, 0, 0, 1.0]])}]
    best, best_y = np.inf, None
    pts = [np.zeros(4)] + [np.r_[0.5 * r[i], 0.5 * v[i]] for i in
                           np.linspace(0, len(v) - 1, min(starts, len(v))).astype(int)]
    for p in pts:
        y0 = np.r_[p, F(np.r_[p, 0]).max()]
        res = minimize(lambda y: y[4], y0, jac=lambda y: np.array([0, 0, 0, 0, 1.0]),
                       constraints=cons, method="SLSQP",
                       options={"ftol": 1e-14, "maxiter": 500})
        y = res.x
        if F(y).max() - y[4] > 1e-10 or inside(y).min() < -1e-10:
            continue                             # not a feasible end point
        if y[4] < best:
            best, best_y = float(y[4]), y
    if best_y is None:
        return -np.inf, False
    rest = inside(best_y).min() > 1e-6 and best > -z2 + 1e-9
    return -best * size ** 2, bool(rest)
