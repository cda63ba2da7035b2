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
#: Relative determinant (|det K| / prod of row norms) below which a candidate's Lagrange
#: system is checked for singularity by its condition number.
SINGULAR_RTOL = 1e-10
#: Condition number above which a Lagrange system counts as singular (affinely dependent
#: lifted points give ~1e16; valid but ill-conditioned systems seen up to ~1e8).
MAX_CONDITION = 1e12
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
    ``gram`` (B, N, N) is :math:`G_{ij} = 2(\\mathbf{r}_i\\cdot\\mathbf{r}_j -
    \\mathbf{v}_i\\cdot\\mathbf{v}_j)`.
    """

    R: np.ndarray
    V: np.ndarray
    z: float
    r_centre: np.ndarray
    v_centre: np.ndarray
    scale: float
    b: np.ndarray
    P: np.ndarray
    gram: np.ndarray

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
        gram = 2.0 * (R @ R.transpose(0, 2, 1) - (V @ V.T)[None])
        return cls(R, V, hold_height / scale, r_centre, v_centre, scale, b, P, gram)


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


def pad_groups(groups: dict[int, tuple[np.ndarray, np.ndarray]]
               ) -> tuple[np.ndarray, np.ndarray]:
    """Concatenate ``size -> (form, subset (M_s, size))`` groups (ascending size) into
    ``form`` (M,) and ``subset`` (M, 5) padded with -1."""
    forms, idxs = [], []
    for s, (form, idx) in sorted(groups.items()):
        pad = np.full((len(form), 5), -1, dtype=np.intp)
        pad[:, :s] = idx
        forms.append(form)
        idxs.append(pad)
    if not forms:
        return np.zeros(0, np.intp), np.zeros((0, 5), np.intp)
    return np.concatenate(forms), np.vstack(idxs)


def solve_candidates(frame: Frame, form: np.ndarray, idx: np.ndarray, *,
                     independent: bool = False) -> Solved:
    """Solve the Lagrange system for every candidate set, in one batched call.

    Parameters
    ----------
    form : ndarray of int, shape (M,)
        Formation index of each candidate.
    idx : ndarray of int, shape (M, 5)
        Robot indices of each candidate set (2..5 of them), padded with -1. Each system
        is padded to 6 x 6 (identity rows for unused slots) so that all sizes share one
        LAPACK call.
    independent : bool
        The caller guarantees that every candidate's lifted points are affinely
        independent (faces of a non-degenerate triangulated hull). The determinant test is
        then skipped; a system that is still singular (Lemma 1 failing) shows up as a
        LAPACK error or a non-finite/huge solution and is dropped.

    Returns
    -------
    Solved
        ``source`` holds each solution's row in the input.

    Candidates whose system is singular (affinely dependent lifted points, or a degenerate
    reduced Hessian where the paper's Lemma 1 fails) are dropped: an affinely independent
    subset spanning the same face is always among the candidates as well.
    """
    if len(form) == 0:
        return Solved.concat([])
    source = np.arange(len(form))
    valid = idx >= 0
    size = valid.sum(axis=1)
    ii = np.where(valid, idx, 0)
    Rs = frame.R[form[:, None], ii] * valid[..., None]          # (M, 5, 2), 0 when unused
    Vs = frame.V[ii] * valid[..., None]
    K = np.zeros((len(form), 6, 6))
    K[:, :5, :5] = frame.gram[form[:, None, None], ii[:, :, None], ii[:, None, :]]
    K[:, :5, :5] *= valid[:, :, None] & valid[:, None, :]
    K[:, :5, 5] = valid
    K[:, 5, :5] = valid
    diag = np.arange(5)
    K[:, diag, diag] += ~valid
    rhs = np.zeros((len(form), 6))
    rhs[:, :5] = np.where(valid, frame.b[form[:, None], ii], 0.0)
    rhs[:, 5] = 1.0
    if independent:
        try:
            sol = np.linalg.solve(K, rhs[..., None])[..., 0]
        except np.linalg.LinAlgError:
            independent = False
        else:
            ok = np.all(np.abs(sol) < 1e9, axis=1)
    if not independent:
        # Cheap screen by the determinant, then the condition number for the suspects.
        det = np.linalg.det(K)
        ok = np.abs(det) > SINGULAR_RTOL * np.prod(np.linalg.norm(K, axis=2), axis=1)
        suspect = np.flatnonzero(~ok)
        if len(suspect):
            ok[suspect] = np.linalg.cond(K[suspect]) < MAX_CONDITION
        sol = np.zeros((len(form), 6))
        sol[ok] = np.linalg.solve(K[ok], rhs[ok][..., None])[..., 0]
    if not np.all(ok):
        form, idx, size, source = form[ok], idx[ok], size[ok], source[ok]
        Rs, Vs, sol = Rs[ok], Vs[ok], sol[ok]
    w = sol[:, :5]
    mu = sol[:, 5]
    ro = np.einsum("ms,msk->mk", w, Rs)
    vo = np.einsum("ms,msk->mk", w, Vs)
    depth2 = -(np.einsum("mk,mk->m", ro, ro) - np.einsum("mk,mk->m", vo, vo) + mu)
    return Solved(form, idx, size, w, mu, ro, vo, depth2, source)


def height_ok(frame: Frame, depth2: np.ndarray | Solved) -> np.ndarray:
    """FK paper eq. 15 and its side conditions: :math:`f(x) < 0` (a real depth) and
    :math:`0 < z_o < z_r` (the object above the ground). ``depth2`` normalised (M,)."""
    d2 = depth2.depth2 if isinstance(depth2, Solved) else depth2
    return (d2 > TAUT_TOL) & (d2 < frame.z * frame.z)


def taut_masks(frame: Frame, solved: Solved, chunk: int = 1 << 24) -> tuple[np.ndarray, np.ndarray]:
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
    B, N = frame.b.shape
    ok = np.zeros(M, dtype=bool)
    taut = np.zeros((M, N), dtype=bool)
    x = np.hstack([solved.ro, solved.vo])
    if B > 1 and 4 * M * N <= chunk:
        # Many small formations: gather each candidate's lifted points (one pass).
        excess = (np.einsum("mnk,mk->mn", frame.P[solved.form, :, :4], x)
                  + frame.b[solved.form] - solved.mu[:, None])
        return excess.max(axis=1, initial=-np.inf) <= TAUT_TOL, excess >= -TAUT_TOL
    if B == 1:
        groups = [np.arange(M)]
    else:
        order = np.argsort(solved.form, kind="stable")
        groups = np.split(order, np.flatnonzero(np.diff(solved.form[order])) + 1)
    step = max(1, chunk // (8 * N))
    for rows in groups:
        if len(rows) == 0:
            continue
        Pf = frame.P[solved.form[rows[0]]]
        for start in range(0, len(rows), step):
            r = rows[start:start + step]
            excess = x[r] @ Pf[:, :4].T + (Pf[:, 4] - solved.mu[r, None])
            ok[r] = excess.max(axis=1, initial=-np.inf) <= TAUT_TOL
            taut[r] = excess >= -TAUT_TOL
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
    \\mathbf{a}_{i_1}` over each affinely independent set ``idx`` (M, 5), padded with -1
    (2..5 members). With 5 members the face is a vertex of the arrangement and the
    result is ``+inf`` (DESIGN.md Sec. 5). The Hessian is scaled to ``diag(1,1,-1,-1)``.
    """
    M = len(form)
    out = np.full(M, np.inf)
    size = (idx >= 0).sum(axis=1)
    rows = np.flatnonzero(size < 5)
    if len(rows) == 0:
        return out
    idx, size = idx[rows], size[rows]
    A = frame.P[form[rows, None], np.maximum(idx, 0), :4]          # (m, 5, 4)
    D = (A[:, 1:, :] - A[:, :1, :]) * (idx[:, 1:, None] >= 0)      # unused rows -> 0
    _, _, vt = np.linalg.svd(D, full_matrices=True)                 # null space: last rows
    # Restrict the Hessian to the last (5 - size) right singular vectors.
    Hr = np.einsum("mik,k,mjk->mij", vt, _H, vt)                   # (m, 4, 4)
    for s in np.unique(size):
        sel = size == s
        k = int(s) - 1
        out[rows[sel]] = np.linalg.eigvalsh(Hr[sel][:, k:, k:])[:, 0]
    return out
