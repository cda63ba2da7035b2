"""Forward kinematics of an N-robot team holding a deformable sheet (VVCM).

Given the sheet, the robots' planar positions and their common holding height, find every
place the object can rest (FK paper: Hu, Liu, Yi, Xiong, "Forward Kinematics of Object
Transport by a Multi-Robot System with Deformable Sheet", Algorithm 1), classify each as
stable, saddle or not an equilibrium, and give each taut cable's share of the load.

Methods (one interface, chosen by ``method``):

``"fast"`` (default)
    Candidate taut sets from the upper convex hull of the lifted points (Qhull), their
    stationary points read off the facet normals (docs/sheet_kinematics.md §2). Same solutions as
    Algorithm 1; O(N^2) candidates. Teams of at most ``SMALL_TEAM`` robots take every
    small subset instead (as ``"subsets"``), one cached table solved for all formations
    at once, which is cheaper there.
``"exhaustive"``
    Algorithm 1 as published: all :math:`\\sum_{k\\ge3}\\binom{N}{k}` taut sets, the rank
    test (eq. 5), the Lagrange solution (eqs. 10-15), the slack and height checks and the
    projection force-closure test, with the step counts of Tables II and IV.
``"subsets"``
    Every set of at most 5 cables as a candidate (complete, O(N^5)); a cross-check of
    ``"fast"`` that needs no convex hull.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import fields
from typing import Iterable, Literal

import numpy as np
from numpy.typing import ArrayLike

from ..._validate import (MAX_SHEET_LENGTH, as_array, as_mass, as_positive, check_range,
    require_nonempty)
from ...errors import InvalidInputError
from ._candidates import Stationary, hull_candidates, padded_small_subsets
from ._finalize import Classified, classify
from .._lifted import (STATUS_NAMES, STATUS_NOT_EQUILIBRIUM, STATUS_STABLE, Frame, Solved,
    height_ok, in_hull_2d, maximiser_masks, pad_groups, solve_candidates, solve_table)
from ._similar import similar_copy
from .._tol import FAST_CHECK_RTOL, SNAP_MIN, SNAP_TOL
from .exhaustive import exhaustive_search, funnel_from
from ..model import Sheet, check_formations, check_hold_height
from .results import GRAVITY, BatchFKResult, Equilibrium, FKResult

__all__ = ["forward_kinematics", "forward_kinematics_batch", "Method", "METHODS"]

Method = Literal["fast", "exhaustive", "subsets"]
METHODS: tuple[str, ...] = ("fast", "exhaustive", "subsets")

#: Up to this many robots every small subset is the candidate set (N = 12: 1,507
#: candidates), as in the compiled kernel (``solver.COMPILED_MAX_N``): both backends
#: then try the same candidates. Complete, and unlike the hull it needs no decision on
#: (nearly) degenerate lifted points -- near a similar copy, with (nearly) collinear or
#: coincident robots the numpy hull path missed states the subsets find.
SMALL_TEAM = 12
#: Above this many robots the hull path may read stationary points off the facet normals
#: (``_candidates._stationary_from_normals``). Up to it (``solver.KERNEL_MAX_N``) the
#: compiled kernel handles the team and solves every upper-hull face by the Lagrange
#: system; the numpy path does the same there, so the two backends try the same
#: candidates (on teams with nearly coincident robots the shortcut reported other
#: non-equilibria than the kernel).
SHORTCUT_ABOVE = 30
#: Candidate systems solved per block when every formation shares one candidate table.
TABLE_BLOCK = 65_536
#: Hull candidates: run the maximiser scan before the projection test when it touches at
#: most this many (candidate, cable) pairs (it is then cheaper than the projection test).
SCAN_FIRST = 20_000


def _check_sheet(sheet: Sheet) -> Sheet:
    if not isinstance(sheet, Sheet):
        try:
            return Sheet(sheet)
        except TypeError:
            raise InvalidInputError("sheet", "must be a taut.sheet.Sheet or an (N, 2) array") from None
    return sheet


def _check_method(method: str) -> Method:
    if not isinstance(method, str) or method not in METHODS:
        raise InvalidInputError("method", f"must be one of {', '.join(METHODS)}; got {method!r}")
    return method  # type: ignore[return-value]


def _check_mass(mass: float | None) -> float | None:
    return None if mass is None else as_mass(mass, "mass")


#: Squared sheet side lengths, shrunk by FAST_CHECK_RTOL, per sheet (see _formations).
_SIDES2: "weakref.WeakKeyDictionary[Sheet, np.ndarray]" = weakref.WeakKeyDictionary()


def _formations(sheet: Sheet, formations: ArrayLike, field: str, single: bool) -> np.ndarray:
    """``check_formation(s)`` with a fast path: formations whose robots are all clearly
    closer than their sheet vertices (squared distances below the cached squared side
    lengths) are accepted at once; anything else gets the full check, which decides
    borderline cases and raises the usual errors. Returns shape (B, N, 2)."""
    r = require_nonempty(as_array(formations, field, ndim=2 if single else 3), field)
    check_range(r, field, MAX_SHEET_LENGTH, "sheet units")
    rb = r[None] if single else r
    if rb.shape[1:] == (sheet.n, 2):
        sides2 = _SIDES2.get(sheet)
        if sides2 is None:
            sides2 = _SIDES2[sheet] = sheet.side_lengths() ** 2 * (1.0 - FAST_CHECK_RTOL)
        d = rb[:, :, None, :] - rb[:, None, :, :]
        if np.all(d[..., 0] * d[..., 0] + d[..., 1] * d[..., 1] <= sides2):
            return rb
    return check_formations(sheet, rb, field)


def _candidates(frame: Frame, sheet: Sheet, method: str
                ) -> tuple[tuple[np.ndarray, np.ndarray] | np.ndarray | None, bool,
                           Stationary | None]:
    """Candidate taut sets of every formation for the Lagrange solver (with its
    ``independent`` flag): ``(form, subset)``, or one ``subset`` table shared by every
    formation; and hull-derived stationary points (generic formations)."""
    B, N = frame.b.shape
    pairs = sheet.has_collinear_vertices
    if method == "subsets" or N <= SMALL_TEAM:
        return padded_small_subsets(N, pairs), False, None
    per_size: dict[int, list[tuple[np.ndarray, np.ndarray]]] = {}
    independent = True
    stationary: list[Stationary] = []
    for b in range(B):
        hc = hull_candidates(frame.P[b], pairs, shortcut=N > SHORTCUT_ABOVE)
        if hc.stationary is not None:
            hc.stationary.form[:] = b
            stationary.append(hc.stationary)
        if hc.subsets:
            # Up to SHORTCUT_ABOVE the kernel screens every system; so does this path.
            independent &= hc.independent and N > SHORTCUT_ABOVE
        for s, idx in hc.subsets.items():
            per_size.setdefault(s, []).append((np.full(len(idx), b, dtype=np.intp), idx))
    groups = {s: (np.concatenate([f for f, _ in parts]), np.vstack([i for _, i in parts]))
              for s, parts in per_size.items()}
    merged = None
    if len(stationary) == 1:
        merged = stationary[0]
    elif stationary:
        merged = Stationary(*(np.concatenate([getattr(p, f) for p in stationary])
                              for f in Stationary.FIELDS))
    return (pad_groups(groups) if groups else None), independent, merged


def _solve(sheet: Sheet, R: np.ndarray, hold_height: float, method: str
           ) -> tuple[Frame, Classified, dict[str, int] | None]:
    frame, c, counts = _solve_as_given(sheet, R, hold_height, method)
    if method != "exhaustive":
        c = _snap_near_similar(sheet, R, hold_height, method, c)
    return frame, c, counts




def _snap_near_similar(sheet: Sheet, R: np.ndarray, hold_height: float, method: str,
                       c: Classified) -> Classified:
    """Formations within ``SNAP_TOL`` (relative) of a similar copy of the sheet, but not
    exactly one: solve the copy instead (when the copy has a stable state).

    Such formations are within float64 resolution of the FK paper's Lemma 2
    configuration (lifted points on a 2-plane): the rest state's taut set is decided by a
    thickness of ~1e-10, its 4- and 5-cable systems are numerically singular, the
    candidates can miss it, and where they find it they name one physical state by many
    taut sets (objects within ~1e-8 of each other; docs/sheet_fk_solver.md, "Next to a
    similar copy"). The copy is solved exactly (every cable taut at the Lemma 2 point,
    minimum-norm non-negative load shares); every method and backend gives that one
    answer. Positions move by about the snap distance, below ``SNAP_TOL`` times the sheet
    size.
    """
    B = R.shape[0]
    todo = np.arange(B)
    copies, scale, dist = similar_copy(sheet.vertices, R)
    near = ((dist > SNAP_MIN * sheet.size) & (dist <= SNAP_TOL * sheet.size)
            & (scale <= 1.0))
    if not near.any():
        return c
    todo, copies = todo[near], copies[near]
    _, c2, _ = _solve_as_given(sheet, copies, hold_height, method)
    replaced = np.zeros(B, dtype=bool)
    replaced[todo[np.unique(c2.form[c2.status == STATUS_STABLE])]] = True
    if not replaced.any():
        return c
    take2 = replaced[todo[c2.form]]
    keep = ~replaced[c.form]
    form = np.concatenate([c.form[keep], todo[c2.form[take2]]])
    order = np.argsort(form, kind="stable")
    merged = {f.name: np.concatenate([getattr(c, f.name)[keep], getattr(c2, f.name)[take2]])
              for f in fields(Classified) if f.name != "form"}
    return Classified(form=form[order], **{k: v[order] for k, v in merged.items()})


def _solve_as_given(sheet: Sheet, R: np.ndarray, hold_height: float, method: str
                    ) -> tuple[Frame, Classified, dict[str, int] | None]:
    frame = Frame.build(sheet.vertices, R, hold_height, sheet.size)
    if method == "exhaustive":
        solved, taut, counts = exhaustive_search(frame)
        return frame, classify(frame, solved, taut), counts
    groups, independent, stationary = _candidates(frame, sheet, method)
    # Rows from the Lagrange solver first, then (hull path) those from the normals, which
    # carry projection-test and curvature results (``None``: nothing known yet).
    parts: list[Solved] = []
    tauts: list[np.ndarray] = []
    N = frame.R.shape[1]
    if groups is not None:
        chunks: Iterable[Solved]
        if isinstance(groups, tuple):
            chunks = [solve_candidates(frame, *groups, independent=independent)]
        else:
            # One table for all formations: solve in cache-sized blocks of formations.
            step = max(1, TABLE_BLOCK // len(groups))
            chunks = (solve_table(frame, groups, slice(b, b + step), independent=independent)
                      for b in range(0, frame.b.shape[0], step))
        for solved in chunks:
            keep = np.flatnonzero(height_ok(frame, solved.depth2))
            ok, taut = maximiser_masks(frame, solved.form[keep], solved.x[keep],
                                       solved.mu[keep])
            parts.append(solved.take(keep[ok]))
            tauts.append(taut[ok])
    done = curv = None
    if stationary is not None:
        # Points already known: filter first, then solve only the survivors for weights.
        # Generic hull: a face's exact taut set is its own vertex set, so the paper's
        # projection test on the face is final for most rows. Cheapest test first: the
        # maximiser scan costs O(N) per row, the projection test O(1) but more calls.
        st = stationary
        keep = np.flatnonzero(height_ok(frame, st.depth2))
        scan_first = len(keep) * N <= SCAN_FIRST
        if scan_first:
            ok, taut = maximiser_masks(frame, st.form[keep], st.x[keep], st.mu[keep])
            keep, taut = keep[ok], taut[ok]
        sub = st.subset[keep]
        inside = in_hull_2d(frame.R[st.form[keep, None], np.maximum(sub, 0)], sub >= 0,
                            st.x[keep, :2])
        keep = keep[inside]
        if scan_first:
            taut = taut[inside]
        else:
            ok, taut = maximiser_masks(frame, st.form[keep], st.x[keep], st.mu[keep])
            keep, taut = keep[ok], taut[ok]
        sv = solve_candidates(frame, st.form[keep], st.subset[keep])
        taut = taut[sv.source]
        before = sum(len(t) for t in tauts)
        done = np.concatenate([np.zeros(before, dtype=bool), taut.sum(axis=1) == sv.size])
        curv = np.concatenate([np.full(before, np.nan), st.curvature[keep[sv.source]]])
        parts.append(sv)
        tauts.append(taut)
    solved = Solved.concat(parts)
    taut = tauts[0] if len(tauts) == 1 else (
        np.vstack(tauts) if tauts else np.zeros((0, N), dtype=bool))
    return frame, classify(frame, solved, taut, done, curv), None


def _user_units(frame: Frame, sheet: Sheet, c: Classified, hold_height: float,
                mass: float | None):
    """Positions in the caller's frame and units, tensions in N."""
    ro = c.ro * frame.scale + frame.r_centre[c.form]
    vo = c.vo * frame.scale + frame.v_centre
    obj = np.empty((len(ro), 3))
    obj[:, :2] = ro
    obj[:, 2] = hold_height - c.depth * frame.scale
    d = frame.V[None, :, :] - c.vo[:, None, :]
    lengths = np.sqrt(d[..., 0] * d[..., 0] + d[..., 1] * d[..., 1])       # normalised
    tensions = None
    if mass is not None:
        # Only equilibria have tensions: elsewhere the "tension" would be negative (a push).
        tensions = c.weights * (mass * GRAVITY) * lengths / c.depth[:, None]
        held = c.taut & (c.status != STATUS_NOT_EQUILIBRIUM)[:, None]
        tensions = np.where(held, tensions, np.where(c.taut, np.nan, 0.0))
    return obj, vo, lengths * frame.scale, tensions


def forward_kinematics(sheet: Sheet, formation: ArrayLike, hold_height: float, *,
                       mass: float | None = None, method: Method = "fast") -> FKResult:
    """Every rest state of the object for one robot formation.

    Parameters
    ----------
    sheet : Sheet
        The sheet (vertices :math:`\\mathcal{V}_N^0` in the sheet frame).
    formation : array_like, shape (N, 2)
        Robot positions :math:`\\mathcal{R}_N` in the world frame, robot ``i`` holding
        sheet vertex ``i``. Same length unit as the sheet.
    hold_height : float
        Height :math:`z_r` of all holding points above the ground (> 0), same unit.
    mass : float, optional
        Object mass in kg; when given, each equilibrium's cable tensions are reported in
        N (g = 9.81 m/s^2). The formula :math:`F_i = w_i m g L_i / d` (FK paper eq. 16
        solved with the weights) uses only a ratio of lengths, so any length unit works.
    method : {"fast", "exhaustive", "subsets"}
        Algorithm (see module docstring). All return the same equilibria, except within
        ``SNAP_TOL`` (1e-7 of the sheet size) of a similar copy of the sheet (the FK
        paper's Lemma 2 configuration), where float64 cannot resolve the taut set: there
        "fast" and "subsets" solve the copy (docs/sheet_fk_solver.md), and the paper's Algorithm 1 ("exhaustive") may find nothing.

    Returns
    -------
    FKResult
        ``.equilibria`` (every state passing the paper's Algorithm 1, each with ``taut``,
        ``object``, ``contact``, ``weights``, ``tensions``, ``status``, ``stable``),
        ``.stable``, ``.lowest``, and ``.funnel`` for the exhaustive method.

    Raises
    ------
    InvalidInputError
        Bad shapes, NaN/inf, robot count different from the sheet's, non-positive
        hold height or mass, unknown method, exhaustive search too large.
    InfeasibleFormationError
        Two robots farther apart than their sheet vertices (paper's FormationFeasible).

    Examples
    --------
    A unit square sheet held by robots on a square of side 0.9 at height 1: the object
    hangs below the centre on all four cables, each as long as the sheet's half-diagonal.

    >>> import taut.sheet as ts
    >>> sheet = ts.Sheet([[0, 0], [1, 0], [1, 1], [0, 1]])
    >>> res = ts.forward_kinematics(sheet, [[0, 0], [0.9, 0], [0.9, 0.9], [0, 0.9]], 1.0,
    ...                             mass=2.0)
    >>> e = res.lowest
    >>> e.taut, e.status, [round(float(c), 4) for c in e.object]
    ((0, 1, 2, 3), 'stable', [0.45, 0.45, 0.6918])
    >>> [round(float(w), 3) for w in e.weights]     # equal load shares
    [0.25, 0.25, 0.25, 0.25]

    Notes
    -----
    The object is a point mass; the sheet inelastic and perfectly flexible; cable ``i``
    is the segment from holding point :math:`(\\mathbf{r}_i, z_r)` to the object with
    length :math:`|\\mathbf{v}_i - \\mathbf{v}_o|` (eq. 1). Solutions require
    :math:`0 < z_o < z_r` (eq. 15: the object does not touch the ground at z = 0).
    """
    sheet = _check_sheet(sheet)
    method = _check_method(method)
    z = _hold_height(hold_height)
    if method == "exhaustive":
        return _forward_numpy(sheet, formation, z, mass, method)
    return cached_solver(sheet, z, method).solve(formation, mass=mass)


def _hold_height(hold_height: float) -> float:
    """``check_hold_height`` with a fast path for a plain positive finite float."""
    if type(hold_height) is float and 0.0 < hold_height < math.inf:
        return hold_height
    return check_hold_height(hold_height)


def _forward_numpy(sheet: Sheet, formation: ArrayLike, z: float, mass: float | None,
                   method: str) -> FKResult:
    """:func:`forward_kinematics` on the numpy path (``sheet``, ``z``, ``method`` already
    validated)."""
    mass = _check_mass(mass)
    Rb = _formations(sheet, formation, "formation", single=True)
    R = Rb[0]
    frame, c, counts = _solve(sheet, Rb, z, method)
    obj, vo, lengths, tensions = _user_units(frame, sheet, c, z, mass)
    # Per-equilibrium slices of the flat taut entries (row-major order of c.taut).
    rows, cols = np.nonzero(c.taut)
    w = c.weights[rows, cols]
    ln = lengths[rows, cols]
    tn = tensions[rows, cols] if tensions is not None else None
    ends = np.cumsum(c.taut.sum(axis=1)).tolist()
    starts = [0] + ends[:-1]
    idx = cols.tolist()
    eqs = [Equilibrium(tuple(idx[a:e]), obj[k], vo[k], w[a:e],
                       None if tn is None or st == STATUS_NOT_EQUILIBRIUM else tn[a:e],
                       ln[a:e], STATUS_NAMES[st])  # type: ignore[arg-type]
           for k, (a, e, st) in enumerate(zip(starts, ends, c.status.tolist()))]
    funnel = funnel_from(counts, len(eqs)) if counts is not None else None
    return FKResult(tuple(eqs), funnel, method, sheet, R, z, mass)


def forward_kinematics_batch(sheet: Sheet, formations: ArrayLike, hold_height: float, *,
                             mass: float | None = None, method: Method = "fast"
                             ) -> BatchFKResult:
    """Forward kinematics of many formations of one sheet at once.

    Parameters
    ----------
    formations : array_like, shape (B, N, 2)
        ``B`` formations; the rest as in :func:`forward_kinematics`.

    Returns
    -------
    BatchFKResult
        Padded arrays with a leading batch axis; ``.result(b)`` gives an
        :class:`FKResult` for one formation.

    Raises
    ------
    InfeasibleFormationError
        With ``.step`` set to the first infeasible formation's index.

    Examples
    --------
    >>> import taut.sheet as ts
    >>> sheet = ts.Sheet([[0, 0], [1, 0], [1, 1], [0, 1]])
    >>> b = ts.forward_kinematics_batch(sheet, [0.9 * sheet.vertices, 0.8 * sheet.vertices], 1.0)
    >>> low = b.result(1).lowest
    >>> b.count.tolist(), low.taut, [round(float(c), 4) for c in low.object]
    ([1, 1], (0, 1, 2, 3), [0.4, 0.4, 0.5757])
    """
    sheet = _check_sheet(sheet)
    method = _check_method(method)
    if method == "exhaustive":
        raise InvalidInputError("method", "the batched form supports 'fast' and 'subsets'")
    z = _hold_height(hold_height)
    return cached_solver(sheet, z, method).solve_batch(formations, mass=mass)


def _forward_numpy_batch(sheet: Sheet, formations: ArrayLike, z: float, mass: float | None,
                         method: str) -> BatchFKResult:
    """:func:`forward_kinematics_batch` on the numpy path (inputs but ``formations`` and
    ``mass`` validated)."""
    if method == "exhaustive":
        raise InvalidInputError("method", "the batched form supports 'fast' and 'subsets'")
    mass = _check_mass(mass)
    R = _formations(sheet, formations, "formations", single=False)
    B, N = R.shape[:2]
    frame, c, _ = _solve(sheet, R, z, method)
    obj, vo, _, tensions = _user_units(frame, sheet, c, z, mass)
    count = np.bincount(c.form, minlength=B)
    K = int(count.max()) if B else 0
    starts = np.concatenate([[0], np.cumsum(count)[:-1]])
    slot = np.arange(len(c.form)) - starts[c.form]
    valid = np.zeros((B, K), dtype=bool)
    valid[c.form, slot] = True
    taut = np.zeros((B, K, N), dtype=bool)
    taut[c.form, slot] = c.taut
    obj_arr = np.full((B, K, 3), np.nan)
    obj_arr[c.form, slot] = obj
    con = np.full((B, K, 2), np.nan)
    con[c.form, slot] = vo
    wts = np.zeros((B, K, N))
    wts[c.form, slot] = c.weights
    ten = None
    if tensions is not None:
        ten = np.zeros((B, K, N))
        ten[c.form, slot] = tensions
    status = np.full((B, K), -1, dtype=np.int8)
    status[c.form, slot] = c.status
    return BatchFKResult(count, valid, taut, obj_arr, con, wts, ten, status, sheet, R, z,
                         mass, method)


from .solver import cached_solver  # noqa: E402  (solver builds on the numpy path above)
