"""Forward kinematics of an N-robot team holding a deformable sheet (VVCM).

Given the sheet, the robots' planar positions and their common holding height, find every
place the object can rest (FK paper: Hu, Liu, Yi, Xiong, "Forward Kinematics of Object
Transport by a Multi-Robot System with Deformable Sheet", Algorithm 1), classify each as
stable, saddle or not an equilibrium, and give each taut cable's share of the load.

Methods (one interface, chosen by ``method``):

``"fast"`` (default)
    Candidate taut sets from the upper convex hull of the lifted points (Qhull), solved
    in one batch (DESIGN.md Sec. 2). Same solutions as Algorithm 1; O(N^2) candidates.
``"exhaustive"``
    Algorithm 1 as published: all :math:`\\sum_{k\\ge3}\\binom{N}{k}` taut sets, the rank
    test (eq. 5), the Lagrange solution (eqs. 10-15), the slack and height checks and the
    projection force-closure test, with the step counts of Tables II and IV.
``"subsets"``
    Every set of at most 5 cables as a candidate (complete, O(N^5)); a cross-check of
    ``"fast"`` that needs no convex hull.
"""

from __future__ import annotations

from typing import Literal

import numpy as np

from .._validate import as_array, as_positive
from ..errors import InvalidInputError
from ._candidates import Stationary, all_small_subsets, hull_candidates
from ._finalize import Classified, classify
from ._kernel import (STATUS_NAMES, Frame, Solved, height_ok, in_hull_2d, pad_groups,
                      solve_candidates, taut_masks)
from .exhaustive import exhaustive_search, funnel_from
from .model import Sheet, check_formation, check_formations, check_hold_height
from .results import GRAVITY, BatchFKResult, Equilibrium, FKResult

__all__ = ["forward_kinematics", "forward_kinematics_batch", "Method", "METHODS"]

Method = Literal["fast", "exhaustive", "subsets"]
METHODS: tuple[str, ...] = ("fast", "exhaustive", "subsets")

#: Up to this many robots every small subset is cheaper than a convex hull.
SMALL_TEAM = 6


def _check_sheet(sheet: Sheet) -> Sheet:
    if not isinstance(sheet, Sheet):
        try:
            return Sheet(sheet)
        except TypeError:
            raise InvalidInputError("sheet", "must be a taut.sheet.Sheet or an (N, 2) array") from None
    return sheet


def _check_method(method: str) -> str:
    if method not in METHODS:
        raise InvalidInputError("method", f"must be one of {', '.join(METHODS)}; got {method!r}")
    return method


def _check_mass(mass: float | None) -> float | None:
    return None if mass is None else as_positive(mass, "mass")


def _candidates(frame: Frame, sheet: Sheet, method: str
                ) -> tuple[dict[int, tuple[np.ndarray, np.ndarray]], bool, Stationary | None]:
    """Candidate taut sets of every formation: groups for the Lagrange solver (with its
    ``independent`` flag) and hull-derived stationary points (generic formations)."""
    B, N = frame.b.shape
    pairs = sheet.has_collinear_vertices
    if method == "subsets" or N <= SMALL_TEAM:
        return all_small_subsets(N, B, pairs), False, None
    per_size: dict[int, list[tuple[np.ndarray, np.ndarray]]] = {}
    independent = True
    stationary: list[Stationary] = []
    for b in range(B):
        hc = hull_candidates(frame.P[b], pairs)
        if hc.stationary is not None:
            hc.stationary.form[:] = b
            stationary.append(hc.stationary)
        if hc.subsets:
            independent &= hc.independent
        for s, idx in hc.subsets.items():
            per_size.setdefault(s, []).append((np.full(len(idx), b, dtype=np.intp), idx))
    groups = {s: (np.concatenate([f for f, _ in parts]), np.vstack([i for _, i in parts]))
              for s, parts in per_size.items()}
    merged = None
    if stationary:
        merged = Stationary(*(np.concatenate([getattr(p, f) for p in stationary])
                              for f in ("form", "subset", "size", "x", "mu", "depth2")))
    return groups, independent, merged


def _solve(sheet: Sheet, R: np.ndarray, hold_height: float, method: str
           ) -> tuple[Frame, Classified, dict[str, int] | None]:
    frame = Frame.build(sheet.vertices, R, hold_height, sheet.size)
    if method == "exhaustive":
        solved, taut, counts = exhaustive_search(frame)
        return frame, classify(frame, solved, taut), counts
    groups, independent, stationary = _candidates(frame, sheet, method)
    parts: list[Solved] = []
    tauts: list[np.ndarray] = []
    checked: list[np.ndarray] = []
    if groups:
        solved = solve_candidates(frame, *pad_groups(groups), independent=independent)
        solved = solved.take(height_ok(frame, solved))
        ok, taut = taut_masks(frame, solved)
        parts.append(solved.take(ok))
        tauts.append(taut[ok])
        checked.append(np.zeros(int(ok.sum()), dtype=bool))
    if stationary is not None:
        # Points already known: filter first, then solve only the survivors for weights.
        # Generic hull: a face's exact taut set is its own vertex set, so the paper's
        # projection test can run before the (costlier) maximiser scan.
        st = stationary
        valid = st.subset >= 0
        keep = height_ok(frame, st.depth2)
        keep[keep] = in_hull_2d(frame.R[st.form[keep, None], np.maximum(st.subset[keep], 0)],
                                valid[keep], st.x[keep, :2])
        pre = Solved(st.form[keep], st.subset[keep], st.size[keep], st.x[keep, :0],
                     st.mu[keep], st.x[keep, :2], st.x[keep, 2:], st.depth2[keep], keep)
        ok, taut = taut_masks(frame, pre)
        sv = solve_candidates(frame, pre.form[ok], pre.subset[ok])
        parts.append(sv)
        tauts.append(taut[ok][sv.source])
        checked.append(tauts[-1].sum(axis=1) == sv.size)
    N = frame.R.shape[1]
    solved = Solved.concat(parts)
    taut = np.vstack(tauts) if tauts else np.zeros((0, N), dtype=bool)
    return frame, classify(frame, solved, taut, np.concatenate(checked) if checked else None), None


def _user_units(frame: Frame, sheet: Sheet, c: Classified, hold_height: float,
                mass: float | None):
    """Positions in the caller's frame and units, tensions in N."""
    ro = c.ro * frame.scale + frame.r_centre[c.form]
    vo = c.vo * frame.scale + frame.v_centre
    zo = hold_height - c.depth * frame.scale
    obj = np.column_stack([ro, zo])
    lengths = np.linalg.norm(frame.V[None, :, :] - c.vo[:, None, :], axis=2)   # normalised
    tensions = None
    if mass is not None:
        tensions = c.weights * (mass * GRAVITY) * lengths / c.depth[:, None]
        tensions = np.where(c.taut, tensions, 0.0)
    return obj, vo, lengths * frame.scale, tensions


def forward_kinematics(sheet: Sheet, formation: np.ndarray, hold_height: float, *,
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
        Object mass in kg; when given, cable tensions are reported in N (g = 9.81 m/s^2;
        lengths must then be in metres only if you want tensions for a real sheet -- the
        tension formula :math:`F_i = w_i m g L_i / d` is unit-free in length).
    method : {"fast", "exhaustive", "subsets"}
        Algorithm (see module docstring). All return the same equilibria.

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

    Notes
    -----
    The object is a point mass; the sheet inelastic and perfectly flexible; cable ``i``
    is the segment from holding point :math:`(\\mathbf{r}_i, z_r)` to the object with
    length :math:`|\\mathbf{v}_i - \\mathbf{v}_o|` (eq. 1). Solutions require
    :math:`0 < z_o < z_r` (eq. 15: the object does not touch the ground at z = 0).
    """
    sheet = _check_sheet(sheet)
    method = _check_method(method)
    mass = _check_mass(mass)
    z = check_hold_height(hold_height)
    R = check_formation(sheet, formation)
    frame, c, counts = _solve(sheet, R[None], z, method)
    obj, vo, lengths, tensions = _user_units(frame, sheet, c, z, mass)
    rows, cols = np.nonzero(c.taut)
    cuts = np.searchsorted(rows, np.arange(1, len(c.form)))
    w = np.split(c.weights[rows, cols], cuts)
    ln = np.split(lengths[rows, cols], cuts)
    tn = np.split(tensions[rows, cols], cuts) if tensions is not None else [None] * len(w)
    eqs = [Equilibrium(tuple(idx.tolist()), obj[k], vo[k], w[k], tn[k], ln[k],
                       STATUS_NAMES[st])  # type: ignore[arg-type]
           for k, (idx, st) in enumerate(zip(np.split(cols, cuts), c.status.tolist()))]
    funnel = funnel_from(counts, len(eqs)) if counts is not None else None
    return FKResult(tuple(eqs), funnel, method, sheet, R, z, mass)


def forward_kinematics_batch(sheet: Sheet, formations: np.ndarray, hold_height: float, *,
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
    """
    sheet = _check_sheet(sheet)
    method = _check_method(method)
    if method == "exhaustive":
        raise InvalidInputError("method", "the batched form supports 'fast' and 'subsets'")
    mass = _check_mass(mass)
    z = check_hold_height(hold_height)
    R = check_formations(sheet, as_array(formations, "formations", ndim=3))
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
