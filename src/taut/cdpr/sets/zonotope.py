"""Facets of zonotopes ``{c + G s : |s|_inf <= 1}``, batched: the hyperplane description
used by the exact available twist set (FASTKIT eqs. 10-16)."""

from __future__ import annotations

import numpy as np

from ..._validate import as_array, check_range
from ...errors import InvalidInputError

#: Largest |generator or center component| accepted (twists and wrenches stay far below).
_ZONO_MAX = 1e12
from ..statics._common import subsets as _subsets
from .._tol import SUBSET_DEGENERACY, TINY

__all__ = ["zonotope_hrep"]


def zonotope_hrep(center: np.ndarray, gens: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Facets of full-dimensional zonotopes ``{c + G s : |s|_inf <= 1}`` in R^d, batched.

    Each (d-1)-subset of generators spanning a hyperplane gives the facet pair
    ``+-n . x <= +-n . c + sum_j |n . g_j|`` with ``n`` its unit normal (the direction of
    the generalised cross product, taken from a complete QR factorisation). Degenerate
    subsets get zero rows with ``+inf`` offsets.

    Parameters
    ----------
    center : (B, d)
    gens : (B, d, g)

    Returns
    -------
    H : (B, 2S, d) unit rows, h : (B, 2S)
    """
    gens = check_range(as_array(gens, "gens", ndim=3), "gens", _ZONO_MAX, "units")
    Bn, d, g = gens.shape
    center = check_range(as_array(center, "center", shape=(Bn, d)), "center", _ZONO_MAX,
                         "units")
    if Bn == 0 or d == 0:
        raise InvalidInputError("gens", "is empty (shape "
                                        f"{'x'.join(map(str, gens.shape))})")
    if g < d or np.any(np.linalg.matrix_rank(gens) < d):
        raise InvalidInputError("limits", "the joints that may move do not span every "
                                          "direction (give each cable a speed range with "
                                          "min < max)")
    sub = _subsets(g, d - 1)
    Gs = np.swapaxes(gens[:, :, sub], 1, 2)                       # (B, S, d, d-1)
    # The last column of a complete QR factor spans the orthogonal complement of the
    # subset (the direction of its generalised cross product); a tiny R diagonal flags a
    # subset that does not span a hyperplane.
    Q, R = np.linalg.qr(Gs, mode="complete")
    N = Q[..., -1]                                                 # (B, S, d), unit
    rdiag = np.abs(np.diagonal(R, axis1=-2, axis2=-1)).min(axis=-1)
    scale = np.abs(gens).max(axis=(1, 2))[:, None] + TINY
    ok = rdiag > SUBSET_DEGENERACY * scale
    N = np.where(ok[..., None], N, 0.0)
    off = np.abs(np.einsum("bsd,bdg->bsg", N, gens)).sum(axis=2)
    nc = np.einsum("bsd,bd->bs", N, center)
    H = np.concatenate([N, -N], axis=1)
    h = np.concatenate([np.where(ok, nc + off, np.inf), np.where(ok, -nc + off, np.inf)], axis=1)
    return H, h


def _facets_base_and_identity(center: np.ndarray, Gb: np.ndarray, hc: np.ndarray
                              ) -> tuple[np.ndarray, np.ndarray]:
    """Facets of the task-mode zonotope with generators ``[Gb, diag(hc)]`` (hc > 0), batched.

    Same facets as :func:`zonotope_hrep`, faster: a (m-1)-subset with ``j`` base columns and
    ``m-1-j`` cable columns ``e_i`` has a normal supported on the ``j+1`` cables it leaves
    out, orthogonal there to the ``j`` base columns, so only (j+1) x j problems are solved.

    Parameters
    ----------
    center : (B, m); Gb : (B, m, g) scaled base columns; hc : (m,) cable half-ranges.
    """
    Bn, m, g = Gb.shape
    normals = []
    for j in range(0, min(g, m - 1) + 1):
        cs = _subsets(m, j + 1)                                    # (nC, j+1) free cables
        for sb in _subsets(g, j):
            sub = Gb[:, cs][:, :, :, sb] if j else np.zeros((Bn, len(cs), j + 1, 0))
            if j:
                Q, R = np.linalg.qr(sub, mode="complete")          # (B, nC, j+1, j+1)
                nc = Q[..., -1]
                rd = np.abs(np.diagonal(R, axis1=-2, axis2=-1)).min(axis=-1)
                ok = rd > SUBSET_DEGENERACY * (np.abs(Gb).max(axis=(1, 2))[:, None] + TINY)
                nc = np.where(ok[..., None], nc, 0.0)
            else:
                nc = np.ones((Bn, len(cs), 1))
            n = np.zeros((Bn, len(cs), m))
            np.put_along_axis(n, np.broadcast_to(cs, (Bn,) + cs.shape), nc, axis=2)
            normals.append(n)
    N = np.concatenate(normals, axis=1)
    ok = np.any(N != 0.0, axis=2)
    off = (np.abs(np.einsum("bsd,bdg->bsg", N, Gb)).sum(axis=2)
           + np.abs(N * hc).sum(axis=2))
    nc = np.einsum("bsd,bd->bs", N, center)
    H = np.concatenate([N, -N], axis=1)
    h = np.concatenate([np.where(ok, nc + off, np.inf), np.where(ok, -nc + off, np.inf)], axis=1)
    return H, h
