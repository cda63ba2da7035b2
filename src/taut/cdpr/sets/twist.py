"""First-order kinematics of mobile cable-driven parallel robots and their available twist
set (ATS), after the FASTKIT paper (Pedemonte, Rasheed et al., §3, eqs. 1-16).

The kinematics behind it are in :mod:`taut.cdpr.kinematics.first_order` (eqs. 1-9) and the modes
and limits in :mod:`taut.cdpr.kinematics.modes`.

The ATS is exact: in task mode it is ``{t : A t in Z}`` with ``Z = {B q_dot : q_dot in
box}`` a zonotope of R^m whose facets are enumerated from its generators (hyperplane
description, :mod:`taut.cdpr.sets.zonotope`); in navigation mode it is the zonotope
``Ad_P J_driver box`` (a parallelepiped for a 6-DoF platform) described in its span, plus
equality rows for the directions it lacks. Both are
:class:`~taut.cdpr.sets.polytope.HPolytopeBatch` instances, like the available wrench set.
Twists are ``t = [v; w]`` (m/s, rad/s, world frame, at P).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, replace
from typing import Any, Literal, Sequence

import numpy as np
from numpy.typing import ArrayLike

from .._batching import is_single, unbatch
from .._tol import RANK_TOL, ZERO_ROW
from ..kinematics.cables import as_poses
from ..kinematics.first_order import FOM_PER_POSE, FirstOrderModel, first_order
from ..model.robot import CableRobot
from ..kinematics.modes import (TWIST_LABELS, Mode, ModeName, MotionLimits, fastkit_motion_limits,
    joint_bounds, resolve_mode)
from .polytope import HPolytopeBatch, lp_max_step
from .zonotope import _facets_base_and_identity, zonotope_hrep
from ._budget import (batch_block, block_size, check_batch_sets, check_set_work,
                      twist_work)
from ..._validate import as_choice, as_count, require_instance
from ..._repr import CompactRepr

__all__ = ["AvailableTwistSet", "available_twist_set", "TwistCapacities", "twist_capacities",
           "support"]

@dataclass(frozen=True, repr=False)
class AvailableTwistSet(HPolytopeBatch, CompactRepr):
    """Exact available twist set at B poses: ``{t : H t <= h, E t = 0}``, a
    :class:`~taut.cdpr.sets.polytope.HPolytopeBatch` of platform twists.

    Attributes
    ----------
    H : (B, S, n)
        Inequality rows (zero rows with ``h = +inf`` are unused), twist units m/s, rad/s.
    h : (B, S)
    E : (B, k, n)
        Orthonormal equality rows (k = 0 in task mode; n minus the rank of the driver's
        twist map in navigation mode).
    poses : (B, 6)
    mode : Mode
    full_rank : (B,) bool
        A has full column rank (task mode); otherwise some twist direction is not
        determined by the joints and the set is unbounded along it.
    model : FirstOrderModel
    limits : MotionLimits
    """

    poses: np.ndarray
    mode: Mode
    full_rank: np.ndarray
    model: FirstOrderModel
    limits: MotionLimits

    def _points(self, x: Any, field: str = "twist") -> np.ndarray:
        return super()._points(x, "twist")


def _task_set(fom: FirstOrderModel, lo: np.ndarray, hi: np.ndarray, blk: int
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Task mode: ``{t : A t in Z}``, Z the joint-space zonotope ``B box`` (eq. 9); the
    facets are enumerated for ``blk`` poses at a time."""
    Bn, m, n = fom.A.shape
    c = 0.5 * (lo + hi)
    half = 0.5 * (hi - lo)
    keep = half > 0
    nb = fom.n_base_joints
    parts = []
    for i in range(0, Bn, blk):
        Bb = fom.B[i:i + blk]
        center = np.einsum("bmq,q->bm", Bb, c)
        if np.all(keep[nb:]):
            kb = keep[:nb]
            Hz, hz = _facets_base_and_identity(center, Bb[:, :, :nb][:, :, kb] * half[:nb][kb],
                                               half[nb:])
        else:
            Hz, hz = zonotope_hrep(center, Bb[:, :, keep] * half[keep])
        parts.append((np.einsum("bsm,bmn->bsn", Hz, fom.A[i:i + blk]), hz))
    H = np.concatenate([p[0] for p in parts])
    hz = np.concatenate([p[1] for p in parts])
    nrm = np.linalg.norm(H, axis=2)
    use = nrm > ZERO_ROW
    H = np.where(use[..., None], H / np.where(use, nrm, 1.0)[..., None], 0.0)
    h = np.where(use, hz / np.where(use, nrm, 1.0), np.where(hz >= 0, np.inf, -np.inf))
    sv = np.linalg.svd(fom.A, compute_uv=False)
    full = sv[:, -1] > RANK_TOL * sv[:, 0]
    return H, h, np.zeros((Bn, 0, n)), full


def _navigation_set(fom: FirstOrderModel, lo: np.ndarray, hi: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Navigation mode: the zonotope ``{M q : q in box}`` of the driver base, described in
    its span (coordinates ``y = U_r^T t``, facets from :func:`zonotope_hrep` in R^r,
    equality rows ``U_perp^T t = 0``)."""
    Bn = fom.A.shape[0]
    c = 0.5 * (lo + hi)
    half = 0.5 * (hi - lo)
    M = fom.base_twists[:, fom.mode.moving[0]]                           # (B, n, 3)
    U, S, _ = np.linalg.svd(M, full_matrices=True)
    r = int(np.sum(S[0] > RANK_TOL * S[0, 0]))
    Ur = U[:, :, :r]
    keep = half > 0
    gens = np.einsum("bnr,bnq->brq", Ur, M[:, :, keep] * half[keep])
    center = np.einsum("bnr,bnq,q->br", Ur, M, c)
    if r == 1:
        g1 = np.abs(gens[:, 0, :]).sum(axis=1)
        H = np.stack([Ur[:, :, 0], -Ur[:, :, 0]], axis=1)
        h = np.stack([center[:, 0] + g1, -center[:, 0] + g1], axis=1)
    else:
        Hz, h = zonotope_hrep(center, gens)
        H = np.einsum("bsr,bnr->bsn", Hz, Ur)
    return H, h, np.swapaxes(U[:, :, r:], 1, 2), np.ones(Bn, dtype=bool)


def available_twist_set(robot: CableRobot, poses: ArrayLike, limits: MotionLimits | None = None,
                        mode: ModeName = "task", moving: Sequence[str] | None = None
                        ) -> AvailableTwistSet:
    """Exact available twist set of the platform (FASTKIT §3.2, eqs. 9-16).

    Parameters
    ----------
    robot : CableRobot
    poses : array_like (6,), (3,), (B, 6) or (B, 3)
        m and rad.
    limits : MotionLimits, optional
        Default :func:`fastkit_motion_limits`.
    mode, moving
        See :func:`taut.cdpr.resolve_mode`. ``mode="task", moving=()`` fixes every base.

    Raises
    ------
    InvalidInputError
        ``cables``: the task-mode facets would need more than
        :data:`taut._validate.MAX_SET_NUMBERS` numbers per pose (e.g. 20 cables with two
        moving bases). ``poses``: the task-mode sets of the batch would hold more than
        that many numbers together (:func:`twist_capacities` takes any batch).

    Returns
    -------
    AvailableTwistSet
        One set for one pose (``H`` (S, n), ``contains`` a bool), a batch of B sets for
        a batch of poses. Task mode: ``{t : A t = B q_dot, q_lo <= q_dot <= q_hi}`` as ``H = H_Z A``,
        ``h = h_Z`` with ``(H_Z, h_Z)`` the facets of the joint-space zonotope ``B box``.
        Navigation mode: ``{Ad_P J_d q_dot_d : q_dot_d in box}``.

    Examples
    --------
    >>> from taut.io.cdpr_model import load_cdpr_model
    >>> ats = available_twist_set(load_cdpr_model("fastkit"), [0.3, 0, 1.0])
    >>> ats.contains([1.0, 0, 0, 0, 0, 0])                # the paper's 1 m/s
    True
    """
    single = is_single(poses)
    limits = fastkit_motion_limits() if limits is None else limits
    md = resolve_mode(robot, mode, moving)
    ats = _twist_sets(robot, as_poses(robot, poses), md, limits)
    if single:
        ats = replace(unbatch(ats, ("H", "h", "E", "poses", "full_rank"), True),
                      model=unbatch(ats.model, FOM_PER_POSE, True))
    return ats


def _twist_sets(robot: CableRobot, P: np.ndarray, md: Mode, limits: MotionLimits, *,
                batch_checked: bool = False) -> AvailableTwistSet:
    """The ATS of checked poses ``P`` (B, 6) in a resolved mode, a batch always. A task-mode
    batch is refused past the set budget unless ``batch_checked`` (the caller builds it a
    block at a time)."""
    fom = first_order(robot, P, md)
    lo, hi = joint_bounds(robot, limits, fom.mode)
    if fom.mode.kind == "task":
        nb = fom.n_base_joints
        moves = hi > lo
        work = twist_work(robot.m, int(moves[:nb].sum()), int(moves[nb:].sum()))
        check_set_work(work, robot, "twist set", f"{nb} moving base joints")
        if not batch_checked:
            check_batch_sets(work[0], robot.dof, fom.A.shape[0], "twist set")
        H, h, E, full = _task_set(fom, lo, hi, block_size(work, 256))
    else:
        H, h, E, full = _navigation_set(fom, lo, hi)
    return AvailableTwistSet(H=H, h=h, E=E, poses=fom.poses, mode=fom.mode, full_rank=full,
                             model=fom, limits=limits)


def ats_blocks(robot: CableRobot, P: np.ndarray, limits: MotionLimits, mode: ModeName,
               moving: Sequence[str] | None) -> Iterator[tuple[slice, AvailableTwistSet]]:
    """The ATS of checked poses ``P`` (B, 6) a block at a time (the first pose alone, which
    sizes the blocks by :func:`batch_block`), so only one block's facets are alive at once:
    ``(poses of the block, its sets)``. The mode is resolved once."""
    md = resolve_mode(robot, mode, moving)
    ats = _twist_sets(robot, P[:1], md, limits)
    blk = batch_block(ats.H.shape[1], ats.H.shape[2])
    yield slice(0, 1), ats
    del ats
    for i in range(1, P.shape[0], blk):
        yield slice(i, i + blk), _twist_sets(robot, P[i:i + blk], md, limits,
                                             batch_checked=True)


@dataclass(frozen=True, repr=False)
class TwistCapacities(CompactRepr):
    """Largest pure platform velocity along each axis (FASTKIT Fig. 13), per pose.

    ``positive[b, k]`` is the largest ``s >= 0`` with ``s e_k`` in the ATS (the other five
    twist components zero), ``negative`` the same along ``-e_k``: m/s for ``vx, vy, vz``,
    rad/s for ``wx, wy, wz``; ``positive`` and ``negative`` are (B, n), or (n,) for one
    pose. ``feasible`` (B, n, 2) (one pose: (n, 2)) says whether ``s = 0`` itself is
    available (False when the limits exclude standing still); ``inf`` marks an
    unbounded direction (A rank-deficient).
    """

    positive: np.ndarray
    negative: np.ndarray
    feasible: np.ndarray
    labels: tuple[str, ...]
    mode: Mode


def twist_capacities(robot: CableRobot, poses: ArrayLike, limits: MotionLimits | None = None,
                     mode: ModeName = "task", moving: Sequence[str] | None = None,
                     method: Literal["hrep", "lp"] = "hrep") -> TwistCapacities:
    """Axis twist capacities (Fig. 13) at poses.

    ``method="hrep"`` shoots rays in the exact H-representation (closed form, batched,
    :meth:`HPolytopeBatch.axis_ray_lengths`); ``method="lp"`` solves ``max s`` s.t.
    ``A (s e) = B q_dot`` (task mode) or ``s e = Ad_P J q_dot`` (navigation),
    ``q_lo <= q_dot <= q_hi``, with HiGHS, one LP per pose and direction (reference
    formulation over joint rates).

    Returns
    -------
    TwistCapacities
        Arrays with a leading axis of B poses for a batch, without it for one pose.

    Examples
    --------
    >>> from taut.io.cdpr_model import load_cdpr_model
    >>> cap = twist_capacities(load_cdpr_model("fastkit"), [0.3, 0, 1.0])
    >>> cap.positive.shape, bool(cap.positive[0] >= 1.0)   # vx: at least the paper's 1 m/s
    ((6,), True)
    """
    as_choice(method, ("hrep", "lp"), "method")
    single = is_single(poses)
    limits = fastkit_motion_limits() if limits is None else limits
    P = as_poses(robot, poses)
    if method == "lp":
        caps = _capacities_lp(robot, P, limits, mode, moving)
    else:
        rays = []
        for _, ats in ats_blocks(robot, P, limits, mode, moving):   # one block's facets
            rays.append(ats.axis_ray_lengths(None, tol=ZERO_ROW, zero=ZERO_ROW))
            dim, md = ats.dim, ats.mode
            del ats                     # before the next block is built, not after
        pos, neg, reach = (np.concatenate([r[k] for r in rays]) for k in range(3))
        caps = TwistCapacities(pos, neg, reach, TWIST_LABELS[:dim], md)
    return unbatch(caps, ("positive", "negative", "feasible"), single)


def _capacities_lp(robot: CableRobot, P: np.ndarray, limits: MotionLimits,
                   mode: ModeName, moving: Sequence[str] | None) -> TwistCapacities:
    fom = first_order(robot, P, resolve_mode(robot, mode, moving))
    lo, hi = joint_bounds(robot, limits, fom.mode)
    Bn, m, n = fom.A.shape
    pos = np.zeros((Bn, n))
    neg = np.zeros((Bn, n))
    feas = np.zeros((Bn, n, 2), dtype=bool)
    bounds = list(zip(lo, hi))
    for b in range(Bn):
        if fom.mode.kind == "task":
            L, Rm = fom.A[b], fom.B[b]                       # A (s e) - B q = 0
        else:
            L, Rm = np.eye(n), fom.base_twists[b, fom.mode.moving[0]]
        for k in range(n):
            for sgn, out, col in ((1.0, pos, 0), (-1.0, neg, 1)):
                status, step = lp_max_step(-Rm, sgn * L[:, k], np.zeros(L.shape[0]), bounds,
                                           step_first=True)
                if status == 0:
                    out[b, k] = step
                    feas[b, k, col] = True
                elif status == 3:
                    out[b, k] = np.inf
                    feas[b, k, col] = True
    return TwistCapacities(pos, neg, feas, TWIST_LABELS[:n], fom.mode)


def support(ats: AvailableTwistSet, direction: ArrayLike, k: int = 0) -> float:
    """Support function ``max d . t`` over the ATS of pose ``k`` (LP over the H-rep, HiGHS);
    ``inf`` when unbounded, ``-inf`` when the set is empty. Same as ``ats.support``."""
    require_instance(ats, AvailableTwistSet, "ats")
    k = as_count(k, "k", maximum=ats.H.shape[0] - 1)
    return ats.support(direction, k)
