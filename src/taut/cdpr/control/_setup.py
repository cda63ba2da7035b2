"""Set-up of a control simulation (private to :mod:`taut.cdpr.control.simulate`): base motions, the
nominal reference geometry and tensions every controller uses (:class:`ControlContext`), and
the wrench-feasibility check of the reference.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any, Final

import numpy as np

from ..._validate import as_array, as_positive
from ...errors import InfeasiblePoseError, InvalidInputError
from ..kinematics._bases import as_base_poses, moved_exits
from .._tol import INTERP_TENSION_TOL
from .controllers import ControlContext
from .dynamics import DynamicsModel
from .plant import moving_body
from ..kinematics.cables import gravity_wrench, rotation_matrices
from ..model.robot import CableRobot
from .references import Reference
from ..statics.tension import distribute_tensions
from ..._repr import CompactRepr

__all__ = ["BaseMotion", "drive_tensions", "DRIVE_TENSION_METHOD"]

#: Base-motion runs distribute tensions on a robot rebuilt every this many control steps and
#: interpolate in between (then restore the wrench balance exactly with W+): a base moving
#: at FASTKIT's 0.2 m/s limit moves 4 mm in 20 ms.
_BASE_STRIDE = 20

#: Fixed bases: reference tensions by the closed form every this many control steps (10 ms),
#: interpolated in between (tensions of a 1 m/s quintic move change by < 0.5 N in 10 ms).
_TENSION_STRIDE = 10


@dataclass(frozen=True, repr=False)
class BaseMotion(CompactRepr):
    """Poses of every base over time (FASTKIT task mode: the active base moves, eq. 8).

    Parameters
    ----------
    times : (S,)
        s, strictly increasing.
    poses : (S, K, 3)
        ``(x, y, theta)`` of every base, m and rad; held at the ends.
    """

    times: Any
    poses: Any

    def __post_init__(self) -> None:
        t = as_array(self.times, "base_motion.times", ndim=1)
        P = as_array(self.poses, "base_motion.poses", ndim=3)
        if P.shape[0] != t.size or P.shape[2] != 3 or t.size < 2:
            raise InvalidInputError("base_motion.poses", "must have shape (S, K, 3) for S >= 2 "
                                                         "times")
        if np.any(np.diff(t) <= 0):
            raise InvalidInputError("base_motion.times", "must be strictly increasing")
        object.__setattr__(self, "times", t)
        object.__setattr__(self, "poses", P)

    @classmethod
    def line(cls, robot: CableRobot, base: str, displacement: Any, duration: float,
             start: float = 0.0, samples: int = 200) -> "BaseMotion":
        """One base moving by ``displacement`` = (dx, dy, dtheta) (m, rad) along a quintic
        profile from ``start`` for ``duration`` s, the others standing still."""
        names = [b.name for b in robot.bases]
        if base not in names:
            raise InvalidInputError("base", f"no base named {base!r} (bases: "
                                            f"{', '.join(names)})")
        duration = as_positive(duration, "duration")
        d = as_array(displacement, "displacement", shape=(3,))
        tau = np.linspace(0.0, 1.0, samples)
        s = 10 * tau**3 - 15 * tau**4 + 6 * tau**5
        P = np.repeat(np.array([b.pose for b in robot.bases])[None], samples, axis=0)
        P[:, names.index(base)] += s[:, None] * d
        return cls(start + duration * tau, P)

    def at(self, times: np.ndarray) -> np.ndarray:
        """Base poses (T, K, 3) at ``times`` (linear interpolation)."""
        flat = self.poses.reshape(len(self.times), -1)
        out = np.column_stack([np.interp(times, self.times, flat[:, j])
                               for j in range(flat.shape[1])])
        return out.reshape(len(times), *self.poses.shape[1:])


@dataclass(frozen=True)
class RefGeometry:
    """Nominal exits (T, m, 3) and their velocities, base poses (T, K, 3)."""

    exits: np.ndarray
    exit_vel: np.ndarray
    base_poses: np.ndarray
    moving: bool


def reference_geometry(robot: CableRobot, times: np.ndarray, base_motion: BaseMotion | None
                       ) -> RefGeometry:
    """Exits of the nominal robot at the control instants."""
    T = len(times)
    if base_motion is None:
        bp = np.repeat(np.array([b.pose for b in robot.bases])[None], T, axis=0)
        ex = np.broadcast_to(robot.exits_world, (T, robot.m, 3))
        return RefGeometry(ex, np.zeros_like(ex), bp, False)
    if not isinstance(base_motion, BaseMotion):
        raise InvalidInputError("base_motion", "must be a taut.cdpr.BaseMotion")
    if base_motion.poses.shape[1] != len(robot.bases):
        raise InvalidInputError("base_motion.poses", f"the model has {len(robot.bases)} "
                                                     "bases")
    bp = as_base_poses(robot, base_motion.at(times), "base_motion.poses")
    ex = moved_exits(robot, bp)
    vel = np.gradient(ex, times, axis=0) if T > 1 else np.zeros_like(ex)
    return RefGeometry(ex, vel, bp, True)


def _inertial_wrench(mass: float, com: np.ndarray, inertia: np.ndarray, vel: np.ndarray,
                     acc: np.ndarray) -> np.ndarray:
    """``-[M a_c; I alpha + w x I w + c x M a_c]`` (T, 6) about P: the d'Alembert wrench of
    the reference motion, passed to the tension distribution as an external wrench."""
    w, alpha = vel[:, 3:], acc[:, 3:]
    ac = acc[:, :3] + np.cross(alpha, com) + np.cross(w, np.cross(w, com))
    f = mass * ac
    Iw = (inertia @ w[:, :, None])[:, :, 0]
    m = (inertia @ alpha[:, :, None])[:, :, 0] + np.cross(w, Iw) + np.cross(com, f)
    return -np.hstack([f, m])


def _tensions(robot: CableRobot, geo: RefGeometry, P: np.ndarray, w_ext: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray]:
    """Reference tensions (T, m) and feasibility (T,): the closed form (fixed bases; tipping
    is monitored, not imposed) or :func:`drive_tensions` (moving bases: tipping imposed).

    Computed every ``_TENSION_STRIDE`` steps (fixed bases: one batched call; moving bases: a
    robot rebuilt every ``_BASE_STRIDE`` steps) and linearly interpolated; the caller then
    restores the wrench balance exactly with ``W+``. Steps whose interpolated tensions leave
    the limits by more than the interpolation tolerance are recomputed exactly."""
    T = len(P)
    stride = _BASE_STRIDE if geo.moving else _TENSION_STRIDE
    idx = np.unique(np.r_[np.arange(0, T, stride), T - 1])
    if not geo.moving:
        res = distribute_tensions(robot, P[idx], "closed_form", external_wrench=w_ext[idx],
                                  tipping=False)
        ts, ok_s = res.tensions, res.success
    else:
        ts, ok_s = drive_tensions(robot, geo.base_poses[idx], P[idx], w_ext[idx])[:2]
    t = np.column_stack([np.interp(np.arange(T), idx, ts[:, j]) for j in range(robot.m)])
    ok = np.interp(np.arange(T), idx, ok_s.astype(float)) > 0.999
    return t, ok


def _exact_where_needed(robot: CableRobot, geo: RefGeometry, P: np.ndarray,
                        w_ext: np.ndarray, t: np.ndarray, ok: np.ndarray
                        ) -> tuple[np.ndarray, np.ndarray]:
    """Recompute exactly (fixed bases) the steps whose interpolated, polished tensions are
    outside the limits."""
    bad = np.any((t < robot.t_min - INTERP_TENSION_TOL) | (t > robot.t_max + INTERP_TENSION_TOL), axis=1) & ok
    if geo.moving or not bad.any():
        return t, ok & ~bad if geo.moving else ok
    res = distribute_tensions(robot, P[bad], "closed_form", external_wrench=w_ext[bad],
                              tipping=False)
    t = t.copy()
    t[bad] = res.tensions
    ok = ok.copy()
    ok[bad] = res.success
    return t, ok


#: Tension distribution of runs whose bases move: the exact min-norm QP, which imposes the
#: tipping limits (the closed form only checks them) and is continuous along a motion.
DRIVE_TENSION_METHOD: Final = "qp_min_norm"


def drive_tensions(robot: CableRobot, base_poses: np.ndarray, poses: np.ndarray,
                   w_ext: np.ndarray | None = None
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Tensions (S, m), success (S,) and edge moments (S, E) of the platform ``poses``
    (S, 6) with the bases at ``base_poses`` (S, K, 3), by :data:`DRIVE_TENSION_METHOD` with
    the tipping limits of ``robot``'s bases as they stand (wheels, or stabilisers deployed)
    imposed: one :func:`distribute_tensions` call per sample (each has its own geometry)."""
    t_s, o_s, m_s = [], [], []
    for i in range(len(poses)):
        r1 = distribute_tensions(_robot_at(robot, base_poses[i]), poses[i],
                                 DRIVE_TENSION_METHOD, tipping=True,
                                 external_wrench=None if w_ext is None else w_ext[i])
        t_s.append(r1.tensions)                   # one pose: (m,)
        o_s.append(r1.success)
        m_s.append(r1.tipping_moments)
    return np.array(t_s), np.array(o_s, dtype=bool), np.array(m_s)


def _robot_at(robot: CableRobot, base_poses: np.ndarray) -> CableRobot:
    bases = tuple(replace(b, exit_points=dict(b.exit_points), pose=base_poses[k])
                  for k, b in enumerate(robot.bases))
    return replace(robot, bases=bases)


def _check_feasible(robot: CableRobot, geo: RefGeometry, times: np.ndarray, P: np.ndarray,
                    w_ext: np.ndarray, t: np.ndarray, ok: np.ndarray) -> np.ndarray:
    """Confirm closed-form failures with an exact LP (moving bases: recompute with
    :func:`drive_tensions`); raise at the first pose no tensions can hold (moving bases: with
    every base upright). Returns tensions with exact ones where only the first try failed."""
    t = t.copy()
    if geo.moving:                    # exact tipping-aware tensions where interpolation failed
        bad = np.nonzero(~ok)[0]
        t[bad], ok_b, _ = drive_tensions(robot, geo.base_poses[bad], P[bad], w_ext[bad])
        if ok_b.all():
            return t
        j = int(bad[~ok_b][0])
        raise InfeasiblePoseError(
            "base_motion", f"no tension distribution holds the platform at "
            f"{np.round(P[j], 4).tolist()} and keeps every base upright (tipping limits of "
            f"the bases as they stand: wheels unless stabilisers are deployed) at t = "
            f"{times[j]:.3f} s, base poses {np.round(geo.base_poses[j], 4).tolist()}; "
            "taut.cdpr.plan_base_drive says where a drive is feasible")
    for i in np.nonzero(~ok)[0]:
        r = robot if not geo.moving else _robot_at(robot, geo.base_poses[i])
        res = distribute_tensions(r, P[i], "lp_min_max", external_wrench=w_ext[i],
                                  tipping=False)
        if not res.success:
            raise InfeasiblePoseError(
                "reference", f"leaves the wrench-feasible workspace at t = {times[i]:.3f} s, "
                f"pose {np.round(P[i], 4).tolist()}: no tensions in [t_min, t_max] balance "
                "gravity and the reference accelerations")
        t[i] = res.tensions
    return t


def build_context(robot: CableRobot, dyn: DynamicsModel, times: np.ndarray, ref: Reference,
                  geo: RefGeometry, dt: float) -> ControlContext:
    """The nominal :class:`ControlContext` at ``times``; raises InfeasiblePoseError when the
    reference leaves the wrench-feasible workspace."""
    P, V, A = ref.sample(times)
    R = rotation_matrices(P[:, 3:])
    M = robot.platform.mass + robot.payload.mass
    c_b, I_b = moving_body(robot, np.ones(1))
    c_loc, I_loc = c_b[0], I_b[0]
    com = R @ c_loc
    inertia = R @ I_loc @ np.swapaxes(R, 1, 2)
    w_ext = _inertial_wrench(M, com, inertia, V, A)
    r = robot.attach_local @ np.swapaxes(R, 1, 2)                 # (T, m, 3)
    vec = geo.exits - P[:, None, :3] - r
    L = np.linalg.norm(vec, axis=2)
    u = vec / L[..., None]
    W = np.concatenate([np.swapaxes(u, 1, 2), np.swapaxes(np.cross(r, u), 1, 2)], axis=1)
    t, ok = _tensions(robot, geo, P, w_ext)
    # W+ = W^T (W W^T)^-1 (W has full row rank on a wrench-feasible reference)
    W_pinv = np.swapaxes(W, 1, 2) @ np.linalg.inv(W @ np.swapaxes(W, 1, 2))
    w_req = -(gravity_wrench(robot, R) + w_ext)
    resid = w_req - (W @ t[:, :, None])[:, :, 0]
    t = t + (W_pinv @ resid[:, :, None])[:, :, 0]
    t, ok = _exact_where_needed(robot, geo, P, w_ext, t, ok)
    if not ok.all():
        t = _check_feasible(robot, geo, times, P, w_ext, t, ok)
    # Eq. 8: l_dot = A t_P - B_b q_dot_b = u . (e_dot - v_attach).
    va = V[:, None, :3] + np.cross(V[:, None, 3:], r)
    L_dot = (u * (geo.exit_vel - va)).sum(axis=2)
    EA, rho = dyn.cable_stiffness, dyn.routing(robot.m)
    L0 = dyn.unstretched_length(L, t, rho)
    t_dot = np.gradient(t, times, axis=0) if len(times) > 2 else np.zeros_like(t)
    L0_dot = EA * L_dot / (EA + t) - EA * (L + rho) * t_dot / (EA + t) ** 2
    L0_ddot = np.gradient(L0_dot, times, axis=0) if len(times) > 2 else np.zeros_like(t)
    CT = np.zeros((len(com), 3, 3))
    CT[:, 1, 0], CT[:, 2, 0], CT[:, 2, 1] = -com[:, 2], com[:, 1], -com[:, 0]
    CT[:, 0, 1], CT[:, 0, 2], CT[:, 1, 2] = com[:, 2], -com[:, 1], com[:, 0]
    return ControlContext(dyn, dt, P, V, A, W, W_pinv, t, L0, L0_dot, L0_ddot, com, CT,
                          inertia, R, M, robot.t_min, robot.t_max,
                          np.ascontiguousarray(geo.exits), np.ascontiguousarray(geo.exit_vel),
                          np.array(robot.attach_local, dtype=float), robot, c_loc, I_loc)
