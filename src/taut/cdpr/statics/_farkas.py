"""Farkas certificates and the exact non-emptiness test of the null-space polyhedron
``{z : G z <= h}`` used by the available wrench set (private; the derivation is in the
docstring of :mod:`taut.cdpr.sets.wrench`)."""

from __future__ import annotations

from typing import Any

import numpy as np

from ._common import subsets as _subsets
from .._tol import MULTIPLIER_SIGN, OPPOSITE_COS, SUBSET_DEGENERACY, TINY

__all__: list[str] = []

def certificates(G: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Farkas certificates for ``G z <= h`` (G: (B, K, r)).

    Returns ``idx`` (S, r + 1) row indices, ``lam`` (r + 1, B, S) non-negative weights with
    max 1 and ``sum_k lam[k] G[idx[:, k]] = 0`` (zero for invalid subsets), and ``valid``
    (B, S). Components are kept on the leading axis so every step is a flat elementwise op.
    """
    B, K, r = G.shape
    s = r + 1
    scale = np.abs(G).max(axis=(1, 2), initial=0.0)[:, None] + TINY
    eps = SUBSET_DEGENERACY
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
        opp = (dot <= -(1 - OPPOSITE_COS) * ni * nj) & (ni > eps * scale) & (nj > eps * scale)
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
    lam /= np.where(tot < 0, -mx, mx) + TINY
    low = lam[0].copy()
    for k in range(1, s):
        np.minimum(low, lam[k], out=low)
    valid = (mx > eps * scale ** r) & (low >= -MULTIPLIER_SIGN)
    np.maximum(lam, 0.0, out=lam)
    lam *= valid
    return idx, lam, valid


def nonempty(G: np.ndarray, h: np.ndarray, tol: float, cert: Any = None) -> np.ndarray:
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
            return np.all(combine(lam, idx, h) >= -tol, axis=1)
        V = G @ np.swapaxes(Z, 1, 2)                      # (B, K, candidates)
        V -= h[:, :, None]
        return np.any(V.max(axis=1) <= tol, axis=1)


def combine(lam: np.ndarray, idx: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """``sum_k lam[k] * rows[:, idx[:, k]]`` for rows (B, K) -> (B, S) or (B, K, n) ->
    (B, S, n)."""
    extra = (None,) * (rows.ndim - 2)
    out = lam[0][(...,) + extra] * rows[:, idx[:, 0]]
    for k in range(1, lam.shape[0]):
        out += lam[k][(...,) + extra] * rows[:, idx[:, k]]
    return out
