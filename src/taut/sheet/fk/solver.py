"""A forward-kinematics solver object for one sheet at one hold height.

Everything that depends only on the sheet and the hold height (normalised vertices,
candidate subset tables, pair limits for the formation check) is computed once; each
:meth:`FKSolver.solve` then costs the solve itself. Teams of up to ``KERNEL_MAX_N``
robots run the compiled kernel of ``_small_kernel`` (numba): every candidate of at most
five cables up to ``COMPILED_MAX_N`` robots, the upper-hull faces above. Larger teams, the
exhaustive method, and every team when numba is missing or ``backend="numpy"``, run the
numpy engine (:mod:`taut.sheet.fk._numpy`). Both give the same equilibria (tested
against each other; docs/sheet_fk_solver.md). An engine: it never imports the front end
(:mod:`taut.sheet.fk.forward`).
"""

from __future__ import annotations

import weakref
from types import ModuleType
from typing import Any, Callable

import numpy as np
from numpy.typing import ArrayLike

from ..._jit import HAVE_NUMBA, not_compiled_reason
from ..._validate import as_array, as_choice, require_nonempty
from ...errors import InvalidInputError
from ._candidates import hull_candidates, padded_small_subsets
from ._finalize import _min_eig_family, _weights_family
from .._lifted import Frame, pad_groups
from .._tol import CURVATURE_TOL, GEOMETRY_RTOL, SCREEN_SLACK, SNAP_MIN, SNAP_TOL, WEIGHT_TOL
from ._numpy import forward_numpy, forward_numpy_batch
from .._options import BACKENDS, METHODS, Backend, Method
from ._batch_result import batch_from_rows
from ._similar import similar_copy
from ..model import Sheet, check_formation, check_formations, feasible_formations
from .results import BatchFKResult, FKResult
from ..team import SheetTeam, require_team

__all__ = ["FKSolver", "COMPILED_MAX_N", "HAVE_NUMBA"]

# HAVE_NUMBA (taut._jit): this process runs the compiled kernels. The kernel module (and
# numba) is imported on the first solver that uses it, so that ``import taut`` stays fast.

sk: ModuleType = None  # type: ignore[assignment]   # taut.sheet._kernels.small, once loaded
bk: ModuleType = None  # type: ignore[assignment]   # taut.sheet._kernels.batch, once loaded


def _load_kernel() -> ModuleType:
    global sk
    if sk is None:
        from .._kernels import small as _small_kernel
        sk = _small_kernel
    return sk

def _batch_kernel() -> ModuleType:
    """taut.sheet._kernels.batch (imported with numba on first use)."""
    global bk
    if bk is None:
        from .._kernels import batch as _batch_kernel
        bk = _batch_kernel
    return bk


#: Up to this team size the default method ("fast") gives the compiled kernel every
#: subset of at most five cables (one cached table); above it, the upper-hull faces of
#: each formation (Qhull) -- every subset costs O(N^5) and loses from N ~ 13 on
#: (measured with bench/bench_fk.py: N = 12 all subsets 0.56 ms, hull path 1.5 ms).
COMPILED_MAX_N = 12
#: Largest team the kernel handles at all (its sort keys pack a taut set in 64 bits).
KERNEL_MAX_N = 30
#: Largest team the ``"subsets"`` method accepts: it tries every set of at most five
#: cables, so its work grows as N**5 (N = 40: 760 000 systems, about a minute on one core).
SUBSETS_MAX_ROBOTS = 40


class FKSolver:
    """Forward kinematics of one sheet team (sheet, hold height, object mass), for many
    formations.

    Parameters
    ----------
    team : SheetTeam
        The sheet (vertices in the sheet frame, any length unit), the height :math:`z_r`
        of the holding points (same unit) and the object mass (kg, for the tensions).
    method : {"fast", "exhaustive", "subsets"}
        As in :func:`~taut.sheet.forward_kinematics`.
    backend : {"auto", "numba", "numpy"}
        ``"auto"``: the compiled kernel where it applies (numba installed, ``method`` not
        ``"exhaustive"``, ``N <= KERNEL_MAX_N``), else numpy. ``"numba"`` insists on the
        kernel (an error where it does not apply); ``"numpy"`` never uses it.

    Attributes
    ----------
    team : SheetTeam
        The team solved for.
    sheet : Sheet
        ``team.sheet``.
    hold_height : float
        ``team.hold_height``.
    backend : str
        The backend actually used, ``"numba"`` or ``"numpy"``.

    Examples
    --------
    >>> import numpy as np
    >>> import taut.sheet as ts
    >>> team = ts.SheetTeam(ts.Sheet([[0, 0], [1, 0], [1, 1], [0, 1]]), 1.0)
    >>> solver = ts.FKSolver(team)
    >>> res = solver.solve([[0, 0], [0.9, 0], [0.9, 0.9], [0, 0.9]])
    >>> [e.taut for e in res.stable]
    [(0, 1, 2, 3)]
    >>> np.round(res.lowest.object, 4).tolist()   # 1 - sqrt(0.5 - 0.405): cables of 0.7071
    [0.45, 0.45, 0.6918]
    >>> batch = solver.solve_batch(np.stack([res.formation, res.formation + 0.1]))
    >>> batch.count.tolist()
    [1, 1]
    """

    __slots__ = ("team", "sheet", "hold_height", "method", "backend", "_Vn", "_table", "_sizes",
                 "_scale", "_vcx", "_vcy", "_lim2", "_width", "_hull", "_A", "_args",
                 "_fast", "_shape", "_mass", "_pack", "_out_shape", "_make", "_make_out",
                 "_solve_one",
                 "__weakref__")

    def __init__(self, team: SheetTeam, *, method: Method = "fast",
                 backend: Backend = "auto") -> None:
        self.team = require_team(team)
        self.sheet = sheet = team.sheet
        self.hold_height = team.hold_height
        self.method = as_choice(method, METHODS, "method")
        backend = as_choice(backend, BACKENDS, "backend")  # type: ignore[assignment]
        N = sheet.n
        if method == "subsets" and N > SUBSETS_MAX_ROBOTS:
            raise InvalidInputError("sheet", f"{N} robots; method 'subsets' takes at most "
                                    f"{SUBSETS_MAX_ROBOTS} (it tries every set of <= 5 "
                                    "cables: N**5 work)")
        fits = method != "exhaustive" and N <= KERNEL_MAX_N
        if backend == "numba":
            if not HAVE_NUMBA:
                raise InvalidInputError("backend", not_compiled_reason())
            if not fits:
                raise InvalidInputError("backend", f"the compiled kernel takes methods 'fast' "
                                                   f"and 'subsets' with N <= {KERNEL_MAX_N}")
        self.backend = "numba" if backend == "numba" or (backend == "auto" and fits
                                                         and HAVE_NUMBA) else "numpy"
        # "fast" above COMPILED_MAX_N: the kernel solves the hull's candidates instead.
        self._hull = method == "fast" and N > COMPILED_MAX_N
        V = sheet.vertices
        self._scale = float(sheet.size)
        vc = V.mean(axis=0)
        self._vcx, self._vcy = float(vc[0]), float(vc[1])
        self._Vn = np.ascontiguousarray((V - vc) / self._scale)
        self._A = np.ascontiguousarray(V - vc)
        # The all-subsets table (O(N^5) rows) only where it is used.
        table = (padded_small_subsets(N, sheet.has_collinear_vertices)
                 if self.backend == "numba" and not self._hull else np.zeros((0, 5), np.intp))
        self._table = np.ascontiguousarray(table, dtype=np.int64)
        self._sizes = np.ascontiguousarray((table >= 0).sum(axis=1), dtype=np.int64)
        limit = sheet.side_lengths() * (1 + GEOMETRY_RTOL) + GEOMETRY_RTOL * sheet.size
        self._lim2 = np.ascontiguousarray(limit * limit)
        self._width = 12 + 3 * N                   # _small_kernel.row_width(N)
        self._args = (self._Vn, self._table, self._sizes, self._scale, self._vcx, self._vcy,
                      self.hold_height, self._lim2)
        # The per-call path (solve): one compiled call on one packed array.
        self._fast = self.backend == "numba" and not self._hull
        self._shape = (N, 2)
        self._mass = team.mass
        self._make = FKResult._rows_maker(self.method, sheet, self.hold_height, team.mass)
        self._make_out = FKResult._out_maker(self.method, sheet, self.hold_height, team.mass)
        self._pack = np.zeros(0)
        self._out_shape = (0, self._width)
        self._solve_one: Callable[..., int] = _no_kernel
        if self.backend == "numba":
            _load_kernel()
            self._pack = _batch_kernel().pack(
                self._Vn, self._A, self._lim2, self._table, self._sizes, self._scale,
                self._vcx, self._vcy, self.hold_height, _snap_screen(self._scale))
            self._out_shape = (bk.out_rows(N, len(table)), self._width)
            if self._fast:
                self._solve_one = _specialised(bk.solve_one, _any_formation(N),
                                               self._pack, np.empty(self._out_shape))

    def __repr__(self) -> str:
        return (f"FKSolver(N={self.sheet.n}, hold_height={self.hold_height:g}, "
                f"method={self.method!r}, backend={self.backend!r})")

    # -- one formation -------------------------------------------------------------------
    def solve(self, formation: ArrayLike, *, check: bool = True) -> FKResult:
        """Every rest state of the object for one formation (as
        :func:`~taut.sheet.forward_kinematics`; tensions in N when the team has a mass).

        Parameters
        ----------
        formation : array_like, shape (N, 2)
            Robot positions, same unit as the sheet.
        check : bool
            Validate ``formation`` (shape, finite, no pair farther apart than
            its sheet vertices). ``False`` skips the Python-side checks for trusted loops
            (a float64 (N, 2) array is checked in nanoseconds either way); a torn or
            non-finite formation still raises.

        Raises
        ------
        InvalidInputError, InfeasibleFormationError
            As :func:`~taut.sheet.forward_kinematics`.
        """
        if self._fast:                              # the hot path: one compiled call
            if (type(formation) is _NDARRAY and formation.dtype is _FLOAT64
                    and formation.shape == self._shape):
                R = formation                       # any strides: the kernel copies it
            else:
                R = self._formation(formation, check)
            out = _EMPTY(self._out_shape)
            code = self._solve_one(R, self._pack, out)
            if code >= 0:                           # the rows are the answer
                return self._make_out(out, code)
            return self._flagged(out, code)
        if self.backend != "numba":
            return forward_numpy(self.sheet, formation, self.hold_height, self._mass,
                                 self.method)
        R = self._formation(formation, check)
        return self._result(R, self._rows(R))

    def _formation(self, formation: ArrayLike, check: bool) -> np.ndarray:
        """``formation`` as a fresh C-contiguous float64 (N, 2) array (validated when
        ``check``; the kernel checks finiteness and the pair limits)."""
        if check:
            return _formation_array(formation, self.sheet)
        R = np.array(formation, dtype=np.float64, order="C")
        if R.shape != self._shape:
            check_formation(self.sheet, R)          # raises the shape error
        return R

    def _flagged(self, out: np.ndarray, code: int) -> FKResult:
        """The result of a :func:`~taut.sheet._kernels.batch.solve_one` call whose rows need
        more than the kernel did (an infeasible formation, weight families, a formation
        next to a similar copy of the sheet)."""
        N = self.sheet.n
        R = out[-1, :2 * N].reshape(N, 2)           # the kernel's copy of the formation
        k, flags = bk.decode(code)
        rows = None if k < 0 else self._finish(R, out[:k], flags & bk.HAS_PENDING,
                                               near=bool(flags & bk.NEAR_COPY))
        return self._result(R, rows)

    def _result(self, R: np.ndarray, rows: np.ndarray | None) -> FKResult:
        """The result for ``R`` from its kernel rows; None (the kernel found ``R``
        infeasible) raises the model's error or, where the model's check accepts ``R``
        (borderline), lets the numpy engine decide."""
        if rows is None:
            check_formation(self.sheet, R)          # raises with the usual message
            return forward_numpy(self.sheet, R, self.hold_height, self._mass, self.method)
        return self._make(rows, R)

    def _rows(self, R: np.ndarray) -> np.ndarray | None:
        """Kernel rows of formation ``R`` (snapped and with weight families resolved);
        None when the kernel found the formation infeasible."""
        found = self._kernel(R)
        if found is None:
            return None
        return self._finish(R, found[0], 0)

    def _finish(self, R: np.ndarray, rows: np.ndarray, pending: int, *,
                near: bool | None = None) -> np.ndarray:
        """Rows of ``R`` after the kernel: weight families resolved (``pending`` rows),
        snapped to a similar copy of the sheet next to one, whether or not a state is stable
        (docs/sheet_fk_solver.md; ``near``: the result of the snap screen when the kernel
        already ran it)."""
        if pending:
            self._resolve_families(R, rows)
        if near is not False:
            snapped = self._snap(R, screened=near is True)
            if snapped is not None:
                return snapped
        return rows

    def _kernel(self, R: np.ndarray) -> tuple[np.ndarray, int] | None:
        """Kernel rows of ``R`` with weight families resolved, and the number of stable
        rows; None for an infeasible formation."""
        table, sizes = (self._table, self._sizes) if not self._hull else self._hull_table(R)
        out = np.empty((len(table), self._width))
        k, stable, pending = sk.solve_formation(
            R, self._Vn, table, sizes, self._scale, self._vcx, self._vcy,
            self.hold_height, self._lim2, out)
        if k < 0:
            return None
        rows = out[:k]
        if pending:
            stable = self._resolve_families(R, rows)
        return rows, stable

    def _hull_table(self, R: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Candidates of ``R`` from the upper hull of its lifted points (``"fast"``,
        docs/sheet_kinematics.md §2), as a padded table and the set sizes."""
        if not sk.feasible(R, self._lim2):
            return self._table[:0], self._sizes[:0]    # the kernel reports infeasible
        P = sk.lifted_points(R, self._Vn, self._scale)
        hc = hull_candidates(P, self.sheet.has_collinear_vertices, shortcut=False,
                             unique=False)
        if not hc.subsets:
            return self._table[:0], self._sizes[:0]
        _, table = pad_groups({s: (np.zeros(len(i), np.intp), i) for s, i in hc.subsets.items()})
        table = np.ascontiguousarray(table, dtype=np.int64)
        return table, (table >= 0).sum(axis=1)

    def _resolve_families(self, R: np.ndarray, rows: np.ndarray) -> int:
        """Weights and kind of rows whose taut set is larger than their candidate (LP,
        as ``_finalize.classify``); returns the number of stable rows."""
        N = self.sheet.n
        frame = Frame.build(self.sheet.vertices, R[None], self.hold_height, self._scale)
        xcol = 8 + 3 * N
        for row in rows:
            if row[0] != sk.PENDING:
                continue
            idx = np.flatnonzero(row[8:8 + N])
            x = row[xcol:xcol + 4]
            w, min_w = _weights_family(frame, 0, idx, x[:2], x[2:])
            min_eig = _min_eig_family(frame, 0, idx)
            row[8 + N:8 + 2 * N] = 0.0
            row[8 + N + idx] = w
            row[0] = (sk.NOT_EQUILIBRIUM if min_w < -WEIGHT_TOL
                      else sk.STABLE if min_eig > CURVATURE_TOL else sk.SADDLE)
        return int(np.count_nonzero(rows[:, 0] == sk.STABLE))

    def _snap(self, R: np.ndarray, *, screened: bool = False) -> np.ndarray | None:
        """``_solve._snap_near_similar`` for one formation: the rows of the similar copy of
        the sheet when ``R`` is within ``SNAP_TOL`` of one and the copy has a stable state,
        whether or not ``R`` itself shows one (docs/sheet_fk_solver.md; ``screened``: the
        cheap screen, ``_snap_screen``, already passed)."""
        size = self.sheet.size
        if not screened:
            scale, dist = sk.similar_fit(R, self._A)    # cheap screen first
            lo, hi, top = _snap_screen(size)
            if not (lo < dist <= hi and scale <= top):
                return None
        copies, scales, dists = similar_copy(self.sheet.vertices, R[None])
        if not (SNAP_MIN * size < dists[0] <= SNAP_TOL * size and scales[0] <= 1.0):
            return None
        found = self._kernel(np.ascontiguousarray(copies[0]))
        if found is None or found[1] == 0:
            return None
        return found[0]

    # -- many formations -----------------------------------------------------------------
    def solve_batch(self, formations: ArrayLike, *, check: bool = True) -> BatchFKResult:
        """Forward kinematics of ``B`` formations (leading axis) of this team.

        Parameters
        ----------
        formations : array_like, shape (B, N, 2)
        check
            As in :meth:`solve`.

        Returns
        -------
        BatchFKResult
            As :func:`~taut.sheet.forward_kinematics_batch`.
        """
        mass = self.team.mass
        if self.backend != "numba" or self.method == "exhaustive":
            return forward_numpy_batch(self.sheet, formations, self.hold_height, mass,
                                        self.method)
        N = self.sheet.n
        if check:
            Rb = require_nonempty(as_array(formations, "formations", ndim=3), "formations")
            if Rb.shape[1:] != (N, 2):
                check_formations(self.sheet, Rb)    # raises the shape error
        else:
            Rb = np.asarray(formations, dtype=np.float64)
        Rb = np.ascontiguousarray(Rb)
        if self._hull:
            return self._solve_batch_hull(Rb, mass)
        feasible = np.ones(len(Rb), dtype=bool)
        rows, form, bad = self._kernel_batch(Rb)
        if bad < 0:
            rows, form = self._fix_batch(Rb, rows, form)
            return batch_from_rows(self.sheet, Rb, self.hold_height, mass, self.method,
                                   feasible, rows, form)
        # A formation the kernel rejects: the model's check decides which (and raises for
        # a non-finite one); the kernel solves the others.
        feasible = feasible_formations(self.sheet, Rb)
        ok = np.flatnonzero(feasible)
        rows, form, bad = np.zeros((0, self._width)), np.zeros(0, np.int64), -1
        if len(ok):
            rows, form, bad = self._kernel_batch(Rb[ok])
        if bad >= 0 or len(ok) == len(Rb):          # a borderline formation: numpy decides
            return forward_numpy_batch(self.sheet, Rb, self.hold_height, mass, self.method)
        rows, form = self._fix_batch(Rb[ok], rows, form)
        return batch_from_rows(self.sheet, Rb, self.hold_height, mass, self.method, feasible,
                               rows, ok[form])

    def _kernel_batch(self, Rb: np.ndarray) -> tuple[np.ndarray, np.ndarray, int]:
        """Kernel rows of formations ``Rb`` (B, N, 2), their formation indices, and the
        index of the first formation the kernel finds infeasible (-1: none)."""
        Rb = np.ascontiguousarray(Rb)
        return bk.solve_formations_ws(
            Rb, self._Vn, self._table, self._sizes, self._scale, self._vcx, self._vcy,
            self.hold_height, self._lim2)

    def _solve_batch_hull(self, Rb: np.ndarray, mass: float | None) -> BatchFKResult:
        """Batch of larger teams: one hull and one kernel call per formation."""
        parts, forms = [], []
        feasible = np.ones(len(Rb), dtype=bool)
        for b in range(len(Rb)):
            rows = self._rows(Rb[b])
            if rows is None:
                if feasible_formations(self.sheet, Rb[b:b + 1])[0]:
                    # The kernel and the model's check disagree (borderline): numpy decides.
                    return forward_numpy_batch(self.sheet, Rb, self.hold_height, mass,
                                               self.method)
                feasible[b] = False
                continue
            parts.append(rows)
            forms.append(np.full(len(rows), b, dtype=np.int64))
        rows = np.vstack(parts) if parts else np.zeros((0, self._width))
        form = np.concatenate(forms) if forms else np.zeros(0, np.int64)
        return batch_from_rows(self.sheet, Rb, self.hold_height, mass, self.method, feasible,
                               rows, form)

    def _fix_batch(self, Rb: np.ndarray, rows: np.ndarray, form: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray]:
        """Resolve weight families and snap formations next to a similar copy of the
        sheet, per formation (both rare), keeping rows grouped by formation in order."""
        pending = np.flatnonzero(rows[:, 0] == sk.PENDING) if len(rows) else rows[:0, 0]
        for b in np.unique(form[pending.astype(np.intp)]) if len(pending) else ():
            sel = np.flatnonzero(form == b)
            block = rows[sel]
            self._resolve_families(Rb[b], block)
            rows[sel] = block
        # The compiled screen on every formation (a few ns each); the exact test of
        # ``_snap`` only on the (rare) formations that pass it.
        near = np.flatnonzero(bk.snap_screen_batch(Rb, self._A, *_snap_screen(self._scale)))
        if not len(near):
            return rows, form
        parts: dict[int, np.ndarray] = {}
        for b in near:
            snapped = self._snap(Rb[b], screened=True)
            if snapped is not None:
                parts[int(b)] = snapped
        if not parts:
            return rows, form
        keep = ~np.isin(form, list(parts))
        all_rows = [rows[keep]] + list(parts.values())
        all_form = [form[keep]] + [np.full(len(r), b, dtype=form.dtype) for b, r in parts.items()]
        rows, form = np.vstack(all_rows), np.concatenate(all_form)
        order = np.argsort(form, kind="stable")
        return rows[order], form[order]


#: What ``solve``'s hot path looks up, as module globals (an attribute lookup on ``np``
#: costs ~20 ns of a ~3 us call).
_FLOAT64, _NDARRAY, _EMPTY = np.dtype(np.float64), np.ndarray, np.empty


def _no_kernel(*args: object) -> int:
    """``FKSolver._solve_one`` of a solver without the per-call kernel (never called:
    ``solve`` takes the kernel path only when ``_fast``)."""
    raise RuntimeError("this FKSolver has no per-call kernel")


def _specialised(kernel: Any, *args: np.ndarray) -> Callable[..., int]:
    """The compiled specialisation of ``kernel`` (a numba dispatcher) for the types of
    ``args``, loaded from numba's on-disk cache (or compiled) as a first call would load
    it, as a plain callable: a call skips numba's dispatch on the argument types (~0.1 us
    of a ~3 us call at N = 3). It checks no type: the caller passes arrays of exactly
    those types (``FKSolver.solve``: a float64 (N, 2) formation of any layout, then the
    pack and a fresh C-contiguous buffer)."""
    import numba

    return kernel.compile(tuple(numba.typeof(a) for a in args))


def _any_formation(N: int) -> np.ndarray:
    """An example float64 (N, 2) formation of numba's most general array type (any
    strides, read-only; numba types unaligned arrays as aligned ones, as its dispatcher
    does): ``solve_one`` specialised for it reads any native float64 (N, 2) array, which
    it copies before anything else (``FKSolver.solve`` passes the caller's array as it
    is)."""
    example = np.zeros((N, 3))[:, :2]
    example.flags.writeable = False
    return example


def _snap_screen(size: float) -> tuple[float, float, float]:
    """Bounds of the snap screen on ``similar_fit``'s distance (low, high) and scale
    (high): ``SNAP_MIN``/``SNAP_TOL`` of the sheet size widened by ``SCREEN_SLACK``."""
    slack = 1.0 + SCREEN_SLACK
    return SNAP_MIN * size / slack, SNAP_TOL * size * slack, slack


def _formation_array(formation: ArrayLike, sheet: Sheet) -> np.ndarray:
    """``formation`` as a fresh C-contiguous float64 (N, 2) array, or the usual
    :class:`InvalidInputError` (finiteness and pair limits are checked in the kernel)."""
    N = sheet.n
    if (type(formation) is np.ndarray and formation.dtype == np.float64
            and formation.shape == (N, 2)):
        return formation.copy()
    R = as_array(formation, "formation", ndim=2)
    if R.shape != (N, 2):
        check_formation(sheet, R)                  # raises the shape error
    return np.ascontiguousarray(R)




# -- cached solvers for the functional front end ------------------------------------------

_SOLVERS: ("weakref.WeakKeyDictionary[Sheet, dict[tuple[float, float | None, str, str], "
            "FKSolver]]") = weakref.WeakKeyDictionary()
#: Solvers kept per sheet (distinct hold heights, masses, methods, backends) by ``cached_solver``.
_PER_SHEET = 16


def cached_solver(team: SheetTeam, method: Method, backend: Backend = "auto") -> FKSolver:
    """The :class:`FKSolver` for ``team`` (a validated :class:`SheetTeam`), ``method`` and
    ``backend``, built once per sheet, hold height, mass, method and backend, and reused."""
    per = _SOLVERS.get(team.sheet)
    if per is None:
        per = _SOLVERS[team.sheet] = {}
    key = (team.hold_height, team.mass, method, backend)
    solver = per.get(key)
    if solver is None:
        if len(per) >= _PER_SHEET:
            per.clear()
        solver = per[key] = FKSolver(team, method=method, backend=backend)
    return solver
