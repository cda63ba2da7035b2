"""First-order kinematics of mobile cable-driven parallel robots (FASTKIT §3, eqs. 1-9).

Conventions (SI units: m, rad, s; float64)
-----------------------------------------
* A platform twist is ``t = [v; w]`` (linear velocity of the reference point P, then angular
  velocity, world frame), the same order as the wrenches of :mod:`taut.cdpr.sets.wrench`.
  The paper writes ``[w; v]``; only the row/column order differs.
* Cable ``i`` (exit point ``e_i`` on its base, attachment ``b_i = p + r_i``) has length
  ``l_i = |e_i - b_i|`` and unit vector ``u_i = (e_i - b_i) / l_i``. With bases fixed,
  ``l_dot = A t`` with the parallel Jacobian (eqs. 1-3)

      ``A[i] = -[u_i^T, (r_i x u_i)^T] = -W[:, i]^T``   (m x n).

* Each mobile base ``k`` is a virtual RPP chain (eqs. 6-7) with joint rates
  ``q_dot_bk = (theta_dot, rho1_dot, rho2_dot)``: yaw rate (rad/s) and the speeds of the
  base-frame origin ``O_bk`` along the base's own x and y axes (m/s). The revolute axis is
  taken through ``O_bk`` (the chain is evaluated at its current configuration), so the
  serial Jacobian of the base frame twist at ``O_bk`` is

      ``J_bk = [[0, R_bk i_0, R_bk j_0], [k_0, 0, 0]]``   (6 x 3, [v; w] rows).

  (The paper's ``k_0 x p`` term appears when that twist is referred to the world origin;
  the velocity field is the same.) The adjoint ``Ad_P = [[I, -[r_bP]x], [0, I]]`` with
  ``r_bP = p - O_bk`` moves the twist to P (eq. 5).
* If the platform moves rigidly with base ``k`` its cables keep their lengths, hence the
  full first-order model (eqs. 4, 8, 9)

      ``A t = B_b q_dot_b + l_dot = B q_dot``,  ``B = [B_b  I_m]``,
      ``B_b[i, 3k:3k+3] = A[i] Ad_P J_bk`` for cables ``i`` leaving base ``k`` (0 otherwise).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
from numpy.typing import ArrayLike

from .._batching import is_single, unbatch
from .cables import as_poses, cable_state
from ..model.robot import CableRobot
from .modes import BASE_JOINTS, Mode, ModeName, resolve_mode
from ..._validate import as_array, require_instance
from ..._repr import CompactRepr

__all__ = ["FirstOrderModel", "first_order_model", "parallel_jacobian", "base_jacobians"]


def _skew(r: np.ndarray) -> np.ndarray:
    """Cross-product matrices of vectors (..., 3) -> (..., 3, 3)."""
    S = np.zeros(r.shape + (3,))
    S[..., 0, 1], S[..., 0, 2] = -r[..., 2], r[..., 1]
    S[..., 1, 0], S[..., 1, 2] = r[..., 2], -r[..., 0]
    S[..., 2, 0], S[..., 2, 1] = -r[..., 1], r[..., 0]
    return S


def base_jacobians(robot: CableRobot, positions: np.ndarray) -> np.ndarray:
    """``Ad_P J_bk`` for every base (eqs. 5, 7): twist of the platform reference point P when
    it moves rigidly with base k, per unit RPP joint rate.

    Parameters
    ----------
    positions : (B, 3)
        Platform reference point P, m.

    Returns
    -------
    ndarray (B, K, 6, 3)
        Rows ``[v; w]``, columns ``(theta_dot, rho1_dot, rho2_dot)``.
    """
    require_instance(robot, CableRobot, "robot")
    positions = as_array(positions, "positions", shape=(None, 3))
    K = len(robot.bases)
    out = np.zeros((positions.shape[0], K, 6, 3))
    for k, base in enumerate(robot.bases):
        R = base.rotation
        J = np.zeros((6, 3))
        J[:3, 1], J[:3, 2] = R[:, 0], R[:, 1]
        J[5, 0] = 1.0
        r_bp = positions - np.array([base.pose[0], base.pose[1], 0.0])
        Ad = np.broadcast_to(np.eye(6), (positions.shape[0], 6, 6)).copy()
        Ad[:, :3, 3:] = -_skew(r_bp)
        out[:, k] = Ad @ J
    return out


def parallel_jacobian(robot: CableRobot, poses: ArrayLike) -> np.ndarray:
    """Parallel Jacobian ``A`` (B, m, n) with ``l_dot = A t`` for fixed bases (eqs. 1-3);
    n = 6 (``t = [v; w]``, m/s and rad/s) or 3 for a point-mass platform. One pose gives
    (m, n)."""
    require_instance(robot, CableRobot, "robot")
    return np.swapaxes(-cable_state(robot, poses).W, -1, -2)


@dataclass(frozen=True, repr=False)
class FirstOrderModel(CompactRepr):
    """``A t = B q_dot`` at B poses (FASTKIT eqs. 4, 8, 9).

    Attributes
    ----------
    poses : (B, 6)
    A : (B, m, n)
        Parallel Jacobian.
    B_b : (B, m, 3K)
        Base block for all K bases (columns ``3k..3k+2`` for base k).
    base_twists : (B, K, n, 3)
        ``Ad_P J_bk`` (rows truncated to n).
    mode : Mode
    B : (B, m, 3k' + m)
        ``[B_b[:, :, moving columns]  I_m]`` for the mode's moving bases (task mode);
        in navigation mode the columns of the driver only, cables excluded.
    joint_names : tuple of str
        Names of the columns of ``B`` (``"<base>.theta"``, ..., ``"<cable>"``).
    lengths : (B, m)
        Cable lengths, m.
    """

    poses: np.ndarray
    A: np.ndarray
    B_b: np.ndarray
    base_twists: np.ndarray
    mode: Mode
    B: np.ndarray
    joint_names: tuple[str, ...]
    lengths: np.ndarray

    @property
    def n_base_joints(self) -> int:
        """Number of base joint rates in ``B`` (3 per moving base)."""
        return 3 * len(self.mode.moving)


#: The per-pose fields of :class:`FirstOrderModel` (dropped to one pose by the batching rule).
FOM_PER_POSE = ("poses", "A", "B_b", "base_twists", "B", "lengths")


def first_order_model(robot: CableRobot, poses: ArrayLike, mode: ModeName = "task",
                      moving: Sequence[str] | None = None) -> FirstOrderModel:
    """First-order kinematic model of a mobile CDPR at poses (FASTKIT eqs. 1-9).

    Parameters
    ----------
    robot : CableRobot
    poses : array_like (6,), (3,), (B, 6) or (B, 3)
        Platform poses, m and rad.
    mode, moving
        See :func:`resolve_mode`.

    Returns
    -------
    FirstOrderModel
        Leading axis of B poses for a batch; none for one pose (``A`` (m, n), ...).

    Examples
    --------
    >>> from taut.io.cdpr_model import load_cdpr_model
    >>> fom = first_order_model(load_cdpr_model("fastkit"), [0, 0, 1.0])
    >>> fom.A.shape, fom.B.shape, fom.joint_names[:2]     # active base moving, 8 cables
    ((8, 6), (8, 11), ('active.theta', 'active.rho1'))
    """
    single = is_single(poses)
    md = resolve_mode(robot, mode, moving)
    fom = first_order(robot, as_poses(robot, poses), md)
    return unbatch(fom, FOM_PER_POSE, single)


def first_order(robot: CableRobot, P: np.ndarray, md: Mode) -> FirstOrderModel:
    """:func:`first_order_model` of checked poses ``P`` (B, 6) in a resolved mode, a batch
    always: the engine behind it, for callers that validated their inputs once."""
    st = cable_state(robot, P, validated=True)
    n = robot.dof
    A6 = -np.concatenate([st.unit, np.cross(st.r, st.unit)], axis=2)       # (B, m, 6)
    T = base_jacobians(robot, P[:, :3])                                    # (B, K, 6, 3)
    K = len(robot.bases)
    Bb = np.zeros((P.shape[0], robot.m, 3 * K))
    for k in range(K):
        sel = robot.cable_base == k
        Bb[:, sel, 3 * k:3 * k + 3] = np.einsum("bij,bjq->biq", A6[:, sel], T[:, k])
    cols = [c for k in md.moving for c in range(3 * k, 3 * k + 3)]
    jn = tuple(f"{robot.bases[k].name}.{j}" for k in md.moving for j in BASE_JOINTS)
    if md.kind == "task":
        Bsel = np.concatenate([Bb[:, :, cols],
                               np.broadcast_to(np.eye(robot.m), (P.shape[0], robot.m, robot.m))],
                              axis=2)
        jn = jn + tuple(c.name for c in robot.cables)
    else:
        Bsel = Bb[:, :, cols]
    return FirstOrderModel(P, A6[:, :, :n].copy(), Bb, T[:, :, :n].copy(), md, Bsel, jn,
                           st.lengths)
