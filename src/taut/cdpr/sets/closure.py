"""Wrench-closure workspace: poses at which the cables can balance *every* external wrench
with positive tensions, tension limits ignored (the classical condition for fully
constrained CDPRs; a suspended robot, which relies on gravity, has none).

Exact test per pose (Gordan's alternative): the cable wrenches ``W`` (n x m, FASTKIT eq. 18)
positively span R^n iff ``W`` has rank n and some ``t > 0`` has ``W t = 0``. The second
condition is the linear program ``max s`` s.t. ``W t = 0``, ``s <= t_i <= 1``, decided by
HiGHS: the pose has wrench closure iff the optimum ``s`` exceeds ``closure_tol``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import linprog

from ..statics._common import svd_split
from .._batching import first, is_single
from .._tol import CLOSURE_TOL
from ..kinematics.cables import as_poses, cable_state
from ..model.robot import CableRobot
from ..._validate import as_tolerance

__all__ = ["wrench_closure"]


def wrench_closure(robot: CableRobot, poses: ArrayLike, *,
                   closure_tol: float = CLOSURE_TOL) -> np.ndarray:
    """Whether each pose has wrench closure, (B,) bool (a bool for one pose).

    Parameters
    ----------
    robot : CableRobot
    poses : array_like (6,), (3,), (B, 6) or (B, 3)
        Platform poses, m and rad.
    closure_tol : float
        Smallest tension, as a fraction of the largest one, of the most balanced
        self-stress ``W t = 0`` for the pose to count (dimensionless).

    Examples
    --------
    >>> from taut.io.cdpr_model import load_cdpr_model
    >>> fc = load_cdpr_model("fastkit_fc")
    >>> wrench_closure(fc, [[0, 0, 1.2], [0, 0, 2.3]]).tolist()
    [True, False]
    >>> wrench_closure(load_cdpr_model("fastkit"), [0, 0, 1.2])   # suspended
    False
    """
    closure_tol = as_tolerance(closure_tol, "closure_tol")
    single = is_single(poses)
    P = as_poses(robot, poses)
    st = cable_state(robot, P, validated=True)
    _, _, full = svd_split(st.W)
    m = robot.m
    out = np.zeros(P.shape[0], dtype=bool)
    c = np.zeros(m + 1)
    c[-1] = -1.0
    A_ub = np.hstack([-np.eye(m), np.ones((m, 1))])          # s - t_i <= 0
    for k in np.nonzero(full)[0]:
        A_eq = np.hstack([st.W[k], np.zeros((st.W.shape[1], 1))])
        sol = linprog(c, A_ub=A_ub, b_ub=np.zeros(m), A_eq=A_eq, b_eq=np.zeros(A_eq.shape[0]),
                      bounds=[(0.0, 1.0)] * m + [(None, None)], method="highs")
        out[k] = sol.status == 0 and -sol.fun > closure_tol
    return first(out) if single else out
