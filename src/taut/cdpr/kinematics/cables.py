"""Cable kinematics and statics of a CDPR at a batch of platform poses.

A pose is ``(x, y, z, roll, pitch, yaw)`` (m, rad); the platform rotation is
``R = Rz(yaw) Ry(pitch) Rx(roll)``. A 3-vector ``(x, y, z)`` means zero orientation.
Batched inputs carry a leading axis of B poses; one pose ``(6,)`` or ``(3,)`` gives
unbatched results (the rule of :mod:`taut.cdpr._batching`). Cable ``i`` pulls the platform along
``u_i``, the unit vector from its attachment point to its exit point.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from ..._validate import as_array, as_flag, require_instance
from ..._validate import MAX_CDPR_LENGTH_M, check_range
from ...errors import InfeasiblePoseError, InvalidInputError
from .._batching import is_single, unbatch
from .._tol import BOX_REL, ZERO_LENGTH_REL
from ..model.robot import CableRobot
from ..._repr import CompactRepr

__all__ = ["as_poses", "rotation_matrices", "CableState", "cable_state", "wrench_matrix",
           "gravity_wrench", "tipping_matrix"]


def as_poses(robot: CableRobot, poses: ArrayLike, field: str = "pose", *,
             check_bounds: bool = True) -> np.ndarray:
    """Validate platform poses and return them as a float64 ``(B, 6)`` array.

    Accepts shapes ``(3,)``, ``(6,)``, ``(B, 3)`` or ``(B, 6)``; a missing orientation is
    zero. Raises :class:`InvalidInputError` on NaN/inf or a wrong shape, and
    :class:`InfeasiblePoseError` when a position lies outside ``robot.bounds``.
    """
    require_instance(robot, CableRobot, "robot")
    check_bounds = as_flag(check_bounds, "check_bounds")
    arr = check_range(poses, field, MAX_CDPR_LENGTH_M, "m or rad")
    if arr.ndim == 1:
        arr = arr[None, :]
    if arr.ndim != 2 or arr.shape[1] not in (3, 6):
        raise InvalidInputError(field, "must be (x, y, z) or (x, y, z, roll, pitch, yaw), "
                                       "optionally with a leading batch axis")
    if arr.shape[0] == 0:
        raise InvalidInputError(field, "is an empty batch (no poses)")
    if arr.shape[1] == 3:
        arr = np.hstack([arr, np.zeros((arr.shape[0], 3))])
    if check_bounds:
        lo, hi = robot.bounds
        tol = BOX_REL * (1.0 + np.abs(robot.bounds).max())
        bad = np.any((arr[:, :3] < lo - tol) | (arr[:, :3] > hi + tol), axis=1)
        if np.any(bad):
            i = int(np.argmax(bad))
            where = f"{field}[{i}]" if arr.shape[0] > 1 else field
            raise InfeasiblePoseError(where, "position {} lies outside the frame box "
                                      "{} .. {} m".format(np.round(arr[i, :3], 4).tolist(),
                                                          np.round(lo, 4).tolist(),
                                                          np.round(hi, 4).tolist()))
    return arr


def rotation_matrices(rpy: ArrayLike) -> np.ndarray:
    """``Rz(yaw) Ry(pitch) Rx(roll)`` for ``rpy`` of shape (B, 3) (rad) -> (B, 3, 3)."""
    rpy = as_array(rpy, "rpy", shape=(None, 3))
    cr, cp, cy = np.cos(rpy.T)
    sr, sp, sy = np.sin(rpy.T)
    R = np.empty((rpy.shape[0], 3, 3))
    R[:, 0, 0] = cy * cp
    R[:, 0, 1] = cy * sp * sr - sy * cr
    R[:, 0, 2] = cy * sp * cr + sy * sr
    R[:, 1, 0] = sy * cp
    R[:, 1, 1] = sy * sp * sr + cy * cr
    R[:, 1, 2] = sy * sp * cr - cy * sr
    R[:, 2, 0] = -sp
    R[:, 2, 1] = cp * sr
    R[:, 2, 2] = cp * cr
    return R


@dataclass(frozen=True, repr=False)
class CableState(CompactRepr):
    """Inverse kinematics of a batch of poses (one pose: every leading B axis dropped).

    Attributes
    ----------
    poses : (B, 6)
    lengths : (B, m)
        Straight-line cable lengths, m.
    unit : (B, m, 3)
        Unit vectors ``u_i`` from attachment to exit point (direction of the cable force
        on the platform).
    r : (B, m, 3)
        Vectors from the platform reference point P to the attachment points, world
        frame, m (FASTKIT's ``r_i``).
    W : (B, n, m)
        Wrench matrix (FASTKIT eq. 18): columns ``[u_i; r_i x u_i]`` (n = 6), or ``u_i``
        for a point-mass platform (n = 3).
    R : (B, 3, 3)
        Platform rotations.
    """

    poses: np.ndarray
    lengths: np.ndarray
    unit: np.ndarray
    r: np.ndarray
    W: np.ndarray
    R: np.ndarray


def cable_state(robot: CableRobot, poses: ArrayLike, *, validated: bool = False
                ) -> CableState:
    """Cable lengths, unit vectors and the wrench matrix W (FASTKIT eq. 18) at poses.

    Parameters
    ----------
    robot : CableRobot
    poses : array_like, (6,), (3,), (B, 6) or (B, 3)
        Platform poses, m and rad.
    validated : bool
        Skip validation when ``poses`` is already a checked ``(B, 6)`` array.

    Returns
    -------
    CableState
        Arrays with a leading axis of B poses for a batch; without it for one pose
        (``lengths`` (m,), ``W`` (n, m), ...).

    Raises
    ------
    InfeasiblePoseError
        A position outside the frame box, or an attachment point on its exit point
        (zero cable length, direction undefined).

    Examples
    --------
    >>> from taut.io.cdpr_model import load_cdpr_model
    >>> robot = load_cdpr_model("fastkit")
    >>> cable_state(robot, [0, 0, 1.0]).W.shape           # one pose: (n, m)
    (6, 8)
    >>> cable_state(robot, [[0, 0, 1.0], [0.5, 0, 1.2]]).lengths.shape   # a batch
    (2, 8)
    """
    validated = as_flag(validated, "validated")
    single = not validated and is_single(poses)
    P = np.asarray(poses) if validated else as_poses(robot, poses)
    if validated and (P.ndim != 2 or P.shape[1] != 6 or P.dtype != np.float64):
        raise InvalidInputError("validated", "True needs poses already checked as a float64 "
                                             "(B, 6) array (see as_poses)")
    R = rotation_matrices(P[:, 3:])
    r = np.einsum("bij,mj->bmi", R, robot.attach_local)
    vec = robot.exits_world[None, :, :] - (P[:, None, :3] + r)
    L = np.linalg.norm(vec, axis=2)
    # One tolerance for the check and for the index it reports (they used to differ, so
    # a near-zero length between the two thresholds named pose 0 instead of the culprit).
    short = np.any(L <= ZERO_LENGTH_REL * (1.0 + np.abs(robot.exits_world).max()), axis=1)
    if np.any(short):
        i = int(np.argmax(short))
        raise InfeasiblePoseError("pose", f"pose {i} puts an attachment point on its exit "
                                          "point (zero cable length)")
    u = vec / L[:, :, None]
    if robot.dof == 3:
        W = np.swapaxes(u, 1, 2).copy()
    else:
        W = np.concatenate([np.swapaxes(u, 1, 2), np.swapaxes(np.cross(r, u), 1, 2)], axis=1)
    return unbatch(CableState(P, L, u, r, W, R), ("poses", "lengths", "unit", "r", "W", "R"),
                   single)


def wrench_matrix(robot: CableRobot, poses: ArrayLike) -> np.ndarray:
    """The wrench matrix W, shape (B, n, m), or (n, m) for one pose (FASTKIT eq. 18); see
    :func:`cable_state`."""
    return cable_state(robot, poses).W


def gravity_wrench(robot: CableRobot, R: ArrayLike) -> np.ndarray:
    """External wrench ``w_e`` (FASTKIT eq. 19) of platform and payload weight, (B, n).

    ``w_e = [f_e; m_e]`` with ``f_e = (m_p + m_l) g`` (N) and ``m_e`` the moment of both
    weights about the platform reference point P (N m), for rotations ``R`` (B, 3, 3);
    one rotation (3, 3) gives one wrench (n,).
    """
    require_instance(robot, CableRobot, "robot")
    R = as_array(R, "R")
    if R.ndim == 2:
        return gravity_wrench(robot, R[None])[0]
    R = as_array(R, "R", shape=(None, 3, 3))
    g = robot.gravity
    f = np.broadcast_to(robot.total_mass * g, (R.shape[0], 3))
    if robot.dof == 3:
        return f.copy()
    mc = robot.platform.mass * robot.platform.com + robot.payload.mass * robot.payload.com
    m = np.cross(R @ mc, g)
    return np.concatenate([f, m], axis=1)


def tipping_matrix(robot: CableRobot, unit: ArrayLike) -> np.ndarray:
    """Tipping coefficients ``T`` (B, E, m) so that the edge moments of FASTKIT eqs. 21-23
    are ``m_C = T t + robot.edge_weight_moment`` (N m) for tensions ``t`` (N).

    ``T[j, i] = u_Cj . ((c_j - b_i) x u_i)`` for a cable ``i`` leaving the base of edge
    ``j`` at exit point ``b_i``; the base is stable when every ``m_C <= 0``. One pose's
    unit vectors (m, 3) give (E, m).
    """
    require_instance(robot, CableRobot, "robot")
    unit = as_array(unit, "unit")
    if unit.ndim == 2:
        return tipping_matrix(robot, unit[None])[0]
    unit = as_array(unit, "unit", shape=(None, robot.m, 3))
    return np.einsum("jik,bik->bji", robot._tip_V, unit)
