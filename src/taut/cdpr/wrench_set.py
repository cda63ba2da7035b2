"""Available wrench set (AWS) of a CDPR on fixed or mobile bases (FASTKIT eq. 24), exact, as
an H-polytope, batched over poses; axis capacities (FASTKIT Fig. 14) and capacity margins.

The AWS is ``{W t : t_min <= t <= t_max, T t <= -m0}``: the image through W of the tension
box intersected with the tipping half-spaces (eqs. 20-23). With ``r = m - n`` redundant
cables write ``t = W+ w + N z`` (``N`` an orthonormal null-space basis). A wrench ``w`` is
available iff the ``r``-dimensional polyhedron ``{z : G z <= h(w)}`` with ``G = A N`` and
``h(w) = b - A W+ w`` is non-empty. By Helly's theorem it is empty iff some ``r + 1`` of
its half-spaces already have no common point, and by Farkas' lemma that happens iff a
``lambda >= 0`` on those rows has ``lambda^T G = 0`` and ``lambda^T h(w) < 0``. For rows in
general position ``lambda`` is the (signed) vector of ``r x r`` minors of ``G`` on the
subset; degenerate subsets reduce to pairs of opposite rows or single zero rows, which are
added too. Hence the AWS is exactly

    ``{w : (lambda^T A W+) w <= lambda^T b  for every certificate lambda}``

- a finite H-representation (possibly with redundant rows, never with missing ones; the
degenerate-subset handling is complete for r <= 2, the case of 8 cables and 6 DoF). This
is Fourier-Motzkin elimination of ``z`` done in one step, and it never enumerates the
``2^m`` tension-box corners. For the tension box alone it reduces to the hyperplane-shifting
description of the wrench zonotope.

Wrench units are mixed (N, N m); rows are normalised to unit Euclidean norm.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from itertools import combinations, product
from typing import Any

import numpy as np
from scipy.optimize import linprog

from .._validate import as_array, as_count, require_instance
from ..errors import InvalidInputError
from ._common import constraints, feas_tol, required_wrench, svd_split
from .kinematics import as_poses, cable_state, gravity_wrench
from .model import CableRobot

__all__ = ["AvailableWrenchSet", "available_wrench_set", "wrench_feasible",
           "AxisCapacities", "axis_capacities", "capacity_margin", "disturbance_box",
           "AXIS_LABELS"]

AXIS_LABELS = ("fx", "fy", "fz", "mx", "my", "mz")


@lru_cache(maxsize=32)
def _subsets(K: int, s: int) -> np.ndarray:
    return np.array(list(combinations(range(K), s)), dtype=np.intp).reshape(-1, s)


def _certificates(G: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Farkas certificates for ``G z <= h`` (G: (B, K, r)).

    Returns ``idx`` (S, r + 1) row indices, ``lam`` (r + 1, B, S) non-negative weights with
    max 1 and ``sum_k lam[k] G[idx[:, k]] = 0`` (zero for invalid subsets), and ``valid``
    (B, S). Components are kept on the leading axis so every step is a flat elementwise op.
    """
    B, K, r = G.shape
    s = r + 1
    scale = np.abs(G).max(axis=(1, 2), initial=0.0)[:, None] + 1e-300
    eps = 1e-10
    idx_parts, lam_parts = [], []
    # Single zero rows: 0 <= h_i.
    gnorm = np.sqrt(np.einsum("bkr,bkr->bk", G, G)) if r else np.zeros((B, K))
    single = np.zeros((s, B, K))
    single[0] = gnorm <= eps * scale
    idx_parts.append(np.repeat(np.arange(K)[:, None], s, axis=1))
    lam_parts.append(single)
    if r >= 1:
        # Pairs of opposite rows: |g_j| h_i + |g_i| h_j >= 0.
        pr = _subsets(K, 2)
        i, j = pr[:, 0], pr[:, 1]
        ni, nj = gnorm[:, i], gnorm[:, j]
        dot = np.einsum("bkr,blr->bkl", G, G).reshape(B, K * K)[:, i * K + j]
        opp = (dot <= -(1 - 1e-12) * ni * nj) & (ni > eps * scale) & (nj > eps * scale)
        lam = np.zeros((s, B, len(pr)))
        lam[0] = np.where(opp, nj, 0.0)
        lam[1] = np.where(opp, ni, 0.0)
        idx_parts.append(np.concatenate([pr, np.repeat(pr[:, 1:], s - 2, axis=1)], axis=1))
        lam_parts.append(lam)
    if r >= 2:
        # (r + 1)-subsets in general position: lambda = signed r x r minors.
        sub = _subsets(K, s)
        if r == 2:
            C = (G[:, :, None, 0] * G[:, None, :, 1]
                 - G[:, :, None, 1] * G[:, None, :, 0]).reshape(B, K * K)   # g_i x g_j
            a, b_, c = sub[:, 0], sub[:, 1], sub[:, 2]
            lam = np.stack([C[:, b_ * K + c], C[:, c * K + a], C[:, a * K + b_]])
        else:
            Gs = G[:, sub]                                     # (B, S, s, r)
            lam = np.stack([(-1) ** k * np.linalg.det(np.delete(Gs, k, axis=2))
                            for k in range(s)])
        idx_parts.append(sub)
        lam_parts.append(lam)
    idx = np.concatenate(idx_parts, axis=0)
    lam = np.concatenate(lam_parts, axis=2)
    absl = np.abs(lam)
    mx = absl[0].copy()
    tot = lam[0].copy()
    for k in range(1, s):
        np.maximum(mx, absl[k], out=mx)
        tot += lam[k]
    lam /= np.where(tot < 0, -mx, mx) + 1e-300
    low = lam[0].copy()
    for k in range(1, s):
        np.minimum(low, lam[k], out=low)
    valid = (mx > eps * scale ** r) & (low >= -1e-9)
    np.maximum(lam, 0.0, out=lam)
    lam *= valid
    return idx, lam, valid


def _nonempty(G: np.ndarray, h: np.ndarray, tol: float, cert=None) -> np.ndarray:
    """Whether ``{z : G z <= h + tol}`` is non-empty, batched (G (B, K, r), h (B, K)).

    For r <= 2 by vertex enumeration: the set is bounded (it contains the tension box
    rows), so when non-empty it has a vertex where r constraint lines meet; r = 2 needs the
    K(K-1)/2 pairwise intersections. For r > 2 the Farkas certificates ``cert`` are used.
    """
    B, K, r = G.shape
    if r == 0:
        return np.all(h >= -tol, axis=1)
    with np.errstate(all="ignore"):
        if r == 1:
            g = G[..., 0]
            Z = (h / np.where(np.abs(g) > 0, g, np.nan))[..., None]          # (B, K, 1)
        elif r == 2:
            pr = _subsets(K, 2)
            i, j = pr[:, 0], pr[:, 1]
            gi, gj = G[:, i], G[:, j]
            det = gi[..., 0] * gj[..., 1] - gi[..., 1] * gj[..., 0]
            hi, hj = h[:, i], h[:, j]
            Z = np.stack([(hi * gj[..., 1] - hj * gi[..., 1]) / det,
                          (gi[..., 0] * hj - gj[..., 0] * hi) / det], axis=-1)
        else:
            idx, lam, _ = cert
            return np.all(_combine(lam, idx, h) >= -tol, axis=1)
        V = G @ np.swapaxes(Z, 1, 2)                      # (B, K, candidates)
        V -= h[:, :, None]
        return np.any(V.max(axis=1) <= tol, axis=1)


def _combine(lam: np.ndarray, idx: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """``sum_k lam[k] * rows[:, idx[:, k]]`` for rows (B, K) -> (B, S) or (B, K, n) ->
    (B, S, n)."""
    extra = (None,) * (rows.ndim - 2)
    out = lam[0][(...,) + extra] * rows[:, idx[:, 0]]
    for k in range(1, lam.shape[0]):
        out += lam[k][(...,) + extra] * rows[:, idx[:, k]]
    return out


@dataclass(frozen=True)
class AvailableWrenchSet:
    """H-representation ``{w : H w <= h}`` of the AWS at B poses (FASTKIT eq. 24).

    Attributes
    ----------
    poses : (B, 6)
    H : (B, S, n)
        Unit-norm rows (zero rows for unused certificates), w in (N, N m).
    h : (B, S)
        Offsets (``+inf`` for unused rows).
    full_rank : (B,) bool
        W has full row rank (otherwise the set is lower-dimensional and ``H`` is unused).
    nonempty : (B,) bool
        False when no tensions satisfy the tension and tipping limits at all.
    tipping : bool
    gravity_wrench : (B, n)
        ``w_e`` of platform and payload weight at each pose.
    """

    poses: np.ndarray
    H: np.ndarray
    h: np.ndarray
    full_rank: np.ndarray
    nonempty: np.ndarray
    tipping: bool
    gravity_wrench: np.ndarray

    def contains(self, wrench: Any, tol: float = 1e-9) -> np.ndarray:
        """Whether cable wrenches ``wrench`` ((n,) or (B, n)) lie in the AWS -> (B,) bool."""
        w = np.broadcast_to(as_array(wrench, "wrench"), self.H.shape[::2])
        ok = np.all(np.einsum("bsn,bn->bs", self.H, w) <= self.h + tol, axis=1)
        return ok & self.full_rank & self.nonempty

    def facets(self, k: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """Distinct rows ``(H, h)`` of pose ``k`` (redundant rows may remain)."""
        keep = np.isfinite(self.h[k])
        Hk, hk = self.H[k][keep], self.h[k][keep]
        _, first = np.unique(np.round(np.column_stack([Hk, hk]), 9), axis=0,
                             return_index=True)
        first.sort()
        return Hk[first], hk[first]


def _prepare(robot: CableRobot, poses: Any, tipping: bool):
    P = as_poses(robot, poses)
    st = cable_state(robot, P, validated=True)
    pinv, N, ok = svd_split(st.W)
    A, b = constraints(robot, st, bool(tipping and robot.has_tipping))
    return P, st, pinv, N, ok, A, b


def available_wrench_set(robot: CableRobot, poses: Any, tipping: bool = True
                         ) -> AvailableWrenchSet:
    """Exact H-representation of the available wrench set (FASTKIT eq. 24) at poses.

    Parameters
    ----------
    robot : CableRobot
    poses : array_like (6,), (3,), (B, 6) or (B, 3)
        Platform poses, m and rad.
    tipping : bool
        Include the tipping constraints of the mobile bases (eqs. 21-23); ignored for
        fixed frames. Without them the set is the classical tension-limited AWS.

    Returns
    -------
    AvailableWrenchSet
        Set of cable wrenches ``W t`` (forces N, moments N m about P, world frame).
    """
    P = as_poses(robot, poses)
    parts = [_aws_block(robot, P[i:i + 256], tipping) for i in range(0, P.shape[0], 256)]
    H, h, ok, nonempty, wg = (np.concatenate(x) for x in zip(*parts))
    return AvailableWrenchSet(P, H, h, ok, nonempty, bool(tipping and robot.has_tipping), wg)


def _aws_block(robot: CableRobot, P: np.ndarray, tipping: bool):
    P, st, pinv, N, ok, A, b = _prepare(robot, P, tipping)
    G = np.einsum("bkm,bmr->bkr", A, N)
    idx, lam, valid = _certificates(G)
    AW = np.einsum("bkm,bmn->bkn", A, pinv)                   # (B, K, n)
    H = _combine(lam, idx, AW)
    h = _combine(lam, idx, b)
    nrm = np.linalg.norm(H, axis=2)
    tol = feas_tol(robot)
    scale = 1.0 + np.abs(AW).max(axis=(1, 2))[:, None]
    flat = nrm <= 1e-12 * scale
    nonempty = ~np.any(valid & flat & (h < -tol), axis=1)
    use = valid & ~flat
    H = np.where(use[..., None], H / np.where(use, nrm, 1.0)[..., None], 0.0)
    h = np.where(use, h / np.where(use, nrm, 1.0), np.inf)
    return H, h, ok, nonempty, gravity_wrench(robot, st.R)


def disturbance_box(robot: CableRobot, half_widths: Any) -> np.ndarray:
    """Vertices (2^n, n) of a box of extra external wrenches ``|w_k| <= half_widths[k]``
    (N, N m); zero half-widths collapse (duplicate vertices are removed)."""
    hw = as_array(half_widths, "disturbance",
                  shape=(require_instance(robot, CableRobot, "robot").dof,))
    if np.any(hw < 0):
        raise InvalidInputError("disturbance", "half-widths must be non-negative")
    V = np.array(list(product(*[(-x, x) if x > 0 else (0.0,) for x in hw])))
    return V.reshape(-1, robot.dof)


def wrench_feasible(robot: CableRobot, poses: Any, *, tipping: bool = True,
                    disturbance: Any = None, chunk: int = 256) -> np.ndarray:
    """Wrench feasibility (FASTKIT §4) of a batch of poses: can the cables hold platform
    and payload weight plus every extra wrench of ``disturbance`` within tension limits
    (eq. 20) and, if ``tipping``, without tipping a mobile base (eqs. 21-23)?

    Exact and vectorised (no LP): with ``r = m - n <= 2`` redundant cables the polygon of
    null-space coordinates ``z`` is tested for a feasible vertex; otherwise the Farkas
    certificates of the module docstring are checked.

    Parameters
    ----------
    poses : array_like (B, 6) or (B, 3), m and rad
    tipping : bool
    disturbance : array_like (V, n), optional
        Extra external wrenches (vertices of a convex set, e.g. :func:`disturbance_box`).
    chunk : int
        Poses per vectorised block (memory ~ chunk * 60 kB with tipping; 256 is
        fastest here).

    Returns
    -------
    ndarray (B,) of bool
    """
    P = as_poses(robot, poses)
    chunk = as_count(chunk, "chunk", minimum=1)
    D = np.zeros((1, robot.dof)) if disturbance is None else \
        as_array(disturbance, "disturbance", shape=(None, robot.dof))
    out = np.empty(P.shape[0], dtype=bool)
    tol = feas_tol(robot)
    for s0 in range(0, P.shape[0], chunk):
        sl = slice(s0, s0 + chunk)
        st = cable_state(robot, P[sl], validated=True)
        pinv, N, ok = svd_split(st.W)
        A, b = constraints(robot, st, bool(tipping and robot.has_tipping))
        G = np.einsum("bkm,bmr->bkr", A, N)
        cert = _certificates(G) if N.shape[2] > 2 else None
        good = ok.copy()
        wreq = required_wrench(robot, st)
        for d in D:                                   # few vertices: loop, poses batched
            tp = np.einsum("bmn,bn->bm", pinv, wreq - d)
            slack = b - np.einsum("bkm,bm->bk", A, tp)                    # (B, K)
            good &= _nonempty(G, slack, 4 * tol, cert)
        out[sl] = good
    return out


@dataclass(frozen=True)
class AxisCapacities:
    """Largest extra external wrench along each axis the platform can resist on top of its
    weight (FASTKIT Fig. 14), per pose.

    Attributes
    ----------
    positive, negative : (B, n)
        Magnitudes along ``+axis`` and ``-axis`` (N for forces, N m for moments); 0 where
        even no extra wrench can be held.
    feasible : (B, n, 2) bool
        Whether some non-negative magnitude is feasible along (+, -) of each axis.
    labels : tuple of str
    tipping : bool
    """

    positive: np.ndarray
    negative: np.ndarray
    feasible: np.ndarray
    labels: tuple[str, ...]
    tipping: bool


def axis_capacities(robot: CableRobot, poses: Any, tipping: bool = True,
                    method: str = "hrep") -> AxisCapacities:
    """Axis capacities ``max s >= 0`` with ``W t + w_e + s e = 0`` (eq. 17) inside the tension
    limits (eq. 20) and, if ``tipping``, the tipping limits (eqs. 21-23), for ``e`` each of
    ``+-x, +-y, +-z`` forces and (6-DoF) moments about P.

    ``method="hrep"`` reads them off the exact AWS (batched); ``"lp"`` solves one HiGHS LP
    per pose and direction (reference).
    """
    if method not in ("hrep", "lp"):
        raise InvalidInputError("method", "must be 'hrep' or 'lp'")
    n = require_instance(robot, CableRobot, "robot").dof
    labels = AXIS_LABELS[:n]
    if method == "lp":
        return _axis_lp(robot, poses, tipping, labels)
    aws = available_wrench_set(robot, poses, tipping)
    B = aws.H.shape[0]
    wg = aws.gravity_wrench
    slack = aws.h + np.einsum("bsn,bn->bs", aws.H, wg)   # rows: -s H e <= h + H w_g
    pos = np.zeros((B, n))
    neg = np.zeros((B, n))
    feas = np.zeros((B, n, 2), dtype=bool)
    tol = feas_tol(robot)
    for k in range(n):
        for sgn, out, col in ((1.0, pos, 0), (-1.0, neg, 1)):
            c = -sgn * aws.H[:, :, k]
            with np.errstate(divide="ignore", invalid="ignore"):
                ratio = slack / c
            hi = np.min(np.where(c > 1e-12, ratio, np.inf), axis=1)
            lo = np.max(np.where(c < -1e-12, ratio, -np.inf), axis=1)
            zero_ok = np.all((np.abs(c) > 1e-12) | (slack >= -tol), axis=1)
            f = (hi >= np.maximum(lo, 0.0) - tol) & zero_ok & aws.full_rank & aws.nonempty
            out[:, k] = np.where(f, np.maximum(hi, 0.0), 0.0)
            feas[:, k, col] = f
    return AxisCapacities(pos, neg, feas, labels, aws.tipping)


def _axis_lp(robot: CableRobot, poses: Any, tipping: bool, labels) -> AxisCapacities:
    P, st, pinv, N, ok, A, b = _prepare(robot, poses, tipping)
    B, n, m = st.W.shape
    wg = gravity_wrench(robot, st.R)
    pos = np.zeros((B, n))
    neg = np.zeros((B, n))
    feas = np.zeros((B, n, 2), dtype=bool)
    bounds = list(zip(robot.t_min, robot.t_max)) + [(0.0, None)]
    for i in range(B):
        extra = A[i, 2 * m:]
        Aub = np.hstack([extra, np.zeros((extra.shape[0], 1))]) if extra.shape[0] else None
        bub = b[i, 2 * m:] if extra.shape[0] else None
        for k in range(n):
            for sgn, out, col in ((1.0, pos, 0), (-1.0, neg, 1)):
                e = np.zeros(n)
                e[k] = sgn
                c = np.zeros(m + 1)
                c[-1] = -1.0
                sol = linprog(c, A_ub=Aub, b_ub=bub, A_eq=np.hstack([st.W[i], e[:, None]]),
                              b_eq=-wg[i], bounds=bounds, method="highs")
                if sol.status == 0:
                    out[i, k] = sol.x[-1]
                    feas[i, k, col] = True
    return AxisCapacities(pos, neg, feas, labels, bool(tipping and robot.has_tipping))


def capacity_margin(robot: CableRobot, poses: Any, disturbance: Any = None,
                    tipping: bool = True) -> np.ndarray:
    """Capacity margin of the required wrench set at poses, (B,).

    The required set is platform and payload weight plus the extra external wrenches
    ``disturbance`` (V, n) (vertices of a convex set, default none). The margin is
    ``min_facets (h_k - max_v H_k w_v)`` over the unit-normal facets of the AWS: the
    distance (in mixed N / N m units) from the required set to the AWS boundary when
    positive; negative when some required wrench is not available. ``-inf`` at singular
    poses or when the AWS is empty.
    """
    aws = available_wrench_set(robot, poses, tipping)
    D = np.zeros((1, robot.dof)) if disturbance is None else \
        as_array(disturbance, "disturbance", shape=(None, robot.dof))
    w = -(aws.gravity_wrench[:, None, :] + D[None, :, :])        # required cable wrenches
    hw = np.einsum("bsn,bvn->bsv", aws.H, w).max(axis=2)
    margin = np.min(aws.h - hw, axis=1)
    return np.where(aws.full_rank & aws.nonempty, margin, -np.inf)
