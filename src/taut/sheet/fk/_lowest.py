"""The lowest rest state by direct minimisation, for formations where the enumeration of
taut sets found no stable state (docs/sheet_fk_solver.md, "The lowest state exists").

The lowest rest state of an object hanging in a sheet is the global minimum of its height
over the feasible set, i.e. the maximum of the depth
:math:`d^2 = \\min_i (|\\mathbf{v}_o - \\mathbf{v}_i|^2 - |\\mathbf{r}_o - \\mathbf{r}_i|^2)`
(FK paper eqs. 1-4), which is the minimum of the nonsmooth function
:math:`F(x) = -d^2` of docs/sheet_kinematics.md §1. The enumeration is complete in exact
arithmetic; it can lose that state where float64 cannot tell the taut set (next to a
similar copy of the sheet: a cable slack by 1e-9 counts as taut and the state's taut set
is then answered by another point) or where the minimum is not strict (a flat valley: no
taut set has a unique stationary point). Here :math:`F` is minimised directly by steepest
descent (:mod:`taut.sheet.sim._descent`) from the reported states and the centroids; the
pieces near the maximum where it stops are re-solved exactly (every subset of 3..5, the
stationarity system of docs/sheet_kinematics.md §3), and the lowest exact equilibrium
there is the answer, strict when its reduced Hessian is positive definite (§5). Where no
subset has an exact equilibrium (a flat minimum) the descent's end, balanced by
non-negative weights, is the answer, not strict. An engine helper: it never imports the
front end or the result classes.
"""

from __future__ import annotations

from itertools import combinations
from math import sqrt
from typing import Callable

import numpy as np

from .._lifted import (Frame, height_ok, maximiser_masks, pad_groups, reduced_hessian_min_eig,
    solve_candidates, taut_at)
from .._tol import (ARRIVAL_ACTIVE_TOL, CURVATURE_TOL, DIRECT_MAXIT, DIRECT_NEAR_MAX,
    DIRECT_NEAR_TOL, DIRECT_RTOL, MERGE_RTOL, TAUT_TOL, WEIGHT_TOL)
from ..sim._descent import descend
from ._finalize import _min_eig_family, _weights_family

__all__ = ["lowest_by_descent", "may_find_stable", "may_find_stable_batch", "FLOOR",
           "OFF_SHEET", "NO_REST"]

_J = np.array([1.0, 1.0, -1.0, -1.0])

#: (taut cables, x (4,) normalised, weights of the taut cables, strict)
_State = tuple[np.ndarray, np.ndarray, np.ndarray, bool]


#: Why the direct minimisation found no rest state (:func:`lowest_by_descent`).
FLOOR, OFF_SHEET, NO_REST = "floor", "off_sheet", "no_rest"


#: Most cables taut at a rest state of a formation in general position: the object's
#: position (3 unknowns) and its contact point on the sheet (2) meet one equation per taut
#: cable. Larger teams always get the direct minimisation (:func:`may_find_stable`).
GENERIC_TAUT_MAX = 5

#: Teams up to this size get the pure-Python copy distance (``_copy_distance``).
_PY_MAX_N = 12


def may_find_stable(vertices: np.ndarray, formation: np.ndarray, size: float) -> bool:
    """Whether :func:`lowest_by_descent` can supply a *stable* state the enumeration missed.

    Where float64 cannot tell a cable slack by ~1e-9 from a taut one, the enumeration can
    lose a strict minimum. That happens in two places:

    * next to a similar copy of the sheet (robots within ``DIRECT_RTOL * size`` of one;
      seed 34152 of the issue-25 property test);
    * in every team of more than :data:`GENERIC_TAUT_MAX` robots: a rest state has five
      unknowns (object position, contact point), so more taut cables than five meet only
      on a set of formations of measure zero -- exactly the all-taut formations that IK
      and the planner make. There the enumeration's five-cable solution counts the other
      cables taut or overstretched by rounding alone (suite-2024 scenario 39's narrow
      hexagon: found on one CPU, lost on another).

    Elsewhere the enumeration is exact up to the rounding of well-conditioned systems and
    its stable states are complete; the descent then adds only a non-strict minimum or
    the reason why there is no rest state, so the common question "does this formation
    hold the object?" (``FKResult.stable``, ``success``) skips it. The decision is made
    here (:func:`_near_copy`, :data:`GENERIC_TAUT_MAX`) and nowhere else;
    :func:`may_find_stable_batch` makes it for many formations at once, with the same
    numbers.

    Parameters
    ----------
    vertices, formation : ndarray, shape (N, 2)
        Sheet vertices and robot positions (caller's length unit).
    size : float
        Sheet size (same unit).
    """
    if len(vertices) > GENERIC_TAUT_MAX:
        return True
    return bool(_near_copy(_copy_distance(vertices, formation), size))


def may_find_stable_batch(vertices: np.ndarray, formations: np.ndarray, size: float
                          ) -> np.ndarray:
    """:func:`may_find_stable` of each of ``B`` formations, in one numpy pass.

    Parameters
    ----------
    vertices : ndarray, shape (N, 2)
        Sheet vertices (caller's length unit).
    formations : ndarray, shape (B, N, 2)
        Robot positions (same unit).
    size : float
        Sheet size (same unit).

    Returns
    -------
    ndarray of bool, shape (B,)
        The scalar decision for each formation (the same distances, bit for bit, up to
        ``_PY_MAX_N`` robots: the same operations in the same order).
    """
    if len(vertices) > GENERIC_TAUT_MAX:
        return np.ones(len(formations), dtype=bool)
    return np.asarray(_near_copy(_copy_distances(vertices, formations), size), dtype=bool)


def _near_copy(dist: np.ndarray | float, size: float) -> np.ndarray | bool:
    """The decision of :func:`may_find_stable` on copy distances (``_copy_distance``)."""
    return dist <= DIRECT_RTOL * size


def _copy_distance(vertices: np.ndarray, formation: np.ndarray) -> float:
    """Largest robot displacement (caller's unit) to the nearest similar copy (rotation and
    scale, centroid kept) of the sheet: the closed-form 2-D Procrustes fit in complex
    numbers :math:`a_i, f_i` (centred vertices and robots),
    :math:`c = \\sum \\bar a_i f_i / \\sum |a_i|^2`, distance
    :math:`\\max_i |c a_i - f_i|` (as fk._similar, without its batched SVD). It runs on
    every ``FKResult.stable`` without a stable state: up to ``_PY_MAX_N`` robots in
    Python floats, in real and imaginary parts (2-4x faster there than numpy's per-call
    overhead; sequential sums, the operations of :func:`_copy_distances` in its order),
    above in numpy complex numbers (the batched version's ~20 array operations cost 2-3x
    these 8 on one formation; the same distance up to rounding)."""
    if len(vertices) > _PY_MAX_N:
        av = np.ascontiguousarray(vertices).view(np.complex128)[:, 0]
        fv = np.ascontiguousarray(formation).view(np.complex128)[:, 0]
        av, fv = av - av.mean(), fv - fv.mean()
        cv = np.vdot(av, fv) / np.vdot(av, av).real
        return float(np.abs(cv * av - fv).max())
    vx, vy = zip(*vertices.tolist())
    fx, fy = zip(*formation.tolist())
    n = len(vx)
    vmx = vmy = fmx = fmy = 0.0
    for i in range(n):
        vmx += vx[i]
        vmy += vy[i]
        fmx += fx[i]
        fmy += fy[i]
    vmx, vmy, fmx, fmy = vmx / n, vmy / n, fmx / n, fmy / n
    ax = [x - vmx for x in vx]
    ay = [y - vmy for y in vy]
    bx = [x - fmx for x in fx]
    by = [y - fmy for y in fy]
    num_r = num_i = den = 0.0
    for i in range(n):
        num_r += ax[i] * bx[i] + ay[i] * by[i]
        num_i += ax[i] * by[i] - ay[i] * bx[i]
        den += ax[i] * ax[i] + ay[i] * ay[i]
    cr, ci = num_r / den, num_i / den
    worst = 0.0
    for i in range(n):
        dx = cr * ax[i] - ci * ay[i] - bx[i]
        dy = cr * ay[i] + ci * ax[i] - by[i]
        d2 = dx * dx + dy * dy
        if d2 > worst:
            worst = d2
    return sqrt(worst)


def _copy_distances(vertices: np.ndarray, formations: np.ndarray) -> np.ndarray:
    """:func:`_copy_distance` of each of ``B`` formations (B, N, 2): the same operations
    on (N, B) arrays, every sum sequential as the loops of the scalar version (the last
    entry of a cumulative sum; a reduction would sum pairwise along a contiguous axis,
    e.g. for B = 1)."""
    F = np.asarray(formations, dtype=np.float64)
    n = F.shape[1]
    V = np.asarray(vertices, dtype=np.float64)
    vx, vy = V[:, 0], V[:, 1]
    ax = (vx - np.cumsum(vx)[-1] / n)[:, None]                  # (N, 1)
    ay = (vy - np.cumsum(vy)[-1] / n)[:, None]
    den = float(np.cumsum(ax * ax + ay * ay)[-1])
    fx = np.ascontiguousarray(F[:, :, 0].T)                     # (N, B)
    fy = np.ascontiguousarray(F[:, :, 1].T)
    bx = fx - np.cumsum(fx, axis=0)[-1] / n
    by = fy - np.cumsum(fy, axis=0)[-1] / n
    cr = np.cumsum(ax * bx + ay * by, axis=0)[-1] / den
    ci = np.cumsum(ax * by - ay * bx, axis=0)[-1] / den
    dx = cr * ax - ci * ay - bx
    dy = cr * ay + ci * ax - by
    return np.sqrt((dx * dx + dy * dy).max(axis=0))


def _off_sheet(V: np.ndarray) -> Callable[[np.ndarray, np.ndarray], str | None]:
    """``arrive`` callback of the descent: :data:`OFF_SHEET` once the contact point
    ``x[2:]`` lies outside the (convex) sheet with vertices ``V`` (N, 2), in order."""
    E = np.roll(V, -1, axis=0) - V
    sign = 1.0 if float(np.sum(E[:, 0] * (V[:, 1] + np.roll(V, -1, axis=0)[:, 1]))) < 0 else -1.0

    def arrive(active: np.ndarray, x: np.ndarray) -> str | None:
        side = E[:, 0] * (x[3] - V[:, 1]) - E[:, 1] * (x[2] - V[:, 0])
        return OFF_SHEET if float((sign * side).min()) < -TAUT_TOL else None
    return arrive


def lowest_by_descent(vertices: np.ndarray, formation: np.ndarray, hold_height: float,
                      size: float, starts: list[tuple[np.ndarray, np.ndarray]]
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, bool] | str:
    """The lowest rest point reached by descending :math:`F` from each start.

    Parameters
    ----------
    vertices, formation : ndarray, shape (N, 2)
        Sheet vertices and robot positions (caller's length unit).
    hold_height, size : float
        Hold height and sheet size (same unit).
    starts : list of (object (3,), contact (2,))
        Extra start points (e.g. the states the enumeration found); the centroids of the
        formation and of the sheet are always tried.

    Returns
    -------
    (taut, object, contact, weights, strict) or str
        Taut cables (ascending indices: every cable at full length, within ``TAUT_TOL``),
        object (3,) and contact (2,) in the caller's frame, the minimum-norm non-negative
        load shares of the taut cables, and whether the minimum is strict (non-negative
        weights and a positive-definite reduced Hessian). Without a rest state, why:
        :data:`FLOOR` (a start lies below the floor, or every descent reaches it),
        :data:`OFF_SHEET` (every descent that does not reach the floor carries the contact
        point over the sheet's edge: the object slides off the sheet) or :data:`NO_REST`
        (a descent stops short of a rest point: no non-negative weights balance it).
    """
    frame = Frame.build(vertices, formation[None], hold_height, size)
    P = frame.P[0]
    A, b = P[:, :4], P[:, 4]
    xs = [np.zeros(4)]
    for obj, contact in starts:
        xs.append(np.concatenate([(obj[:2] - frame.r_centre[0]) / size,
                                  (contact - frame.v_centre) / size]))
    floor = -frame.z ** 2
    if any(float(x0 @ (_J * x0) + (A @ x0 + b).max()) < floor for x0 in xs):
        return FLOOR                             # a start already lies below the floor
    # With the contact point on the (convex) sheet every cable is at most the sheet's
    # diameter D long, so F >= -D^2: a descent below that has left the sheet.
    D2 = float(((frame.V[:, None] - frame.V[None]) ** 2).sum(axis=2).max())
    reach = max(floor, -D2)
    best, best_f, why = None, np.inf, FLOOR
    arrive = _off_sheet(frame.V)
    for x0 in xs:
        x = descend(P, x0, arrive, reach, maxit=DIRECT_MAXIT)
        if x is None or isinstance(x, str):      # below the floor or off the sheet
            if x is not None or reach > floor:
                why = OFF_SHEET
            continue
        f = float(x @ (_J * x) + (A @ x + b).max())
        if f < best_f:
            best, best_f = x, f
    if best is None:
        return why
    if not 0.0 < -best_f < frame.z ** 2:
        return NO_REST
    state = _exact_nearby(frame, best) or _balanced_end(frame, best)
    if state is None:
        return NO_REST
    idx, x, w, strict = state
    depth2 = -float((x @ (_J * x) + A @ x + b).max())
    obj = np.empty(3)
    obj[:2] = x[:2] * size + frame.r_centre[0]
    obj[2] = hold_height - np.sqrt(max(depth2, 0.0)) * size
    contact = x[2:] * size + frame.v_centre
    return idx, obj, contact, np.asarray(w, dtype=np.float64), bool(strict)


def _taut_weights(frame: Frame, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """The cables at full length at ``x`` (within ``TAUT_TOL``), their minimum-norm
    non-negative weights and the largest achievable least weight (``_weights_family``)."""
    P = frame.P[0]
    depth2 = -float(x @ (_J * x) + (P[:, :4] @ x + P[:, 4]).max())     # F's depth at x
    idx = np.flatnonzero(taut_at(frame, 0, x, depth2))
    w, t_star = _weights_family(frame, 0, idx, x[:2], x[2:])
    return idx, w, t_star


def _exact_nearby(frame: Frame, x_end: np.ndarray) -> _State | None:
    """The lowest exact equilibrium among the subsets of 3..5 of the pieces within
    ``DIRECT_NEAR_TOL`` of the maximum at ``x_end`` (at most ``DIRECT_NEAR_MAX`` of them,
    the highest): each subset's stationarity system solved exactly, kept when its pieces
    are the maximum there (FK paper eq. 4), the object is above the floor (eq. 15) and its
    weights are non-negative; strict when its reduced Hessian is positive definite
    (docs/sheet_kinematics.md §5). Among equilibria whose depths agree within
    ``TAUT_TOL``, a strict one is preferred. None when no subset has an equilibrium."""
    P = frame.P[0]
    vals = P[:, :4] @ x_end + P[:, 4]
    order = np.argsort(-vals, kind="stable")
    near = np.sort(order[:DIRECT_NEAR_MAX][vals[order[:DIRECT_NEAR_MAX]]
                                           >= vals.max() - DIRECT_NEAR_TOL])
    if len(near) < 3:
        return None
    groups = {}
    for s in range(3, min(5, len(near)) + 1):
        c = np.array(list(combinations(near, s)), dtype=np.intp)
        groups[s] = (np.zeros(len(c), np.intp), c)
    sol = solve_candidates(frame, *pad_groups(groups))
    ok, _ = maximiser_masks(frame, sol.form, sol.x, sol.mu)
    members = sol.subset >= 0
    min_w = np.where(members, sol.w, np.inf).min(axis=1)
    keep = np.flatnonzero(ok & height_ok(frame, sol) & (min_w >= -WEIGHT_TOL))
    if len(keep) == 0:
        return None
    eig = reduced_hessian_min_eig(frame, sol.form[keep], sol.subset[keep])
    strict = eig > CURVATURE_TOL
    deepest = float(sol.depth2[keep].max())
    # The deepest (lowest object), a strict one among those as deep within TAUT_TOL.
    rank = np.lexsort((-sol.depth2[keep], ~strict, sol.depth2[keep] < deepest - TAUT_TOL))
    k = int(rank[0])
    x = sol.x[keep[k]]
    idx, w, _ = _taut_weights(frame, x)
    return idx, x, w, bool(strict[k])


def _balanced_end(frame: Frame, x_end: np.ndarray) -> _State | None:
    """The descent's end as a rest point when no subset of its pieces has an exact
    equilibrium (a flat minimum): moved to the nearest point that non-negative weights of
    the active pieces balance exactly (NNLS, sum w = 1 weighted heavily), at most
    ``MERGE_RTOL`` away; strict only if its reduced Hessian says so. None when no such
    weights exist (the descent stopped short of a rest point)."""
    P = frame.P[0]
    vals = x_end @ (_J * x_end) + P[:, :4] @ x_end + P[:, 4]
    idx = np.flatnonzero(vals >= vals.max() - ARRIVAL_ACTIVE_TOL)
    if len(idx) < 2:
        return None                              # the descent stopped short of a rest point
    from scipy.optimize import nnls              # rare: imported here, not with FK

    E = np.vstack([frame.R[0, idx].T, frame.V[idx].T])
    heavy = 1e3
    w_nn, _ = nnls(np.vstack([E, heavy * np.ones(len(idx))]), np.append(x_end, heavy))
    if not w_nn.sum() > 0:
        return None
    w_nn = w_nn / w_nn.sum()
    if np.abs(E @ w_nn - x_end).max() > MERGE_RTOL:
        return None                              # no balance here: not a rest point
    x = E @ w_nn
    w, t_star = _weights_family(frame, 0, idx, x[:2], x[2:])
    if not t_star >= -WEIGHT_TOL:
        w = w_nn
    strict = len(idx) >= 3 and _min_eig_family(frame, 0, idx) > CURVATURE_TOL
    return idx, x, w, bool(strict)
