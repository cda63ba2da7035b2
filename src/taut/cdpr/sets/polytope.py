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

from ..._validate import as_array, as_flag, check_range
from ...errors import InvalidInputError
from .._tol import CONTAINS_TOL, SPAN_TOL, ZERO_ROW
from ..._repr import CompactRepr

__all__ = ["HPolytopeBatch", "lp_max_step"]


@dataclass(frozen=True, repr=False)
class HPolytopeBatch(CompactRepr):
    """B polyhedra ``{x : H x <= h, E x = 0}`` in R^n, or one polyhedron.

    One polyhedron (the set at one pose) has no leading axis (``H`` (S, n), ``h`` (S,),
    ``E`` (k, n)) and its methods return scalars (``contains`` a bool) instead of (B,)
    arrays: the batching rule of :mod:`taut.cdpr._batching`.

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
    >>> one = HPolytopeBatch(box.H[0], box.h[0], box.E[0])     # one polyhedron
    >>> one.contains([0.5, -1.5]), float(one.margin([0.5, -1.5]))
    (True, 0.5)
    """

    H: np.ndarray
    h: np.ndarray
    E: np.ndarray

    @property
    def single(self) -> bool:
        """Whether this is one polyhedron (no leading batch axis)."""
        return bool(self.H.ndim == 2)

    @property
    def batch(self) -> int:
        """Number of polyhedra B (1 for a single polyhedron)."""
        return 1 if self.single else int(self.H.shape[0])

    @property
    def dim(self) -> int:
        """Ambient dimension n."""
        return int(self.H.shape[-1])

    def _rows(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(H, h, E)`` with a leading batch axis (added for a single polyhedron)."""
        if self.single:
            return self.H[None], self.h[None], self.E[None]
        return self.H, self.h, self.E

    def _out(self, value: np.ndarray) -> Any:
        """Per-polyhedron results (B, ...) -> without the batch axis for one polyhedron."""
        if not self.single:
            return value
        v = value[0]
        return bool(v) if isinstance(v, np.bool_) else v

    def _points(self, x: Any, field: str) -> np.ndarray:
        """Validate one point (n,) or one per polyhedron (B, n) -> (B, n)."""
        n, B = self.dim, self.batch
        p = as_array(x, field)
        if p.ndim not in (1, 2) or p.shape[-1] != n or (p.ndim == 2 and p.shape[0] not in (1, B)):
            raise InvalidInputError(field, f"must have {n} components, one point or one per "
                                           "pose")
        return np.broadcast_to(p, (B, n))

    def contains(self, x: ArrayLike, tol: float = CONTAINS_TOL) -> Any:
        """Whether points ``(n,)`` or ``(B, n)`` lie in the polyhedra -> (B,) bool (a bool
        for one polyhedron); ``tol`` is an absolute slack in the set's units."""
        return self._out(self._contains(x, tol))

    def _contains(self, x: ArrayLike, tol: float) -> np.ndarray:
        H, h, E = self._rows()
        p = self._points(x, "point")
        ok = np.all(np.einsum("bsn,bn->bs", H, p) <= h + tol, axis=1)
        if E.shape[1]:
            ok &= np.all(np.abs(np.einsum("bkn,bn->bk", E, p)) <= tol, axis=1)
        return ok

    def margin(self, x: ArrayLike) -> Any:
        """``min_s (h_s - H_s x)`` (B,) (a float for one polyhedron): distance of ``x`` to
        the boundary along the unit normals when inside, negative outside (equality
        violations count as ``-|E x|``)."""
        H, h, E = self._rows()
        p = self._points(x, "point")
        m = np.min(h - np.einsum("bsn,bn->bs", H, p), axis=1)
        if E.shape[1]:
            m = np.minimum(m, -np.abs(np.einsum("bkn,bn->bk", E, p)).max(axis=1))
        return self._out(m)

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

        For one polyhedron ``origin`` is (n,) and both results are scalars.
        """
        H, h, E = self._rows()
        if origin is not None and self.single:
            origin = np.asarray(origin)[None]
        c = np.einsum("bsn,n->bs", H, direction)
        slack = h if origin is None else h - np.einsum("bsn,bn->bs", H, origin)
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = slack / c
            loose = (slack + tol) / c            # every row relaxed by tol, as in contains
        hi = np.min(np.where(c > zero, ratio, np.inf), axis=1)
        lo = np.max(np.where(c < -zero, ratio, -np.inf), axis=1)
        zero_ok = np.all((np.abs(c) > zero) | (slack >= -tol), axis=1)
        # Whether some s >= 0 satisfies every row to within tol. The slack tol of a row is
        # tol / |c| along the ray (|c| <= 1 for unit rows and a unit direction), so the
        # interval test is made on the relaxed rows, not on s with the row tolerance (that
        # missed a point-like interval, lo - hi ~ 3e-8 N with tol 1.5e-8 N, that the LP
        # finds: tests/cdpr/sets/test_wrench_set.py::test_random_point_mass_robots).
        hi_loose = np.min(np.where(c > zero, loose, np.inf), axis=1)
        lo_loose = np.max(np.where(c < -zero, loose, -np.inf), axis=1)
        reach = zero_ok & ((hi >= np.maximum(lo, 0.0) - tol)
                           | (hi_loose >= np.maximum(lo_loose, 0.0)))
        if E.shape[1]:
            along = np.abs(np.einsum("bkn,n->bk", E, direction)).max(axis=1) <= SPAN_TOL
            hi = np.where(along, hi, 0.0)
        return self._out(np.where(reach, np.maximum(hi, 0.0), 0.0)), self._out(reach)

    def axis_ray_lengths(self, origin: np.ndarray | None, *, tol: float, sign: float = 1.0,
                         zero: float = ZERO_ROW
                         ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`ray_lengths` along ``+sign e_k`` and ``-sign e_k`` for every axis k.

        Returns ``positive`` (B, n), ``negative`` (B, n) and ``reach`` (B, n, 2) (columns
        ``+``, ``-``; one polyhedron: (n,), (n,), (n, 2)). ``sign = -1`` measures along
        ``-e_k`` for "positive" (used by the wrench set, whose points are cable wrenches
        opposing the external wrench).
        """
        if self.single:
            H, h, E = self._rows()
            o = None if origin is None else np.asarray(origin)[None]
            pos, neg, reach = HPolytopeBatch(H, h, E).axis_ray_lengths(o, tol=tol, sign=sign,
                                                                       zero=zero)
            return pos[0], neg[0], reach[0]
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
        Hs, hs, Es = self._rows()
        if np.any(hs[k] == -np.inf):
            return -np.inf
        keep = np.isfinite(hs[k])
        E = Es[k]
        sol = linprog(-d, A_ub=Hs[k][keep], b_ub=hs[k][keep],
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
        Hs, hs, _ = self._rows()
        keep = np.isfinite(hs[k])
        Hk, hk = Hs[k][keep], hs[k][keep]
        _, first = np.unique(np.round(np.column_stack([Hk, hk]), 9), axis=0,
                             return_index=True)
        first.sort()
        return Hk[first], hk[first]


#: Largest |coefficient| :func:`lp_max_step` accepts (tensions, wrenches and joint rates
#: stay many orders below; HiGHS treats 1e20 as infinite).
_LP_MAX = 1e15


def _lp_bounds(x_bounds: Any, nx: int) -> list[tuple[float | None, float | None]]:
    """``x_bounds`` as ``nx`` pairs ``(low, high)``, each a number or None (unbounded)."""
    if isinstance(x_bounds, (str, bytes)) or not hasattr(x_bounds, "__len__"):
        raise InvalidInputError("x_bounds", f"must be {nx} (low, high) pairs")
    if len(x_bounds) != nx:
        raise InvalidInputError("x_bounds", f"must be {nx} (low, high) pairs, got "
                                            f"{len(x_bounds)}")
    out: list[tuple[float | None, float | None]] = []
    for k, pair in enumerate(x_bounds):
        if isinstance(pair, (str, bytes)) or not hasattr(pair, "__len__") or len(pair) != 2:
            raise InvalidInputError(f"x_bounds[{k}]", "must be a (low, high) pair")
        lo, hi = (_lp_bound(v, f"x_bounds[{k}]") for v in pair)
        out.append((lo, hi))
    return out


def _lp_bound(value: Any, field: str) -> float | None:
    """One LP bound: None or +-inf (unbounded) or a number within ``_LP_MAX``."""
    if value is None:
        return None
    arr = as_array(value, field, ndim=0) if not (
        isinstance(value, (float, np.floating)) and np.isinf(value)) else None
    if arr is None:
        return float(value)
    return float(check_range(arr, field, _LP_MAX, "units"))


def lp_max_step(A_eq_x: np.ndarray, step_col: np.ndarray, b_eq: np.ndarray,
                x_bounds: Sequence[tuple[float | None, float | None]], *,
                A_ub_x: np.ndarray | None = None, b_ub: np.ndarray | None = None,
                step_first: bool = False) -> tuple[int, float]:
    """``max s >= 0`` subject to ``A_eq_x x + step_col s = b_eq``, ``x`` in its bounds and
    ``A_ub_x x <= b_ub``, by HiGHS: the LP twin of :meth:`HPolytopeBatch.ray_lengths`
    written over the joint variables (tensions or joint rates) instead of the H-rep.

    Returns ``(status, s)``: scipy's status (0 solved, 2 infeasible, 3 unbounded) and the
    optimal step (NaN unless solved). ``step_first`` puts ``s`` before ``x`` in the
    variable vector (the order only matters for ties between optimal vertices).
    """
    A_eq_x = check_range(as_array(A_eq_x, "A_eq_x", ndim=2), "A_eq_x", _LP_MAX, "units")
    ne, nx = A_eq_x.shape
    step_col = check_range(as_array(step_col, "step_col", shape=(ne,)), "step_col", _LP_MAX,
                           "units")
    b_eq = check_range(as_array(b_eq, "b_eq", shape=(ne,)), "b_eq", _LP_MAX, "units")
    x_bounds = _lp_bounds(x_bounds, nx)
    step_first = as_flag(step_first, "step_first")
    if (A_ub_x is None) != (b_ub is None):
        raise InvalidInputError("A_ub_x" if A_ub_x is None else "b_ub",
                                "give A_ub_x and b_ub together")
    if A_ub_x is not None:
        A_ub_x = check_range(as_array(A_ub_x, "A_ub_x", shape=(None, nx)), "A_ub_x", _LP_MAX,
                             "units")
        b_ub = check_range(as_array(b_ub, "b_ub", shape=(A_ub_x.shape[0],)), "b_ub", _LP_MAX,
                           "units")
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
