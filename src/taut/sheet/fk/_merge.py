"""One physical rest state, one answer: equilibria whose object and contact points coincide
within ``MERGE_RTOL`` of the sheet size are merged (docs/sheet_fk_solver.md, "One state,
one answer").

Near a similar copy of the sheet (regular sheets at a scaled copy, coordinates written to
finite digits, noise far below any physical scale) the lifted points are nearly
co-planar and float64 splits one rest point into several candidate taut sets, each
reported as its own "state". The merged state keeps the lowest member's object and
contact point (a stable member first) and that member's taut set: the cables at full
length at that point (the one definition, :func:`taut.sheet._lifted.taut_at`, which the
solvers evaluated there on the formation they solved). Not the union of the members' taut
sets: a member up to ``MERGE_RTOL`` away can have a cable taut that is slack by ~1e-6 of
the squared size at the kept point, where the simulator, testing the cables at its own
point, calls it slack (issue 25). Its weights are the minimum-norm non-negative weights
of that set (``_finalize._weights_family``: an SVD-truncated, well-conditioned solve), and
its kind the best of the members' (stable before saddle before not an equilibrium). An
engine helper: used by the result constructors of every method, backend and the batch.
"""

from __future__ import annotations

import numpy as np

from ._finalize import _weights_family
from .._lifted import Frame
from .._tol import MERGE_RTOL

__all__ = ["coincident_groups", "merged_weights"]


def coincident_groups(obj: np.ndarray, contact: np.ndarray, size: float) -> np.ndarray | None:
    """Labels (K,) of states whose object (K, 3) and contact (K, 2) points coincide within
    ``MERGE_RTOL * size`` (single linkage, max-norm of both distances), or None when all
    ``K`` states are distinct (the common case, decided by one pairwise comparison)."""
    K = len(obj)
    if K < 2:
        return None
    tol = MERGE_RTOL * size
    d = np.maximum(np.abs(obj[:, None, :] - obj[None, :, :]).max(axis=2),
                   np.abs(contact[:, None, :] - contact[None, :, :]).max(axis=2))
    close = (d <= tol) | np.eye(K, dtype=bool)
    if np.count_nonzero(close) == K:             # only the diagonal
        return None
    labels = np.arange(K)
    changed = True
    while changed:                               # single-linkage components (K is small)
        new = np.where(close, labels[None, :], K).min(axis=1)
        changed = bool(np.any(new != labels))
        labels = new[new]
    return labels


def merged_weights(vertices: np.ndarray, formation: np.ndarray, hold_height: float,
                   scale: float, idx: np.ndarray, r_o: np.ndarray, v_o: np.ndarray
                   ) -> np.ndarray:
    """Minimum-norm non-negative load shares (k,) of taut cables ``idx`` holding the
    object at ``r_o`` (2,) with contact ``v_o`` (2,), caller's units (FK paper eqs. 10-12:
    :math:`\\sum w_i \\mathbf{r}_i = \\mathbf{r}_o`, :math:`\\sum w_i \\mathbf{v}_i =
    \\mathbf{v}_o`, :math:`\\sum w_i = 1`)."""
    frame = Frame.build(vertices, formation[None], hold_height, scale)
    ro = (np.asarray(r_o, dtype=np.float64) - frame.r_centre[0]) / scale
    vo = (np.asarray(v_o, dtype=np.float64) - frame.v_centre) / scale
    w, _ = _weights_family(frame, 0, idx, ro, vo)
    return np.asarray(w, dtype=np.float64)
