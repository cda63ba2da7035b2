"""The similar copy of the sheet closest to a formation (the FK paper's Lemma 2
configuration, docs/sheet_fk_solver.md "Next to a similar copy")."""

from __future__ import annotations

import numpy as np

__all__ = ["similar_copy"]


def similar_copy(vertices: np.ndarray, formations: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Closest similar copy ``s Q V + t`` of the sheet to each formation (Procrustes fit,
    rotation only, no reflection; centroid kept).

    Returns the copies (B, N, 2), their scale factors ``s`` (B,) and the largest robot
    displacement to reach them (B,), in the formations' unit (inf where the best fit
    needs a reflection)."""
    A = vertices - vertices.mean(axis=0)
    rc = formations.mean(axis=1, keepdims=True)
    M = np.einsum("ni,bnj->bij", A, formations - rc)              # (B, 2, 2)
    U, S, Wt = np.linalg.svd(M)
    Q = np.swapaxes(U @ Wt, 1, 2)                                 # rotation: A -> formation
    scale = S.sum(axis=1) / np.sum(A * A)
    copies = scale[:, None, None] * (A @ np.swapaxes(Q, 1, 2)) + rc
    dist = np.abs(copies - formations).max(axis=(1, 2))
    dist[np.linalg.det(Q) < 0] = np.inf
    return copies, scale, dist
