"""Collision and stabiliser monitors of the mission's phases (private; issue 30, part 5).

Cables against shelves (:func:`cable_clearance`): each cable is the straight segment from
its exit point to its attachment point on the platform (world frame, m); each shelf is the
solid box ``footprint x [0, height]``. A segment touches a shelf exactly when its part
inside the height slab ``0 <= z <= height``, projected on the floor, meets the footprint
(shapely, exact). Otherwise its clearance is the least distance from the shelf to that
in-slab part (exact, shapely) and to :data:`CABLE_SAMPLES` points of the whole segment
(``hypot`` of the horizontal distance and the height above the top): an upper bound of
the true 3-D gap, off by at most half a sample spacing where the cable passes over a shelf.

Stabilisers (:func:`stabiliser_sequence`): deploying lowers the stabilisers base by base,
in the model's base order; retracting lifts them in the reverse order. The phase passes
through every intermediate state, each held for an equal share of its time.
"""

from __future__ import annotations

import numpy as np
import shapely

from ..kinematics.cables import cable_state
from ..model.robot import CableRobot
from .warehouse import Warehouse, to_world_frame

__all__ = ["CABLE_SAMPLES", "cable_segments", "segments_clearance", "cable_clearance", "stabiliser_sequence"]

#: Points per cable at which the gap above a shelf's top is measured.
CABLE_SAMPLES = 24


def cable_segments(robot: CableRobot, site_pose: np.ndarray, poses: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray]:
    """Exit points and attachment points (T, m, 3) in the world of the robot at
    ``site_pose`` (x, y, yaw) with the platform at ``poses`` (T, 6) (robot frame), m."""
    cs = cable_state(robot, np.atleast_2d(poses))
    attach = cs.poses[:, None, :3] + cs.r
    exits = np.broadcast_to(robot.exits_world, attach.shape)
    return to_world_frame(site_pose, exits), to_world_frame(site_pose, attach)


def _slab_part(a: np.ndarray, b: np.ndarray, height: float
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The parts of segments ``a -> b`` (N, 3) with ``0 <= z <= height``: their ends
    (N, 3) twice and whether the part exists (N,)."""
    dz = b[:, 2] - a[:, 2]
    flat = np.abs(dz) < 1e-12
    safe = np.where(flat, 1.0, dz)
    t0 = np.where(flat, 0.0, (0.0 - a[:, 2]) / safe)
    t1 = np.where(flat, 1.0, (height - a[:, 2]) / safe)
    lo, hi = np.minimum(t0, t1), np.maximum(t0, t1)
    inside_flat = (a[:, 2] >= 0.0) & (a[:, 2] <= height)
    exists = np.where(flat, inside_flat, (hi >= 0.0) & (lo <= 1.0))
    lo, hi = np.clip(lo, 0.0, 1.0), np.clip(hi, 0.0, 1.0)
    return a + lo[:, None] * (b - a), a + hi[:, None] * (b - a), exists


def _samples(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:data:`CABLE_SAMPLES` points (N, S, 3) of segments ``a -> b`` (N, 3) and their
    floor projections as shapely points (N * S,)."""
    s = np.linspace(0.0, 1.0, CABLE_SAMPLES)
    pts = a[:, None] + s[None, :, None] * (b - a)[:, None]
    return pts, shapely.points(pts[..., :2].reshape(-1, 2))


def _shelf_gap(footprint: shapely.Polygon, height: float, a: np.ndarray, b: np.ndarray,
               samples: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
    """Gap (N,) between segments ``a -> b`` (N, 3) and the box ``footprint x [0, height]``,
    m (module docstring; 0 when they touch); ``samples``: :func:`_samples` of them."""
    pts, geoms = _samples(a, b) if samples is None else samples
    horiz = shapely.distance(footprint, geoms)
    above = np.maximum(pts[..., 2] - height, 0.0).reshape(-1)
    gap = np.hypot(horiz, above).reshape(len(a), -1).min(axis=1)
    p, q, exists = _slab_part(a, b, height)
    line = exists & (np.abs(q[:, :2] - p[:, :2]).max(axis=1) > 1e-12)
    dot = exists & ~line                     # a vertical in-slab part: one floor point
    if line.any():
        lines = shapely.linestrings(np.stack([p[line, :2], q[line, :2]], axis=1))
        gap[line] = np.minimum(gap[line], shapely.distance(footprint, lines))
    if dot.any():
        gap[dot] = np.minimum(gap[dot], shapely.distance(footprint,
                                                         shapely.points(p[dot, :2])))
    return gap


def segments_clearance(warehouse: Warehouse, exits: np.ndarray, attach: np.ndarray
                       ) -> float:
    """Least gap between the cables ``exits -> attach`` (..., 3) (world, m) and any shelf,
    m (``inf`` without shelves)."""
    if not warehouse.shelves:
        return float("inf")
    a, b = exits.reshape(-1, 3), attach.reshape(-1, 3)
    samples = _samples(a, b)
    return float(min(_shelf_gap(sh.footprint, sh.height, a, b, samples).min()
                     for sh in warehouse.shelves))


def cable_clearance(warehouse: Warehouse, robot: CableRobot, site_pose: np.ndarray,
                    poses: np.ndarray) -> float:
    """Least gap between any cable and any shelf over the platform ``poses`` (T, 6)
    (robot frame) of ``robot`` at ``site_pose``, m (``inf`` without shelves)."""
    return segments_clearance(warehouse, *cable_segments(robot, site_pose, poses))


def stabiliser_sequence(robot: CableRobot, deploy: bool) -> list[tuple[bool, ...]]:
    """The stabiliser states (one flag per base) a deploy (``deploy``) or a retract passes
    through, first and last included (module docstring)."""
    has = [b.mobile and b.stabilisers is not None for b in robot.bases]
    state = [not deploy and h for h in has]
    out = [tuple(state)]
    order = range(len(has)) if deploy else reversed(range(len(has)))
    for k in order:
        if has[k]:
            state[k] = deploy
            out.append(tuple(state))
    return out
