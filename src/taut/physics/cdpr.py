"""Mobile cable-driven parallel robots in MuJoCo: do the bases stay down?

The platform is a free body; each cable is a spatial tendon from its exit site on a base
to its attachment site on the platform, pulled by a tendon actuator with the given
constant tension; each mobile base is a free body resting on its support polygon
(contact spheres at the wheels, and at the stabiliser feet when deployed) on a floor with
Coulomb friction. After :data:`~taut.physics._tol.CDPR_DURATION` seconds each base is
judged: ``"stays"``, ``"tips"`` (its vertical axis tilted) or ``"slides"`` (moved
without tipping, which FASTKIT's static tipping model, eqs. 21-23, does not cover).
SI units (m, kg, N, s).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from .._outcome import check_status
from .._validate import MAX_DURATION_S, as_array, as_bounded, as_positive
from ..cdpr import (CableRobot, TensionMethod, distribute_tensions, rotation_matrices,
                    tipping_moments)
from ..cdpr.kinematics.cables import as_poses
from ..errors import InvalidInputError, require_extra
from . import _tol
from .._repr import CompactRepr

__all__ = ["TippingCheck", "TippingGridCheck", "replay_tipping", "replay_tipping_grid"]


@dataclass(frozen=True, eq=False, repr=False)
class TippingCheck(CompactRepr):
    """Bases of a cable robot at one pose under given tensions, in MuJoCo and in taut.

    Attributes
    ----------
    verdicts : tuple of str
        Per base, robot order: ``"stays"``, ``"tips"``, ``"slides"`` or ``"fixed"``.
    tilt : ndarray, shape (n_bases,)
        Final tilt of each base's vertical axis, degrees.
    slip : ndarray, shape (n_bases,)
        Horizontal displacement of each base's origin, m.
    moments : ndarray, shape (E,)
        taut's edge moments :math:`m_{C_j}` (FASTKIT eqs. 21-23), N m.
    margin : float
        taut's tipping margin ``-max(moments)``, N m (> 0: taut says no base tips).
    taut_stays : bool
        taut's verdict: every moment <= 0.
    physics_stays : bool
        Every base stays (or is fixed) in the simulation.
    success, status, message
        ``success`` when both verdicts agree (status ``"ok"``, else ``"unverified"``).
    """

    verdicts: tuple[str, ...]
    tilt: np.ndarray
    slip: np.ndarray
    moments: np.ndarray
    margin: float
    taut_stays: bool
    physics_stays: bool
    success: bool
    status: str
    message: str


@dataclass(frozen=True, eq=False, repr=False)
class TippingGridCheck(CompactRepr):
    """:func:`replay_tipping` over a batch of poses, as arrays.

    ``verdicts`` (B, n_bases) of str, ``margin`` (B,), ``taut_stays`` / ``physics_stays``
    / ``feasible`` (B,) bool (``feasible``: tensions were found; other rows are NaN/False),
    ``success`` (B,) bool, ``status`` (B,) str, ``message`` one line.
    """

    poses: np.ndarray
    verdicts: np.ndarray
    margin: np.ndarray
    taut_stays: np.ndarray
    physics_stays: np.ndarray
    feasible: np.ndarray
    success: np.ndarray
    status: np.ndarray
    message: str


def _quat(R: np.ndarray) -> list[float]:
    import mujoco

    q = np.zeros(4)
    mujoco.mju_mat2Quat(q, np.ascontiguousarray(R).ravel())
    return q.tolist()


def _add_base(spec: Any, base: Any, k: int, friction: float) -> None:
    import mujoco

    x, y, th = base.pose
    body = spec.worldbody.add_body(name=f"base{k}", pos=[x, y, 0.0],
                                   quat=_quat(rotation_matrices(np.array([[0, 0, th]]))[0]))
    if base.mobile:
        # MuJoCo takes the larger friction of two touching geoms: feet and floor share it.
        body.add_joint(name=f"base{k}", type=mujoco.mjtJoint.mjJNT_FREE)
        poly = base.support_polygon
        ext = np.ptp(poly, axis=0)
        hz = max(2 * float(base.com[2]), 0.1)
        m = float(base.mass)
        body.mass = m
        body.ipos = base.com.tolist()
        body.inertia = [m * (ext[1] ** 2 + hz ** 2) / 12, m * (ext[0] ** 2 + hz ** 2) / 12,
                        m * (ext[0] ** 2 + ext[1] ** 2) / 12]
        body.explicitinertial = True
        for j, (px, py) in enumerate(poly):
            body.add_geom(name=f"foot{k}_{j}", type=mujoco.mjtGeom.mjGEOM_SPHERE,
                          size=[_tol.FOOT_RADIUS, 0, 0], pos=[px, py, _tol.FOOT_RADIUS],
                          mass=0.0, condim=3, friction=[friction, 0.005, 1e-4])
    for name, p in zip(base.exit_names, base.exit_local):
        body.add_site(name=f"exit{k}_{name}", pos=p.tolist())


def _build(robot: CableRobot, pose: np.ndarray, tensions: np.ndarray, friction: float
           ) -> tuple[Any, Any, list[int]]:
    """Compile the robot at ``pose`` with actuators set to ``tensions``."""
    import mujoco

    spec = mujoco.MjSpec()
    spec.modelname = "taut_cdpr"
    spec.option.timestep = _tol.CDPR_TIMESTEP
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.option.solver = mujoco.mjtSolver.mjSOL_NEWTON
    spec.option.gravity = robot.gravity.tolist()
    spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
    spec.worldbody.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0, 0, 1],
                            condim=3, friction=[friction, 0.005, 1e-4])
    for k, base in enumerate(robot.bases):
        _add_base(spec, base, k, friction)
    R = rotation_matrices(pose[None, 3:])[0]
    plat = spec.worldbody.add_body(name="platform", pos=pose[:3].tolist(), quat=_quat(R))
    mp, mq = robot.platform.mass, robot.payload.mass
    mass = max(mp + mq, _tol.MIN_BODY_MASS)
    com = (mp * robot.platform.com + mq * robot.payload.com) / mass
    inertia = np.array(robot.platform.inertia, dtype=float)
    for m_, c_ in ((mp, robot.platform.com), (mq, robot.payload.com)):
        d = c_ - com
        inertia = inertia + m_ * (d @ d * np.eye(3) - np.outer(d, d))
    inertia = inertia + _tol.MIN_BODY_INERTIA * np.eye(3)
    plat.mass = mass
    plat.ipos = com.tolist()
    plat.fullinertia = [inertia[0, 0], inertia[1, 1], inertia[2, 2],
                        inertia[0, 1], inertia[0, 2], inertia[1, 2]]
    plat.explicitinertial = True
    plat.add_joint(name="platform", type=mujoco.mjtJoint.mjJNT_FREE,
                   damping=mass / _tol.PLATFORM_DAMPING_TIME)
    for name, p in zip(robot.platform.attach_names, robot.platform.attach_local):
        plat.add_site(name=f"attach_{name}", pos=p.tolist())
    for i, c in enumerate(robot.cables):
        k = [b.name for b in robot.bases].index(c.base)
        ten = spec.add_tendon(name=f"cable{i}")
        ten.wrap_site(f"exit{k}_{c.exit}")
        ten.wrap_site(f"attach_{c.attachment}")
        # Motor on the tendon: a negative force shortens it (a cable pulls).
        spec.add_actuator(name=f"winch{i}", target=f"cable{i}",
                          trntype=mujoco.mjtTrn.mjTRN_TENDON, gainprm=[1.0] + [0.0] * 9)
    model = spec.compile()
    data = mujoco.MjData(model)
    data.ctrl[:] = -tensions
    mobile = [k for k, b in enumerate(robot.bases) if b.mobile]
    return model, data, mobile


def _judge(model: Any, data: Any, robot: CableRobot, mobile: list[int]
           ) -> tuple[tuple[str, ...], np.ndarray, np.ndarray]:
    verdicts, tilt, slip = [], np.zeros(len(robot.bases)), np.zeros(len(robot.bases))
    for k, base in enumerate(robot.bases):
        if k not in mobile:
            verdicts.append("fixed")
            continue
        b = model.body(f"base{k}").id
        zaxis = np.asarray(data.xmat[b]).reshape(3, 3)[:, 2]
        tilt[k] = float(np.degrees(np.arccos(np.clip(zaxis[2], -1.0, 1.0))))
        slip[k] = float(np.linalg.norm(np.asarray(data.xpos[b])[:2] - base.pose[:2]))
        if tilt[k] > _tol.TIP_ANGLE:
            verdicts.append("tips")
        elif slip[k] > _tol.SLIDE_DISTANCE:
            verdicts.append("slides")
        else:
            verdicts.append("stays")
    return tuple(verdicts), tilt, slip


def replay_tipping(robot: CableRobot, pose: Any, tensions: Any, *,
                   friction: float = _tol.FLOOR_FRICTION,
                   duration: float = _tol.CDPR_DURATION) -> TippingCheck:
    """Simulate the robot at one pose under constant cable tensions and compare the bases'
    behaviour with taut's tipping moments (FASTKIT eqs. 21-23).

    Parameters
    ----------
    robot : CableRobot
    pose : array_like, shape (6,) or (3,)
        Platform pose ``(x, y, z, roll, pitch, yaw)``, m and rad.
    tensions : array_like, shape (m,)
        Cable tensions, N (e.g. from :func:`taut.cdpr.distribute_tensions`).
    friction : float
        Floor friction coefficient.
    duration : float
        Simulated time, s.

    Returns
    -------
    TippingCheck

    Examples
    --------
    >>> from taut.io.cdpr_model import load_cdpr_model
    >>> from taut.cdpr import distribute_tensions
    >>> robot = load_cdpr_model("fastkit")
    >>> pose = [-2.0, 0.0, 0.2, 0.0, 0.0, 0.0]
    >>> t = distribute_tensions(robot, pose, "lp_min_sum", tipping=False).tensions
    >>> r = replay_tipping(robot, pose, t)
    >>> r.verdicts, r.taut_stays, bool(r.success)
    (('stays', 'stays'), True, True)
    """
    require_extra("mujoco")
    import mujoco

    P = as_poses(robot, pose)
    if P.shape[0] != 1:
        raise InvalidInputError("pose", "one pose; use replay_tipping_grid for a batch")
    t = as_array(tensions, "tensions", shape=(len(robot.cables),))
    if np.any(t < 0):
        raise InvalidInputError("tensions", "cables cannot push: every tension must be >= 0")
    mu = as_positive(friction, "friction")
    T = as_positive(duration, "duration")
    model, data, mobile = _build(robot, P[0], t, mu)
    steps = int(round(T / model.opt.timestep))
    for _ in range(steps):
        mujoco.mj_step(model, data)
    verdicts, tilt, slip = _judge(model, data, robot, mobile)
    tip = tipping_moments(robot, P, t[None])
    moments = tip.moments[0]
    margin = float(-moments.max()) if moments.size else float("inf")
    taut_stays = bool(tip.stable[0])
    phys = all(v in ("stays", "fixed") for v in verdicts)
    ok = phys == taut_stays
    names = [b.name for b in robot.bases]
    said = ", ".join(f"{n} {v}" for n, v in zip(names, verdicts))
    msg = (f"physics: {said}; taut margin {margin:.4g} N m "
           f"({'no base tips' if taut_stays else 'a base tips'})")
    return TippingCheck(verdicts, tilt, slip, moments, margin, taut_stays, phys, ok,
                        check_status("ok" if ok else "unverified"), msg)


def replay_tipping_grid(robot: CableRobot, poses: Any, *,
                        method: TensionMethod = "lp_min_sum",
                        tipping: bool = False, friction: float = _tol.FLOOR_FRICTION,
                        duration: float = _tol.CDPR_DURATION,
                        progress: Callable[[int, int], None] | None = None
                        ) -> TippingGridCheck:
    """:func:`replay_tipping` at every pose of a batch (e.g. a workspace grid from
    :func:`taut.cdpr.grid_points`), with tensions from
    :func:`taut.cdpr.distribute_tensions` (``method``, ``tipping`` passed explicitly).

    ``tipping`` defaults to False here, unlike every analysis of :mod:`taut.cdpr`: this
    check asks whether taut's tipping verdict for tensions chosen *without* the tipping
    constraints agrees with the simulated bases; tensions that already avoid tipping would
    leave nothing to check."""
    require_extra("mujoco")
    duration = as_bounded(duration, "duration", MAX_DURATION_S, "s")
    P = as_poses(robot, poses)
    dist = distribute_tensions(robot, P, method, tipping=tipping)
    B, nb = P.shape[0], len(robot.bases)
    verdicts = np.full((B, nb), "", dtype=object)
    margin = np.full(B, np.nan)
    taut_stays = np.zeros(B, dtype=bool)
    phys = np.zeros(B, dtype=bool)
    success = np.zeros(B, dtype=bool)
    status = np.full(B, "infeasible", dtype=object)
    for b in range(B):
        if dist.success[b]:
            r = replay_tipping(robot, P[b], dist.tensions[b], friction=friction,
                              duration=duration)
            verdicts[b] = r.verdicts
            margin[b], taut_stays[b], phys[b] = r.margin, r.taut_stays, r.physics_stays
            success[b], status[b] = r.success, r.status
        if progress is not None:
            progress(b + 1, B)
    n = int(dist.success.sum())
    agree = int(success.sum())
    msg = f"{agree} of {n} pose(s) with tensions agree (taut vs physics); {B - n} without tensions"
    return TippingGridCheck(P, verdicts, margin, taut_stays, phys, dist.success.copy(),
                            success, status.astype(str), msg)
