"""One batched H-polytope type for the available wrench set and the available twist set.

A batch of B polyhedra ``{x : H x <= h, E x = 0}`` in R^n (one per platform pose), with
``H`` (B, S, n) unit rows (zero rows with ``h = +inf`` are unused padding, so every pose
has the same S), ``h`` (B, S) and ``E`` (B, k, n) orthonormal equality rows (k = 0 when
the set is full-dimensional). The wrench set of FASTKIT eq. 24 and the twist set of
eqs. 10-16 are both such batches; their membership tests, margins, ray lengths along the
axes (capacities, FASTKIT Figs. 13-14), support functions and LP cross-checks are written
once here.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import linprog

from .._validate import as_array
from ..errors import InvalidInputError
from ._tol import CONTAINS_TOL, SPAN_TOL, ZERO_ROW

__all__ = ["HPolytopeBatch", "lp_max_step"]


@dataclass(frozen=True)
class HPolytopeBatch:
    """B polyhedra ``{x : H x <= h, E x = 0}`` in R^n.

    Attributes
    ----------
    H : (B, S, n)
        Inequality rows (unit norm; zero rows with ``h = +inf`` are unused).
    h : (B, S)
        Offsets.
    E : (B, k, n)
        Orthonormal equality rows (k may be 0).

    Examples
    --------
    >>> import numpy as np
    >>> box = HPolytopeBatch(np.array([[[1.0, 0], [-1, 0], [0, 1], [0, -1]]]),
    ...                      np.array([[1.0, 1, 2, 2]]), np.zeros((1, 0, 2)))
    >>> box.contains([0.5, -1.5]).tolist(), box.margin([0.5, -1.5]).tolist()
    ([True], [0.5])
    """

    H: np.ndarray
    h: np.ndarray
    E: np.ndarray

    @property
    def batch(self) -> int:
        """Number of polyhedra B."""
        return int(self.H.shape[0])

    @property
    def dim(self) -> int:
        """Ambient dimension n."""
        return int(self.H.shape[2])

    def _points(self, x: Any, field: str) -> np.ndarray:
        """Validate one point (n,) or one per polyhedron (B, n) -> (B, n)."""
        n, B = self.dim, self.batch
        p = as_array(x, field)
        if p.ndim not in (1, 2) or p.shape[-1] != n or (p.ndim == 2 and p.shape[0] not in (1, B)):
            raise InvalidInputError(field, f"must have {n} components, one point or one per "
                                           "pose")
        return np.broadcast_to(p, (B, n))

    def contains(self, x: ArrayLike, tol: float = CONTAINS_TOL) -> np.ndarray:
        """Whether points ``(n,)`` or ``(B, n)`` lie in the polyhedra -> (B,) bool; ``tol``
        is an absolute slack in the set's units."""
        p = self._points(x, "point")
        ok = np.all(np.einsum("bsn,bn->bs", self.H, p) <= self.h + tol, axis=1)
        if self.E.shape[1]:
            ok &= np.all(np.abs(np.einsum("bkn,bn->bk", self.E, p)) <= tol, axis=1)
        return ok

    def margin(self, x: ArrayLike) -> np.ndarray:
        """``min_s (h_s - H_s x)`` (B,): distance of ``x`` to the boundary along the unit
        normals when inside, negative outside (equality violations count as ``-|E x|``)."""
        p = self._points(x, "point")
        m = np.min(self.h - np.einsum("bsn,bn->bs", self.H, p), axis=1)
        if self.E.shape[1]:
            m = np.minimum(m, -np.abs(np.einsum("bkn,bn->bk", self.E, p)).max(axis=1))
        return m

    def ray_lengths(self, origin: np.ndarray | None, direction: np.ndarray, *,
                    tol: float, zero: float = ZERO_ROW) -> tuple[np.ndarray, np.ndarray]:
        """Largest ``s >= 0`` with ``origin + s d`` in the set, per polyhedron.

        Parameters
        ----------
        origin : (B, n) or None (the origin)
        direction : (n,)
        tol : float
            Slack on the rows at ``s = 0`` and on the interval test (set units).
        zero : float
            Row components ``|H d| <= zero`` count as parallel to the ray.

        Returns
        -------
        length : (B,)
            The largest step (``inf`` when unbounded; 0 where ``reach`` is False, and where
            the direction leaves the span of ``E``'s complement).
        reach : (B,) bool
            Whether ``s = 0`` (or some ``s >= 0``) is in the set at all.
        """
        c = np.einsum("bsn,n->bs", self.H, direction)
        slack = self.h if origin is None else self.h - np.einsum("bsn,bn->bs", self.H, origin)
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = slack / c
        hi = np.min(np.where(c > zero, ratio, np.inf), axis=1)
        lo = np.max(np.where(c < -zero, ratio, -np.inf), axis=1)
        zero_ok = np.all((np.abs(c) > zero) | (slack >= -tol), axis=1)
        reach = zero_ok & (hi >= np.maximum(lo, 0.0) - tol)
        if self.E.shape[1]:
            along = np.abs(np.einsum("bkn,n->bk", self.E, direction)).max(axis=1) <= SPAN_TOL
            hi = np.where(along, hi, 0.0)
        return np.where(reach, np.maximum(hi, 0.0), 0.0), reach

    def axis_ray_lengths(self, origin: np.ndarray | None, *, tol: float, sign: float = 1.0,
                         zero: float = ZERO_ROW
                         ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`ray_lengths` along ``+sign e_k`` and ``-sign e_k`` for every axis k.

        Returns ``positive`` (B, n), ``negative`` (B, n) and ``reach`` (B, n, 2) (columns
        ``+``, ``-``). ``sign = -1`` measures along ``-e_k`` for "positive" (used by the
        wrench set, whose points are cable wrenches opposing the external wrench).
        """
        B, n = self.batch, self.dim
        pos, neg = np.zeros((B, n)), np.zeros((B, n))
        reach = np.zeros((B, n, 2), dtype=bool)
        for k in range(n):
            for sgn, out, col in ((1.0, pos, 0), (-1.0, neg, 1)):
                d = np.zeros(n)
                d[k] = sign * sgn
                out[:, k], reach[:, k, col] = self.ray_lengths(origin, d, tol=tol, zero=zero)
        return pos, neg, reach

    def support(self, direction: ArrayLike, k: int = 0) -> float:
        """Support function ``max d . x`` over polyhedron ``k`` (LP over the H-rep, HiGHS);
        ``inf`` when unbounded, ``-inf`` when empty."""
        d = as_array(direction, "direction", shape=(self.dim,))
        if np.any(self.h[k] == -np.inf):
            return -np.inf
        keep = np.isfinite(self.h[k])
        E = self.E[k]
        sol = linprog(-d, A_ub=self.H[k][keep], b_ub=self.h[k][keep],
                      A_eq=E if E.shape[0] else None,
                      b_eq=np.zeros(E.shape[0]) if E.shape[0] else None,
                      bounds=[(None, None)] * d.size, method="highs")
        if sol.status == 3:
            return np.inf
        if sol.status != 0:
            return -np.inf
        return float(-sol.fun)

    def facets(self, k: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """Distinct rows ``(H, h)`` of polyhedron ``k`` (redundant rows may remain)."""
        keep = np.isfinite(self.h[k])
        Hk, hk = self.H[k][keep], self.h[k][keep]
        _, first = np.unique(np.round(np.column_stack([Hk, hk]), 9), axis=0,
                             return_index=True)
        first.sort()
        return Hk[first], hk[first]


def lp_max_step(A_eq_x: np.ndarray, step_col: np.ndarray, b_eq: np.ndarray,
                x_bounds: Sequence[tuple[float, float | None]], *,
                A_ub_x: np.ndarray | None = None, b_ub: np.ndarray | None = None,
                step_first: bool = False) -> tuple[int, float]:
    """``max s >= 0`` subject to ``A_eq_x x + step_col s = b_eq``, ``x`` in its bounds and
    ``A_ub_x x <= b_ub``, by HiGHS: the LP twin of :meth:`HPolytopeBatch.ray_lengths`
    written over the joint variables (tensions or joint rates) instead of the H-rep.

    Returns ``(status, s)``: scipy's status (0 solved, 2 infeasible, 3 unbounded) and the
    optimal step (NaN unless solved). ``step_first`` puts ``s`` before ``x`` in the
    variable vector (the order only matters for ties between optimal vertices).
    """
    nx = A_eq_x.shape[1]
    col = step_col.reshape(-1, 1)
    if step_first:
        Aeq = np.hstack([col, A_eq_x])
        bounds = [(0.0, None)] + list(x_bounds)
        Aub = None if A_ub_x is None else np.hstack([np.zeros((A_ub_x.shape[0], 1)), A_ub_x])
        c = np.zeros(1 + nx)
        c[0] = -1.0
    else:
        Aeq = np.hstack([A_eq_x, col])
        bounds = list(x_bounds) + [(0.0, None)]
        Aub = None if A_ub_x is None else np.hstack([A_ub_x, np.zeros((A_ub_x.shape[0], 1))])
        c = np.zeros(nx + 1)
        c[-1] = -1.0
    sol = linprog(c, A_ub=Aub, b_ub=b_ub, A_eq=Aeq, b_eq=b_eq, bounds=bounds, method="highs")
    if sol.status != 0:
        return int(sol.status), float("nan")
    return 0, float(sol.x[0] if step_first else sol.x[-1])
