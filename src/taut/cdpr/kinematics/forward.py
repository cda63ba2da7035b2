"""Forward kinematics of a CDPR: platform poses from cable lengths, for fixed frames and for
mobile bases standing anywhere (FASTKIT paper, §3: the inverse of the geometric model whose
derivative is eq. 1).

Method: batched Levenberg-Marquardt least squares on the length equations
``|b_i - p - R a_i| = l_i``, with the pose updated on SE(3) (``p += dp``,
``R <- exp([dtheta]) R``) and the Jacobian the parallel Jacobian ``A = -[u_i, r_i x u_i]``
of eq. 1. Every sample starts from ``initial_guess`` (default: centre of the desired
workspace, level); samples that do not converge are restarted from seeded random poses in
the frame box. A result is ``success`` only when the largest length residual is below
``taut.cdpr._tol.FK_RESIDUAL_TOL``; inconsistent lengths (no pose has them) end as
``not_converged`` with the least-squares pose and its residual, never as a silent answer.
With ``all_solutions=True`` every start is run and distinct zero-residual poses are counted
(``n_solutions``): more than one means the lengths admit several assembly modes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from ..._validate import as_array
from ...errors import InvalidInputError
from ._bases import as_base_poses, moved_exits
from .._tol import (FK_DAMPING_MAX, FK_DAMPING_MIN, FK_DAMPING_START, FK_MAX_ITER, FK_POLISH_TOL,
    FK_RESIDUAL_TOL, FK_SAME_SOLUTION, SO3_SMALL_ANGLE, SO3_TAYLOR_SQ)
from .._batching import unbatch
from .cables import as_poses, rotation_matrices
from ..model.robot import CableRobot
from ..._validate import as_count, as_flag, require_instance
from ..._repr import CompactRepr

__all__ = ["CableFKResult", "cable_forward_kinematics"]


# phi @ _SKEW_GEN is the row-major flattening of [phi]x.
_SKEW_GEN = np.zeros((3, 9))
_SKEW_GEN[2, 1], _SKEW_GEN[1, 2], _SKEW_GEN[0, 5] = -1.0, 1.0, -1.0
_SKEW_GEN[2, 3], _SKEW_GEN[1, 6], _SKEW_GEN[0, 7] = 1.0, -1.0, 1.0
_EYE3 = np.eye(3)


def so3_exp(phi: np.ndarray) -> np.ndarray:
    """Rotation matrices ``exp([phi]x)`` (B, 3, 3) of rotation vectors ``phi`` (B, 3), rad
    (Rodrigues' formula, series near zero)."""
    th2 = (phi * phi).sum(axis=1)
    if th2.max() < SO3_TAYLOR_SQ:         # Taylor series, error < th^6 / 5040 < 1e-22
        a = 1.0 - th2 / 6.0 * (1.0 - th2 / 20.0)
        b = 0.5 - th2 / 24.0 * (1.0 - th2 / 30.0)
    else:
        th = np.sqrt(th2)
        small = th < SO3_SMALL_ANGLE
        a = np.where(small, 1.0 - th2 / 6.0, np.sin(th) / np.where(small, 1.0, th))
        b = np.where(small, 0.5 - th2 / 24.0, (1.0 - np.cos(th)) / np.where(small, 1.0, th2))
    K = (phi @ _SKEW_GEN).reshape(-1, 3, 3)
    return _EYE3 + a[:, None, None] * K + b[:, None, None] * (K @ K)


def rpy_from_matrices(R: np.ndarray) -> np.ndarray:
    """``(roll, pitch, yaw)`` (B, 3), rad, of rotations ``R = Rz(yaw) Ry(pitch) Rx(roll)``
    (B, 3, 3); the inverse of :func:`taut.cdpr.rotation_matrices` for |pitch| < pi/2."""
    pitch = -np.arcsin(np.clip(R[:, 2, 0], -1.0, 1.0))
    roll = np.arctan2(R[:, 2, 1], R[:, 2, 2])
    yaw = np.arctan2(R[:, 1, 0], R[:, 0, 0])
    return np.column_stack([roll, pitch, yaw])


@dataclass(frozen=True, repr=False)
class CableFKResult(CompactRepr):
    """Poses for a batch of cable-length vectors (one vector (m,): the leading B axis of
    every array dropped, ``success`` a bool, ``status`` a str).

    Attributes
    ----------
    poses : (B, 6)
        ``(x, y, z, roll, pitch, yaw)``, m and rad (the least-squares pose where not
        converged).
    residual : (B,)
        Largest ``|L_i(pose) - l_i|``, m.
    iterations : (B,)
        Levenberg-Marquardt iterations of the start that produced the pose.
    n_solutions : (B,)
        Distinct zero-residual poses found (only counted with ``all_solutions``; else 1
        where converged, 0 elsewhere).
    success : (B,) bool
    status : (B,) str
        ``"ok"`` or ``"not_converged"``.
    message : str
    """

    poses: np.ndarray
    residual: np.ndarray
    iterations: np.ndarray
    n_solutions: np.ndarray
    success: np.ndarray
    status: np.ndarray
    message: str


def _solve(exits: np.ndarray, attach: np.ndarray, lengths: np.ndarray, p: np.ndarray,
           R: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Batched LM from (p, R); returns p, R, residual (B,), iterations (B,)."""
    B = p.shape[0]
    lam = np.full(B, FK_DAMPING_START)
    it = np.zeros(B, dtype=int)

    def resid(p: np.ndarray, R: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        r = np.einsum("bij,mj->bmi", R, attach)
        vec = exits - p[:, None, :] - r
        L = np.linalg.norm(vec, axis=2)
        return L - lengths, vec / L[:, :, None], r

    e, u, r = resid(p, R)
    cost = np.einsum("bm,bm->b", e, e)
    last = np.full(B, np.inf)
    for _ in range(FK_MAX_ITER):
        # Keep polishing past the success tolerance until the step stalls: the suspended
        # FASTKIT geometry amplifies length residuals ~500x into the pose.
        act = (np.abs(e).max(axis=1) > FK_POLISH_TOL) & (last > FK_POLISH_TOL)
        if not np.any(act):
            break
        J = -np.concatenate([u, np.cross(r, u)], axis=2)        # (B, m, 6), eq. 1
        H = np.einsum("bmi,bmj->bij", J, J)
        g = np.einsum("bmi,bm->bi", J, e)
        Hd = H + lam[:, None, None] * (np.eye(6) * (1.0 + np.einsum("bii->bi", H)[:, None, :]))
        step = -np.linalg.solve(Hd, g[..., None])[..., 0]
        step[~act] = 0.0
        last = np.where(act, np.abs(step).max(axis=1), last)
        p_new = p + step[:, :3]
        R_new = so3_exp(step[:, 3:]) @ R
        e_new, u_new, r_new = resid(p_new, R_new)
        c_new = np.einsum("bm,bm->b", e_new, e_new)
        good = act & np.isfinite(c_new) & (c_new <= cost)
        p = np.where(good[:, None], p_new, p)
        R = np.where(good[:, None, None], R_new, R)
        e = np.where(good[:, None], e_new, e)
        u = np.where(good[:, None, None], u_new, u)
        r = np.where(good[:, None, None], r_new, r)
        cost = np.where(good, c_new, cost)
        lam = np.where(good, np.maximum(lam / 10.0, FK_DAMPING_MIN),
                       np.minimum(lam * 10.0, FK_DAMPING_MAX))
        it += act
    return p, R, np.abs(e).max(axis=1), it


def _default_start(robot: CableRobot) -> np.ndarray:
    box = robot.desired_workspace if robot.desired_workspace is not None else robot.bounds
    return np.r_[0.5 * (box[0] + box[1]), 0.0, 0.0, 0.0]


def cable_forward_kinematics(robot: CableRobot, lengths: ArrayLike, *,
                             base_poses: ArrayLike | None = None,
                             initial_guess: ArrayLike | None = None, restarts: int = 8,
                             seed: int = 0, all_solutions: bool = False) -> CableFKResult:
    """Platform poses that give the cable lengths (the inverse of
    :func:`taut.cdpr.cable_state`).

    Parameters
    ----------
    robot : CableRobot
    lengths : array_like (m,) or (B, m)
        Straight-line cable lengths, m (> 0).
    base_poses : array_like (K, 3) or (B, K, 3), optional
        ``(x, y, theta)`` of every base (default: the model's poses); mobile bases only move.
    initial_guess : array_like (6,) or (B, 6), optional
        Start pose(s); default the centre of the desired workspace, level.
    restarts : int
        Seeded random restarts for samples that did not converge, alternately near the best
        pose so far (0.05 m, 0.1 rad) and anywhere in the frame box (|angles| < 0.3 rad);
        with ``all_solutions``, frame-box restarts for every sample.
    seed : int
    all_solutions : bool
        Run every restart and count distinct solutions in ``n_solutions``.

    Returns
    -------
    CableFKResult
        Arrays with a leading axis of B for lengths (B, m); without it for lengths (m,).

    Examples
    --------
    >>> from taut.io.cdpr_model import load_cdpr_model
    >>> from taut.cdpr import cable_state
    >>> robot = load_cdpr_model("fastkit")
    >>> pose = [0.4, 0.05, 1.1, 0.02, -0.03, 0.1]
    >>> fk = cable_forward_kinematics(robot, cable_state(robot, pose).lengths)
    >>> fk.success, bool(np.allclose(fk.poses, pose, atol=1e-9))
    (True, True)
    """
    require_instance(robot, CableRobot, "robot")
    as_count(restarts, "restarts", maximum=1000)
    as_count(seed, "seed")
    all_solutions = as_flag(all_solutions, "all_solutions")
    lengths_arr = as_array(lengths, "lengths")
    single = lengths_arr.ndim == 1
    if single:
        lengths_arr = lengths_arr[None]
    if lengths_arr.ndim != 2 or lengths_arr.shape[1] != robot.m:
        raise InvalidInputError("lengths", f"must have shape ({robot.m},) or (B, {robot.m})")
    if np.any(lengths_arr <= 0):
        raise InvalidInputError("lengths", "cable lengths must be positive")
    if isinstance(restarts, bool) or int(restarts) != restarts or restarts < 0:
        raise InvalidInputError("restarts", f"must be a non-negative integer, got {restarts}")
    B = lengths_arr.shape[0]
    if base_poses is None:
        exits = np.broadcast_to(robot.exits_world, (B, robot.m, 3))
    else:
        bp = as_base_poses(robot, base_poses)
        exits = np.broadcast_to(moved_exits(robot, bp), (B, robot.m, 3))
    start = _default_start(robot) if initial_guess is None else initial_guess
    x0 = as_poses(robot, start, "initial_guess", check_bounds=False)
    if x0.shape[0] not in (1, B):
        raise InvalidInputError("initial_guess", f"must be one pose (6,) or ({B}, 6), one per "
                                                 "sample")
    x0 = np.broadcast_to(x0, (B, 6))
    p, R, res, it = _solve(exits, robot.attach_local, lengths_arr, x0[:, :3].copy(),
                           rotation_matrices(x0[:, 3:]))
    sols = [(p, R, res)]
    rng = np.random.default_rng(seed)
    lo, hi = robot.bounds
    for j in range(int(restarts)):
        todo = np.arange(B) if all_solutions else np.nonzero(res > FK_RESIDUAL_TOL)[0]
        if todo.size == 0:
            break
        if j % 2 == 0 and not all_solutions:     # near the best pose: escapes a shallow trap
            ps = p[todo] + rng.normal(0.0, 0.05, (todo.size, 3))
            Rs = so3_exp(rng.normal(0.0, 0.1, (todo.size, 3))) @ R[todo]
        else:                                    # anywhere in the frame box
            ps = rng.uniform(lo, hi, (todo.size, 3))
            Rs = rotation_matrices(rng.uniform(-0.3, 0.3, (todo.size, 3)))
        p2, R2, r2, i2 = _solve(exits[todo], robot.attach_local, lengths_arr[todo], ps, Rs)
        if all_solutions:
            pf, Rf = np.full_like(p, np.nan), np.full_like(R, np.nan)
            pf[todo], Rf[todo] = p2, R2
            rf = np.full(B, np.inf)
            rf[todo] = r2
            sols.append((pf, Rf, rf))
        better = r2 < res[todo]
        k = todo[better]
        p[k], R[k], res[k], it[k] = p2[better], R2[better], r2[better], i2[better]
    ok = res <= FK_RESIDUAL_TOL
    n_sol = ok.astype(int)
    if all_solutions:
        n_sol = _count_distinct(sols, B)
    status = np.where(ok, "ok", "not_converged")
    msg = (f"{int(ok.sum())} of {B} length vectors solved to {FK_RESIDUAL_TOL:g} m"
           + ("" if ok.all() else f"; worst residual {float(res.max()):.3g} m "
              "(lengths no pose can have, or no start in the basin)"))
    poses = np.column_stack([p, rpy_from_matrices(R)])
    return unbatch(CableFKResult(poses, res, it, n_sol, ok, status, msg),
                   ("poses", "residual", "iterations", "n_solutions", "success", "status"),
                   single)


def _count_distinct(sols: list[tuple[np.ndarray, np.ndarray, np.ndarray]], B: int
                    ) -> np.ndarray:
    """Number of distinct converged poses per sample over all starts."""
    out = np.zeros(B, dtype=int)
    for b in range(B):
        found: list[tuple[np.ndarray, np.ndarray]] = []
        for p, R, r in sols:
            if not r[b] <= FK_RESIDUAL_TOL:
                continue
            if not any(np.linalg.norm(p[b] - q) < FK_SAME_SOLUTION
                       and np.abs(R[b] - S).max() < FK_SAME_SOLUTION for q, S in found):
                found.append((p[b], R[b]))
        out[b] = len(found)
    return out
