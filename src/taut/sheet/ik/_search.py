"""Search for an all-taut stable formation over (angles, load shares)
(docs/sheet_kinematics.md §6; planning paper eq. 10).

Everything here works in the normalised frame of a target: object over the origin, contact
at the origin, lengths divided by the sheet size; robot ``i`` stands at :math:`\\rho_i
\\mathbf{u}(\\theta_i)` and the unknowns are the angles :math:`\\theta` and the weights
:math:`w` of the polytope :math:`W` (see :mod:`taut.sheet.ik._certificate`).

* :func:`joint_optimise`: SLSQP over :math:`(\\theta, w)` maximising the tension-weighted
  alignment with preferred directions (or minimising the motion from a reference), every
  equilibrium condition a constraint; an optional margin keeps the pair limits strict;
* :func:`multistart_search`: the completeness stage. Starts spread over the structure of
  the problem (weights at vertices of :math:`W` mixed with the max-entropy point, angles
  balanced for those weights by the geometric-median construction around random preferred
  directions, and random angles), each solved for feasibility with the pair limits *without*
  margin, so solutions with a pair at exactly its sheet distance (the boundary case) are
  found;
* :func:`check_solution`: the exact acceptance test of a candidate;
* :func:`solve_pairs` and :class:`PairLimits`: both stages' SLSQP solves, given only the
  robot pairs near their limits or neighbouring (constraint generation: every pair is
  checked on each result and the near ones added), not all N(N-1)/2 pair rows.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np
from scipy.optimize import linprog, minimize

from ._weights import closure_directions
from .._lifted import Frame, reduced_hessian_min_eig
from .._tol import (BOUNDARY_RTOL, EQUATION_RTOL, IK_PAIR_NEAR, IK_PAIR_NEIGHBOURS,
    IK_PAIR_ROUNDS, IK_PAIR_SHRINK, IK_SLSQP_FTOL, MIN_CURVATURE, MIN_WEIGHT, RANK_TOL, TINY)

__all__ = ["robots", "curvature", "check_solution", "joint_optimise", "multistart_search",
           "solve_pairs", "PairLimits", "Candidate"]


@dataclass(frozen=True)
class Candidate:
    """A balanced (angles, weights) pair; ``how`` names the stage that found it."""

    angles: np.ndarray
    weights: np.ndarray
    how: str


def robots(rho: np.ndarray, th: np.ndarray) -> np.ndarray:
    """Robots (..., N, 2) at reach ``rho`` (N,) and angles ``th`` (..., N)."""
    return rho[:, None] * np.stack([np.cos(th), np.sin(th)], axis=-1)


def _independent_rows(D: np.ndarray, rank: int) -> list[int]:
    """Greedy choice of ``rank`` linearly independent rows of ``D`` (k, 4)."""
    chosen: list[int] = []
    for i in np.argsort(-np.linalg.norm(D, axis=1)):
        trial = chosen + [int(i)]
        sv = np.linalg.svd(D[trial], compute_uv=False)
        if sv[-1] > RANK_TOL * max(float(sv[0]), TINY):
            chosen = trial
        if len(chosen) == rank:
            break
    return chosen


def curvature(R: np.ndarray, V: np.ndarray) -> np.ndarray:
    """Smallest reduced-Hessian eigenvalue of the all-taut state (docs/sheet_kinematics.md
    §5) for robots R (..., N, 2) and vertices V (N, 2), normalised units.

    The tangent space of all N cables equals that of any affinely independent subset
    spanning the same affine hull, so the kernel's :func:`reduced_hessian_min_eig` is
    called on such a subset (``inf`` when the rows have rank 4: the cables fix the state).
    """
    lead = R.shape[:-2]
    N = R.shape[-2]
    Rf = R.reshape(-1, N, 2)
    B = Rf.shape[0]
    frame = Frame.build(V, Rf, 1.0, 1.0)
    A = frame.P[..., :4]
    D = A[:, 1:, :] - A[:, :1, :]
    sv = np.linalg.svd(D, compute_uv=False)
    rank = np.sum(sv > RANK_TOL * np.maximum(sv[:, :1], TINY), axis=1)
    out = np.full(B, np.inf)
    low = np.flatnonzero(rank < 4)
    if len(low):
        idx = np.full((len(low), 5), -1, dtype=np.intp)
        for k, b in enumerate(low):
            rows = _independent_rows(D[b], int(rank[b]))
            idx[k, 0] = 0
            idx[k, 1:1 + len(rows)] = np.array(rows, dtype=np.intp) + 1
        out[low] = reduced_hessian_min_eig(frame, low, idx)
    return out.reshape(lead)


def check_solution(V: np.ndarray, rho: np.ndarray, w: np.ndarray, th: np.ndarray
                   ) -> tuple[bool, np.ndarray, float, float, float]:
    """Exact checks of a candidate (normalised units).

    Returns ok, robots (N, 2), spacing (smallest :math:`D_{ij} - |r_i - r_j|`, may be
    down to ``-BOUNDARY_RTOL`` for a pair at its limit), curvature, balance residual.
    """
    R = robots(rho, th)
    iu, ju = np.triu_indices(len(rho), 1)
    spacing = np.linalg.norm(V[iu] - V[ju], axis=1) - np.linalg.norm(R[iu] - R[ju], axis=1)
    curv = float(curvature(R, V))
    bal = float(np.linalg.norm((w[:, None] * R).sum(axis=0)))
    cres = max(abs(w.sum() - 1.0), float(np.abs(w @ V).max()))
    ok = bool(w.min() >= MIN_WEIGHT and spacing.min() >= -BOUNDARY_RTOL
              and curv >= MIN_CURVATURE and bal <= EQUATION_RTOL and cres <= EQUATION_RTOL)
    return ok, R, float(spacing.min()), curv, bal


def polish(V: np.ndarray, rho: np.ndarray, w: np.ndarray, th: np.ndarray
           ) -> tuple[np.ndarray, np.ndarray] | None:
    """Make the balance exact (to rounding): project w onto the five linear conditions
    (sum 1, contact, horizontal balance) for the fixed angles, three times."""
    N = len(rho)
    if not np.all(np.isfinite(w)) or not np.all(np.isfinite(th)):
        return None
    for _ in range(3):
        E = np.vstack([np.ones(N), V.T, robots(rho, th).T])
        rhs = np.array([1.0, 0.0, 0.0, 0.0, 0.0])
        w = w - np.linalg.pinv(E) @ (E @ w - rhs)
    return th, w


@dataclass(frozen=True)
class PairLimits:
    """The pair limits :math:`|r_i - r_j|^2 \\le L_{ij} = (D_{ij} - m)^2 \\cdot`
    ``spacing_factor`` over all pairs ``i < j`` (``np.triu_indices`` order; normalised
    lengths, ``margin`` :math:`m`)."""

    iu: np.ndarray
    ju: np.ndarray
    lim2: np.ndarray

    @classmethod
    def build(cls, V: np.ndarray, spacing_factor: float, margin: float = 0.0
              ) -> "PairLimits":
        iu, ju = np.triu_indices(len(V), 1)
        D = np.maximum(np.sqrt(np.sum((V[iu] - V[ju]) ** 2, axis=1)) - margin, 0.0)
        return cls(iu, ju, D * D * spacing_factor)

    def slack(self, R: np.ndarray) -> np.ndarray:
        """:math:`L_{ij} - |r_i - r_j|^2` of every pair for robots R (N, 2)."""
        return self.lim2 - np.sum((R[self.iu] - R[self.ju]) ** 2, axis=1)

    def working(self, R: np.ndarray, neighbours: int) -> np.ndarray:
        """Mask of the pairs a solve from robots R (N, 2) is given: those whose slack is
        below ``IK_PAIR_NEAR`` of their limit (violated ones included) and each robot's
        ``neighbours`` nearest robots."""
        N = len(R)
        use = self.slack(R) < IK_PAIR_NEAR * self.lim2
        k = min(neighbours, N - 1)
        if k >= N - 1:
            use[:] = True
        elif k > 0:
            d2 = np.sum((R[:, None, :] - R[None, :, :]) ** 2, axis=-1)
            np.fill_diagonal(d2, np.inf)
            near = np.argpartition(d2, k - 1, axis=1)[:, :k]
            i = np.repeat(np.arange(N), k)
            lo, hi = np.minimum(i, near.ravel()), np.maximum(i, near.ravel())
            use[lo * N - lo * (lo + 1) // 2 + hi - lo - 1] = True
        return use


def _constraints(V: np.ndarray, rho: np.ndarray, limits: PairLimits, use: np.ndarray,
                 min_weight: float, need_curv: bool) -> list[dict[str, Any]]:
    """SLSQP constraints over z = (theta, w): the five equations, the weights, the pair
    limits ``limits`` selected by the mask ``use`` (:class:`PairLimits`) and, for N <= 4,
    the curvature."""
    N = len(rho)
    iu, ju, vdist2 = limits.iu[use], limits.ju[use], limits.lim2[use]

    def d_robots(th: np.ndarray) -> np.ndarray:
        return rho[:, None] * np.column_stack([-np.sin(th), np.cos(th)])

    def eq(z: np.ndarray) -> np.ndarray:
        th, w = z[:N], z[N:]
        return np.concatenate([[w.sum() - 1.0], w @ V, (w[:, None] * robots(rho, th)).sum(0)])

    def eq_jac(z: np.ndarray) -> np.ndarray:
        th, w = z[:N], z[N:]
        J = np.zeros((5, 2 * N))
        J[0, N:] = 1.0
        J[1:3, N:] = V.T
        J[3:5, :N] = (w[:, None] * d_robots(th)).T
        J[3:5, N:] = robots(rho, th).T
        return J

    def ineq(z: np.ndarray) -> np.ndarray:
        th, w = z[:N], z[N:]
        R = robots(rho, th)
        return np.concatenate([w - min_weight, vdist2 - np.sum((R[iu] - R[ju]) ** 2, axis=1)])

    def ineq_jac(z: np.ndarray) -> np.ndarray:
        th = z[:N]
        R, dR = robots(rho, th), d_robots(th)
        P = len(iu)
        J = np.zeros((N + P, 2 * N))
        J[:N, N:] = np.eye(N)
        diff = R[iu] - R[ju]
        rows = N + np.arange(P)
        J[rows, iu] = -2 * np.einsum("pk,pk->p", diff, dR[iu])
        J[rows, ju] = 2 * np.einsum("pk,pk->p", diff, dR[ju])
        return J

    cons: list[dict[str, Any]] = [{"type": "eq", "fun": eq, "jac": eq_jac},
                                  {"type": "ineq", "fun": ineq, "jac": ineq_jac}]
    if need_curv:
        cons.append({"type": "ineq",
                     "fun": lambda z: np.atleast_1d(np.minimum(
                         curvature(robots(rho, z[:N]), V), 1.0) - 10 * MIN_CURVATURE)})
    return cons


def _alignment_objective(rho: np.ndarray, phi: np.ndarray
                         ) -> Callable[[np.ndarray], tuple[float, np.ndarray]]:
    """Minus the tension-weighted alignment with the preferred directions phi."""
    N = len(rho)

    def obj(z: np.ndarray) -> tuple[float, np.ndarray]:
        th, w = z[:N], z[N:]
        a = w * rho
        S, c = a.sum(), np.cos(th - phi)
        A = (a * c).sum()
        g = np.concatenate([a * np.sin(th - phi) / S, -(rho * c * S - A * rho) / S ** 2])
        return -A / S, g
    return obj


def _motion_objective(rho: np.ndarray, ref: np.ndarray
                      ) -> Callable[[np.ndarray], tuple[float, np.ndarray]]:
    """Total squared robot motion from the reference formation ``ref`` (N, 2)."""
    N = len(rho)

    def obj(z: np.ndarray) -> tuple[float, np.ndarray]:
        th = z[:N]
        diff = robots(rho, th) - ref
        dR = rho[:, None] * np.column_stack([-np.sin(th), np.cos(th)])
        g_th = 2 * np.einsum("ik,ik->i", diff, dR)
        return float(np.sum(diff ** 2)), np.concatenate([g_th, np.zeros(N)])
    return obj


def _slsqp(obj: Callable[[np.ndarray], tuple[float, np.ndarray]], z0: np.ndarray,
           cons: list[dict[str, Any]], N: int, maxiter: int = 300
           ) -> np.ndarray | None:
    try:
        res = minimize(obj, z0, jac=True, method="SLSQP", constraints=cons,
                       bounds=[(None, None)] * N + [(0.0, 1.0)] * N,
                       options={"maxiter": maxiter, "ftol": IK_SLSQP_FTOL})
    except (ValueError, np.linalg.LinAlgError):  # pragma: no cover - defensive
        return None
    return np.asarray(res.x)


def solve_pairs(obj: Callable[[np.ndarray], tuple[float, np.ndarray]], z0: np.ndarray,
                V: np.ndarray, rho: np.ndarray, limits: PairLimits, min_weight: float,
                need_curv: bool, maxiter: int = 300,
                neighbours: int = IK_PAIR_NEIGHBOURS) -> np.ndarray | None:
    """SLSQP over z = (theta, w) from ``z0`` with the pair limits generated: the first
    solve is given the pairs :meth:`PairLimits.working` picks at ``z0``; after each solve
    every pair is checked, the pairs it picks at the result that were left out are added,
    and the solve is repeated from ``z0`` (a warm start from the violating point reached
    fewer formations in the tests), at most ``IK_PAIR_ROUNDS`` solves; then the last point
    is returned, for the caller's exact check. A pair left out of the final solve is at
    least ``IK_PAIR_NEAR`` of its limit inside it (inactive), so a stationary point of the
    final solve is one of the problem with every pair. Returns z, or None when SLSQP
    fails."""
    N = len(rho)
    use = limits.working(robots(rho, z0[:N]), neighbours)
    z = z0
    for _ in range(IK_PAIR_ROUNDS):
        out = _slsqp(obj, z0, _constraints(V, rho, limits, use, min_weight, need_curv), N,
                     maxiter)
        if out is None or not np.all(np.isfinite(out)):
            return out
        z = out
        add = limits.working(robots(rho, z[:N]), neighbours) & ~use
        if not add.any():
            break
        use |= add
    return z


def joint_optimise(V: np.ndarray, rho: np.ndarray, phi: np.ndarray, w0: np.ndarray,
                   th0: np.ndarray, ref: np.ndarray | None, need_curv: bool,
                   margin: float = 0.0) -> tuple[np.ndarray, np.ndarray] | None:
    """SLSQP over (theta, w) from (th0, w0): the alignment with ``phi`` (or the motion
    from ``ref``), pair limits kept strictly inside (factor 1 - 1e-7) and ``margin``
    (normalised length) inside their sheet distances, generated (:func:`solve_pairs`).
    Returns polished (theta, w) or None."""
    N = len(rho)
    obj = _alignment_objective(rho, phi) if ref is None else _motion_objective(rho, ref)
    limits = PairLimits.build(V, 1 - IK_PAIR_SHRINK, margin)
    z = solve_pairs(obj, np.concatenate([th0, w0]), V, rho, limits, MIN_WEIGHT * 10,
                    need_curv)
    return None if z is None else polish(V, rho, z[N:], z[:N])


def _polytope_vertices(V: np.ndarray, rng: np.random.Generator, count: int
                       ) -> list[np.ndarray]:
    """Vertices of W = {w >= 0, sum w = 1, sum w v = 0} exposed by random objectives."""
    N = len(V)
    A_eq = np.vstack([np.ones(N), V.T])
    out = []
    for _ in range(count):
        lp = linprog(rng.normal(size=N), A_eq=A_eq, b_eq=[1.0, 0.0, 0.0],
                     bounds=[(0, None)] * N, method="highs")
        if lp.success:
            out.append(np.asarray(lp.x))
    return out


def _starts(V: np.ndarray, rho: np.ndarray, w_max: np.ndarray, phi: np.ndarray,
            rng: np.random.Generator, budget: int
            ) -> list[tuple[np.ndarray, np.ndarray]]:
    """(theta0, w0) starts spread over the problem's structure (module docstring)."""
    N = len(rho)
    verts = _polytope_vertices(V, rng, max(1, budget // 4)) if N > 3 else []
    out = []
    for k in range(budget):
        if verts and k % 2 == 1:
            mix = rng.uniform(0.2, 0.8)
            w0 = mix * verts[k % len(verts)] + (1 - mix) * w_max
        else:
            w0 = w_max
        if k % 3 == 2:
            th0 = rng.uniform(-np.pi, np.pi, N)
        else:
            pref = phi + rng.uniform(-np.pi, np.pi) + rng.normal(scale=0.3 * (k > 0), size=N)
            u = closure_directions(w0 * rho, np.column_stack([np.cos(pref), np.sin(pref)]))
            th0 = pref if u is None else np.arctan2(u[:, 1], u[:, 0])
        out.append((th0, w0))
    return out


def multistart_search(V: np.ndarray, rho: np.ndarray, w_max: np.ndarray, phi: np.ndarray,
                      accept: Callable[[np.ndarray, np.ndarray], bool], *, budget: int,
                      seed: int = 0) -> tuple[Candidate | None, int]:
    """The completeness stage (module docstring): up to ``budget`` SLSQP feasibility
    solves (objective: stay near the start) with the pair limits without margin.
    ``accept(theta, w)`` is the caller's exact test (including forward kinematics).

    Returns the first accepted candidate (or None) and the number of solves run.
    """
    N = len(rho)
    rng = np.random.default_rng(seed)
    limits = PairLimits.build(V, 1.0)
    tried = 0
    for th0, w0 in _starts(V, rho, w_max, phi, rng, budget):
        tried += 1
        z0 = np.concatenate([th0, w0])

        def obj(z: np.ndarray, z0: np.ndarray = z0) -> tuple[float, np.ndarray]:
            d = z - z0
            return 1e-3 * float(d @ d), 2e-3 * d

        z = solve_pairs(obj, z0, V, rho, limits, 2 * MIN_WEIGHT, N <= 4, maxiter=200)
        out = None if z is None else polish(V, rho, z[N:], z[:N])
        if out is not None and accept(*out):
            return Candidate(out[0], out[1], "search"), tried
    return None, tried
