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


def _unique_rows(rows: np.ndarray, N: int) -> np.ndarray:
    rows = np.sort(rows, axis=1)
    s = rows.shape[1]
    if N ** s < 2 ** 62:
        key = np.zeros(len(rows), dtype=np.int64)
        for c in range(s):
            key = key * N + rows[:, c]
        _, first = np.unique(key, return_index=True)
        return rows[np.sort(first)]
    return np.unique(rows, axis=0)


def _facet_subsets(simplices: np.ndarray, N: int, pairs: bool) -> dict[int, np.ndarray]:
    out: dict[int, np.ndarray] = {}
    width = simplices.shape[1]
    for s in sizes_for(N, pairs):
        if s > width:
            continue
        sub = simplices[:, combo_table(width, s)].reshape(-1, s)
        out[s] = _unique_rows(sub, N)
    return out


def hull_subsets(P: np.ndarray, pairs: bool) -> dict[int, np.ndarray]:
    """Candidate sets for one formation from the upper hull of its lifted points.

    Parameters
    ----------
    P : ndarray, shape (N, 5)
        Lifted points in normalised units.
    pairs : bool
        Also emit 2-subsets (needed only when the sheet has collinear vertices).

    Returns
    -------
    dict
        ``size -> subsets (M_s, size)``.

    Degenerate inputs (the lifted points span fewer than 5 dimensions, e.g. the FK
    paper's Lemma 2 and Table V where all of them lie on a 2-plane) are handled in the
    affine hull of the points: if the "up" axis lies in that hull only its upper faces
    can be exposed; otherwise every face can, including the whole point set.
    """
    N = len(P)
    centre = P.mean(axis=0)
    Pc = P - centre
    _, sv, vt = np.linalg.svd(Pc, full_matrices=False)
    d = int(np.sum(sv > RANK_TOL * max(1.0, sv[0])))
    if N <= d + 1 or N <= 5:
        return {s: combo_table(N, s) for s in sizes_for(N, pairs)}
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
            return {s: combo_table(N, s) for s in sizes_for(N, pairs)}
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
        out[s] = row if s not in out else _unique_rows(np.vstack([out[s], row]), N)
    return out
