"""Candidate taut sets for forward kinematics.

At any ``x`` the cables that are taut are the maximisers of the affine pieces
:math:`g_i(x) = (\\mathbf{a}_i, b_i) \\cdot (x, 1)`, i.e. the lifted points
:math:`P_i = (\\mathbf{a}_i, b_i) \\in \\mathbb{R}^5` on the face of their convex hull
exposed by the direction ``(x, 1)``. Only faces of the *upper* hull (facets whose outward
normal has a positive last component, and their sub-faces) can be taut sets (DESIGN.md
Sec. 2). Every taut set ``T`` has an affinely independent subset of at most 5 points that
spans its face, and such a subset is a face of some simplex of Qhull's triangulated
output (option ``Qt``); so all 3-, 4- and 5-subsets of the upper simplices (plus 2-subsets
when three sheet vertices are collinear, the only way three lifted points can be
collinear) contain a spanning subset of every possible taut set. Solving each candidate
and reading the exact maximiser set at its solution then yields every solution of the
paper's Algorithm 1 without visiting its :math:`\\sum_k \\binom{N}{k}` subsets.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations

import numpy as np
from scipy.linalg import qr
from scipy.spatial import ConvexHull, QhullError

#: Singular values of the centred lifted points below this (normalised units) are zero.
RANK_TOL = 1e-9


def _combo_table(n: int, k: int) -> np.ndarray:
    return np.array(list(combinations(range(n), k)), dtype=np.intp).reshape(-1, k)


_COMBOS: dict[tuple[int, int], np.ndarray] = {}


def combo_table(n: int, k: int) -> np.ndarray:
    """All ``k``-subsets of ``range(n)`` in lexicographic order, shape (C(n, k), k)."""
    key = (n, k)
    if key not in _COMBOS:
        _COMBOS[key] = _combo_table(n, k)
    return _COMBOS[key]


def sizes_for(N: int, pairs: bool) -> range:
    """Candidate set sizes: 3..min(5, N), and 2 when pairs can span a taut face."""
    return range(2 if pairs else 3, min(5, N) + 1)


def all_small_subsets(N: int, B: int, pairs: bool) -> dict[int, tuple[np.ndarray, np.ndarray]]:
    """Every subset of size 2/3..5 for each of ``B`` formations (complete for any N; used
    where it is cheaper than the hull, i.e. small N, and as the fast method's cross-check)."""
    groups = {}
    for s in sizes_for(N, pairs):
        table = combo_table(N, s)
        groups[s] = (np.repeat(np.arange(B), len(table)), np.tile(table, (B, 1)))
    return groups


def _unique_sorted_rows(rows: np.ndarray, N: int) -> np.ndarray:
    """Distinct rows of an integer array whose rows are each sorted ascending."""
    s = rows.shape[1]
    if N ** s < 2 ** 62:
        key = rows[:, 0].astype(np.int64)
        for c in range(1, s):
            key = key * N + rows[:, c]
        _, first = np.unique(key, return_index=True)
        return rows[first]
    return np.unique(rows, axis=0)


def _facet_subsets(simplices: np.ndarray, N: int, pairs: bool) -> dict[int, np.ndarray]:
    out: dict[int, np.ndarray] = {}
    simplices = np.sort(simplices, axis=1)        # subsets of sorted rows come out sorted
    width = simplices.shape[1]
    for s in sizes_for(N, pairs):
        if s > width:
            continue
        if s == width:
            out[s] = simplices                    # Qhull's simplices are distinct
            continue
        out[s] = _unique_sorted_rows(simplices[:, combo_table(width, s)].reshape(-1, s), N)
    return out


@dataclass
class Stationary:
    """Candidate sets with their stationary points already computed from the hull.

    ``subset`` (M, 5) padded with -1, ``size`` (M,), ``x`` (M, 4) the point
    :math:`(\\mathbf{r}_o, \\mathbf{v}_o)`, ``mu`` (M,) the common piece value, ``depth2``
    (M,), all normalised; ``form`` (M,) the formation index.
    """

    form: np.ndarray
    subset: np.ndarray
    size: np.ndarray
    x: np.ndarray
    mu: np.ndarray
    depth2: np.ndarray


@dataclass
class HullCandidates:
    """Candidates of one formation: ``subsets`` to be solved by the Lagrange kernel
    (``independent`` as in :func:`solve_candidates`), or ``stationary`` points computed
    directly from the facet normals (then ``subsets`` is empty)."""

    subsets: dict[int, np.ndarray]
    independent: bool
    stationary: Stationary | None = None


_J = np.array([1.0, 1.0, -1.0, -1.0])
_PROBE = np.array([0.6180339887, 0.7071067812, 0.5772156649, 0.3183098862, 0.2718281828,
                   0.1414213562])


def _key(rows: np.ndarray, N: int) -> np.ndarray:
    key = rows[:, 0].astype(np.int64)
    for c in range(1, rows.shape[1]):
        key = key * N + rows[:, c]
    return key


def _stationary_from_normals(P: np.ndarray, hull: ConvexHull, basis: np.ndarray
                             ) -> Stationary | None:
    """Stationary points of every upper face of a simplicial, full-dimensional hull.

    For a face ``S`` the points ``x`` at which exactly the pieces of ``S`` are maximal
    satisfy ``(x, 1) = sum_F alpha_F n_F`` over the facets ``F`` containing ``S`` (their
    outward normals ``n_F`` span the directions orthogonal to ``S``). So ``M_S`` (where
    the pieces of ``S`` are equal) is the affine set through ``x_f = n_f[:4] / n_f[4]``
    (``f`` an upper facet containing ``S``) spanned by ``u_g = n_g[:4] - n_g[4] x_f`` for
    ``5 - |S|`` other facets ``g``; the stationary point of ``q + g_i`` on it solves a
    1x1 or 2x2 system (closed form). This replaces the paper's Lagrange solve (eq. 14)
    for every candidate; the exact maximiser test still decides which are valid.

    Returns None for hulls where this shortcut does not apply (coplanar or merged
    facets), which then go through the general solver.
    """
    if len(hull.coplanar):
        return None
    eq = hull.equations
    # Qt gives every simplex of a merged (non-simplicial) facet that facet's hyperplane.
    probe = eq @ _PROBE
    if len(np.unique(probe)) < len(probe):
        return None
    nP = eq[:, :5] @ basis.T                             # outward normals in lifted coords
    upper = nP[:, 4] > 1e-12
    N = len(P)
    simp = np.sort(hull.simplices, axis=1)
    nf = len(simp)
    uf = np.flatnonzero(upper)
    subsets, xs = [], []
    # Facets: the stationary point is the facet's own vertex of the arrangement.
    subsets.append(simp[uf])
    xs.append(nP[uf, :4] / nP[uf, 4:5])
    # Ridges: facet f minus its vertex j, shared with neighbour g = neighbors[f, j]
    # (Qhull orders neighbours opposite the unsorted simplex's vertices).
    f, j = np.nonzero(upper[:, None] & np.ones((1, 5), bool))
    g = hull.neighbors[f, j]
    keep = ~upper[g] | (f < g)
    f, j, g = f[keep], j[keep], g[keep]
    ridge = np.sort(np.where(np.arange(5) == j[:, None], -1, hull.simplices[f]), axis=1)[:, 1:]
    faces = [(ridge, f, g[:, None])]
    # 2-faces: group the 3-subsets of all simplices; each is shared by >= 3 facets.
    tab = combo_table(5, 3)
    sub = simp[:, tab].reshape(-1, 3)
    fid = np.repeat(np.arange(nf), len(tab))
    key = _key(sub, N) * 2 + (~upper[fid])               # upper facets first within a face
    order = np.argsort(key)
    key, sub, fid = key[order] // 2, sub[order], fid[order]
    start = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
    count = np.diff(np.r_[start, len(key)])
    first = fid[start]
    if np.any(count[upper[first]] < 3):
        return None
    keep = upper[first]
    start = start[keep]
    faces.append((sub[start], fid[start], fid[start[:, None] + np.arange(1, 3)]))
    for face, f, g in faces:
        xf = nP[f, :4] / nP[f, 4:5]
        m = g.shape[1]
        U = nP[g, :4] - nP[g, 4:5] * xf[:, None, :]            # (M, m, 4)
        A = np.einsum("mik,k,mjk->mij", U, _J, U)
        rhs = -np.einsum("mik,mk->mi", U, _J * xf + 0.5 * P[face[:, 0], :4])
        scale = np.einsum("mik,mik->m", U, U)
        if m == 1:
            det = A[:, 0, 0]
            ok = np.abs(det) > 1e-12 * scale
            t = rhs[ok] / det[ok, None]
        else:
            det = A[:, 0, 0] * A[:, 1, 1] - A[:, 0, 1] * A[:, 1, 0]
            ok = np.abs(det) > 1e-12 * scale ** 2
            A, rhs, det = A[ok], rhs[ok], det[ok]
            t = np.column_stack([A[:, 1, 1] * rhs[:, 0] - A[:, 0, 1] * rhs[:, 1],
                                 A[:, 0, 0] * rhs[:, 1] - A[:, 1, 0] * rhs[:, 0]]) / det[:, None]
        xs.append(xf[ok] + np.einsum("mi,mik->mk", t, U[ok]))
        pad = np.full((int(ok.sum()), 5), -1, dtype=np.intp)
        pad[:, :face.shape[1]] = face[ok]
        subsets.append(pad)
    subset = np.vstack(subsets)
    x = np.vstack(xs)
    size = (subset >= 0).sum(axis=1)
    first = P[subset[:, 0]]
    mu = np.einsum("mk,mk->m", first[:, :4], x) + first[:, 4]
    depth2 = -(np.einsum("mk,k,mk->m", x, _J, x) + mu)
    return Stationary(np.zeros(len(x), np.intp), subset, size, x, mu, depth2)


def hull_candidates(P: np.ndarray, pairs: bool) -> HullCandidates:
    """Candidate sets for one formation from the upper hull of its lifted points.

    Parameters
    ----------
    P : ndarray, shape (N, 5)
        Lifted points in normalised units.
    pairs : bool
        Also emit 2-subsets (needed only when the sheet has collinear vertices).

    Degenerate inputs (the lifted points span fewer than 5 dimensions, e.g. the FK
    paper's Lemma 2 and Table V where all of them lie on a 2-plane) are handled in the
    affine hull of the points: if the "up" axis lies in that hull only its upper faces
    can be exposed; otherwise every face can, including the whole point set. Generic
    inputs (full-dimensional, simplicial hull) get their stationary points directly
    from the facet normals (:func:`_stationary_from_normals`).
    """
    N = len(P)
    centre = P.mean(axis=0)
    Pc = P - centre
    _, sv, vt = np.linalg.svd(Pc, full_matrices=False)
    d = int(np.sum(sv > RANK_TOL * max(1.0, sv[0])))
    if N <= d + 1 or N <= 5:
        return HullCandidates({s: combo_table(N, s) for s in sizes_for(N, pairs)}, False)
    basis = vt[:d].T                                   # (5, d)
    Y = Pc @ basis
    up = basis[4]                                      # e5 expressed in the hull's coordinates
    up_in_hull = np.linalg.norm(up) > 1.0 - 1e-9
    try:
        hull = ConvexHull(Y, qhull_options="Qt")
    except QhullError:
        try:
            hull = ConvexHull(Y, qhull_options="QJ")
        except QhullError:                             # pragma: no cover - last resort
            return HullCandidates({s: combo_table(N, s) for s in sizes_for(N, pairs)}, False)
    if d == 5 and not pairs:
        stationary = _stationary_from_normals(P, hull, basis)
        if stationary is not None:
            return HullCandidates({}, True, stationary)
    simplices = hull.simplices
    if up_in_hull:
        upper = hull.equations[:, :d] @ up > -1e-12
        simplices = simplices[upper]
    out = _facet_subsets(simplices, N, pairs)
    if not up_in_hull and d + 1 <= 5:
        # The whole point set is a face (exposed by a direction orthogonal to its hull):
        # add one affinely independent spanning subset of it.
        i0 = int(np.argmax(np.einsum("ij,ij->i", Pc, Pc)))
        _, _, piv = qr((P - P[i0]).T, pivoting=True, mode="economic")
        whole = np.sort(np.concatenate([[i0], piv[:d]]).astype(np.intp))
        s = len(whole)
        row = whole[None, :].astype(np.intp)
        out[s] = row if s not in out else _unique_sorted_rows(np.vstack([out[s], row]), N)
    return HullCandidates(out, d == 5)
