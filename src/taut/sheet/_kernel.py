"""Numerical core of VVCM forward kinematics, batched over candidate taut sets.

Notation (FK paper, Sec. III; DESIGN.md Sec. 1). Robots :math:`\\mathbf{r}_i`, sheet
vertices :math:`\\mathbf{v}_i`, unknowns :math:`x = (\\mathbf{r}_o, \\mathbf{v}_o)`. The
feasibility of cable ``i`` (eq. 1) reads :math:`g_i(x) + q(x) + d^2 \\le 0` with

* :math:`q(x) = |\\mathbf{r}_o|^2 - |\\mathbf{v}_o|^2` (Hessian ``diag(2, 2, -2, -2)``, eq. 8),
* :math:`g_i(x) = \\mathbf{a}_i \\cdot x + b_i`, :math:`\\mathbf{a}_i = (-2\\mathbf{r}_i, 2\\mathbf{v}_i)`,
  :math:`b_i = |\\mathbf{r}_i|^2 - |\\mathbf{v}_i|^2`,

so the lowest object for a given ``x`` has depth :math:`d^2 = -(q + \\max_i g_i)`. For a
candidate set ``S`` the paper's Lagrange system (eqs. 10-14) is solved here in its
equivalent *weight* form: the stationary point of ``q`` on ``{g_i equal, i in S}`` satisfies
:math:`\\mathbf{r}_o = \\sum w_i \\mathbf{r}_i`, :math:`\\mathbf{v}_o = \\sum w_i \\mathbf{v}_i`,
:math:`\\sum w_i = 1` and

.. math:: \\begin{bmatrix} G & \\mathbf{1} \\\\ \\mathbf{1}^T & 0 \\end{bmatrix}
          \\begin{bmatrix} w \\\\ \\mu \\end{bmatrix} =
          \\begin{bmatrix} b_S \\\\ 1 \\end{bmatrix}, \\qquad
          G_{ij} = 2(\\mathbf{r}_i\\cdot\\mathbf{r}_j - \\mathbf{v}_i\\cdot\\mathbf{v}_j),

where :math:`\\mu` is the common value of :math:`g_i` on ``S``. The paper's multipliers
are :math:`\\lambda_j = -w_j` (``j != i_1``). The weights are exactly the normalised
vertical tension shares (FK paper eq. 16), which makes force closure an exact test:
``w >= 0`` (DESIGN.md Sec. 3).

All work is done in a normalised frame (formation and sheet centred, lengths divided by
the sheet size), so every tolerance below is relative to the sheet size.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Cable ``j`` counts as taut when :math:`L_j^2 - l_j^2 \\ge -` this (in sheet-size^2 units).
TAUT_TOL = 1e-9
#: Weights above ``-WEIGHT_TOL`` count as non-negative (weights are dimensionless, sum 1).
WEIGHT_TOL = 1e-9
#: Reduced-Hessian eigenvalues above this count as positive (dimensionless).
CURVATURE_TOL = 1e-9
#: Relative determinant below which a candidate's Lagrange system counts as singular.
SINGULAR_RTOL = 1e-11
#: Angular slack (radians) of the paper's projection test.
ANGLE_TOL = 1e-9

STATUS_STABLE, STATUS_SADDLE, STATUS_NOT_EQUILIBRIUM = 0, 1, 2
STATUS_NAMES = ("stable", "saddle", "not_equilibrium")

# Reduced Hessian of q, up to the factor 2 (does not change signs).
_H = np.array([1.0, 1.0, -1.0, -1.0])


@dataclass(frozen=True)
class Frame:
    """Formations and sheet in normalised coordinates.

    ``R`` (B, N, 2) robots, ``V`` (N, 2) vertices, ``z`` hold height, all divided by
    ``scale``; ``r_centre`` (B, 2) and ``v_centre`` (2,) were subtracted before scaling.
    ``P`` (B, N, 5) are the lifted points :math:`(\\mathbf{a}_i, b_i)` and ``b`` (B, N).
    """

    R: np.ndarray
    V: np.ndarray
    z: float
    r_centre: np.ndarray
    v_centre: np.ndarray
    scale: float
    b: np.ndarray
    P: np.ndarray

    @classmethod
    def build(cls, vertices: np.ndarray, formations: np.ndarray, hold_height: float,
              scale: float) -> "Frame":
        v_centre = vertices.mean(axis=0)
        r_centre = formations.mean(axis=1)
        V = (vertices - v_centre) / scale
        R = (formations - r_centre[:, None, :]) / scale
        b = np.einsum("bnk,bnk->bn", R, R) - np.einsum("nk,nk->n", V, V)[None, :]
        B, N = b.shape
        P = np.empty((B, N, 5))
        P[..., :2] = -2.0 * R
        P[..., 2:4] = 2.0 * V
        P[..., 4] = b
        return cls(R, V, hold_height / scale, r_centre, v_centre, scale, b, P)


@dataclass
class Solved:
    """Stationary points of candidate sets (flat over all candidates of all sizes).

    ``form`` (M,) formation index; ``subset`` (M, 5) robot indices padded with -1;
    ``size`` (M,); ``w`` (M, 5) weights padded with 0; ``mu`` (M,); ``ro``, ``vo`` (M, 2);
    ``depth2`` (M,) normalised :math:`d^2`; ``source`` (M,) position of the candidate in
    its size group's input.
    """

    form: np.ndarray
    subset: np.ndarray
    size: np.ndarray
    w: np.ndarray
    mu: np.ndarray
    ro: np.ndarray
    vo: np.ndarray
    depth2: np.ndarray
    source: np.ndarray

    FIELDS = ("form", "subset", "size", "w", "mu", "ro", "vo", "depth2", "source")

    def take(self, keep: np.ndarray) -> "Solved":
        return Solved(*(getattr(self, f)[keep] for f in self.FIELDS))

    @classmethod
    def concat(cls, parts: list["Solved"]) -> "Solved":
        if not parts:
            z2 = np.zeros((0, 2))
            return cls(np.zeros(0, np.intp), np.zeros((0, 5), np.intp), np.zeros(0, np.intp),
                       np.zeros((0, 5)), np.zeros(0), z2, z2.copy(), np.zeros(0),
                       np.zeros(0, np.intp))
        return cls(*(np.concatenate([getattr(p, f) for p in parts]) for f in cls.FIELDS))


def solve_candidates(frame: Frame, groups: dict[int, tuple[np.ndarray, np.ndarray]]) -> Solved:
    """Solve the Lagrange system for every candidate set, in one batched call.

    Parameters
    ----------
    groups : dict
        ``size -> (form (M_s,), subset (M_s, size))``; sizes 2..5. Each system is padded
        to 6 x 6 (identity rows for unused slots) so that all sizes share one LAPACK call.

    Candidates whose system is singular (affinely dependent lifted points, or a degenerate
    reduced Hessian where the paper's Lemma 1 fails) are dropped: an affinely independent
    subset spanning the same face is always among the candidates as well.
    """
    forms, idxs, sizes, sources = [], [], [], []
    for s, (form, idx) in sorted(groups.items()):
        if len(form) == 0:
            continue
        pad = np.full((len(form), 5), -1, dtype=np.intp)
        pad[:, :s] = idx
        forms.append(form)
        idxs.append(pad)
        sizes.append(np.full(len(form), s, dtype=np.intp))
        sources.append(np.arange(len(form), dtype=np.intp))
    if not forms:
        return Solved.concat([])
    form = np.concatenate(forms)
    idx = np.vstack(idxs)
    size = np.concatenate(sizes)
    source = np.concatenate(sources)
    valid = idx >= 0
    ii = np.where(valid, idx, 0)
    Rs = frame.R[form[:, None], ii] * valid[..., None]          # (M, 5, 2), 0 when unused
    Vs = frame.V[ii] * valid[..., None]
    K = np.zeros((len(form), 6, 6))
    K[:, :5, :5] = 2.0 * (Rs @ Rs.transpose(0, 2, 1) - Vs @ Vs.transpose(0, 2, 1))
    K[:, :5, 5] = valid
    K[:, 5, :5] = valid
    diag = np.arange(5)
    K[:, diag, diag] += ~valid
    rhs = np.zeros((len(form), 6))
    rhs[:, :5] = np.where(valid, frame.b[form[:, None], ii], 0.0)
    rhs[:, 5] = 1.0
    det = np.linalg.det(K)
    ok = np.abs(det) > SINGULAR_RTOL * np.prod(np.linalg.norm(K, axis=2), axis=1)
    if not np.all(ok):
        form, idx, size, source = form[ok], idx[ok], size[ok], source[ok]
        Rs, Vs, K, rhs = Rs[ok], Vs[ok], K[ok], rhs[ok]
    sol = np.linalg.solve(K, rhs[..., None])[..., 0]
    w = sol[:, :5]
    mu = sol[:, 5]
    ro = np.einsum("ms,msk->mk", w, Rs)
    vo = np.einsum("ms,msk->mk", w, Vs)
    depth2 = -(np.einsum("mk,mk->m", ro, ro) - np.einsum("mk,mk->m", vo, vo) + mu)
    return Solved(form, idx, size, w, mu, ro, vo, depth2, source)


def height_ok(frame: Frame, solved: Solved) -> np.ndarray:
    """FK paper eq. 15 and its side conditions: :math:`f(x) < 0` (a real depth) and
    :math:`0 < z_o < z_r` (the object above the ground)."""
    d2 = solved.depth2
    return (d2 > TAUT_TOL) & (np.sqrt(np.maximum(d2, 0.0)) < frame.z)


def taut_masks(frame: Frame, solved: Solved, chunk: int = 1 << 22) -> tuple[np.ndarray, np.ndarray]:
    """Maximiser sets of the pieces at each solution.

    Returns
    -------
    ok : ndarray of bool, shape (M,)
        The candidate's pieces attain the maximum (no other cable would be over-stretched:
        FK paper eq. 1 holds for every cable).
    taut : ndarray of bool, shape (M, N)
        Cables whose :math:`g_j` is within ``TAUT_TOL`` of the maximum (the exact taut set).
    """
    M = len(solved.form)
    N = frame.R.shape[1]
    ok = np.zeros(M, dtype=bool)
    taut = np.zeros((M, N), dtype=bool)
    step = max(1, chunk // max(N, 1))
    for start in range(0, M, step):
        sl = slice(start, min(M, start + step))
        f = solved.form[sl]
        g = (-2.0 * np.einsum("mnk,mk->mn", frame.R[f], solved.ro[sl])
             + 2.0 * (solved.vo[sl] @ frame.V.T) + frame.b[f])
        excess = g - solved.mu[sl, None]
        ok[sl] = excess.max(axis=1) <= TAUT_TOL
        taut[sl] = excess >= -TAUT_TOL
    return ok, taut


def in_hull_2d(points: np.ndarray, valid: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Whether ``p`` (M, 2) lies in the convex hull of ``points`` (M, m, 2) where ``valid``.

    The point is inside (or on the boundary) iff the directions from it to the points
    leave no angular gap larger than pi. This is the FK paper's force-closure test
    (Sec. III-A.3: the projection :math:`\\mathbf{r}_o` inside the taut robots' polygon).
    """
    d = points - p[:, None, :]
    dist = np.linalg.norm(d, axis=2)
    scale = np.max(np.where(valid, dist, 0.0), axis=1, initial=0.0)
    coincide = np.any(valid & (dist <= 1e-12 * np.maximum(scale, 1.0)[:, None]), axis=1)
    ang = np.arctan2(d[..., 1], d[..., 0])
    first = np.argmax(valid, axis=1)
    ang = np.where(valid, ang, ang[np.arange(len(p)), first][:, None])
    ang = np.sort(ang, axis=1)
    gaps = np.diff(ang, axis=1)
    wrap = 2 * np.pi - (ang[:, -1] - ang[:, 0])
    max_gap = np.maximum(gaps.max(axis=1, initial=0.0), wrap)
    return coincide | (max_gap <= np.pi + ANGLE_TOL)


def reduced_hessian_min_eig(frame: Frame, form: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """Smallest eigenvalue of the Hessian of ``q`` restricted to the face's tangent space.

    The tangent space is the null space of the differences :math:`\\mathbf{a}_i -
    \\mathbf{a}_{i_1}` over the affinely independent set ``idx`` (M, s). For ``s = 5`` the
    face is a vertex of the arrangement and the result is ``+inf`` (DESIGN.md Sec. 5).
    """
    M, s = idx.shape
    if s >= 5 or M == 0:
        return np.full(M, np.inf)
    A = frame.P[form[:, None], idx, :4]                  # (M, s, 4)
    D = A[:, 1:, :] - A[:, :1, :]
    _, _, vt = np.linalg.svd(D, full_matrices=True)
    Z = vt[:, s - 1:, :]                                  # (M, 5-s, 4) orthonormal rows
    Hr = np.einsum("mik,k,mjk->mij", Z, _H, Z)
    return np.linalg.eigvalsh(Hr)[:, 0]
