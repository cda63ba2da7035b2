"""Workspace boxes and base placement of mobile CDPRs: validating a desired workspace box,
moving the mobile bases to new ``(x, y, theta)`` and measuring how far a base footprint
reaches over the workspace seen from above. Units: m, rad."""

from __future__ import annotations

from dataclasses import replace
from typing import Any, Mapping

import numpy as np
from numpy.typing import ArrayLike

from ..._validate import MAX_CDPR_LENGTH_M, as_array, as_box, check_range
from ...errors import InvalidInputError
from ..model.robot import CableRobot
from ..._validate import as_flag, require_instance

__all__ = ["workspace_box", "place_bases", "footprint_overlap"]


def workspace_box(box: ArrayLike, field: str = "workspace", *, allow_flat: bool = False
                  ) -> np.ndarray:
    """Validate a workspace box ``[[xmin, ymin, zmin], [xmax, ymax, zmax]]`` (m) -> (2, 3).

    Raises :class:`InvalidInputError` on NaN/inf, a wrong shape, or a box with no volume
    (some ``max <= min``; with ``allow_flat`` only ``max < min``, so slices such as the
    FASTKIT preset's ``desired_workspace`` pass)."""
    allow_flat = as_flag(allow_flat, "allow_flat")
    b = check_range(box, field, MAX_CDPR_LENGTH_M, "m")
    if b.shape == (6,):                       # CLI order: xmin xmax ymin ymax zmin zmax
        b = b.reshape(3, 2).T
    if b.shape != (2, 3):
        raise InvalidInputError(field, "must be [[xmin, ymin, zmin], [xmax, ymax, zmax]] or "
                                       "xmin xmax ymin ymax zmin zmax")
    bad = b[1] < b[0] if allow_flat else b[1] <= b[0]
    if np.any(bad):
        k = int(np.argmax(bad))
        a = "xyz"[k]
        what = ("lower corner above upper corner" if allow_flat else "box has no volume")
        raise InvalidInputError(field, f"{what}: {a}max {b[1, k]:g} "
                                       f"{'<' if allow_flat else '<='} {a}min {b[0, k]:g}")
    return b


def place_bases(robot: CableRobot, poses: Mapping[str, Any] | Any) -> CableRobot:
    """The robot with mobile bases moved to new ``(x, y, theta)`` (m, rad).

    ``poses`` maps base names to poses, or is a (k, 3) array in the order of the mobile
    bases. The frame box (``bounds``) is recomputed from the moved exit points."""
    require_instance(robot, CableRobot, "robot")
    mobile = [b.name for b in robot.bases if b.mobile]
    if isinstance(poses, Mapping):
        new = {str(k): as_array(v, f"poses[{k}]", shape=(3,)) for k, v in poses.items()}
        for k in new:
            if k not in [b.name for b in robot.bases]:
                raise InvalidInputError("poses", f"no base named {k!r}")
    else:
        arr = as_array(poses, "poses", shape=(len(mobile), 3))
        new = dict(zip(mobile, arr))
    bases = tuple(replace(b, exit_points=dict(b.exit_points), pose=new[b.name])
                  if b.name in new else b for b in robot.bases)
    return replace(robot, bases=bases, bounds=None)


def footprint_overlap(robot: CableRobot, box: np.ndarray) -> float:
    """Largest penetration depth (m) of a base footprint into the workspace rectangle seen
    from above (separating-axis test; 0 when clear).

    Examples
    --------
    >>> from taut.io.cdpr_model import load_cdpr_model
    >>> footprint_overlap(load_cdpr_model("fastkit"), np.array([[-1.0, -1, 0], [1, 1, 1]]))
    0.0
    """
    require_instance(robot, CableRobot, "robot")
    box = as_box(box, "box", allow_flat=True)
    rect = np.array([[box[0, 0], box[0, 1]], [box[1, 0], box[0, 1]],
                     [box[1, 0], box[1, 1]], [box[0, 0], box[1, 1]]])
    worst = 0.0
    for b in robot.bases:
        if not b.mobile:
            continue
        poly = b.support_world()[:, :2]
        depth = np.inf
        for P, Q in ((poly, rect), (rect, poly)):
            e = np.roll(P, -1, axis=0) - P
            nrm = np.column_stack([e[:, 1], -e[:, 0]])
            size = np.linalg.norm(nrm, axis=1, keepdims=True)
            keep = size[:, 0] > 0              # a flat box's zero-length edges: no axis
            nrm = nrm[keep] / size[keep]
            if not nrm.size:
                continue
            a, c = P @ nrm.T, Q @ nrm.T
            depth = min(depth, float(np.min(np.minimum(a.max(0) - c.min(0),
                                                       c.max(0) - a.min(0)))))
        worst = max(worst, depth)
    return max(worst, 0.0)
