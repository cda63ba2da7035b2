"""Available wrench set (AWS) of a CDPR on fixed or mobile bases (FASTKIT eq. 24), exact, as
an H-polytope, batched over poses; axis capacities (FASTKIT Fig. 14) and capacity margins.

The AWS is ``{W t : t_min <= t <= t_max, T t <= -m0}``: the image through W of the tension
box intersected with the tipping half-spaces (eqs. 20-23). With ``r = m - n`` redundant
cables write ``t = W+ w + N z`` (``N`` an orthonormal null-space basis). A wrench ``w`` is
available iff the ``r``-dimensional polyhedron ``{z : G z <= h(w)}`` with ``G = A N`` and
``h(w) = b - A W+ w`` is non-empty. By Helly's theorem it is empty iff some ``r + 1`` of
its half-spaces already have no common point, and by Farkas' lemma that happens iff a
``lambda >= 0`` on those rows has ``lambda^T G = 0`` and ``lambda^T h(w) < 0``. For rows in
general position ``lambda`` is the (signed) vector of ``r x r`` minors of ``G`` on the
subset; degenerate subsets reduce to pairs of opposite rows or single zero rows, which are
added too. Hence the AWS is exactly

    ``{w : (lambda^T A W+) w <= lambda^T b  for every certificate lambda}``

- a finite H-representation (possibly with redundant rows, never with missing ones; the
degenerate-subset handling is complete for r <= 2, the case of 8 cables and 6 DoF). This
is Fourier-Motzkin elimination of ``z`` done in one step, and it never enumerates the
``2^m`` tension-box corners. For the tension box alone it reduces to the hyperplane-shifting
description of the wrench zonotope.

Wrench units are mixed (N, N m); rows are normalised to unit Euclidean norm.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from itertools import product
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from ..._validate import as_array, as_choice, as_count, as_flag, require_instance
from ...errors import InvalidInputError
from .._batching import first, is_single, unbatch
from ..statics._common import (constraints, feas_tol, required_wrench, svd_split,
    wrench_vertices)
from ..statics._farkas import certificates, combine, nonempty
from .._tol import CONTAINS_TOL, VERTEX_SLACK, ZERO_ROW
from ..kinematics.cables import as_poses, cable_state, gravity_wrench
from ..model.robot import CableRobot
from .polytope import HPolytopeBatch, lp_max_step
from ._budget import (batch_block, block_size, check_batch_sets, check_set_work,
                      wrench_work)
from ..._repr import CompactRepr

__all__ = ["AvailableWrenchSet", "available_wrench_set", "wrench_feasible",
           "AxisCapacities", "axis_capacities", "capacity_margin", "external_wrench_box",
           "AXIS_LABELS"]

AXIS_LABELS = ("fx", "fy", "fz", "mx", "my", "mz")


@dataclass(frozen=True, repr=False)
class AvailableWrenchSet(HPolytopeBatch, CompactRepr):
    """H-representation ``{w : H w <= h}`` of the AWS at B poses (FASTKIT eq. 24), a
    :class:`~taut.cdpr.sets.polytope.HPolytopeBatch` of cable wrenches.

    Attributes
    ----------
    H : (B, S, n)
        Unit-norm rows (zero rows for unused certificates), w in (N, N m).
    h : (B, S)
        Offsets (``+inf`` for unused rows).
    E : (B, 0, n)
        No equality rows (the set is full-dimensional where W has full rank).
    poses : (B, 6)
    full_rank : (B,) bool
        W has full row rank (otherwise the set is lower-dimensional and ``H`` is unused).
    nonempty : (B,) bool
        False when no tensions satisfy the tension and tipping limits at all.
    tipping : bool
    gravity_wrench : (B, n)
        ``w_e`` of platform and payload weight at each pose.
    sliding : bool
        Whether the friction rows of :mod:`taut.cdpr.statics.sliding` are included.
    """

    poses: np.ndarray
    full_rank: np.ndarray
    nonempty: np.ndarray
    tipping: bool
    gravity_wrench: np.ndarray
    sliding: bool = False

    def contains(self, wrench: ArrayLike, tol: float = CONTAINS_TOL) -> Any:
        """Whether cable wrenches ``wrench`` ((n,) or (B, n)) lie in the AWS -> (B,) bool
        (a bool for the set at one pose)."""
        ok = self._contains(wrench, tol) & np.atleast_1d(self.full_rank & self.nonempty)
        return self._out(ok)


def _prepare(robot: CableRobot, poses: Any, tipping: bool, sliding: bool = False
             ) -> tuple[Any, ...]:
    P = as_poses(robot, poses)
    st = cable_state(robot, P, validated=True)
    pinv, N, ok = svd_split(st.W)
    A, b = constraints(robot, st, bool(tipping and robot.has_tipping), sliding)
    return P, st, pinv, N, ok, A, b


def available_wrench_set(robot: CableRobot, poses: ArrayLike, *, tipping: bool = True,
                         sliding: bool = True) -> AvailableWrenchSet:
    """Exact H-representation of the available wrench set (FASTKIT eq. 24) at poses.

    Parameters
    ----------
    robot : CableRobot
    poses : array_like (6,), (3,), (B, 6) or (B, 3)
        Platform poses, m and rad.
    tipping : bool
        Include the tipping constraints of the mobile bases (eqs. 21-23); ignored for
        fixed frames. Without them the set is the classical tension-limited AWS.
    sliding : bool, default True
        Include the friction rows of the mobile bases that have a friction coefficient
        (:mod:`taut.cdpr.statics.sliding`); no effect on a model without one.

    Raises
    ------
    InvalidInputError
        ``cables``: the enumeration would build more than
        :data:`taut._validate.MAX_SET_NUMBERS` numbers per pose (more than 12 cables for a
        6-DoF platform on a fixed frame). ``poses``: the sets of the batch would hold more
        than that many numbers together (e.g. more than 1,844 poses of FASTKIT, 12 of a
        12-cable 6-DoF robot); :func:`axis_capacities`, :func:`capacity_margin` and
        :func:`wrench_feasible` take any batch.

    Returns
    -------
    AvailableWrenchSet
        Set of cable wrenches ``W t`` (forces N, moments N m about P, world frame): one
        set (``H`` (S, n), ``contains`` a bool) for one pose, B sets for B poses.

    Examples
    --------
    >>> from taut.io.cdpr_model import load_cdpr_model
    >>> robot = load_cdpr_model("fastkit")
    >>> aws = available_wrench_set(robot, [0, 0, 0.6])
    >>> aws.contains(-aws.gravity_wrench)               # it can hold its own weight
    True
    """
    tipping = as_flag(tipping, "tipping")
    sliding = as_flag(sliding, "sliding")
    single = is_single(poses)
    P = as_poses(robot, poses)
    slide = bool(sliding and robot.has_sliding)
    work = wrench_work(robot, tipping, slide)
    check_set_work(work, robot, "wrench set")
    check_batch_sets(work[0], robot.dof, P.shape[0], "wrench set")
    aws = _wrench_sets(robot, P, tipping, slide, work)
    return unbatch(aws, ("H", "h", "E", "poses", "full_rank", "nonempty", "gravity_wrench"),
                   single)


def _wrench_sets(robot: CableRobot, P: np.ndarray, tipping: bool, slide: bool,
                 work: tuple[int, int]) -> AvailableWrenchSet:
    """The AWS of the checked poses ``P`` (B, 6), enumerated :func:`block_size` poses at a
    time (``work``: :func:`wrench_work`, already checked)."""
    blk = block_size(work, 256)
    parts = [_aws_block(robot, P[i:i + blk], tipping, slide)
             for i in range(0, P.shape[0], blk)]
    H, h, ok, nonempty_, wg = (np.concatenate(x) for x in zip(*parts))
    return AvailableWrenchSet(H=H, h=h, E=np.zeros((P.shape[0], 0, robot.dof)), poses=P,
                              full_rank=ok, nonempty=nonempty_,
                              tipping=bool(tipping and robot.has_tipping), gravity_wrench=wg,
                              sliding=slide)


def _aws_blocks(robot: CableRobot, P: np.ndarray, tipping: bool, sliding: bool
                ) -> Iterator[tuple[slice, AvailableWrenchSet]]:
    """The AWS of the checked poses ``P`` (B, 6) a block of poses at a time
    (:func:`batch_block`), so only one block's facets are alive at once: ``(poses of the
    block, its sets)``."""
    slide = bool(sliding and robot.has_sliding)
    work = wrench_work(robot, tipping, slide)
    check_set_work(work, robot, "wrench set")
    blk = batch_block(work[0], robot.dof)
    for i in range(0, P.shape[0], blk):
        yield slice(i, i + blk), _wrench_sets(robot, P[i:i + blk], tipping, slide, work)


def _aws_block(robot: CableRobot, P: np.ndarray, tipping: bool, sliding: bool
               ) -> tuple[np.ndarray, ...]:
    P, st, pinv, N, ok, A, b = _prepare(robot, P, tipping, sliding)
    G = np.einsum("bkm,bmr->bkr", A, N)
    idx, lam, valid = certificates(G)
    AW = np.einsum("bkm,bmn->bkn", A, pinv)                   # (B, K, n)
    H = combine(lam, idx, AW)
    h = combine(lam, idx, b)
    nrm = np.linalg.norm(H, axis=2)
    tol = feas_tol(robot)
    scale = 1.0 + np.abs(AW).max(axis=(1, 2))[:, None]
    flat = nrm <= ZERO_ROW * scale
    nonempty_ = ~np.any(valid & flat & (h < -tol), axis=1)
    use = valid & ~flat
    H = np.where(use[..., None], H / np.where(use, nrm, 1.0)[..., None], 0.0)
    h = np.where(use, h / np.where(use, nrm, 1.0), np.inf)
    return H, h, ok, nonempty_, gravity_wrench(robot, st.R)


def external_wrench_box(robot: CableRobot, half_widths: ArrayLike) -> np.ndarray:
    """Vertices (2^n, n) of a box of extra external wrenches ``|w_k| <= half_widths[k]``
    (N, N m); zero half-widths collapse (duplicate vertices are removed).

    Examples
    --------
    >>> from taut.io.cdpr_model import load_cdpr_model
    >>> external_wrench_box(load_cdpr_model("fastkit"), [2, 0, 3, 0, 0, 0]).shape
    (4, 6)
    """
    hw = as_array(half_widths, "half_widths",
                  shape=(require_instance(robot, CableRobot, "robot").dof,))
    if np.any(hw < 0):
        raise InvalidInputError("half_widths", "must be non-negative")
    V = np.array(list(product(*[(-x, x) if x > 0 else (0.0,) for x in hw])))
    return V.reshape(-1, robot.dof)



def wrench_feasible(robot: CableRobot, poses: ArrayLike, *, tipping: bool = True,
                    external_wrench: ArrayLike | None = None, chunk: int = 256,
                    sliding: bool = True) -> np.ndarray:
    """Wrench feasibility (FASTKIT §4) of a batch of poses: can the cables hold platform
    and payload weight plus every extra wrench of ``external_wrench`` within tension limits
    (eq. 20) and, if ``tipping``, without tipping a mobile base (eqs. 21-23)?

    Exact and vectorised (no LP): with ``r = m - n <= 2`` redundant cables the polygon of
    null-space coordinates ``z`` is tested for a feasible vertex; otherwise the Farkas
    certificates of the module docstring are checked.

    Parameters
    ----------
    poses : array_like (6,), (3,), (B, 6) or (B, 3), m and rad
    tipping : bool, default True
    external_wrench : array_like (V, n) or (n,), optional
        Extra external wrenches (vertices of a convex set, e.g.
        :func:`external_wrench_box`), N and N m.
    chunk : int
        Poses per vectorised block (memory ~ chunk * 60 kB with tipping; 256 is
        fastest here); fewer when a block would exceed the budget of
        :data:`taut._validate.MAX_SET_NUMBERS`.
    sliding : bool, default True
        Also require the friction condition of :mod:`taut.cdpr.statics.sliding` (bases with a
        friction coefficient only).

    Returns
    -------
    ndarray (B,) of bool, or a bool for one pose

    Examples
    --------
    >>> from taut.io.cdpr_model import load_cdpr_model
    >>> robot = load_cdpr_model("fastkit")
    >>> wrench_feasible(robot, [[0, 0, 0.6], [2, 0, 1.8]]).tolist()
    [True, False]
    >>> wrench_feasible(robot, [0, 0, 0.6])
    True
    """
    tipping = as_flag(tipping, "tipping")
    sliding = as_flag(sliding, "sliding")
    single = is_single(poses)
    P = as_poses(robot, poses)
    chunk = as_count(chunk, "chunk", minimum=1)
    if robot.m - robot.dof > 2:                       # Farkas certificates (else vertices)
        work = wrench_work(robot, tipping, sliding)
        check_set_work(work, robot, "wrench set")
        chunk = block_size(work, chunk)
    D = wrench_vertices(robot, external_wrench)
    out = np.empty(P.shape[0], dtype=bool)
    tol = feas_tol(robot)
    for s0 in range(0, P.shape[0], chunk):
        sl = slice(s0, s0 + chunk)
        st = cable_state(robot, P[sl], validated=True)
        pinv, N, ok = svd_split(st.W)
        A, b = constraints(robot, st, bool(tipping and robot.has_tipping), sliding)
        G = np.einsum("bkm,bmr->bkr", A, N)
        cert = certificates(G) if N.shape[2] > 2 else None
        good = ok.copy()
        wreq = required_wrench(robot, st)
        for d in D:                                   # few vertices: loop, poses batched
            tp = np.einsum("bmn,bn->bm", pinv, wreq - d)
            slack = b - np.einsum("bkm,bm->bk", A, tp)                    # (B, K)
            good &= nonempty(G, slack, VERTEX_SLACK * tol, cert)
        out[sl] = good
    return first(out) if single else out


@dataclass(frozen=True, repr=False)
class AxisCapacities(CompactRepr):
    """Largest extra external wrench along each axis the platform can resist on top of its
    weight (FASTKIT Fig. 14), per pose.

    Attributes
    ----------
    positive, negative : (B, n), or (n,) for one pose
        Magnitudes along ``+axis`` and ``-axis`` (N for forces, N m for moments); 0 where
        even no extra wrench can be held.
    feasible : (B, n, 2) bool, or (n, 2) for one pose
        Whether some non-negative magnitude is feasible along (+, -) of each axis.
    labels : tuple of str
    tipping : bool
    """

    positive: np.ndarray
    negative: np.ndarray
    feasible: np.ndarray
    labels: tuple[str, ...]
    tipping: bool


def axis_capacities(robot: CableRobot, poses: ArrayLike, *, tipping: bool = True,
                    method: Literal["hrep", "lp"] = "hrep", sliding: bool = True
                    ) -> AxisCapacities:
    """Axis capacities ``max s >= 0`` with ``W t + w_e + s e = 0`` (eq. 17) inside the tension
    limits (eq. 20) and, if ``tipping``, the tipping limits (eqs. 21-23), for ``e`` each of
    ``+-x, +-y, +-z`` forces and (6-DoF) moments about P.

    ``method="hrep"`` reads them off the exact AWS (batched rays of
    :meth:`HPolytopeBatch.axis_ray_lengths` from the cable wrench ``-w_e`` along ``-e``);
    ``"lp"`` solves one HiGHS LP per pose and direction (reference).

    Examples
    --------
    >>> from taut.io.cdpr_model import load_cdpr_model
    >>> cap = axis_capacities(load_cdpr_model("fastkit"), [0, 0, 0.6])
    >>> cap.positive.shape, bool(cap.positive[2] > 0)      # one pose: (n,)
    ((6,), True)
    """
    as_choice(method, ("hrep", "lp"), "method")
    tipping = as_flag(tipping, "tipping")
    sliding = as_flag(sliding, "sliding")
    n = require_instance(robot, CableRobot, "robot").dof
    labels = AXIS_LABELS[:n]
    single = is_single(poses)
    P = as_poses(robot, poses)
    if method == "lp":
        caps = _axis_lp(robot, P, tipping, labels, sliding)
    else:
        pos = np.zeros((P.shape[0], n))
        neg = np.zeros((P.shape[0], n))
        reach = np.zeros((P.shape[0], n, 2), dtype=bool)
        for sl, aws in _aws_blocks(robot, P, tipping, sliding):
            p, q, r = aws.axis_ray_lengths(-aws.gravity_wrench, tol=feas_tol(robot),
                                           sign=-1.0, zero=ZERO_ROW)
            ok = (aws.full_rank & aws.nonempty)[:, None]
            pos[sl], neg[sl], reach[sl] = np.where(ok, p, 0.0), np.where(ok, q, 0.0), \
                r & ok[..., None]
            del aws                     # before the next block is built, not after
        caps = AxisCapacities(pos, neg, reach, labels, bool(tipping and robot.has_tipping))
    return unbatch(caps, ("positive", "negative", "feasible"), single)


def _axis_lp(robot: CableRobot, poses: ArrayLike, tipping: bool,
             labels: tuple[str, ...], sliding: bool) -> AxisCapacities:
    P, st, pinv, N, ok, A, b = _prepare(robot, poses, tipping, sliding)
    B, n, m = st.W.shape
    wg = gravity_wrench(robot, st.R)
    pos = np.zeros((B, n))
    neg = np.zeros((B, n))
    feas = np.zeros((B, n, 2), dtype=bool)
    bounds = list(zip(robot.t_min, robot.t_max))
    for i in range(B):
        extra = A[i, 2 * m:]
        Aub = extra if extra.shape[0] else None
        bub = b[i, 2 * m:] if extra.shape[0] else None
        for k in range(n):
            for sgn, out, col in ((1.0, pos, 0), (-1.0, neg, 1)):
                e = np.zeros(n)
                e[k] = sgn
                status, step = lp_max_step(st.W[i], e, -wg[i], bounds, A_ub_x=Aub, b_ub=bub)
                if status == 0:
                    out[i, k] = step
                    feas[i, k, col] = True
    return AxisCapacities(pos, neg, feas, labels, bool(tipping and robot.has_tipping))


def capacity_margin(robot: CableRobot, poses: ArrayLike,
                    external_wrench: ArrayLike | None = None, *, tipping: bool = True,
                    sliding: bool = True) -> np.ndarray:
    """Capacity margin of the required wrench set at poses, (B,) (a float for one pose).

    The required set is platform and payload weight plus the extra external wrenches
    ``external_wrench`` (V, n) (vertices of a convex set, default none). The margin is
    ``min_facets (h_k - max_v H_k w_v)`` over the unit-normal facets of the AWS: the
    distance (in mixed N / N m units) from the required set to the AWS boundary when
    positive; negative when some required wrench is not available. ``-inf`` at singular
    poses or when the AWS is empty.

    Examples
    --------
    >>> from taut.io.cdpr_model import load_cdpr_model
    >>> robot = load_cdpr_model("fastkit")
    >>> bool(capacity_margin(robot, [0, 0, 0.6]) > 0)           # one pose: a float
    True
    >>> (capacity_margin(robot, [[0, 0, 0.6], [2, 0, 1.8]]) > 0).tolist()
    [True, False]
    """
    tipping = as_flag(tipping, "tipping")
    sliding = as_flag(sliding, "sliding")
    single = is_single(poses)
    P = as_poses(robot, poses)
    D = wrench_vertices(robot, external_wrench)
    out = np.empty(P.shape[0])
    for sl, aws in _aws_blocks(robot, P, tipping, sliding):   # one block's facets at a time
        w = -(aws.gravity_wrench[:, None, :] + D[None, :, :])    # required cable wrenches
        hw = np.einsum("bsn,bvn->bsv", aws.H, w).max(axis=2)
        margin = np.min(aws.h - hw, axis=1)
        out[sl] = np.where(aws.full_rank & aws.nonempty, margin, -np.inf)
        del aws, hw                     # before the next block is built, not after
    return first(out) if single else out
