"""Cable interference: cable-cable distances and cable-platform collisions along poses.

Cables are straight segments from their attachment point (world, at the pose) to their
exit point. The platform is the box spanned by its attachment points in the platform frame
(for FASTKIT the 0.6 x 0.36 x 0.2 m body whose corners carry the cables). Units: m.

* Cable-cable: the exact closest distance between two segments (clamped closest points of
  the two supporting lines, C. Ericson, "Real-Time Collision Detection", §5.1.9), batched
  over poses and all pairs. A pair interferes when its distance is at most
  ``min_distance`` (the cable diameter: the axes of two touching cables are one diameter
  apart). Two cables whose endpoints merely come close count like any others (they rub
  at the eyelets). Pairs *sharing* an anchor (the same attachment point, as in IPAnema 1,
  or the same exit point) touch there by design; they are compared beyond
  ``anchor_length`` from the shared anchor (each segment trimmed by that much at the
  shared end), so they interfere only if they run together: overlap along a length, or
  leave the anchor at an angle ``theta`` with ``2 anchor_length sin(theta / 2)`` below
  ``min_distance``.
* Cable-platform: a cable collides with the platform when its segment enters the open box
  (the box shrunk by ``box_tol``, so a cable leaving from a corner or face does not count)
  - a slab test.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .._batching import is_single, unbatch
from .._tol import ANCHOR_LENGTH, BOX_REL, SEGMENT_PARALLEL, TINY
from .cables import as_poses, cable_state
from ...errors import InvalidInputError
from ..model.robot import CableRobot
from ..._validate import (MAX_CDPR_LENGTH_M, as_array, as_bounded, as_tolerance, check_range,
    require_instance)
from ..._repr import CompactRepr

__all__ = ["segment_distance", "Interference", "cable_interference"]


def segment_distance(p0: np.ndarray, p1: np.ndarray, q0: np.ndarray, q1: np.ndarray
                     ) -> np.ndarray:
    """Closest distance between segments ``[p0, p1]`` and ``[q0, q1]``, broadcast over
    leading axes ((..., 3) each) -> (...). Segments of zero length are points."""
    p0, p1, q0, q1 = (check_range(as_array(v, k), k, MAX_CDPR_LENGTH_M, "m")
                      for v, k in ((p0, "p0"), (p1, "p1"), (q0, "q0"), (q1, "q1")))
    for v, k in ((p0, "p0"), (p1, "p1"), (q0, "q0"), (q1, "q1")):
        if v.ndim == 0 or v.shape[-1] != 3:
            raise InvalidInputError(k, "must be points (..., 3)")
    try:
        np.broadcast_shapes(p0.shape, p1.shape, q0.shape, q1.shape)
    except ValueError:
        raise InvalidInputError("p0", "p0, p1, q0 and q1 must broadcast together") from None
    d1, d2, r = p1 - p0, q1 - q0, p0 - q0
    a = np.einsum("...i,...i", d1, d1)
    e = np.einsum("...i,...i", d2, d2)
    f = np.einsum("...i,...i", d2, r)
    c = np.einsum("...i,...i", d1, r)
    b = np.einsum("...i,...i", d1, d2)
    den = a * e - b * b
    tiny = TINY
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(den > SEGMENT_PARALLEL * a * e, np.clip((b * f - c * e) / np.maximum(den, tiny),
                                                  0.0, 1.0), 0.0)
        t = np.where(e > tiny, (b * s + f) / np.maximum(e, tiny), 0.0)
        s = np.where(t < 0, np.clip(-c / np.maximum(a, tiny), 0.0, 1.0),
                     np.where(t > 1, np.clip((b - c) / np.maximum(a, tiny), 0.0, 1.0), s))
        t = np.clip(t, 0.0, 1.0)
        point_q = e <= tiny                         # [q0, q1] is a point
        s = np.where(point_q, np.clip(-c / np.maximum(a, tiny), 0.0, 1.0), s)
        t = np.where(point_q, 0.0, t)
        point_p = a <= tiny                         # [p0, p1] is a point
        t = np.where(point_p, np.clip(f / np.maximum(e, tiny), 0.0, 1.0), t)
        s = np.where(point_p, 0.0, s)
    gap = (p0 + s[..., None] * d1) - (q0 + t[..., None] * d2)
    return np.sqrt(np.einsum("...i,...i", gap, gap))


@dataclass(frozen=True, repr=False)
class Interference(CompactRepr):
    """Interference of the cables at B poses (one pose: the leading B axis dropped).

    Attributes
    ----------
    distance : (B, m, m)
        Closest distance between cables i and j, m (``inf`` on the diagonal; for pairs
        sharing an endpoint, between their parts beyond ``anchor_length`` from it).
    cable_cable : (B,) bool
        Some pair is closer than ``min_distance``.
    cable_platform : (B, m) bool
        Cable i passes through the platform box.
    free : (B,) bool
        No cable-cable and no cable-platform interference.
    min_distance : float
    """

    distance: np.ndarray
    cable_cable: np.ndarray
    cable_platform: np.ndarray
    free: np.ndarray
    min_distance: float


def _through_box(a: np.ndarray, e: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Whether segments a -> e ((..., 3), platform frame) meet the open box (lo, hi)."""
    d = e - a
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = (lo - a) / d
        t2 = (hi - a) / d
    inside_slab = (a > lo) & (a < hi)                   # for d == 0: inside or never
    t_lo = np.where(d != 0, np.minimum(t1, t2), np.where(inside_slab, -np.inf, np.inf))
    t_hi = np.where(d != 0, np.maximum(t1, t2), np.where(inside_slab, np.inf, -np.inf))
    enter = np.maximum(t_lo.max(axis=-1), 0.0)
    leave = np.minimum(t_hi.min(axis=-1), 1.0)
    return enter < leave


def _ends(plain: np.ndarray, trimmed: np.ndarray, shared: np.ndarray
          ) -> tuple[np.ndarray, np.ndarray]:
    """Pairwise segment ends (B, m, m, 3) for cable i (first) and j (second): the trimmed
    end where the pair shares that anchor, else the plain one."""
    sh = shared[None, :, :, None]
    first = np.where(sh, trimmed[:, :, None], plain[:, :, None])
    second = np.where(sh, trimmed[:, None, :], plain[:, None, :])
    return first, second


def cable_interference(robot: CableRobot, poses: ArrayLike, *, min_distance: float = 0.0,
                       box_tol: float = BOX_REL, anchor_length: float = ANCHOR_LENGTH
                       ) -> Interference:
    """Cable-cable distances and cable-platform collisions at poses.

    Parameters
    ----------
    robot : CableRobot
    poses : array_like (6,), (3,), (B, 6) or (B, 3)
        Platform poses, m and rad.
    min_distance : float
        Clearance below which two cables interfere (cable diameter, m; 0: only crossing,
        within a round-off slack of ``1e-9 (1 + max |exit|)`` m).
    box_tol : float
        The platform box is shrunk by ``box_tol * (1 + its largest extent)`` m before the
        collision test (so cables leaving from its surface do not count).
    anchor_length : float
        Length along two cables from an anchor they share over which their contact is by
        design and ignored, m (see the module docstring).

    Examples
    --------
    >>> from taut.io.cdpr_model import load_cdpr_model
    >>> robot = load_cdpr_model("fastkit")
    >>> res = cable_interference(robot, [[0.5, 0, 1.0, 0, 0, 0], [0.5, 0, 1.0, 0, 0, 0.05]])
    >>> res.cable_cable.tolist(), res.free.tolist()    # level: crossing pairs meet
    ([True, False], [False, True])
    """
    require_instance(robot, CableRobot, "robot")
    as_tolerance(min_distance, "min_distance")
    as_tolerance(box_tol, "box_tol")
    anchor_length = as_bounded(anchor_length, "anchor_length", MAX_CDPR_LENGTH_M, "m",
                               positive=False)
    single = is_single(poses)
    P = as_poses(robot, poses)
    st = cable_state(robot, P, validated=True)
    att = P[:, None, :3] + st.r                                  # (B, m, 3)
    ex = np.broadcast_to(robot.exits_world, att.shape)
    m = robot.m
    if not (np.isfinite(min_distance) and min_distance >= 0):
        raise InvalidInputError("min_distance", "must be a non-negative length, m")
    share_a = np.all(robot.attach_local[:, None] == robot.attach_local[None], axis=2)
    share_e = np.all(robot.exits_world[:, None] == robot.exits_world[None], axis=2)
    trim = np.minimum(anchor_length, st.lengths)[..., None] * st.unit      # (B, m, 3)
    a_i, a_j = _ends(att, att + trim, share_a)
    e_i, e_j = _ends(ex, ex - trim, share_e)
    D = segment_distance(a_i, e_i, a_j, e_j)
    D = np.where(np.eye(m, dtype=bool)[None], np.inf, D)
    touch = min_distance + BOX_REL * (1.0 + float(np.abs(robot.exits_world).max()))
    close = np.any(D.reshape(len(P), -1) <= touch, axis=1)
    lo, hi = robot.attach_local.min(axis=0), robot.attach_local.max(axis=0)
    shrink = box_tol * (1.0 + float(np.max(hi - lo)))
    R = st.R
    a_loc = np.einsum("bji,bmj->bmi", R, att - P[:, None, :3])   # R^T (x - p)
    e_loc = np.einsum("bji,bmj->bmi", R, ex - P[:, None, :3])
    through = _through_box(a_loc, e_loc, lo + shrink, hi - shrink)
    if not np.all(hi - lo > 2 * shrink):          # flat or point platform: no volume
        through = np.zeros_like(through)
    res = Interference(D, close, through, ~close & ~through.any(axis=1), float(min_distance))
    return unbatch(res, ("distance", "cable_cable", "cable_platform", "free"), single)
