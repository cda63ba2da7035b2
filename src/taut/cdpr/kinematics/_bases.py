"""Moving bases (private): world exit points and support-polygon edges of a CDPR whose mobile
bases stand at poses other than those of the model (FASTKIT task mode, eq. 8).

``base_poses`` has shape (..., K, 3): ``(x, y, theta)`` per base, m and rad.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..._validate import as_array
from ...errors import InvalidInputError
from ..model.robot import CableRobot


def as_base_poses(robot: CableRobot, base_poses: Any, field: str = "base_poses") -> np.ndarray:
    """Validate base poses (K, 3) or (B, K, 3) -> float64 (B, K, 3); fixed frames may not
    move."""
    K = len(robot.bases)
    arr = as_array(base_poses, field)
    if arr.ndim == 2:
        arr = arr[None]
    if arr.ndim != 3 or arr.shape[1:] != (K, 3):
        raise InvalidInputError(field, f"must have shape ({K}, 3) or (B, {K}, 3): "
                                       "(x, y, theta) per base")
    ref = np.array([b.pose for b in robot.bases])
    moved = np.any(np.abs(arr - ref[None]) > 0.0, axis=(0, 2))
    for k, b in enumerate(robot.bases):
        if moved[k] and not b.mobile:
            raise InvalidInputError(field, f"base {b.name!r} is a fixed frame, it cannot move")
    return arr


def _transforms(robot: CableRobot, base_poses: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rotation (B, K, 3, 3) and translation (B, K, 3) taking each base from its model pose
    to ``base_poses``."""
    ref = np.array([b.pose for b in robot.bases])
    dth = base_poses[..., 2] - ref[:, 2]
    c, s = np.cos(dth), np.sin(dth)
    Rz = np.zeros(base_poses.shape[:-1] + (3, 3))
    Rz[..., 0, 0], Rz[..., 0, 1], Rz[..., 1, 0], Rz[..., 1, 1] = c, -s, s, c
    Rz[..., 2, 2] = 1.0
    p_ref = np.column_stack([ref[:, :2], np.zeros(len(ref))])
    p_new = np.concatenate([base_poses[..., :2], np.zeros(base_poses.shape[:-1] + (1,))],
                           axis=-1)
    t = p_new - np.einsum("...kij,kj->...ki", Rz, p_ref)
    return Rz, t


def moved_exits(robot: CableRobot, base_poses: np.ndarray) -> np.ndarray:
    """World exit points (B, m, 3), m, with the bases at ``base_poses`` (B, K, 3)."""
    Rz, t = _transforms(robot, base_poses)
    cb = np.asarray(robot.cable_base, dtype=np.intp)
    Rc = Rz[:, cb]                                     # (B, m, 3, 3)
    return np.einsum("bmij,mj->bmi", Rc, robot.exits_world) + t[:, cb]


def moved_edges(robot: CableRobot, base_poses: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Support-polygon edge points and unit directions (B, E, 3) and the weight moments
    ``u_Cj . ((g - c_j) x w_g)`` (B, E) with the bases at ``base_poses`` (FASTKIT eqs. 21-23).

    A planar rigid motion of a base moves its edges and centre of mass together and gravity is
    vertical, so the weight moments do not change; they are returned broadcast for clarity.
    """
    Rz, t = _transforms(robot, base_poses)
    eb = np.asarray(robot.edge_base, dtype=np.intp)
    pts = np.einsum("beij,ej->bei", Rz[:, eb], robot.edge_points) + t[:, eb]
    dirs = np.einsum("beij,ej->bei", Rz[:, eb], robot.edge_dirs)
    m0 = np.broadcast_to(robot.edge_weight_moment, (base_poses.shape[0], robot.n_edges))
    return pts, dirs, m0
