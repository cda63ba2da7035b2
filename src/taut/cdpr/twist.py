"""First-order kinematics of mobile cable-driven parallel robots and their available twist
set (ATS), after the FASTKIT paper (Pedemonte, Rasheed et al., §3, eqs. 1-16).

Conventions (SI units: m, rad, s; float64)
-----------------------------------------
* A platform twist is ``t = [v; w]`` (linear velocity of the reference point P, then angular
  velocity, world frame), the same order as the wrenches of :mod:`taut.cdpr.wrench_set`.
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

Modes (eqs. 10-16)
------------------
``"task"``: cables and the bases named in ``moving`` move, every other base is fixed
(default ``moving``: the first mobile base, FASTKIT's active base, listed first in its model
file). ``moving=()`` is the "bases fixed" case of the paper's Fig. 13.
``"navigation"``: all bases are coupled to the ``driver`` base (default the first mobile
base) and the platform is fixed to them; no cable moves, so ``t = Ad_P J_driver q_dot``.

The ATS is exact: in task mode it is ``{t : A t in Z}`` with ``Z = {B q_dot : q_dot in
box}`` a zonotope of R^m whose facets are enumerated from its generators (hyperplane
description); in navigation mode it is the zonotope ``Ad_P J_driver box`` (a parallelepiped
for a 6-DoF platform) described in its span, plus equality rows for the directions it
lacks.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from itertools import combinations
from typing import Any, Sequence

import numpy as np
from scipy.optimize import linprog

from .._validate import as_array
from ..errors import InvalidInputError
from .kinematics import as_poses, cable_state
from .model import CableRobot

__all__ = ["MotionLimits", "fastkit_motion_limits", "MODES", "Mode", "resolve_mode",
           "FirstOrderModel", "first_order_model", "parallel_jacobian", "base_jacobians",
           "AvailableTwistSet", "available_twist_set", "TwistCapacities", "twist_capacities",
           "TWIST_LABELS", "BASE_JOINTS", "support", "joint_bounds", "zonotope_hrep"]

MODES = ("task", "navigation")
TWIST_LABELS = ("vx", "vy", "vz", "wx", "wy", "wz")
BASE_JOINTS = ("theta", "rho1", "rho2")


def _pair(lo: Any, hi: Any, fld: str, shape: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
    a = as_array(lo, f"{fld}_min")
    b = as_array(hi, f"{fld}_max")
    try:
        a = np.broadcast_to(a, shape).astype(float)
        b = np.broadcast_to(b, shape).astype(float)
    except ValueError:
        raise InvalidInputError(fld, f"limits must be a number or have shape {shape}") from None
    if np.any(a > b):
        k = int(np.argmax(a > b))
        raise InvalidInputError(fld, f"minimum {a.flat[k]:g} exceeds maximum {b.flat[k]:g}")
    return a, b


@dataclass(frozen=True)
class MotionLimits:
    """Joint velocity limits of a mobile CDPR (FASTKIT eqs. 10-16).

    Parameters
    ----------
    base_min, base_max : (3,)
        Limits of every moving base's RPP joint rates ``(theta_dot [rad/s], rho1_dot [m/s],
        rho2_dot [m/s])`` (yaw rate, forward and lateral speed in the base frame).
    cable_min, cable_max : float or (m,)
        Cable speed limits, m/s (negative = reeling in).

    Raises
    ------
    InvalidInputError
        NaN/inf, wrong shape, or a minimum above its maximum.
    """

    base_min: Any = (-0.2, -0.2, -0.2)
    base_max: Any = (0.2, 0.2, 0.2)
    cable_min: Any = -2.0
    cable_max: Any = 2.0

    def __post_init__(self) -> None:
        lo, hi = _pair(self.base_min, self.base_max, "limits.base", (3,))
        object.__setattr__(self, "base_min", lo)
        object.__setattr__(self, "base_max", hi)
        c_lo = as_array(self.cable_min, "limits.cable_min")
        c_hi = as_array(self.cable_max, "limits.cable_max")
        if c_lo.ndim > 1 or c_hi.ndim > 1:
            raise InvalidInputError("limits.cable", "must be a number or a vector (m,)")
        shape = np.broadcast_shapes(c_lo.shape, c_hi.shape) if (c_lo.ndim or c_hi.ndim) else ()
        lo, hi = _pair(c_lo, c_hi, "limits.cable", shape)
        object.__setattr__(self, "cable_min", lo)
        object.__setattr__(self, "cable_max", hi)

    def cable_bounds(self, m: int) -> tuple[np.ndarray, np.ndarray]:
        """Cable speed limits broadcast to ``(m,)``, m/s."""
        try:
            return (np.broadcast_to(self.cable_min, (m,)).copy(),
                    np.broadcast_to(self.cable_max, (m,)).copy())
        except ValueError:
            raise InvalidInputError("limits.cable", f"has {np.size(self.cable_min)} entries "
                                                    f"for a robot with {m} cables") from None


def fastkit_motion_limits() -> MotionLimits:
    """FASTKIT's joint velocity limits as printed in the paper: active base
    ``|theta_dot| <= 0.2 rad/s``, ``|rho1_dot|, |rho2_dot| <= 0.2 m/s`` (eqs. 10-12) and cable
    speeds ``|l_dot| <= 2 m/s`` (eq. 16, from the motor/winch table). The passive base is
    fixed in task mode (eqs. 13-15) through the mode, not through these limits."""
    return MotionLimits((-0.2, -0.2, -0.2), (0.2, 0.2, 0.2), -2.0, 2.0)


@dataclass(frozen=True)
class Mode:
    """A resolved operating mode: ``kind`` ("task" or "navigation"), the indices of the bases
    whose joints move (``moving``; the driver alone in navigation mode) and their names."""

    kind: str
    moving: tuple[int, ...]
    names: tuple[str, ...]


def resolve_mode(robot: CableRobot, mode: str = "task",
                 moving: Sequence[str] | None = None) -> Mode:
    """Check a mode against the model.

    Parameters
    ----------
    mode : {"task", "navigation"}
    moving : sequence of base names, optional
        Task mode: the bases that move (default: the first mobile base; ``()`` fixes all).
        Navigation mode: exactly one driver base (default the first mobile base).

    Raises
    ------
    InvalidInputError
        Unknown mode, a base name the model lacks, a fixed (non-mobile) base asked to move,
        or no mobile base to drive in navigation mode.
    """
    if mode not in MODES:
        raise InvalidInputError("mode", f"unknown mode {mode!r}; choose one of "
                                        + ", ".join(MODES))
    names = [b.name for b in robot.bases]
    mobile = [b.name for b in robot.bases if b.mobile]
    if moving is None:
        chosen: tuple[str, ...] = tuple(mobile[:1])
    elif isinstance(moving, str):
        chosen = (moving,)
    else:
        chosen = tuple(str(s) for s in moving)
    for s in chosen:
        if s not in names:
            raise InvalidInputError("mode.moving", f"no base named {s!r} in model "
                                    f"{robot.name!r} (bases: {', '.join(names)})")
        if not robot.bases[names.index(s)].mobile:
            raise InvalidInputError("mode.moving", f"base {s!r} is a fixed frame, it cannot "
                                                   "move")
    if len(set(chosen)) != len(chosen):
        raise InvalidInputError("mode.moving", "a base is named twice")
    if mode == "navigation" and len(chosen) != 1:
        raise InvalidInputError("mode.moving", "navigation mode needs exactly one driver "
                                               "(mobile) base")
    return Mode(mode, tuple(names.index(s) for s in chosen), chosen)


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


def parallel_jacobian(robot: CableRobot, poses: Any) -> np.ndarray:
    """Parallel Jacobian ``A`` (B, m, n) with ``l_dot = A t`` for fixed bases (eqs. 1-3);
    n = 6 (``t = [v; w]``, m/s and rad/s) or 3 for a point-mass platform."""
    return -np.swapaxes(cable_state(robot, poses).W, 1, 2)


@dataclass(frozen=True)
class FirstOrderModel:
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


def first_order_model(robot: CableRobot, poses: Any, mode: str = "task",
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
    """
    md = resolve_mode(robot, mode, moving)
    P = as_poses(robot, poses)
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


def joint_bounds(robot: CableRobot, limits: MotionLimits, md: Mode
                 ) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper joint-rate bounds in the column order of ``FirstOrderModel.B``."""
    lo = [limits.base_min] * len(md.moving)
    hi = [limits.base_max] * len(md.moving)
    if md.kind == "task":
        c_lo, c_hi = limits.cable_bounds(robot.m)
        lo.append(c_lo)
        hi.append(c_hi)
    if not lo:
        return np.zeros(0), np.zeros(0)
    return np.concatenate(lo), np.concatenate(hi)


@lru_cache(maxsize=16)
def _subsets(g: int, s: int) -> np.ndarray:
    if s == 0:
        return np.zeros((1, 0), dtype=np.intp)
    return np.array(list(combinations(range(g), s)), dtype=np.intp).reshape(-1, s)


def zonotope_hrep(center: np.ndarray, gens: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Facets of full-dimensional zonotopes ``{c + G s : |s|_inf <= 1}`` in R^d, batched.

    Each (d-1)-subset of generators spanning a hyperplane gives the facet pair
    ``+-n . x <= +-n . c + sum_j |n . g_j|`` with ``n`` its unit normal (the direction of
    the generalised cross product, taken from a complete QR factorisation). Degenerate
    subsets get zero rows with ``+inf`` offsets.

    Parameters
    ----------
    center : (B, d)
    gens : (B, d, g)

    Returns
    -------
    H : (B, 2S, d) unit rows, h : (B, 2S)
    """
    Bn, d, g = gens.shape
    if g < d or np.any(np.linalg.matrix_rank(gens) < d):
        raise InvalidInputError("limits", "the joints that may move do not span every "
                                          "direction (give each cable a speed range with "
                                          "min < max)")
    sub = _subsets(g, d - 1)
    Gs = np.swapaxes(gens[:, :, sub], 1, 2)                       # (B, S, d, d-1)
    # The last column of a complete QR factor spans the orthogonal complement of the
    # subset (the direction of its generalised cross product); a tiny R diagonal flags a
    # subset that does not span a hyperplane.
    Q, R = np.linalg.qr(Gs, mode="complete")
    N = Q[..., -1]                                                 # (B, S, d), unit
    rdiag = np.abs(np.diagonal(R, axis1=-2, axis2=-1)).min(axis=-1)
    scale = np.abs(gens).max(axis=(1, 2))[:, None] + 1e-300
    ok = rdiag > 1e-10 * scale
    N = np.where(ok[..., None], N, 0.0)
    off = np.abs(np.einsum("bsd,bdg->bsg", N, gens)).sum(axis=2)
    nc = np.einsum("bsd,bd->bs", N, center)
    H = np.concatenate([N, -N], axis=1)
    h = np.concatenate([np.where(ok, nc + off, np.inf), np.where(ok, -nc + off, np.inf)], axis=1)
    return H, h


def _facets_base_and_identity(center: np.ndarray, Gb: np.ndarray, hc: np.ndarray
                              ) -> tuple[np.ndarray, np.ndarray]:
    """Facets of the task-mode zonotope with generators ``[Gb, diag(hc)]`` (hc > 0), batched.

    Same facets as :func:`zonotope_hrep`, faster: a (m-1)-subset with ``j`` base columns and
    ``m-1-j`` cable columns ``e_i`` has a normal supported on the ``j+1`` cables it leaves
    out, orthogonal there to the ``j`` base columns, so only (j+1) x j problems are solved.

    Parameters
    ----------
    center : (B, m); Gb : (B, m, g) scaled base columns; hc : (m,) cable half-ranges.
    """
    Bn, m, g = Gb.shape
    normals = []
    for j in range(0, min(g, m - 1) + 1):
        cs = _subsets(m, j + 1)                                    # (nC, j+1) free cables
        for sb in _subsets(g, j):
            sub = Gb[:, cs][:, :, :, sb] if j else np.zeros((Bn, len(cs), j + 1, 0))
            if j:
                Q, R = np.linalg.qr(sub, mode="complete")          # (B, nC, j+1, j+1)
                nc = Q[..., -1]
                rd = np.abs(np.diagonal(R, axis1=-2, axis2=-1)).min(axis=-1)
                ok = rd > 1e-10 * (np.abs(Gb).max(axis=(1, 2))[:, None] + 1e-300)
                nc = np.where(ok[..., None], nc, 0.0)
            else:
                nc = np.ones((Bn, len(cs), 1))
            n = np.zeros((Bn, len(cs), m))
            np.put_along_axis(n, np.broadcast_to(cs, (Bn,) + cs.shape), nc, axis=2)
            normals.append(n)
    N = np.concatenate(normals, axis=1)
    ok = np.any(N != 0.0, axis=2)
    off = (np.abs(np.einsum("bsd,bdg->bsg", N, Gb)).sum(axis=2)
           + np.abs(N * hc).sum(axis=2))
    nc = np.einsum("bsd,bd->bs", N, center)
    H = np.concatenate([N, -N], axis=1)
    h = np.concatenate([np.where(ok, nc + off, np.inf), np.where(ok, -nc + off, np.inf)], axis=1)
    return H, h


@dataclass(frozen=True)
class AvailableTwistSet:
    """Exact available twist set at B poses: ``{t : H t <= h, E t = 0}``.

    Attributes
    ----------
    poses : (B, 6)
    H : (B, S, n)
        Inequality rows (zero rows with ``h = +inf`` are unused), twist units m/s, rad/s.
    h : (B, S)
    E : (B, k, n)
        Orthonormal equality rows (k = 0 in task mode; n minus the rank of the driver's
        twist map in navigation mode).
    mode : Mode
    full_rank : (B,) bool
        A has full column rank (task mode); otherwise some twist direction is not
        determined by the joints and the set is unbounded along it.
    model : FirstOrderModel
    limits : MotionLimits
    """

    poses: np.ndarray
    H: np.ndarray
    h: np.ndarray
    E: np.ndarray
    mode: Mode
    full_rank: np.ndarray
    model: FirstOrderModel
    limits: MotionLimits

    def _twists(self, twist: Any) -> np.ndarray:
        n = self.H.shape[2]
        t = as_array(twist, "twist")
        if t.ndim not in (1, 2) or t.shape[-1] != n or (t.ndim == 2 and
                                                         t.shape[0] not in (1, self.H.shape[0])):
            raise InvalidInputError("twist", f"must have {n} components (v then w), one twist "
                                             f"or one per pose")
        return np.broadcast_to(t, (self.H.shape[0], n))

    def contains(self, twist: Any, tol: float = 1e-9) -> np.ndarray:
        """Whether twists ``(n,)`` or ``(B, n)`` lie in the set -> (B,) bool; ``tol`` is an
        absolute slack in m/s (rad/s)."""
        t = self._twists(twist)
        ok = np.all(np.einsum("bsn,bn->bs", self.H, t) <= self.h + tol, axis=1)
        if self.E.shape[1]:
            ok &= np.all(np.abs(np.einsum("bkn,bn->bk", self.E, t)) <= tol, axis=1)
        return ok

    def margin(self, twist: Any) -> np.ndarray:
        """Signed distance-like margin ``min_s (h_s - H_s t)`` (m/s, rad/s mixed) of twists
        to the set boundary, (B,); negative when the twist is not available (equality
        violations count as ``-|E t|``)."""
        t = self._twists(twist)
        m = np.min(self.h - np.einsum("bsn,bn->bs", self.H, t), axis=1)
        if self.E.shape[1]:
            m = np.minimum(m, -np.abs(np.einsum("bkn,bn->bk", self.E, t)).max(axis=1))
        return m


def available_twist_set(robot: CableRobot, poses: Any, limits: MotionLimits | None = None,
                        mode: str = "task", moving: Sequence[str] | None = None
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
        See :func:`resolve_mode`. ``mode="task", moving=()`` fixes every base.

    Returns
    -------
    AvailableTwistSet
        Task mode: ``{t : A t = B q_dot, q_lo <= q_dot <= q_hi}`` as ``H = H_Z A``,
        ``h = h_Z`` with ``(H_Z, h_Z)`` the facets of the joint-space zonotope ``B box``.
        Navigation mode: ``{Ad_P J_d q_dot_d : q_dot_d in box}``.
    """
    limits = fastkit_motion_limits() if limits is None else limits
    fom = first_order_model(robot, poses, mode, moving)
    lo, hi = joint_bounds(robot, limits, fom.mode)
    Bn, m, n = fom.A.shape
    c = 0.5 * (lo + hi)
    half = 0.5 * (hi - lo)
    if fom.mode.kind == "task":
        keep = half > 0
        center = np.einsum("bmq,q->bm", fom.B, c)
        nb = fom.n_base_joints
        if np.all(keep[nb:]):
            kb = keep[:nb]
            Hz, hz = _facets_base_and_identity(center, fom.B[:, :, :nb][:, :, kb] * half[:nb][kb],
                                               half[nb:])
        else:
            Hz, hz = zonotope_hrep(center, fom.B[:, :, keep] * half[keep])
        H = np.einsum("bsm,bmn->bsn", Hz, fom.A)
        nrm = np.linalg.norm(H, axis=2)
        use = nrm > 1e-12
        H = np.where(use[..., None], H / np.where(use, nrm, 1.0)[..., None], 0.0)
        h = np.where(use, hz / np.where(use, nrm, 1.0), np.where(hz >= 0, np.inf, -np.inf))
        sv = np.linalg.svd(fom.A, compute_uv=False)
        full = sv[:, -1] > 1e-9 * sv[:, 0]
        E = np.zeros((Bn, 0, n))
    else:
        # Zonotope {M q : q in box} of the driver base, described in its span: coordinates
        # y = U_r^T t, facets from zonotope_hrep in R^r, equality rows U_perp^T t = 0.
        M = fom.base_twists[:, fom.mode.moving[0]]                           # (B, n, 3)
        U, S, _ = np.linalg.svd(M, full_matrices=True)
        r = int(np.sum(S[0] > 1e-9 * S[0, 0]))
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
        E = np.swapaxes(U[:, :, r:], 1, 2)
        full = np.ones(Bn, dtype=bool)
    return AvailableTwistSet(fom.poses, H, h, E, fom.mode, full, fom, limits)


@dataclass(frozen=True)
class TwistCapacities:
    """Largest pure platform velocity along each axis (FASTKIT Fig. 13), per pose.

    ``positive[b, k]`` is the largest ``s >= 0`` with ``s e_k`` in the ATS (the other five
    twist components zero), ``negative`` the same along ``-e_k``: m/s for ``vx, vy, vz``,
    rad/s for ``wx, wy, wz``. ``feasible`` (B, n, 2) says whether ``s = 0`` itself is
    available (False when the limits exclude standing still); ``inf`` marks an
    unbounded direction (A rank-deficient).
    """

    positive: np.ndarray
    negative: np.ndarray
    feasible: np.ndarray
    labels: tuple[str, ...]
    mode: Mode


def twist_capacities(robot: CableRobot, poses: Any, limits: MotionLimits | None = None,
                     mode: str = "task", moving: Sequence[str] | None = None,
                     method: str = "hrep") -> TwistCapacities:
    """Axis twist capacities (Fig. 13) at poses.

    ``method="hrep"`` shoots rays in the exact H-representation (closed form, batched);
    ``method="lp"`` solves ``max s`` s.t. ``A (s e) = B q_dot`` (task mode) or
    ``s e = Ad_P J q_dot`` (navigation), ``q_lo <= q_dot <= q_hi``, with HiGHS, one LP per
    pose and direction (reference formulation over joint rates).
    """
    if method not in ("hrep", "lp"):
        raise InvalidInputError("method", "must be 'hrep' or 'lp'")
    limits = fastkit_motion_limits() if limits is None else limits
    if method == "lp":
        return _capacities_lp(robot, poses, limits, mode, moving)
    ats = available_twist_set(robot, poses, limits, mode, moving)
    Bn, S, n = ats.H.shape
    pos = np.zeros((Bn, n))
    neg = np.zeros((Bn, n))
    feas = np.zeros((Bn, n, 2), dtype=bool)
    for k in range(n):
        for sgn, out, col in ((1.0, pos, 0), (-1.0, neg, 1)):
            c = sgn * ats.H[:, :, k]
            with np.errstate(divide="ignore", invalid="ignore"):
                ratio = ats.h / c
            hi_s = np.min(np.where(c > 1e-12, ratio, np.inf), axis=1)
            lo_s = np.max(np.where(c < -1e-12, ratio, -np.inf), axis=1)
            zero_ok = np.all((np.abs(c) > 1e-12) | (ats.h >= -1e-12), axis=1)
            if ats.E.shape[1]:
                along = np.abs(ats.E[:, :, k]).max(axis=1) <= 1e-9
            else:
                along = np.ones(Bn, dtype=bool)
            f = zero_ok & (hi_s >= np.maximum(lo_s, 0.0) - 1e-12)
            val = np.where(along, np.maximum(hi_s, 0.0), 0.0)
            out[:, k] = np.where(f, val, 0.0)
            feas[:, k, col] = f
    return TwistCapacities(pos, neg, feas, TWIST_LABELS[:n], ats.mode)


def _capacities_lp(robot, poses, limits, mode, moving) -> TwistCapacities:
    fom = first_order_model(robot, poses, mode, moving)
    lo, hi = joint_bounds(robot, limits, fom.mode)
    Bn, m, n = fom.A.shape
    pos = np.zeros((Bn, n))
    neg = np.zeros((Bn, n))
    feas = np.zeros((Bn, n, 2), dtype=bool)
    nq = lo.size
    bounds = [(0.0, None)] + list(zip(lo, hi))
    for b in range(Bn):
        if fom.mode.kind == "task":
            L, Rm = fom.A[b], fom.B[b]                       # A (s e) - B q = 0
        else:
            L, Rm = np.eye(n), fom.base_twists[b, fom.mode.moving[0]]
        for k in range(n):
            for sgn, out, col in ((1.0, pos, 0), (-1.0, neg, 1)):
                Aeq = np.hstack([sgn * L[:, k:k + 1], -Rm])
                cost = np.zeros(1 + nq)
                cost[0] = -1.0
                sol = linprog(cost, A_eq=Aeq, b_eq=np.zeros(Aeq.shape[0]), bounds=bounds,
                              method="highs")
                if sol.status == 0:
                    out[b, k] = sol.x[0]
                    feas[b, k, col] = True
                elif sol.status == 3:
                    out[b, k] = np.inf
                    feas[b, k, col] = True
    return TwistCapacities(pos, neg, feas, TWIST_LABELS[:n], fom.mode)


def support(ats: AvailableTwistSet, direction: Any, k: int = 0) -> float:
    """Support function ``max d . t`` over the ATS of pose ``k`` (LP over the H-rep, HiGHS);
    ``inf`` when unbounded, ``-inf`` when the set is empty."""
    d = as_array(direction, "direction", shape=(ats.H.shape[2],))
    keep = np.isfinite(ats.h[k])
    if np.any(ats.h[k] == -np.inf):
        return -np.inf
    E = ats.E[k]
    sol = linprog(-d, A_ub=ats.H[k][keep], b_ub=ats.h[k][keep],
                  A_eq=E if E.shape[0] else None, b_eq=np.zeros(E.shape[0]) if E.shape[0]
                  else None, bounds=[(None, None)] * d.size, method="highs")
    if sol.status == 3:
        return np.inf
    if sol.status != 0:
        return -np.inf
    return float(-sol.fun)

