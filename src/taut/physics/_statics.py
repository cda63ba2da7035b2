"""Statics of a point load on the inextensible sheet, used to read and to explain the
physics checks (no MuJoCo here).

* :func:`least_pull`: the smallest sideways pull a statically indeterminate set of taut
  straight cables (or tendons) can exert on a point load in the flat sheet, for the
  simulation's measured forces and for taut's model alike.
* :func:`lowest_point_load` and :func:`barrier`: the object's potential as a function of
  its contact point (the lowest point load at sheet point v, FK paper Sec. II: every cable
  satisfies :math:`|\\mathbf{p} - \\mathbf{r}_i|^2 + \\ldots \\le |\\mathbf{v} -
  \\mathbf{v}_i|^2`), and the highest point of it along a straight path between two rest
  states: an upper bound on the rim of the first state's basin.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import lsq_linear, minimize

from . import _tol

__all__ = ["least_pull", "model_pull", "lowest_point_load", "barrier"]


def least_pull(fixed: np.ndarray, flat: np.ndarray, space: np.ndarray,
               resultant: np.ndarray) -> tuple[np.ndarray, float]:
    r"""Least net pull :math:`\mathbf{f} + \sum_j T_j \mathbf{a}_j` in the flat sheet over
    tensions :math:`T_j \ge 0` whose resultant in space is ``resultant``.

    Parameters
    ----------
    fixed : ndarray, shape (2,)
        Pull of forces that cannot be redistributed.
    flat : ndarray, shape (k, 2)
        Unit direction in the flat sheet of each redistributable cable
        :math:`(\mathbf{v}_j - \mathbf{v}_o) / |\mathbf{v}_j - \mathbf{v}_o|`.
    space : ndarray, shape (k, 3)
        Its unit direction in space, from the load towards the held corner.
    resultant : ndarray, shape (3,)
        The force the cables must exert on the load together.

    Returns
    -------
    pull : ndarray, shape (2,)
    residual : float
        Norm of the unbalanced resultant (0 up to about |pull| / ``BALANCE_WEIGHT``^2 when
        non-negative tensions can carry ``resultant``).

    Examples
    --------
    Four cables at right angles in plan, sloping up at 45 degrees: any pair of opposite
    tensions may be exchanged, so they can hold a unit weight without any pull, although
    a lopsided set of forces that carries it (1, 0, 1, 0 times 1/sqrt(2)) pulls.

    >>> import numpy as np
    >>> a = np.array([[1.0, 0], [0, 1], [-1, 0], [0, -1]])
    >>> s = np.column_stack([a, np.ones(4)]) / np.sqrt(2)
    >>> pull, res = least_pull(np.zeros(2), a, s, np.array([0.0, 0, 1]))
    >>> bool(np.linalg.norm(pull) < 1e-9 and res < 1e-9)
    True
    """
    w = _tol.BALANCE_WEIGHT
    A = np.vstack([w * space.T, flat.T])
    b = np.concatenate([w * np.asarray(resultant, float), -np.asarray(fixed, float)])
    # Bounded-variable least squares (active set, exact at convergence); scipy 1.15's
    # nnls returned a non-optimal answer on a rotated copy of a 5-cable case.
    T = lsq_linear(A, b, bounds=(0.0, np.inf), method="bvls", tol=_tol.LSQ_TOL).x
    return fixed + flat.T @ T, float(np.linalg.norm(space.T @ T - resultant))


def model_pull(vertices: np.ndarray, formation: np.ndarray, hold_height: float,
               taut: tuple[int, ...], obj: np.ndarray, contact: np.ndarray) -> float:
    """The least sideways pull taut's own model exerts on the object at one of its states,
    as a fraction of the weight: 0 at an equilibrium, positive at a state that is not one,
    ``inf`` when its taut cables cannot carry the weight with non-negative tensions."""
    J = list(taut)
    P = np.column_stack([formation[J], np.full(len(J), hold_height)])
    space = P - obj
    space /= np.linalg.norm(space, axis=1)[:, None]
    flat = vertices[J] - contact
    flat /= np.linalg.norm(flat, axis=1)[:, None]
    pull, residual = least_pull(np.zeros(2), flat, space, np.array([0.0, 0.0, 1.0]))
    return float(np.linalg.norm(pull)) if residual <= _tol.BALANCE_SLACK else np.inf


def lowest_point_load(vertices: np.ndarray, formation: np.ndarray, hold_height: float,
                      contact: np.ndarray, start: np.ndarray) -> np.ndarray:
    """Lowest position (3,) of a point load at sheet point ``contact``: every robot ``i``
    at most :math:`|\\mathbf{v} - \\mathbf{v}_i|` away (a convex problem, solved by SLSQP
    from ``start``)."""
    reach = np.linalg.norm(vertices - contact, axis=1)
    P = np.column_stack([formation, np.full(len(formation), hold_height)])
    cons = {"type": "ineq", "fun": lambda p: reach ** 2 - np.sum((p - P) ** 2, axis=1)}
    res = minimize(lambda p: p[2], start, constraints=[cons], method="SLSQP",
                   options={"ftol": _tol.POINT_LOAD_FTOL, "maxiter": 500})
    return np.asarray(res.x, dtype=float)


def barrier(vertices: np.ndarray, formation: np.ndarray, hold_height: float,
            a: tuple[np.ndarray, np.ndarray], b: tuple[np.ndarray, np.ndarray]) -> float:
    """How far the object must rise above rest state ``a`` to reach rest state ``b`` when its
    contact point moves straight from one to the other in the flat sheet (each state as
    (object position, contact point)): an upper bound on the depth of ``a``'s basin,
    scenario units."""
    p = np.asarray(a[0], dtype=float)
    top = p[2]
    for t in np.linspace(0.0, 1.0, _tol.BARRIER_SAMPLES)[1:]:
        v = (1 - t) * np.asarray(a[1]) + t * np.asarray(b[1])
        p = lowest_point_load(vertices, formation, hold_height, v, p)
        top = max(top, float(p[2]))
    return top - float(a[0][2])
