"""Load shares and balanced directions for inverse kinematics (docs/sheet_kinematics.md §6).

* :func:`maxent_weights`: the maximum-entropy point of the weight polytope
  :math:`\\{w \\ge 0, \\sum w_i = 1, \\sum w_i (\\mathbf{v}_i - \\mathbf{v}_o) = 0\\}`;
* :func:`closure_directions`: unit vectors :math:`\\mathbf{u}_i` maximising the alignment
  :math:`\\sum a_i \\mathbf{u}_i \\cdot \\mathbf{p}_i` subject to :math:`\\sum a_i
  \\mathbf{u}_i = 0`, through the weighted geometric median (Fermat-Weber dual).
"""

from __future__ import annotations

import numpy as np

from .._tol import (ARMIJO_C1, CLOSURE_RTOL, MAXENT_GRAD_TOL, MAXENT_MIN_STEP, MEDIAN_COINCIDE,
    MEDIAN_MIN_STEP, MEDIAN_RTOL, TINY)

__all__ = ["maxent_weights", "closure_directions"]


def maxent_weights(V: np.ndarray, vo: np.ndarray, scale: float) -> np.ndarray:
    """Maximum-entropy weights of the contact point ``vo`` (barycentric when N = 3).

    Newton's method on the 2-D dual: :math:`w_i \\propto \\exp(\\lambda \\cdot
    (\\mathbf{v}_i - \\mathbf{v}_o))`.

    Parameters
    ----------
    V : ndarray, shape (N, 2)
        Sheet vertices.
    vo : ndarray, shape (2,)
        Contact point, strictly inside the sheet.
    scale : float
        Length scale (the sheet size) that makes the dual well conditioned.

    Returns
    -------
    ndarray, shape (N,)
    """
    E = (V - vo) / scale
    lam = np.zeros(2)

    def dual(lam: np.ndarray) -> tuple[float, np.ndarray]:
        s = E @ lam
        top = s.max()
        e = np.exp(s - top)
        return float(top + np.log(e.sum())), e / e.sum()

    f, w = dual(lam)
    for _ in range(200):
        g = w @ E
        if np.linalg.norm(g) < MAXENT_GRAD_TOL:
            break
        H = (E * w[:, None]).T @ E - np.outer(g, g)
        try:
            step = -np.linalg.solve(H + TINY * np.eye(2), g)
        except np.linalg.LinAlgError:
            step = -g
        t = 1.0
        while True:
            f_new, w_new = dual(lam + t * step)
            if f_new <= f + ARMIJO_C1 * t * float(g @ step) or t < MAXENT_MIN_STEP:
                break
            t *= 0.5
        lam, f, w = lam + t * step, f_new, w_new
    return w


def _median_unit_vectors(p: np.ndarray, m: np.ndarray) -> np.ndarray | None:
    diff = p - m
    n = np.linalg.norm(diff, axis=1)
    if n.min() <= MEDIAN_COINCIDE:
        return None
    return diff / n[:, None]


def closure_directions(a: np.ndarray, p: np.ndarray) -> np.ndarray | None:
    """Unit vectors u_i maximising sum a_i u_i . p_i subject to sum a_i u_i = 0.

    ``u_i = (p_i - m)/|p_i - m|`` with ``m`` the ``a``-weighted geometric median of the
    ``p_i`` (damped Newton on the convex :math:`\\Phi(m) = \\sum a_i |p_i - m|`).

    Parameters
    ----------
    a : ndarray, shape (N,)
        Side lengths :math:`a_i = w_i \\rho_i > 0` of the closing polygon.
    p : ndarray, shape (N, 2)
        Preferred unit directions.

    Returns
    -------
    ndarray, shape (N, 2), or None
        None when the median sits on one of the points (no balanced directions this way).
    """
    total = a.sum()
    m = (a[:, None] * p).sum(axis=0) / total

    def phi(m: np.ndarray) -> float:
        return float((a * np.linalg.norm(p - m, axis=1)).sum())

    f = phi(m)
    for _ in range(100):
        u = _median_unit_vectors(p, m)
        if u is None:
            return None
        n = np.linalg.norm(p - m, axis=1)
        g = -(a[:, None] * u).sum(axis=0)
        if np.linalg.norm(g) <= MEDIAN_RTOL * total:
            return u
        H = np.einsum("i,ijk->jk", a / n, np.eye(2)[None] - u[:, :, None] * u[:, None, :])
        try:
            step = -np.linalg.solve(H, g)
        except np.linalg.LinAlgError:
            step = -g
        t = 1.0
        while True:
            trial = m + t * step
            f_new = phi(trial)
            if f_new <= f + ARMIJO_C1 * t * float(g @ step) or t < MEDIAN_MIN_STEP:
                break
            t *= 0.5
        if t < MEDIAN_MIN_STEP:
            break
        m, f = trial, f_new
    u = _median_unit_vectors(p, m)
    if u is None:
        return None
    return u if np.linalg.norm((a[:, None] * u).sum(axis=0)) <= CLOSURE_RTOL * total else None
