"""Numerical core of VVCM forward kinematics, batched over candidate taut sets.

Notation (FK paper, Sec. III; docs/sheet_kinematics.md §1). Robots :math:`\\mathbf{r}_i`, sheet
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
``w >= 0`` (docs/sheet_kinematics.md §3).

All work is done in a normalised frame (formation and sheet centred, lengths divided by
the sheet size), so every tolerance below is relative to the sheet size.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._tol import (ANGLE_TOL, COINCIDE_RTOL2, CURVATURE_TOL, MAX_CONDITION, MAX_SOLUTION,
    SINGULAR_RTOL, TAUT_TOL, WEIGHT_TOL)
from ._util import Q_SIGNS

__all__ = ["TAUT_TOL", "WEIGHT_TOL", "CURVATURE_TOL", "SINGULAR_RTOL", "MAX_CONDITION",
           "ANGLE_TOL", "KIND_STABLE", "KIND_SADDLE", "KIND_NOT_EQUILIBRIUM",
           "KIND_NAMES", "Frame", "Solved", "solve_candidates", "solve_table",
           "height_ok", "taut_at", "taut_masks", "maximiser_masks", "in_hull_2d",
           "reduced_hessian_min_eig", "pad_groups"]

#: Codes of the kinds of rest state (``Equilibrium.kind``) in the solvers' arrays.
KIND_STABLE, KIND_SADDLE, KIND_NOT_EQUILIBRIUM = 0, 1, 2
KIND_NAMES = ("stable", "saddle", "not_equilibrium")

# Reduced Hessian of q, up to the factor 2 (does not change signs).
_H = Q_SIGNS
# Columns and signs of the 3 x 3 minors giving the null vector of a 3 x 4 matrix.
_MINOR_COLS = np.array([[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]])
_MINOR_SIGN = np.array([1.0, -1.0, 1.0, -1.0])
_ONES4 = np.ones(4)
# Offset (from N) of the augmented-table row standing for an unused slot 2, 3 or 4.
_UNUSED_SLOT = np.arange(5) - 2


@dataclass(frozen=True)
class Frame:
    """Formations and sheet in normalised coordinates.

    ``R`` (B, N, 2) robots, ``V`` (N, 2) vertices, ``z`` hold height, all divided by
    ``scale``; ``r_centre`` (B, 2) and ``v_centre`` (2,) were subtracted before scaling.
    ``P`` (B, N, 5) are the lifted points :math:`(\\mathbf{a}_i, b_i)` and ``b`` (B, N).

    Two augmented tables let :func:`solve_candidates` assemble every padded 6 x 6 Lagrange
    system with a single gather: ``kaug`` (B, N + 4, N + 4) holds the Gram matrix
    :math:`G_{ij} = 2(\\mathbf{r}_i\\cdot\\mathbf{r}_j - \\mathbf{v}_i\\cdot\\mathbf{v}_j)`
    bordered by indices ``N .. N + 2`` (up to three unused slots: identity rows and
    columns) and index ``N + 3`` (the constraint :math:`\\sum w_i = 1`: ones against
    real indices); ``baug`` (B, N + 4) the matching right-hand side (``b``, 0, 0, 0, 1).
    ``X`` (B, N + 3, 4) holds :math:`(\\mathbf{r}_i, \\mathbf{v}_i)` and three zero rows.
    """

    R: np.ndarray
    V: np.ndarray
    z: float
    r_centre: np.ndarray
    v_centre: np.ndarray
    scale: float
    b: np.ndarray
    P: np.ndarray
    kaug: np.ndarray
    baug: np.ndarray
    X: np.ndarray

    @property
    def gram(self) -> np.ndarray:
        """(B, N, N) Gram matrix :math:`G` (a view of ``kaug``)."""
        N = self.b.shape[1]
        return self.kaug[:, :N, :N]

    @classmethod
    def build(cls, vertices: np.ndarray, formations: np.ndarray, hold_height: float,
              scale: float) -> "Frame":
        v_centre = vertices.mean(axis=0)
        r_centre = formations.mean(axis=1)
        B, N = formations.shape[:2]
        X = np.zeros((B, N + 3, 4))
        X[:, :N, :2] = formations - r_centre[:, None, :]
        X[:, :N, 2:] = vertices - v_centre
        X[:, :N] /= scale
        R, V = X[:, :N, :2], X[0, :N, 2:]
        sq = X * X
        b = (sq[:, :N, 0] + sq[:, :N, 1]) - (sq[:, :N, 2] + sq[:, :N, 3])
        P = np.empty((B, N, 5))
        P[..., :4] = X[:, :N] * np.array([-2.0, -2.0, 2.0, 2.0])
        P[..., 4] = b
        kaug = np.zeros((B, N + 4, N + 4))
        kaug[:, :N, :N] = 2.0 * (R @ R.transpose(0, 2, 1) - (V @ V.T)[None])
        unused = np.arange(N, N + 3)
        kaug[:, unused, unused] = 1.0
        kaug[:, :N, N + 3] = 1.0
        kaug[:, N + 3, :N] = 1.0
        baug = np.zeros((B, N + 4))
        baug[:, :N] = b
        baug[:, N + 3] = 1.0
        return cls(R, V, hold_height / scale, r_centre, v_centre, scale, b, P, kaug, baug, X)


@dataclass
class Solved:
    """Stationary points of candidate sets (flat over all candidates of all sizes).

    ``form`` (M,) formation index; ``subset`` (M, 5) robot indices padded with -1;
    ``size`` (M,); ``w`` (M, 5) weights padded with 0; ``mu`` (M,); ``x`` (M, 4) the point
    :math:`(\\mathbf{r}_o, \\mathbf{v}_o)` (``ro``, ``vo`` are views of it); ``depth2``
    (M,) normalised :math:`d^2`; ``source`` (M,) position of the candidate in its input.
    """

    form: np.ndarray
    subset: np.ndarray
    size: np.ndarray
    w: np.ndarray
    mu: np.ndarray
    x: np.ndarray
    depth2: np.ndarray
    source: np.ndarray

    FIELDS = ("form", "subset", "size", "w", "mu", "x", "depth2", "source")

    @property
    def ro(self) -> np.ndarray:
        return self.x[:, :2]

    @property
    def vo(self) -> np.ndarray:
        return self.x[:, 2:]

    def take(self, keep: np.ndarray) -> "Solved":
        return Solved(*(getattr(self, f)[keep] for f in self.FIELDS))

    @classmethod
    def concat(cls, parts: list["Solved"]) -> "Solved":
        if len(parts) == 1:
            return parts[0]
        if not parts:
            return cls(np.zeros(0, np.intp), np.zeros((0, 5), np.intp), np.zeros(0, np.intp),
                       np.zeros((0, 5)), np.zeros(0), np.zeros((0, 4)), np.zeros(0),
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
    M = len(form)
    if M == 0:
        return Solved.concat([])
    B, N = frame.b.shape
    n2 = N + 4
    J = _slots(idx, N)
    if B > 1:
        J += (form * n2)[:, None]
    K = frame.kaug.reshape(-1)[(J * n2)[:, :, None] + (J % n2)[:, None, :]]
    rhs = frame.baug.reshape(-1)[J]
    # Unused slots gather zero rows of X.
    XJ = frame.X.reshape(-1, 4)[J[:, :5] - (J[:, :5] // n2)] if B > 1 else frame.X[0][J[:, :5]]
    ok, sol = _screen_and_solve(K, rhs, independent)
    return _stationary_points(ok, sol, XJ, form, idx)


def solve_table(frame: Frame, table: np.ndarray, forms: slice = slice(None), *,
                independent: bool = False) -> Solved:
    """:func:`solve_candidates` for the same candidate ``table`` (C, 5) in each formation
    of the range ``forms`` (rows formation-major). The systems are gathered by
    broadcasting the small table over the formations, without (B * C, 6, 6) index arrays.
    Large blocks are solved per set size ``s`` at their own size ``s + 1`` (the padding
    changes neither the determinant nor the row norms of the screen; suspects get their
    condition number from the padded 6 x 6 form, as in :func:`solve_candidates`)."""
    first, stop, _ = forms.indices(frame.b.shape[0])
    B, N, C = stop - first, frame.b.shape[1], len(table)
    if B * C <= 0:
        return Solved.concat([])
    J = _slots(table, N)
    XJ = frame.X[first:stop, J[:, :5]].reshape(B * C, 5, 4)
    if B == 1:
        form, idx = np.full(C, first, dtype=np.intp), table
    else:
        form = np.repeat(np.arange(first, stop), C)
        idx = np.broadcast_to(table, (B, C, 5)).reshape(B * C, 5)
    if independent or B * C < PER_SIZE_MIN:
        K = frame.kaug[first:stop, J[:, :, None], J[:, None, :]].reshape(B * C, 6, 6)
        rhs = frame.baug[first:stop, J].reshape(B * C, 6)
        ok, sol = _screen_and_solve(K, rhs, independent)
        return _stationary_points(ok, sol, XJ, form, idx)
    sizes = (table >= 0).sum(axis=1)
    ok = np.empty((B, C), dtype=bool)
    sol = np.zeros((B, C, 6))
    for size in np.unique(sizes):
        cols = np.flatnonzero(sizes == size)            # contiguous: rows sorted by size
        a, e, n = cols[0], cols[-1] + 1, size + 1
        Js = np.concatenate([J[a:e, :size], J[a:e, 5:]], axis=1)
        K = frame.kaug[first:stop, Js[:, :, None], Js[:, None, :]].reshape(-1, n, n)
        rhs = frame.baug[first:stop, Js].reshape(-1, n)
        ok_s, sol_s = _screen_and_solve(K, rhs, False)
        ok[:, a:e] = ok_s.reshape(B, e - a)
        sol[:, a:e, :size] = sol_s[:, :size].reshape(B, e - a, size)
        sol[:, a:e, 5] = sol_s[:, size].reshape(B, e - a)
    return _stationary_points(ok.reshape(-1), sol.reshape(-1, 6), XJ, form, idx)


#: solve_table solves per set size from this many systems on (fewer LAPACK flops; more
#: calls).
PER_SIZE_MIN = 4096


def _slots(idx: np.ndarray, N: int) -> np.ndarray:
    """Rows of the augmented tables (see Frame) for each candidate's 6 slots: member
    ``i`` -> ``i``, an unused slot ``j`` (always j >= 2) -> ``N + j - 2``, the last slot
    -> the constraint row ``N + 3``."""
    J = np.empty((len(idx), 6), dtype=np.intp)
    J[:, :5] = np.where(idx >= 0, idx, _UNUSED_SLOT + N)
    J[:, 5] = N + 3
    return J


def _screen_and_solve(K: np.ndarray, rhs: np.ndarray, independent: bool
                      ) -> tuple[np.ndarray, np.ndarray]:
    """Solve the systems ``K`` (M, n, n) ``[w, mu] = rhs`` (M, n) (n <= 6: a candidate's
    members and its constraint row, possibly padded to 6) and flag the non-singular ones
    (policy of :func:`solve_candidates`). ``K`` is overwritten where singular."""
    ok: np.ndarray | None = None
    if independent:
        try:
            sol = np.linalg.solve(K, rhs[..., None])[..., 0]
        except np.linalg.LinAlgError:
            independent = False
        else:
            ok = np.all(np.abs(sol) < MAX_SOLUTION, axis=1)
    if not independent:
        # Cheap screen by the determinant, then the condition number for the suspects
        # (of the 6 x 6 padded form: identity rows and columns for unused slots).
        det = np.linalg.det(K)
        ok = np.abs(det) > SINGULAR_RTOL * np.prod(np.sqrt(np.einsum("mij,mij->mi", K, K)),
                                                   axis=1)
        suspect = np.flatnonzero(~ok)
        if len(suspect):
            n = K.shape[1]
            padded = np.zeros((len(suspect), 6, 6))
            padded[:, n:, n:] = np.eye(6 - n)
            padded[:, :n, :n] = K[suspect]
            ok[suspect] = np.linalg.cond(padded) < MAX_CONDITION
        if not ok.all():
            K[~ok] = np.eye(K.shape[1])        # singular: solved harmlessly, dropped later
        sol = np.linalg.solve(K, rhs[..., None])[..., 0]
    assert ok is not None
    return ok, sol


def _stationary_points(ok: np.ndarray, sol: np.ndarray, XJ: np.ndarray, form: np.ndarray,
                       idx: np.ndarray) -> Solved:
    """Keep the solved candidates flagged ``ok`` and form their stationary points from
    the padded solutions ``sol`` (M, 6) = (w, mu) and the members' ``(r_i, v_i)`` rows
    ``XJ`` (M, 5, 4) (zero rows for unused slots)."""
    M = len(sol)
    source = None
    if not ok.all():
        source = np.flatnonzero(ok)
        form, idx, XJ, sol = form[source], idx[source], XJ[source], sol[source]
    w = sol[:, :5]
    mu = sol[:, 5]
    x = np.matmul(w[:, None, :], XJ)[:, 0]                      # sum_j w_j (r_j, v_j)
    sq = x * x
    depth2 = -((sq[:, 0] + sq[:, 1]) - (sq[:, 2] + sq[:, 3]) + mu)
    size = (idx >= 0).sum(axis=1)
    return Solved(form, idx, size, w, mu, x, depth2,
                  np.arange(M) if source is None else source)


def height_ok(frame: Frame, depth2: np.ndarray | Solved) -> np.ndarray:
    """FK paper eq. 15 and its side conditions: :math:`f(x) < 0` (a real depth) and
    :math:`0 < z_o < z_r` (the object above the ground). ``depth2`` normalised (M,)."""
    d2 = depth2.depth2 if isinstance(depth2, Solved) else depth2
    return (d2 > TAUT_TOL) & (d2 < frame.z * frame.z)


def taut_at(frame: Frame, b: int, x: np.ndarray, depth2: float) -> np.ndarray:
    """The one definition of "taut" (docs/sheet_fk_solver.md, "Which cables are taut"):
    the cables at their full length at a state of formation ``b``.

    Cable :math:`j` is taut when :math:`(L_j^2 - l_j^2)/s^2 \\ge -` ``TAUT_TOL``, with
    :math:`L_j` the robot-to-object distance and :math:`l_j = |\\mathbf{v}_j -
    \\mathbf{v}_o|` the cable's length on the sheet (FK paper eq. 1 with equality). In
    lifted form (docs/sheet_kinematics.md §1) :math:`(L_j^2 - l_j^2)/s^2 = g_j(x) +
    x^\\top J x + d^2` with :math:`g_j(x) = \\mathbf{a}_j \\cdot x + b_j` the lifted
    piece: the compiled kernels (``_kernels.small``, ``_kernels.step``) and
    :func:`maximiser_masks` evaluate exactly this sum as ``g_j(x) - mu`` at a solved state
    (where :math:`d^2 = -(x^\\top J x + \\mu)`); states known only by their point (merged
    states, the direct minimisation's) are decided here.

    Parameters
    ----------
    frame : Frame
        The normalised formations and sheet.
    b : int
        Which formation of ``frame``.
    x : ndarray, shape (4,)
        The state's (r_o, v_o), normalised (centred, divided by the sheet size).
    depth2 : float
        Its squared depth :math:`((z_r - z_o)/s)^2` (normalised area).

    Returns
    -------
    ndarray of bool, shape (N,)
        The taut cables.
    """
    P = frame.P[b]
    stretch = P[:, :4] @ x + P[:, 4] + (x[0] * x[0] + x[1] * x[1] - x[2] * x[2]
                                         - x[3] * x[3] + depth2)
    return np.asarray(stretch >= -TAUT_TOL)


def taut_masks(frame: Frame, solved: Solved, chunk: int = 1 << 24) -> tuple[np.ndarray, np.ndarray]:
    """Maximiser sets of the pieces at each solution (see :func:`maximiser_masks`)."""
    return maximiser_masks(frame, solved.form, solved.x, solved.mu, chunk)


def maximiser_masks(frame: Frame, form: np.ndarray, x: np.ndarray, mu: np.ndarray,
                    chunk: int = 1 << 24) -> tuple[np.ndarray, np.ndarray]:
    """Maximiser sets of the pieces at points ``x`` (M, 4) of formations ``form`` (M,)
    where the candidate's pieces take the value ``mu`` (M,).

    Returns
    -------
    ok : ndarray of bool, shape (M,)
        The candidate's pieces attain the maximum (no other cable would be over-stretched:
        FK paper eq. 1 holds for every cable).
    taut : ndarray of bool, shape (M, N)
        Cables whose :math:`g_j` is within ``TAUT_TOL`` of the maximum (the exact taut set).
    """
    M = len(form)
    B, N = frame.b.shape
    if B == 1 and M * N <= chunk // 8:
        P = frame.P[0]
        excess = x @ P[:, :4].T + (P[:, 4] - mu[:, None])
        return excess.max(axis=1, initial=-np.inf) <= TAUT_TOL, excess >= -TAUT_TOL
    ok = np.zeros(M, dtype=bool)
    taut = np.zeros((M, N), dtype=bool)
    if B > 1 and 4 * M * N <= chunk:
        # Many small formations: gather each candidate's lifted points (one pass).
        excess = np.matmul(frame.P[form, :, :4], x[:, :, None])[..., 0]
        excess += frame.b[form] - mu[:, None]
        return excess.max(axis=1, initial=-np.inf) <= TAUT_TOL, excess >= -TAUT_TOL
    if B == 1:
        groups = [np.arange(M)]
    else:
        order = np.argsort(form, kind="stable")
        groups = np.split(order, np.flatnonzero(np.diff(form[order])) + 1)
    step = max(1, chunk // (8 * N))
    for rows in groups:
        if len(rows) == 0:
            continue
        Pf = frame.P[form[rows[0]]]
        for start in range(0, len(rows), step):
            r = rows[start:start + step]
            excess = x[r] @ Pf[:, :4].T + (Pf[:, 4] - mu[r, None])
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
    dist2 = d[..., 0] * d[..., 0] + d[..., 1] * d[..., 1]
    scale2 = np.max(dist2, axis=1, where=valid, initial=1.0)     # max(scale, 1) squared
    coincide = np.any(valid & (dist2 <= COINCIDE_RTOL2 * scale2[:, None]), axis=1)
    ang = np.arctan2(d[..., 1], d[..., 0])
    # Unused slots repeat the row's first valid direction (no new gap); the last column
    # closes the circle.
    first = ang[np.arange(len(p)), np.argmax(valid, axis=1)]
    ang = np.sort(np.where(valid, ang, first[:, None]), axis=1)
    gaps = np.diff(ang, axis=1, append=ang[:, :1] + 2 * np.pi)
    return coincide | (gaps.max(axis=1) <= np.pi + ANGLE_TOL)


def reduced_hessian_min_eig(frame: Frame, form: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """Smallest eigenvalue of the Hessian of ``q`` restricted to the face's tangent space.

    The tangent space is the null space of the differences :math:`\\mathbf{a}_i -
    \\mathbf{a}_{i_1}` over each affinely independent set ``idx`` (M, 5), padded with -1
    (2..5 members). With 5 members the face is a vertex of the arrangement and the
    result is ``+inf`` (docs/sheet_kinematics.md §5). The Hessian is scaled to ``diag(1,1,-1,-1)``.
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
    if size.min() == 4:
        # One-dimensional tangent space: its direction n is the generalised cross
        # product of the three differences (signed 3 x 3 minors); result n'Hn / n'n.
        n = np.linalg.det(D[:, :3, _MINOR_COLS].transpose(0, 2, 1, 3)) * _MINOR_SIGN
        nn = n * n
        out[rows] = (nn @ _H) / (nn @ _ONES4)
        return out
    _, _, vt = np.linalg.svd(D, full_matrices=True)                 # null space: last rows
    if size.min() >= 3:
        # Tangent space of dimension 1 or 2: the last two right singular vectors z1, z2;
        # closed-form eigenvalues of the 2 x 2 restriction (or z2' H z2 alone).
        Z = vt[:, 2:, :]
        h = np.matmul(Z * _H, Z.transpose(0, 2, 1))                 # (m, 2, 2)
        a, c, b = h[:, 0, 0], h[:, 1, 1], h[:, 0, 1]
        half = 0.5 * (a - c)
        out[rows] = np.where(size == 4, c, 0.5 * (a + c) - np.sqrt(half * half + b * b))
        return out
    # Restrict the Hessian to the last (5 - size) right singular vectors.
    Hr = np.matmul(vt * _H, vt.transpose(0, 2, 1))                  # (m, 4, 4)
    for s in np.unique(size):
        sel = size == s
        k = int(s) - 1
        out[rows[sel]] = np.linalg.eigvalsh(Hr[sel][:, k:, k:])[:, 0]
    return out
