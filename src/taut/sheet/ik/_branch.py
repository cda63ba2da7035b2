"""Branch-and-bound proof that no all-taut formation balances a target
(docs/sheet_kinematics.md §6, planning paper eq. 10).

Normalised frame of a target as in :mod:`taut.sheet.ik._certificate`: robot ``k`` stands at
:math:`\\rho_k \\mathbf{u}(\\theta_k)`, the weights :math:`w` lie in the polytope :math:`W`,
the closure :math:`\\sum_k w_k \\rho_k \\mathbf{u}(\\theta_k) = 0` must hold and every pair
must keep the circular angle distance :math:`|\\theta_i - \\theta_k| \\le \\alpha_{ik} =
\\arccos c_{ik}` (the pairwise sheet limit).

**Frame relaxation.** Seen from cable ``i`` (rotate so that :math:`\\theta_i = 0`), cable
``k`` points at :math:`\\delta = \\theta_k - \\theta_i` in a known arc :math:`A_{ik}`. For any
:math:`\\lambda_i \\in R^2` the closure gives :math:`0 = \\lambda_i \\cdot \\sum_k a_k
\\mathbf{u}(\\delta_k) \\ge \\sum_k a_k s_{ik}(\\lambda_i)` with :math:`s_{ik}(\\lambda) =
\\min_{\\delta \\in A_{ik}} \\lambda \\cdot \\mathbf{u}(\\delta)` (closed form) and
:math:`s_{ii}(\\lambda) = \\lambda_x`. Summed over the frames and combined with
:math:`\\mu \\cdot \\sum_k w_k \\mathbf{v}_k = 0`: if

.. math:: g_k = \\rho_k \\sum_i s_{ik}(\\lambda_i) + \\mu \\cdot \\mathbf{v}_k > 0
          \\quad \\text{for every } k,

then :math:`\\sum_k w_k g_k \\le 0` contradicts :math:`w \\ge 0, \\sum w = 1`: no formation
has its angles in those arcs. The multipliers come from an LP in which every arc is replaced
by a polygon containing it (tangents and chord), so the exact :math:`s_{ik}` the check uses
are only larger.

**Branching.** With the angles measured from a reference cable ``r`` (:math:`\\theta_r =
0`, any formation can be turned so), a box gives every other :math:`\\theta_k` an interval;
the arc of pair ``(i, k)`` is the interval of :math:`\\theta_k - \\theta_i` cut by the pair
limit (empty: the box is refuted by that pair alone). Boxes the relaxation does not refute
are halved along their widest side. The proof is the tree of splits with one refutation per
leaf, re-checked by :func:`verify_branch_proof` (which walks the tree from the root box, so
the leaves cover every formation by construction).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Union

import numpy as np
from scipy.optimize import linprog

from .._tol import CERTIFICATE_MIN_MARGIN, RELAX_COS_SLACK

__all__ = ["BranchProof", "branch_proof", "verify_branch_proof", "pair_angle_limits",
           "pair_cosine_limits"]

_TWO_PI = 2.0 * np.pi

#: A preorder tree: ("split", k, mid) | ("pair", i, k) | ("lp", lam (N, 2), mu (2,)).
Node = Union[tuple[str, int, float], tuple[str, int, int], tuple[str, np.ndarray, np.ndarray]]
Box = list[tuple[float, float]]
Arcs = list[list[tuple[float, float]]]


@dataclass(frozen=True, eq=False)
class BranchProof:
    """A refutation tree: reference cable, preorder nodes, number of boxes examined."""

    reference: int
    nodes: tuple[Node, ...]
    boxes: int


def pair_cosine_limits(V: np.ndarray, rho: np.ndarray) -> np.ndarray:
    """c_ij (N, N): the smallest admissible cos(theta_i - theta_j); +inf on the diagonal
    is replaced by 1 (a robot is at distance 0 from itself)."""
    D2 = np.sum((V[:, None, :] - V[None, :, :]) ** 2, axis=2)
    with np.errstate(divide="ignore", invalid="ignore"):
        c = (rho[:, None] ** 2 + rho[None, :] ** 2 - D2) / (2 * rho[:, None] * rho[None, :])
    c = np.where(np.isfinite(c), c, -1.0)
    np.fill_diagonal(c, 1.0)
    return c


def pair_angle_limits(V: np.ndarray, rho: np.ndarray) -> np.ndarray:
    """:math:`\\alpha_{ik}` (N, N), radians in [0, pi]: the largest admissible circular
    angle between cables i and k, from the cosine limits loosened by RELAX_COS_SLACK
    (0 on the diagonal)."""
    c = pair_cosine_limits(V, rho) - RELAX_COS_SLACK
    alpha = np.arccos(np.clip(c, -1.0, 1.0))
    np.fill_diagonal(alpha, 0.0)
    return np.asarray(alpha)


def _cut(lo: float, hi: float, alpha: float) -> tuple[float, float] | None:
    """Arc containing every x in [lo, hi] with circular |x| <= alpha; None if none."""
    if alpha >= np.pi:
        return (lo, hi)                                   # no limit (full when >= 2 pi)
    pieces = []
    for n in range(-2, 3):
        a, b = max(lo, n * _TWO_PI - alpha), min(hi, n * _TWO_PI + alpha)
        if a <= b:
            pieces.append((a - n * _TWO_PI, b - n * _TWO_PI))
    if not pieces:
        return None
    return (min(p[0] for p in pieces), max(p[1] for p in pieces))


def _node_arcs(box: Box, alpha: np.ndarray) -> Arcs | tuple[int, int]:
    """Arcs A_ik of a box (theta_k in box[k]), or the pair (i, k) that refutes it."""
    N = len(box)
    arcs = [[(0.0, 0.0)] * N for _ in range(N)]
    for i in range(N):
        for k in range(N):
            if i != k:
                a = _cut(box[k][0] - box[i][1], box[k][1] - box[i][0], float(alpha[i, k]))
                if a is None:
                    return (i, k)
                arcs[i][k] = a
    return arcs


def _arc_min(lam: np.ndarray, lo: float, hi: float) -> float:
    """min over delta in [lo, hi] of lam . u(delta) (exact)."""
    n = float(np.hypot(lam[0], lam[1]))
    if n == 0.0:
        return 0.0
    away = np.arctan2(lam[1], lam[0]) + np.pi           # direction where lam . u = -|lam|
    if hi - lo >= _TWO_PI or (away - lo) % _TWO_PI <= hi - lo:
        return -n
    return float(min(lam[0] * np.cos(lo) + lam[1] * np.sin(lo),
                     lam[0] * np.cos(hi) + lam[1] * np.sin(hi)))


def _separation(V: np.ndarray, rho: np.ndarray, arcs: Arcs, lam: np.ndarray,
                mu: np.ndarray) -> float:
    """min_k g_k of the module docstring with the exact arc minima."""
    N = len(rho)
    g = [rho[k] * (lam[k][0] + sum(_arc_min(lam[i], *arcs[i][k]) for i in range(N) if i != k))
         + float(mu @ V[k]) for k in range(N)]
    return float(min(g))


def _polygon(lo: float, hi: float) -> tuple[np.ndarray, np.ndarray]:
    """(G, h): a polygon {x : G x <= h} containing the arc [lo, hi] of the unit circle."""
    width = hi - lo
    if width >= _TWO_PI:
        phis = np.linspace(0.0, _TWO_PI, 13)[:-1]
        return np.column_stack([np.cos(phis), np.sin(phis)]), np.ones(12)
    phis = np.linspace(lo, hi, max(2, int(np.ceil(width / (np.pi / 6)))) + 1)
    mid = 0.5 * (lo + hi)
    G = np.vstack([np.column_stack([np.cos(phis), np.sin(phis)]),
                   [[-np.cos(mid), -np.sin(mid)]]])
    return G, np.concatenate([np.ones(len(phis)), [-np.cos(0.5 * width)]])


def _multipliers(V: np.ndarray, rho: np.ndarray, arcs: Arcs
                 ) -> tuple[float, np.ndarray, np.ndarray]:
    """LP: maximise t subject to g_k >= t with polygon arcs, |lam| <= 1 componentwise.

    Variables: lam (2N), mu (2), t, and per arc (i, k) the dual weights nu of its polygon
    plus sigma_ik <= min over the polygon of lam_i . x = max{-h.nu : G^T nu = -lam_i}."""
    N = len(rho)
    polys = [(i, k, *_polygon(*arcs[i][k])) for i in range(N) for k in range(N) if i != k]
    offsets = np.cumsum([2 * N + 3] + [len(h) + 1 for *_, h in polys])
    nvar = int(offsets[-1])
    A_eq = np.zeros((2 * len(polys), nvar))
    A_ub = np.zeros((len(polys) + N, nvar))
    for p, ((i, k, G, h), off) in enumerate(zip(polys, offsets[:-1])):
        m = len(h)
        A_eq[2 * p:2 * p + 2, off:off + m] = G.T
        A_eq[2 * p, 2 * i] = A_eq[2 * p + 1, 2 * i + 1] = 1.0
        A_ub[p, off:off + m] = h
        A_ub[p, off + m] = 1.0
        A_ub[len(polys) + k, off + m] = -rho[k]
    for k in range(N):
        row = A_ub[len(polys) + k]
        row[2 * k] = -rho[k]
        row[2 * N:2 * N + 2] = -V[k]
        row[2 * N + 2] = 1.0
    cost = np.zeros(nvar)
    cost[2 * N + 2] = -1.0
    bounds: list[tuple[float | None, float | None]] = (
        [(-1.0, 1.0)] * (2 * N) + [(None, None)] * 2 + [(None, 1.0)])
    for *_, h in polys:
        bounds += [(0.0, None)] * len(h) + [(None, None)]
    lp = linprog(cost, A_ub=A_ub, b_ub=np.zeros(len(A_ub)), A_eq=A_eq,
                 b_eq=np.zeros(len(A_eq)), bounds=bounds, method="highs")
    if not lp.success:                                   # pragma: no cover - defensive
        return 0.0, np.zeros((N, 2)), np.zeros(2)
    return float(lp.x[2 * N + 2]), lp.x[:2 * N].reshape(N, 2).copy(), lp.x[2 * N:2 * N + 2]


def _root_box(alpha: np.ndarray, r: int) -> Box:
    return [(0.0, 0.0) if k == r else (-float(alpha[r, k]), float(alpha[r, k]))
            for k in range(len(alpha))]


def branch_proof(V: np.ndarray, rho: np.ndarray, *, max_boxes: int,
                 reference: int | None = None) -> BranchProof | None:
    """Search a refutation tree (module docstring) with at most ``max_boxes`` boxes.

    Parameters
    ----------
    V : ndarray, shape (N, 2)
        Sheet vertices relative to the contact, divided by the sheet size.
    rho : ndarray, shape (N,)
        Horizontal reaches (same unit), all real.
    max_boxes : int
        Budget; None is returned when it runs out (no claim either way).
    reference : int, optional
        Cable whose angle is fixed at 0; default the longest reach.

    Returns
    -------
    BranchProof or None
    """
    alpha = pair_angle_limits(V, rho)
    r = int(np.argmax(rho)) if reference is None else reference
    margin = CERTIFICATE_MIN_MARGIN * max(1.0, float(rho.max()))
    nodes: list[Node] = []
    stack: list[Box] = [_root_box(alpha, r)]
    boxes = 0
    while stack:
        box = stack.pop()
        boxes += 1
        if boxes > max_boxes:
            return None
        arcs = _node_arcs(box, alpha)
        if isinstance(arcs, tuple):
            nodes.append(("pair", arcs[0], arcs[1]))
            continue
        t, lam, mu = _multipliers(V, rho, arcs)
        if t > margin and _separation(V, rho, arcs, lam, mu) > margin:
            nodes.append(("lp", lam, mu))
            continue
        k = int(np.argmax([hi - lo for lo, hi in box]))
        lo, hi = box[k]
        mid = 0.5 * (lo + hi)
        nodes.append(("split", k, mid))
        right, left = list(box), list(box)
        left[k], right[k] = (lo, mid), (mid, hi)
        stack += [right, left]                         # left first: preorder
    return BranchProof(r, tuple(nodes), boxes)


def verify_branch_proof(proof: BranchProof, V: np.ndarray, rho: np.ndarray) -> bool:
    """Re-check a refutation tree from the target data alone: walk it from the root box,
    recompute every leaf's arcs and test its refutation with exact arc minima."""
    N = len(rho)
    if not (0 <= proof.reference < N) or not proof.nodes:
        return False
    alpha = pair_angle_limits(V, rho)
    stack: list[Box] = [_root_box(alpha, proof.reference)]
    for node in proof.nodes:
        if not stack:
            return False
        box = stack.pop()
        if node[0] == "split":
            k, mid = int(node[1]), float(node[2])
            lo, hi = box[k]
            if not (0 <= k < N and lo <= mid <= hi):
                return False
            left, right = list(box), list(box)
            left[k], right[k] = (lo, mid), (mid, hi)
            stack += [right, left]
            continue
        if node[0] not in ("pair", "lp"):
            return False
        arcs = _node_arcs(box, alpha)
        if isinstance(arcs, tuple):
            continue                                 # a pair refutes the box outright
        if node[0] == "pair":
            return False
        lam, mu = np.asarray(node[1], float), np.asarray(node[2], float)
        if lam.shape != (N, 2) or mu.shape != (2,) or not (
                _separation(V, rho, arcs, lam, mu) > 0.0):
            return False
    return not stack

