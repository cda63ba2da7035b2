"""Candidate taut sets for forward kinematics.

At any ``x`` the cables that are taut are the maximisers of the affine pieces
:math:`g_i(x) = (\\mathbf{a}_i, b_i) \\cdot (x, 1)`, i.e. the lifted points
:math:`P_i = (\\mathbf{a}_i, b_i) \\in \\mathbb{R}^5` on the face of their convex hull
exposed by the direction ``(x, 1)``. Only faces of the *upper* hull (facets whose outward
normal has a positive last component, and their sub-faces) can be taut sets (docs/sheet_kinematics.md
§2). Every taut set ``T`` has an affinely independent subset of at most 5 points that
spans its face, and such a subset is a face of some simplex of Qhull's triangulated
output (option ``Qt``); so all 3-, 4- and 5-subsets of the upper simplices (plus 2-subsets
when three sheet vertices are collinear, the only way three lifted points can be
collinear) contain a spanning subset of every possible taut set. Solving each candidate
and reading the exact maximiser set at its solution then yields every solution of the
paper's Algorithm 1 without visiting its :math:`\\sum_k \\binom{N}{k}` subsets.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from scipy.spatial import ConvexHull

from .._tol import (CLOSED_FORM_RTOL, EXACT_FLAT, FALLBACK_SIN, GRAM_SCHMIDT_RTOL2, NEAR_FLAT,
    RANK_TOL, TINY, UP_IN_HULL_TOL, UPPER_NORMAL_TOL)
from .._util import Q_SIGNS, combo_table

#: Nearly flat teams up to this size get every subset as a candidate.
NEAR_FLAT_SUBSETS = 14


def sizes_for(N: int, pairs: bool) -> range:
    """Candidate set sizes: 3..min(5, N), and 2 when pairs can span a taut face."""
    return range(2 if pairs else 3, min(5, N) + 1)


_PADDED: dict[tuple[int, bool], np.ndarray] = {}


def padded_small_subsets(N: int, pairs: bool) -> np.ndarray:
    """Every subset of size 2/3..5 of ``range(N)``, ascending size, padded with -1 to
    shape (M, 5) (cached; read-only). Complete for any N: the candidates of small teams,
    where it is cheaper than the hull, and of the fast method's cross-check."""
    key = (N, pairs)
    if key not in _PADDED:
        parts = []
        for s in sizes_for(N, pairs):
            table = combo_table(N, s)
            pad = np.full((len(table), 5), -1, dtype=np.intp)
            pad[:, :s] = table
            parts.append(pad)
        table = np.vstack(parts) if parts else np.zeros((0, 5), np.intp)
        table.flags.writeable = False
        _PADDED[key] = table
    return _PADDED[key]


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


def _add_rows(out: dict[int, np.ndarray], size: int, rows: np.ndarray, N: int) -> None:
    """Merge sorted candidate rows of one size into ``out`` (size -> rows), without
    duplicates."""
    if size in out:
        rows = _unique_sorted_rows(np.vstack([out[size], rows]), N)
    out[size] = rows


def _every_subset(N: int, pairs: bool) -> "HullCandidates":
    """Every subset of every candidate size: complete, for small or degenerate teams."""
    return HullCandidates({s: combo_table(N, s) for s in sizes_for(N, pairs)}, False)


def _facet_subsets(simplices: np.ndarray, N: int, pairs: bool, *, unique: bool = True
                   ) -> dict[int, np.ndarray]:
    """Every candidate-size subset of the simplices' vertex sets (size -> sorted rows),
    without repeats unless ``unique`` is False (repeats cost the compiled kernel less
    than removing them)."""
    out: dict[int, np.ndarray] = {}
    simplices = np.sort(simplices, axis=1)        # subsets of sorted rows come out sorted
    width = simplices.shape[1]
    for s in sizes_for(N, pairs):
        if s > width:
            continue
        if s == width:
            out[s] = simplices                    # Qhull's simplices are distinct
            continue
        rows = simplices[:, combo_table(width, s)].reshape(-1, s)
        out[s] = _unique_sorted_rows(rows, N) if unique else rows
    return out


@dataclass
class Stationary:
    """Candidate sets with their stationary points already computed from the hull.

    ``subset`` (M, 5) padded with -1, ``size`` (M,), ``x`` (M, 4) the point
    :math:`(\\mathbf{r}_o, \\mathbf{v}_o)`, ``mu`` (M,) the common piece value, ``depth2``
    (M,), all normalised; ``form`` (M,) the formation index; ``curvature`` (M,) the
    smallest eigenvalue of the reduced Hessian on the face (as
    :func:`~taut.sheet._lifted.reduced_hessian_min_eig`, ``+inf`` for facets).
    """

    form: np.ndarray
    subset: np.ndarray
    size: np.ndarray
    x: np.ndarray
    mu: np.ndarray
    depth2: np.ndarray
    curvature: np.ndarray

    FIELDS = ("form", "subset", "size", "x", "mu", "depth2", "curvature")


@dataclass
class HullCandidates:
    """Candidates of one formation: ``subsets`` to be solved by the Lagrange kernel
    (``independent`` as in :func:`solve_candidates`), or ``stationary`` points computed
    directly from the facet normals (then ``subsets`` is empty)."""

    subsets: dict[int, np.ndarray]
    independent: bool
    stationary: Stationary | None = None


_J = Q_SIGNS
_ONES = np.ones(4)
#: Positions of the 3-subsets of a 5-vertex simplex, and of the two vertices left out.
_TRI_POS = combo_table(5, 3)
_TRI_REST = np.array([[i for i in range(5) if i not in c] for c in _TRI_POS], dtype=np.intp)
_PROBE = np.array([0.6180339887, 0.7071067812, 0.5772156649, 0.3183098862, 0.2718281828,
                   0.1414213562])


def _stationary_from_normals(P: np.ndarray, hull: ConvexHull, basis: np.ndarray
                             ) -> tuple[Stationary, dict[int, np.ndarray]] | None:
    """Stationary points of every upper face of a simplicial, full-dimensional hull.

    For a face ``S`` the points ``x`` at which exactly the pieces of ``S`` are maximal
    satisfy ``(x, 1) = sum_F alpha_F n_F`` over the facets ``F`` containing ``S`` (their
    outward normals ``n_F`` span the directions orthogonal to ``S``). So ``M_S`` (where
    the pieces of ``S`` are equal) is the affine set through ``x_f = n_f[:4] / n_f[4]``
    (``f`` an upper facet containing ``S``) spanned by ``u_g = n_g[:4] - n_g[4] x_f`` for
    ``5 - |S|`` other facets ``g``; the stationary point of ``q + g_i`` on it solves a
    1x1 or 2x2 system (closed form). This replaces the paper's Lagrange solve (eq. 14)
    for every candidate; the exact maximiser test still decides which are valid
    (docs/sheet_kinematics.md §2).

    Returns the stationary points, and the faces (``size -> subsets``) whose directions
    are too ill-conditioned for the closed form (nearly coplanar neighbouring facets),
    which go through the general solver; or None for hulls where the shortcut does not
    apply at all (coplanar points or merged facets).
    """
    facets = _upper_facets(hull, basis)
    if facets is None:
        return None
    nP, upper, uf = facets
    simp_u = hull.simplices[uf]                  # Qhull's vertex order: neighbours follow it
    sorted_u = np.sort(simp_u, axis=1)
    nbr = hull.neighbors[uf]
    # Facets: the stationary point is the facet's own vertex of the arrangement.
    subsets = [sorted_u]
    xs = [nP[uf, :4] / nP[uf, 4:5]]
    sizes = [np.full(len(uf), 5, dtype=np.intp)]
    curvs = [np.full(len(uf), np.inf)]
    faces = [_ridge_faces(nP, upper, uf, simp_u, sorted_u, nbr),
             _triangle_faces(nP, uf, simp_u, sorted_u, nbr, len(P))]
    fallback: dict[int, list[np.ndarray]] = {}
    for face, xf, dirs in faces:
        c = _J * xf + 0.5 * P[face[:, 0], :4]             # gradient terms at x_f (any i)
        if len(dirs) == 1:
            ok, x, curv = _closed_form_line(xf, c, dirs[0])
        else:
            ok, x, curv = _closed_form_plane(xf, c, dirs[0], dirs[1])
        curvs.append(curv)
        if not np.all(ok):
            s_face = 5 - len(dirs)
            fallback.setdefault(s_face, []).append(face[~ok, :s_face])
        xs.append(x)
        subsets.append(face[ok])
        sizes.append(np.full(len(x), 5 - len(dirs), dtype=np.intp))
    subset = np.vstack(subsets)
    x = np.vstack(xs)
    first = P[subset[:, 0]]
    mu = (first[:, :4] * x) @ _ONES + first[:, 4]
    sq = x * x
    depth2 = -((sq[:, 0] + sq[:, 1]) - (sq[:, 2] + sq[:, 3]) + mu)
    return Stationary(np.zeros(len(x), np.intp), subset, np.concatenate(sizes), x, mu, depth2,
                      np.concatenate(curvs)), {s: np.vstack(v) for s, v in fallback.items()}


def _upper_facets(hull: ConvexHull, basis: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """Outward unit normals ``nP`` of every facet in lifted coordinates, the upper mask
    and the upper facets' indices; None when the hull has coplanar points or merged
    facets (Qt gives every simplex of a merged facet that facet's hyperplane)."""
    if len(hull.coplanar):
        return None
    eq = hull.equations
    probe = np.sort(eq @ _PROBE)
    if np.any(probe[1:] == probe[:-1]):
        return None
    nP = eq[:, :5] @ basis.T         # outward unit normals in lifted coords (basis orthogonal)
    upper = nP[:, 4] > UPPER_NORMAL_TOL
    return nP, upper, np.flatnonzero(upper)


def _ridge_faces(nP: np.ndarray, upper: np.ndarray, uf: np.ndarray, simp_u: np.ndarray,
                 sorted_u: np.ndarray, nbr: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray, tuple[np.ndarray, ...]]:
    """Ridges (4-faces): facet f minus its vertex j, shared with neighbour g =
    neighbors[f, j] (Qhull orders neighbours opposite the unsorted simplex's vertices),
    each once. Returns the padded subsets, the points x_f and the direction u_g."""
    fi, j = np.nonzero(~upper[nbr] | (uf[:, None] < nbr))
    f, g = uf[fi], nbr[fi, j]
    rows = sorted_u[fi]
    ridge = np.full((len(f), 5), -1, dtype=np.intp)
    ridge[:, :4] = rows[rows != simp_u[fi, j][:, None]].reshape(-1, 4)
    x1 = nP[f, :4] / nP[f, 4:5]
    return ridge, x1, (nP[g, :4] - nP[g, 4:5] * x1,)


def _triangle_faces(nP: np.ndarray, uf: np.ndarray, simp_u: np.ndarray, sorted_u: np.ndarray,
                    nbr: np.ndarray, N: int
                    ) -> tuple[np.ndarray, np.ndarray, tuple[np.ndarray, ...]]:
    """2-faces: every 3-subset S of an upper facet f. The facets sharing with f the ridges
    opposite f's two other vertices also contain S (f's neighbours around S). Of the upper
    facets containing S keep the one whose two directions u_g are best conditioned:
    nearly coplanar neighbours give tiny or nearly parallel ones."""
    perm = np.argsort(simp_u, axis=1)              # sorted_u = simp_u in the order perm
    tri = sorted_u[:, _TRI_POS].reshape(-1, 3)
    f3 = np.repeat(uf, 10)
    g3 = np.take_along_axis(nbr, perm, axis=1)[:, _TRI_REST].reshape(-1, 2)
    x3 = nP[f3, :4] / nP[f3, 4:5]
    u3 = nP[g3[:, 0], :4] - nP[g3[:, 0], 4:5] * x3               # |n_g| = 1
    v3 = nP[g3[:, 1], :4] - nP[g3[:, 1], 4:5] * x3
    uu3, vv3, uv3 = (u3 * u3) @ _ONES, (v3 * v3) @ _ONES, (u3 * v3) @ _ONES
    sin2 = np.maximum(vv3 - uv3 * uv3 / np.maximum(uu3, TINY), 0.0) / np.maximum(vv3, TINY)
    score = np.minimum(np.minimum(uu3, vv3), sin2)
    face_id = tri @ np.array([N * N, N, 1])
    if N ** 3 < 2 ** 40:
        # One float sort: by face, best score first within a face (1 / (2 + score) lies
        # in (0, 1/2] and keeps >= 12 bits beside face ids below 2**40).
        order = np.argsort(face_id + 1.0 / (2.0 + score))
    else:                                                 # pragma: no cover - huge teams
        order = np.lexsort((-score, face_id))
    face_key = face_id[order]
    keep = np.ones(len(order), dtype=bool)
    np.not_equal(face_key[1:], face_key[:-1], out=keep[1:])
    pick = order[keep]
    face = np.full((len(pick), 5), -1, dtype=np.intp)
    face[:, :3] = tri[pick]
    return face, x3[pick], (u3[pick], v3[pick])


def _closed_form_line(xf: np.ndarray, c: np.ndarray, u: np.ndarray
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Stationary point of q + g_i on the line x_f + t u (a 1x1 system, A = u J u') and
    the reduced Hessian's eigenvalue on it; ``ok`` False where the direction is nearly
    lost to cancellation (left to the general Lagrange kernel)."""
    uu = u * u
    a11, n1 = uu @ _J, uu @ _ONES
    r1 = -((u * c) @ _ONES)
    size_u = np.sqrt(n1)                              # relative to |n_g| = 1
    ok = (np.abs(a11) > CLOSED_FORM_RTOL * n1) & (size_u > FALLBACK_SIN)
    x = xf[ok] + (r1[ok] / a11[ok])[:, None] * u[ok]
    return ok, x, a11[ok] / n1[ok]


def _closed_form_plane(xf: np.ndarray, c: np.ndarray, u: np.ndarray, v: np.ndarray
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Stationary point of q + g_i on the plane x_f + span(u, v) (a 2x2 system in closed
    form) and the reduced Hessian's smallest eigenvalue on it, in an orthonormal basis
    (Gram-Schmidt e1 = u / |u|, e2 ~ v - (v.e1) e1). Nearly parallel u, v lose digits:
    their curvature is NaN (left to the SVD-based reduced_hessian_min_eig)."""
    uu, vv = u * u, v * v
    a11, n1 = uu @ _J, uu @ _ONES
    r1 = -((u * c) @ _ONES)
    size_u = np.sqrt(n1)
    a12, a22 = (u * v) @ _J, vv @ _J
    r2 = -((v * c) @ _ONES)
    det = a11 * a22 - a12 * a12
    m2, g12 = vv @ _ONES, (u * v) @ _ONES
    n2 = n1 + m2
    size_v = np.sqrt(m2)
    sin_uv = np.sqrt(np.maximum(m2 - g12 * g12 / np.maximum(n1, TINY), 0.0) /
                     np.maximum(m2, TINY))
    ok = ((np.abs(det) > CLOSED_FORM_RTOL * n2 * n2) & (size_u > FALLBACK_SIN)
          & (size_v > FALLBACK_SIN) & (sin_uv > FALLBACK_SIN))
    t1 = (a22 * r1 - a12 * r2)[ok] / det[ok]
    t2 = (a11 * r2 - a12 * r1)[ok] / det[ok]
    x = xf[ok] + t1[:, None] * u[ok] + t2[:, None] * v[ok]
    n1, m2, g12, a11, a12, a22 = n1[ok], m2[ok], g12[ok], a11[ok], a12[ok], a22[ok]
    s1 = g12 / n1                                    # n1 > 0 where ok
    w2 = m2 - s1 * g12                               # |v - s1 u|^2
    good = w2 > GRAM_SCHMIDT_RTOL2 * m2
    w2 = np.where(good, w2, 1.0)
    h11 = a11 / n1
    h12 = (a12 - s1 * a11) / np.sqrt(n1 * w2)
    h22 = (a22 - 2.0 * s1 * a12 + s1 * s1 * a11) / w2
    half = 0.5 * (h11 - h22)
    curv = 0.5 * (h11 + h22) - np.sqrt(half * half + h12 * h12)
    return ok, x, np.where(good, curv, np.nan)


def hull_candidates(P: np.ndarray, pairs: bool, *, shortcut: bool = True,
                    unique: bool = True) -> HullCandidates:
    """Candidate sets for one formation from the upper hull of its lifted points.

    Parameters
    ----------
    P : ndarray, shape (N, 5)
        Lifted points in normalised units.
    pairs : bool
        Also emit 2-subsets (needed only when the sheet has collinear vertices).
    shortcut : bool
        Allow stationary points straight from the facet normals (else every candidate
        comes back as a subset, for the compiled kernel).
    unique : bool
        Remove repeated subsets of generic hulls (False: the caller copes with repeats).

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
        return _every_subset(N, pairs)
    thinnest = sv[min(len(sv), 5) - 1] / max(1.0, sv[0])
    if EXACT_FLAT < thinnest < NEAR_FLAT:
        # Nearly but not exactly flat (e.g. a formation within ~1e-9 of the sheet scaled,
        # the Lemma 2 configuration): neither the flat nor the full-dimensional hull is
        # numerically reliable, and the rest state's taut set is decided by the tiny
        # thickness. Every subset up to 5 for small teams (complete); otherwise the faces
        # of the flat hull together with those of a joggled full-dimensional hull.
        if N <= NEAR_FLAT_SUBSETS:
            return _every_subset(N, pairs)
        flat = _hull_faces(P, Pc, vt, d, pairs, shortcut=False)
        from scipy.spatial import ConvexHull, QhullError
        try:
            joggled = ConvexHull(Pc, qhull_options="QJ").simplices
        except QhullError:                             # pragma: no cover - last resort
            return flat
        out = dict(flat.subsets)
        for size, rows in _facet_subsets(joggled, N, pairs).items():
            _add_rows(out, size, rows, N)
        return HullCandidates(out, False)
    return _hull_faces(P, Pc, vt, d, pairs, shortcut=shortcut, unique=unique)


def _hull_faces(P: np.ndarray, Pc: np.ndarray, vt: np.ndarray, d: int, pairs: bool, *,
                shortcut: bool, unique: bool = True) -> HullCandidates:
    """Candidates from the upper faces of the hull of the lifted points ``P`` (N, 5) in
    their ``d``-dimensional affine hull (``Pc`` centred, ``vt`` its right singular vectors);
    ``shortcut``: stationary points straight from the facet normals where it applies."""
    # Qhull (scipy.spatial, ~0.2 s to import) only where a hull is built: small teams on
    # the compiled path never need it.
    from scipy.spatial import ConvexHull, QhullError

    N = len(P)
    basis = vt[:d].T                                   # (5, d)
    Y = Pc @ basis
    up = basis[4]                                      # e5 expressed in the hull's coordinates
    up_in_hull = np.linalg.norm(up) > 1.0 - UP_IN_HULL_TOL
    try:
        hull = ConvexHull(Y, qhull_options="Qt")
    except QhullError:
        try:
            hull = ConvexHull(Y, qhull_options="QJ")
        except QhullError:                             # pragma: no cover - last resort
            return _every_subset(N, pairs)
    if shortcut and d == 5 and not pairs:
        found = _stationary_from_normals(P, hull, basis)
        if found is not None:
            stationary, fallback = found
            return HullCandidates(fallback, True, stationary)
    simplices = hull.simplices
    if up_in_hull:
        upper = hull.equations[:, :d] @ up > -UPPER_NORMAL_TOL
        simplices = simplices[upper]
    out = _facet_subsets(simplices, N, pairs, unique=unique)
    if not up_in_hull and d + 1 <= 5:
        # The whole point set is a face (exposed by a direction orthogonal to its hull):
        # add one affinely independent spanning subset of it.
        i0 = int(np.argmax(np.einsum("ij,ij->i", Pc, Pc)))
        from scipy.linalg import qr

        _, _, piv = qr((P - P[i0]).T, pivoting=True, mode="economic")
        whole = np.sort(np.concatenate([[i0], piv[:d]]).astype(np.intp))
        _add_rows(out, len(whole), whole[None, :].astype(np.intp), N)
    return HullCandidates(out, d == 5)
