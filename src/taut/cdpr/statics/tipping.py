"""Tipping of mobile bases (FASTKIT eqs. 21-23).

For every edge ``j`` of the support polygon of a mobile base (contact points ``c_j`` in
counter-clockwise order seen from above, ``u_Cj`` the unit vector from ``c_j`` to
``c_{j+1}``) the moment about the edge of the base weight ``w_g`` (at the base centre of
mass ``g``) and of the cable forces on the base is

    m_Cj = u_Cj . ((g - c_j) x w_g) + sum_i u_Cj . ((c_j - b_i) x t_i u_i),

summed over the cables ``i`` leaving that base at exit point ``b_i`` (``t_i u_i`` is the
force of cable ``i`` on the platform, so ``-t_i u_i`` acts on the base). The base does not
tip when every ``m_Cj <= 0``. With the counter-clockwise orientation the weight term is
negative for a centre of mass inside the polygon: that is the paper's sign convention.
Any number of mobile bases and polygon sizes are handled; fixed frames have no edges.
"""

from __future__ import annotations

from dataclasses import dataclass
import numpy as np
from numpy.typing import ArrayLike

from ..._validate import MAX_TENSION_N, as_array, check_range
from ...errors import InvalidInputError
from .._batching import is_single, unbatch
from ._common import feas_tol
from ..kinematics.cables import as_poses, cable_state, tipping_matrix
from ..model.robot import CableRobot
from ..._repr import CompactRepr

__all__ = ["TippingResult", "tipping_moments"]


@dataclass(frozen=True, repr=False)
class TippingResult(CompactRepr):
    """Edge moments at a batch of poses (one pose: the leading B axis dropped).

    Attributes
    ----------
    moments : (B, E)
        ``m_Cj`` of eqs. 21-23, N m, edges in ``robot.edge_base`` order.
    stable : (B,) bool
        Every moment <= 0 (within a tolerance scaled by the largest tension limit).
    worst_edge : (B,) int
        Index of the largest moment (-1 when the robot has no mobile base).
    edge_base : (E,) int
        Base index of each edge.
    base_moment : (B, K)
        Per base (``robot.bases`` order) its largest edge moment, N m; ``-inf`` for a base
        without a support polygon (a fixed frame cannot tip). Minus the base's tipping
        margin.
    base_stable : (B, K) bool
        The base does not tip: its ``base_moment`` <= 0 within the tolerance of ``stable``.
    """

    moments: np.ndarray
    stable: np.ndarray
    worst_edge: np.ndarray
    edge_base: np.ndarray
    base_moment: np.ndarray
    base_stable: np.ndarray


def tipping_moments(robot: CableRobot, poses: ArrayLike, tensions: ArrayLike) -> TippingResult:
    """Moments of base weight and cable forces about every support-polygon edge of every
    mobile base (FASTKIT eqs. 21-23).

    Parameters
    ----------
    robot : CableRobot
    poses : array_like (6,), (3,), (B, 6) or (B, 3)
        Platform poses, m and rad.
    tensions : array_like (m,) or (B, m)
        Cable tensions, N (one row is used for every pose).

    Returns
    -------
    TippingResult
        ``moments`` (B, E), ``stable`` (B,) for a batch; (E,) and a bool for one pose.

    Examples
    --------
    >>> from taut.io.cdpr_model import load_cdpr_model
    >>> robot = load_cdpr_model("fastkit")
    >>> tip = tipping_moments(robot, [0, 0, 0.6], robot.t_min)
    >>> tip.moments.shape == (robot.n_edges,), tip.stable
    (True, True)
    """
    single = is_single(poses)
    P = as_poses(robot, poses)
    t = check_range(tensions, "tensions", MAX_TENSION_N, "N")
    if t.ndim == 1 and t.shape != (robot.m,):
        raise InvalidInputError("tensions", f"must have shape ({robot.m},) or "
                                            f"({P.shape[0]}, {robot.m})")
    t = np.broadcast_to(t, (P.shape[0], robot.m)) if t.ndim == 1 else t
    if t.shape != (P.shape[0], robot.m):
        raise InvalidInputError("tensions", f"must have shape ({P.shape[0]}, {robot.m})")
    st = cable_state(robot, P, validated=True)
    M = np.einsum("bji,bi->bj", tipping_matrix(robot, st.unit), t) + robot.edge_weight_moment
    tol = feas_tol(robot)
    stable = np.all(M <= tol, axis=1)
    worst = np.argmax(M, axis=1) if M.shape[1] else np.full(P.shape[0], -1)
    per_base = np.full((P.shape[0], len(robot.bases)), -np.inf)
    for k in range(len(robot.bases)):
        sel = robot.edge_base == k
        if np.any(sel):
            per_base[:, k] = M[:, sel].max(axis=1)
    return unbatch(TippingResult(M, stable, worst, robot.edge_base.copy(), per_base,
                                 per_base <= tol),
                   ("moments", "stable", "worst_edge", "base_moment", "base_stable"), single)
