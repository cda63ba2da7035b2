"""Whether the platform stays inside the exits' bounding box (a geometric workspace
condition for robots whose model asks for it, ``platform_inside_exits: true``).

The box is the axis-aligned bounding box of all cable exit points (world frame), extended
down to the ground ``z = 0`` when every exit is above it (the frame of a suspended robot
reaches the floor; the same rule as the default ``bounds`` of :class:`CableRobot`). The
platform is the box spanned by its attachment points in the platform frame (as in
:mod:`taut.cdpr.kinematics.interference`); it is inside when all 8 corners of that box, at the pose,
are inside the exits' box (both boxes are convex, so the corners decide). Units: m.
"""

from __future__ import annotations

from itertools import product

import numpy as np
from numpy.typing import ArrayLike

from ..._validate import as_tolerance, require_instance
from .._batching import is_single
from .._tol import BOX_REL
from ..kinematics.cables import as_poses, rotation_matrices
from ..model.robot import CableRobot

__all__ = ["platform_inside_exits"]


def exits_box(robot: CableRobot) -> np.ndarray:
    """The exits' bounding box from the ground up, ``[[xmin, ymin, zmin], [xmax, ymax,
    zmax]]`` (2, 3), m."""
    ex = robot.exits_world
    lo, hi = ex.min(axis=0), ex.max(axis=0)
    lo[2] = min(0.0, float(lo[2]))
    return np.stack([lo, hi])


def platform_corners(robot: CableRobot, poses: np.ndarray) -> np.ndarray:
    """World coordinates (B, 8, 3) of the corners of the platform's attachment-point box at
    validated poses (B, 6), m."""
    lo, hi = robot.attach_local.min(axis=0), robot.attach_local.max(axis=0)
    local = np.array(list(product(*zip(lo, hi))))                     # (8, 3)
    R = rotation_matrices(poses[:, 3:])
    return poses[:, None, :3] + np.einsum("bij,kj->bki", R, local)


def platform_inside_exits(robot: CableRobot, poses: ArrayLike, *,
                          box_tol: float = BOX_REL) -> np.ndarray | bool:
    """Whether the whole platform lies inside the exits' bounding box: (B,) bool for a
    batch of poses, a bool for one pose.

    Parameters
    ----------
    robot : CableRobot
    poses : array_like (6,), (3,), (B, 6) or (B, 3)
        Platform poses, m and rad.
    box_tol : float
        A corner on a face is inside within ``box_tol * (1 + max |exit coordinate|)`` m.

    Examples
    --------
    >>> from taut.io.cdpr_model import load_cdpr_model
    >>> robot = load_cdpr_model("fastkit")       # exits at x = +-2.6 m, platform 0.6 m long
    >>> platform_inside_exits(robot, [[2.2, 0, 1.0], [2.4, 0, 1.0]]).tolist()
    [True, False]
    """
    require_instance(robot, CableRobot, "robot")
    box_tol = as_tolerance(box_tol, "box_tol")
    single = is_single(poses)
    P = as_poses(robot, poses)
    box = exits_box(robot)
    tol = box_tol * (1.0 + float(np.abs(robot.exits_world).max()))
    c = platform_corners(robot, P)
    inside = np.all((c >= box[0] - tol) & (c <= box[1] + tol), axis=(1, 2))
    return bool(inside[0]) if single else inside
