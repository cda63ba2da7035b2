"""Kinematic redundancy resolution of mobile CDPRs (FASTKIT §2-3: in task mode the active
base adds 3 joints to the m cables, so ``A t = B q_dot`` (eq. 9) has a 3k-dimensional family
of solutions for a desired platform twist ``t``).

Since ``B = [B_b  I_m]``, the cable speeds follow from the base rates:
``l_dot = A t - B_b q_dot_b``. Only the 3k base rates are free; the problem is a small
strictly convex QP over them with box constraints on base rates and cable speeds.

Objectives (joint rates are normalised by their limits, ``s_j = max(|lo_j|, |hi_j|)``, so
that rad/s and m/s mix on a common dimensionless scale):

* ``"min_norm"``: minimise ``sum_j (q_dot_j / s_j)^2`` over all joints (bases and cables);
* ``"least_base"``: minimise ``sum_j (q_dot_bj / s_j)^2`` over the base joints only, plus a
  1e-6 weight on the cables to make the solution unique: the bases move only when the cables
  alone cannot produce the twist within their limits.

Feasibility is decided by an LP (HiGHS); the QP is solved by DAQP (:mod:`taut._qp`), or
SciPy's SLSQP from that feasible point where DAQP is not installed, and its result is
re-checked against the limits.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal, Sequence

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import linprog

from ..._qp import solve_qp
from ..._validate import as_array, as_choice
from ...errors import InvalidInputError
from .._tol import LEAST_BASE_CABLE_WEIGHT, RATE_FLOOR, REDUNDANCY_TOL, SCALE_ONE, SLSQP_FTOL
from ..kinematics.first_order import FirstOrderModel, first_order_model
from ..model.robot import CableRobot
from ..kinematics.modes import ModeName, MotionLimits, fastkit_motion_limits, joint_bounds
from ..._validate import as_tolerance, require_instance
from ..._repr import CompactRepr

__all__ = ["OBJECTIVES", "RedundancyResult", "resolve_redundancy"]

OBJECTIVES = ("min_norm", "least_base")
Objective = Literal["min_norm", "least_base"]


@dataclass(frozen=True, repr=False)
class RedundancyResult(CompactRepr):
    """Joint rates for one desired platform twist.

    Attributes
    ----------
    success : bool
        The twist is available (inside the ATS) and ``q_dot`` reproduces it within limits.
    status : str
        ``"ok"``, or ``"infeasible"`` when only a fraction ``scale`` of the twist is
        available within the joint limits.
    message : str
        One line: what was found, or why not.
    q_dot : (3k + m,) or (3,)
        Joint rates in ``joint_names`` order (base rates rad/s, m/s; cable speeds m/s).
        When infeasible: the rates of the largest feasible fraction ``scale`` of the twist.
    base_rates : (3k,)
    cable_speeds : (m,)
        Zero in navigation mode.
    scale : float
        Largest ``s in [0, 1]`` such that ``s t`` is available (1 when feasible).
    residual : float
        ``max |A t - B q_dot|`` for the returned rates at ``scale``, m/s.
    objective : str
    joint_names : tuple of str
    """

    success: bool
    status: str
    message: str
    q_dot: np.ndarray
    base_rates: np.ndarray
    cable_speeds: np.ndarray
    scale: float
    residual: float
    objective: str
    joint_names: tuple[str, ...]


def _lp_scale(C: np.ndarray, d: np.ndarray, lo: np.ndarray, hi: np.ndarray, nb: int
              ) -> tuple[float, np.ndarray]:
    """max s in [0, 1] with ``lo <= [x; d s - C x] <= hi`` over base rates x (nb,)."""
    m = d.size
    # variables (x, s); constraints on cables: lo_c <= d s - C x <= hi_c
    A_ub = np.vstack([np.hstack([-C, d[:, None]]), np.hstack([C, -d[:, None]])])
    b_ub = np.concatenate([hi[nb:], -lo[nb:]])
    cost = np.zeros(nb + 1)
    cost[-1] = -1.0
    bounds = list(zip(lo[:nb], hi[:nb])) + [(0.0, 1.0)]
    sol = linprog(cost, A_ub=A_ub if m else None, b_ub=b_ub if m else None, bounds=bounds,
                  method="highs")
    if sol.status != 0:
        return -1.0, np.zeros(nb)
    return float(sol.x[-1]), sol.x[:nb]


def resolve_redundancy(robot: CableRobot, pose: ArrayLike, twist: ArrayLike,
                       limits: MotionLimits | None = None, *, mode: ModeName = "task",
                       moving: Sequence[str] | None = None, objective: Objective = "min_norm",
                       tol: float = REDUNDANCY_TOL) -> RedundancyResult:
    """Joint rates producing a desired platform twist within joint limits.

    Parameters
    ----------
    robot : CableRobot
    pose : array_like (6,) or (3,)
        Platform pose, m and rad.
    twist : array_like (n,)
        Desired ``[v; w]`` (m/s, rad/s), world frame, at the platform reference point.
    limits : MotionLimits, optional
        Default :func:`fastkit_motion_limits`.
    mode, moving
        See :func:`taut.cdpr.sets.twist.resolve_mode`.
    objective : {"min_norm", "least_base"}
    tol : float
        Slack on limits and on the twist residual, m/s.

    Returns
    -------
    RedundancyResult

    Examples
    --------
    >>> from taut.io.cdpr_model import load_cdpr_model
    >>> res = resolve_redundancy(load_cdpr_model("fastkit"), [1, 0, 0.8], [0.5, 0, 0, 0, 0, 0])
    >>> res.success, res.status, res.scale
    (True, 'ok', 1.0)
    """
    require_instance(robot, CableRobot, "robot")
    as_tolerance(tol, "tol")
    as_choice(objective, OBJECTIVES, "objective")
    limits = fastkit_motion_limits() if limits is None else limits
    P = as_array(pose, "pose")
    if P.ndim != 1:
        raise InvalidInputError("pose", "must be a single pose (x, y, z[, roll, pitch, yaw])")
    fom = first_order_model(robot, P[None], mode, moving)       # a batch of one pose
    n = fom.A.shape[2]
    t = as_array(twist, "twist")
    if t.shape != (n,):
        raise InvalidInputError("twist", f"must have {n} components (v then w)")
    lo, hi = joint_bounds(robot, limits, fom.mode)
    nb = fom.n_base_joints
    names = fom.joint_names
    if fom.mode.kind == "navigation":
        return _navigation(fom, t, lo, hi, objective, names, tol, robot.m)
    C = fom.B[0][:, :nb]
    d = fom.A[0] @ t
    scale, x0 = _lp_scale(C, d, lo, hi, nb)
    if scale < 0:
        q = np.concatenate([np.zeros(nb), np.zeros(robot.m)])
        return RedundancyResult(False, "infeasible", "even standing still violates the joint "
                                "limits (every limit interval must contain 0)", q, q[:nb],
                                q[nb:], 0.0, float(np.abs(d).max()), objective, names)
    feasible = scale >= 1.0 - SCALE_ONE
    s_use = 1.0 if feasible else scale
    dd = d * s_use
    w = 1.0 / np.maximum(np.maximum(np.abs(lo), np.abs(hi)), RATE_FLOOR)
    wb, wc = w[:nb], w[nb:]
    cable_w = 1.0 if objective == "min_norm" else LEAST_BASE_CABLE_WEIGHT
    x = x0
    if nb:
        def f(x):
            c = (dd - C @ x) * wc
            return float(np.sum((x * wb) ** 2) + cable_w ** 2 * np.sum(c ** 2))

        Cw = C * (cable_w * wc)[:, None]                   # f(x) = |wb x|^2 + |Cw x - dw|^2
        sol = solve_qp(2.0 * (np.diag(wb ** 2) + Cw.T @ Cw), -2.0 * Cw.T @ (cable_w * wc * dd),
                       A_ub=np.vstack([C, -C]), b_ub=np.concatenate([dd - lo[nb:], hi[nb:] - dd]),
                       lb=lo[:nb], ub=hi[:nb], x0=x0, ftol=SLSQP_FTOL, unconverged=True)
        xq = np.clip(x0 if sol is None else sol, lo[:nb], hi[:nb])
        lq = dd - C @ xq
        if np.all(lq <= hi[nb:] + tol) and np.all(lq >= lo[nb:] - tol) and f(xq) <= f(x0):
            x = xq
    cables = dd - C @ x
    q = np.concatenate([x, cables])
    resid = float(np.abs(fom.A[0] @ (t * s_use) - fom.B[0] @ q).max())
    message = ("the twist is available within the joint limits" if feasible else
               f"the twist is outside the available twist set; only {scale:.3f} of it is "
               "reachable within the joint limits")
    return RedundancyResult(bool(feasible), "ok" if feasible else "infeasible", message, q, x,
                            cables, float(s_use), resid, objective, names)


def _navigation(fom: FirstOrderModel, t: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                objective: str, names: tuple[str, ...], tol: float, m: int
                ) -> RedundancyResult:
    M = fom.base_twists[0, fom.mode.moving[0]]                 # (n, 3)
    x, *_ = np.linalg.lstsq(M, t, rcond=None)
    resid = float(np.abs(M @ x - t).max())
    if resid > tol * (1 + np.abs(t).max()):
        q = np.zeros(3)
        return RedundancyResult(False, "infeasible", "in navigation mode the platform only "
                                "moves like the driver base (planar twists vx, vy, wz)", q, q,
                                np.zeros(m), 0.0, resid, objective, names)
    # scale so that x stays inside [lo, hi]
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.where(x > 0, hi / x, np.where(x < 0, lo / x, np.inf))
    scale = float(min(1.0, r.min())) if np.all(lo <= 0) and np.all(hi >= 0) else 0.0
    feasible = scale >= 1.0 - SCALE_ONE
    xs = x * (1.0 if feasible else scale)
    message = ("the driver base produces the twist within its limits" if feasible else
               f"the driver base would exceed its limits; only {scale:.3f} of the twist is "
               "reachable")
    return RedundancyResult(bool(feasible), "ok" if feasible else "infeasible", message, xs,
                            xs, np.zeros(m), 1.0 if feasible else scale,
                            float(np.abs(M @ xs - t * (1.0 if feasible else scale)).max()),
                            objective, names)
