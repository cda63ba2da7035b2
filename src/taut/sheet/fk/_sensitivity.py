"""Sensitivities of a sheet equilibrium to the robots' positions (issue 28, part 2).

Within its taut set :math:`T` (k cables) a rest state solves the stationarity (KKT)
conditions of the VVCM model (FK paper, Hu et al., eqs. 3-4 and the force balance of
Sec. II; docs/sheet_sensitivity.md):

.. math::

    |r_o - r_i|^2 - |v_o - v_i|^2 + s = 0 \\ (i \\in T), \\quad
    r_o = \\sum_T w_i r_i, \\quad v_o = \\sum_T w_i v_i, \\quad \\sum_T w_i = 1,

with :math:`s = d^2 = (z_r - z_o)^2`: k + 5 equations in the k + 5 unknowns
:math:`(r_o, v_o, s, w)`. Where their Jacobian is regular (the constraint gradients are
independent and the reduced Hessian is regular, e.g. every strict minimum with at most
five taut cables) the implicit function theorem gives the exact derivatives of the object,
the contact point, the load shares and the tensions with respect to every robot's
(x, y); slack robots do not enter. Everything is computed in the frame normalised by the
sheet size (:mod:`taut.sheet._tol`), on first access of an :class:`Equilibrium`'s
``jacobian`` (the FK hot path does not pay for it).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..._units import GRAVITY
from .._tol import MAX_CONDITION

__all__ = ["Sensitivity", "equilibrium_sensitivity"]


class Sensitivity(NamedTuple):
    """Derivatives of one rest state with respect to the robots' positions (private to
    :class:`~taut.sheet.Equilibrium`, which exposes them; NaN where the state's
    stationarity system is singular)."""

    object: np.ndarray          # (3, N, 2), dimensionless
    contact: np.ndarray         # (2, N, 2), dimensionless
    weights: np.ndarray         # (k, N, 2), per length unit
    tensions: np.ndarray | None  # (k, N, 2), N per length unit
    margin: float               # length unit


def _system(dr: np.ndarray, dv: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The linearised stationarity system ``M X = B`` of module docstring: unknowns
    (dr_o 2, dv_o 2, ds 1, dw k), one right-hand side per taut robot coordinate (2k);
    ``dr``, ``dv`` (k, 2) are r_i - r_o, v_i - v_o (normalised)."""
    k = len(w)
    n = k + 5
    M = np.zeros((n, n))
    M[:k, 0:2] = -2.0 * dr
    M[:k, 2:4] = 2.0 * dv
    M[:k, 4] = 1.0
    M[k:k + 2, 0:2] = np.eye(2)
    M[k:k + 2, 5:] = -dr.T
    M[k + 2:k + 4, 2:4] = np.eye(2)
    M[k + 2:k + 4, 5:] = -dv.T
    M[k + 4, 5:] = 1.0
    B = np.zeros((n, k, 2))
    ar = np.arange(k)
    B[ar, ar, :] = -2.0 * dr
    B[k, :, 0] = w
    B[k + 1, :, 1] = w
    return M, B.reshape(n, 2 * k)


def _singular(k: int, N: int, n_weights: int, mass: bool) -> Sensitivity:
    nan = np.full
    return Sensitivity(nan((3, N, 2), np.nan), nan((2, N, 2), np.nan),
                       nan((n_weights, N, 2), np.nan),
                       nan((n_weights, N, 2), np.nan) if mass else None, 0.0)


def equilibrium_sensitivity(vertices: np.ndarray, formation: np.ndarray, hold_height: float,
                            mass: float | None, scale: float, taut: tuple[int, ...],
                            obj: np.ndarray, contact: np.ndarray, weights: np.ndarray
                            ) -> Sensitivity:
    """The :class:`Sensitivity` of the state (``taut``, ``obj``, ``contact``, ``weights``)
    of ``formation`` (N, 2) holding ``vertices`` (N, 2) at ``hold_height``; ``scale`` is
    the sheet size (normalisation), ``mass`` kg or None."""
    N, idx = len(formation), np.asarray(taut, dtype=np.intp)
    k = len(idx)
    ro, vo = obj[:2], contact
    dr = (formation[idx] - ro) / scale
    dv = (vertices[idx] - vo) / scale
    d = (hold_height - obj[2]) / scale
    M, B = _system(dr, dv, weights)
    if k > 5 or d <= 0 or np.linalg.cond(M) > MAX_CONDITION:
        return _singular(k, N, len(weights), mass is not None)
    X = np.linalg.solve(M, B).reshape(k + 5, k, 2)
    J = np.zeros((3, N, 2))
    J[0:2, idx] = X[0:2]
    J[2, idx] = -X[4] / (2.0 * d)
    Jv = np.zeros((2, N, 2))
    Jv[:, idx] = X[2:4]
    Jw = np.zeros((k, N, 2))
    Jw[:, idx] = X[5:] / scale
    tensions = None
    if mass is not None:
        tensions = _tension_jacobian(dv, d, weights, Jw, Jv, J[2], mass, scale)
    margin = _margin(vertices, formation, scale, idx, obj, contact, d, weights, Jw, J, Jv)
    return Sensitivity(J, Jv, Jw, tensions, margin)


def _tension_jacobian(dv: np.ndarray, d: float, w: np.ndarray, Jw: np.ndarray,
                      Jv: np.ndarray, Jz: np.ndarray, mass: float, scale: float
                      ) -> np.ndarray:
    """d F_i / d r_j (k, N, 2), N per length unit, of :math:`F_i = w_i m g l_i / d`
    (FK paper Sec. II; ``d`` and ``dv`` normalised)."""
    ln = np.linalg.norm(dv, axis=1)                          # l_i, normalised
    dln = -np.einsum("ia,anc->inc", dv / ln[:, None], Jv)     # d l_i / d r (normalised)
    dd = -Jz                                                  # d d / d r = -dz / dr
    ratio = ln / d
    dratio = (dln / d - (ln / d ** 2)[:, None, None] * dd[None]) / scale
    return mass * GRAVITY * (Jw * ratio[:, None, None] + w[:, None, None] * dratio)


def _margin(vertices: np.ndarray, formation: np.ndarray, scale: float, idx: np.ndarray,
            obj: np.ndarray, contact: np.ndarray, d: float, w: np.ndarray, Jw: np.ndarray,
            J: np.ndarray, Jv: np.ndarray) -> float:
    """Least Frobenius norm of a robot displacement (N, 2) at which the linearisation
    puts a load share at 0 or a slack cable at taut (length unit; 0 when a share is
    already <= 0)."""
    if np.any(w <= 0):
        return 0.0
    gw = np.linalg.norm(Jw.reshape(len(w), -1), axis=1)
    best = float(np.min(np.where(gw > 0, w / np.where(gw > 0, gw, 1.0), np.inf)))
    slack = np.setdiff1d(np.arange(len(formation)), idx)
    if len(slack):
        drs = (formation[slack] - obj[:2]) / scale
        dvs = (vertices[slack] - contact) / scale
        h = np.sum(dvs * dvs, axis=1) - np.sum(drs * drs, axis=1) - d * d   # >= 0
        # dh = -2 dv_j . dv_o + 2 dr_j . dr_o - 2 dr_j . dr_j(own) - ds, ds = -2 d dz
        G = (-2.0 * np.einsum("ja,anc->jnc", dvs, Jv) + 2.0 * np.einsum("ja,anc->jnc", drs, J[:2])
             + 2.0 * d * J[2][None])
        G[np.arange(len(slack)), slack] -= 2.0 * drs
        g = np.linalg.norm(G.reshape(len(slack), -1), axis=1)
        ok = g > 0
        if np.any(ok):
            best = min(best, float(np.min(np.maximum(h[ok], 0.0) / g[ok]) * scale))
    return best
