"""The lowest rest state by direct minimisation, for formations where the enumeration of
taut sets found no stable state (docs/sheet_fk_solver.md, "The lowest state exists").

An object hanging in a sheet always has a lowest rest state: the global minimum of its
height over the feasible set, i.e. the maximum of the depth
:math:`d^2 = \\min_i (|\\mathbf{v}_o - \\mathbf{v}_i|^2 - |\\mathbf{r}_o - \\mathbf{r}_i|^2)`
(FK paper eqs. 1-4), which is the minimum of the nonsmooth function
:math:`F(x) = -d^2` of docs/sheet_kinematics.md §1. Next to a similar copy of the sheet the
enumeration can lose it to rounding (elsewhere it is complete: the enumeration is exact
up to rounding of well-conditioned systems, so only formations within ``DIRECT_RTOL`` of a
similar copy are searched, which keeps the common "no state above the floor" answer
cheap); here :math:`F` is minimised directly by steepest
descent (:mod:`taut.sheet.sim._descent`) from the reported states and the centroids, and
the end point is classified by its taut set: the cables at full length there. An engine
helper: it never imports the front end or the result classes.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import nnls

from .._lifted import Frame, solve_candidates
from .._tol import (ARRIVAL_ACTIVE_TOL, CURVATURE_TOL, DIRECT_MAXIT, DIRECT_RTOL, MERGE_RTOL,
    WEIGHT_TOL)
from ..sim._descent import descend
from ._finalize import _min_eig_family, _weights_family

__all__ = ["lowest_by_descent", "near_copy"]

_J = np.array([1.0, 1.0, -1.0, -1.0])


def _never(active: np.ndarray, x: np.ndarray) -> None:
    return None


def near_copy(vertices: np.ndarray, formation: np.ndarray, size: float) -> bool:
    """Whether ``formation`` lies within ``DIRECT_RTOL * size`` of a similar copy of the
    sheet (where the direct minimisation may be needed)."""
    return _copy_distance(vertices, formation) <= DIRECT_RTOL * size


def _copy_distance(vertices: np.ndarray, formation: np.ndarray) -> float:
    """Largest robot displacement to the nearest similar copy (rotation and scale, centroid
    kept) of the sheet: the closed-form 2-D Procrustes fit in complex numbers,
    :math:`c = \\sum \\bar a_i f_i / \\sum |a_i|^2` (as fk._similar, without its batched SVD)."""
    a = vertices[:, 0] - vertices[:, 0].mean() + 1j * (vertices[:, 1] - vertices[:, 1].mean())
    f = formation[:, 0] - formation[:, 0].mean() + 1j * (formation[:, 1] - formation[:, 1].mean())
    c = np.vdot(a, f) / np.vdot(a, a).real
    return float(np.abs(c * a - f).max())


def lowest_by_descent(vertices: np.ndarray, formation: np.ndarray, hold_height: float,
                      size: float, starts: list[tuple[np.ndarray, np.ndarray]]
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, bool] | None:
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
    (taut, object, contact, weights, strict) or None
        Taut cables (ascending indices), object (3,) and contact (2,) in the caller's frame,
        the minimum-norm non-negative load shares of the taut cables, and whether the
        minimum is strict (non-negative weights and a positive-definite reduced Hessian);
        None when every descent reaches the ground (:math:`z_o \\le 0`) or stops short of a
        rest point (no non-negative weights balance the object at its end).
    """
    if not near_copy(vertices, formation, size):
        return None                              # the enumeration is complete out here
    frame = Frame.build(vertices, formation[None], hold_height, size)
    P = frame.P[0]
    A, b = P[:, :4], P[:, 4]
    xs = [np.zeros(4)]
    for obj, contact in starts:
        xs.append(np.concatenate([(obj[:2] - frame.r_centre[0]) / size,
                                  (contact - frame.v_centre) / size]))
    floor = -frame.z ** 2
    if any(float(x0 @ (_J * x0) + (A @ x0 + b).max()) < floor for x0 in xs):
        return None                              # a start already lies below the floor
    best, best_f = None, np.inf
    for x0 in xs:
        x = descend(P, x0, _never, floor, maxit=DIRECT_MAXIT)
        if x is None:
            continue
        f = float(x @ (_J * x) + (A @ x + b).max())
        if f < best_f:
            best, best_f = x, f
    if best is None or not 0.0 < -best_f < frame.z ** 2:
        return None
    vals = best @ (_J * best) + A @ best + b
    idx = np.flatnonzero(vals >= vals.max() - ARRIVAL_ACTIVE_TOL)
    x = best
    if 2 <= len(idx) <= 5:                       # polish: the exact stationary point
        cand = np.full((1, 5), -1, dtype=np.intp)
        cand[0, :len(idx)] = idx
        sol = solve_candidates(frame, np.zeros(1, np.intp), cand)
        if len(sol.x) and np.abs(sol.x[0] - best).max() <= MERGE_RTOL and sol.depth2[0] > 0:
            x = sol.x[0]
    if len(idx) < 2:
        return None                              # the descent stopped short of a rest point
    # The descent's end is exact only to its tolerance: move it to the nearest point that
    # non-negative weights of the active cables balance exactly (NNLS, sum w = 1 weighted
    # heavily); a rest point is at most MERGE_RTOL away from where the descent stopped.
    E = np.vstack([frame.R[0, idx].T, frame.V[idx].T])
    heavy = 1e3
    w_nn, _ = nnls(np.vstack([E, heavy * np.ones(len(idx))]), np.append(x, heavy))
    if not w_nn.sum() > 0:
        return None
    w_nn = w_nn / w_nn.sum()
    if np.abs(E @ w_nn - x).max() > MERGE_RTOL:
        return None                              # no balance here: not a rest point
    x = E @ w_nn
    vals = x @ (_J * x) + A @ x + b
    depth2 = -float(vals.max())
    w, t_star = _weights_family(frame, 0, idx, x[:2], x[2:])
    if not t_star >= -WEIGHT_TOL:
        w = w_nn
    strict = len(idx) >= 3 and _min_eig_family(frame, 0, idx) > CURVATURE_TOL
    obj = np.empty(3)
    obj[:2] = x[:2] * size + frame.r_centre[0]
    obj[2] = hold_height - np.sqrt(max(depth2, 0.0)) * size
    contact = x[2:] * size + frame.v_centre
    return idx, obj, contact, np.asarray(w, dtype=np.float64), bool(strict)
