"""A placement-independent lift certificate for mobile CDPR deployment (our own, built on
FASTKIT's statics: eq. 17 equilibrium, eq. 20 tension limits): an upper bound, valid for
every placement of the mobile bases, on how much the cables can lift over the top face of
a workspace box. When it falls below platform and payload weight, no placement makes the
box wrench-feasible. Units: m, N."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import minimize

from ..._validate import MAX_BATCH, as_array
from ...errors import InvalidInputError
from ..statics._common import wrench_vertices
from .._tol import LIFT_FTOL, LIFT_GTOL, LIFT_RTOL, REFUTE_REL
from ..model.robot import CableRobot
from .placement import workspace_box
from ..workspace.wrench_feasible import grid_points
from ..._validate import as_tolerance, require_instance
from ..._validate import require_instance
from ..._repr import CompactRepr

__all__ = ["LiftBound", "lift_bound", "upward_force_bound"]


def _lift_terms(t_max: np.ndarray, c: np.ndarray, d: np.ndarray) -> np.ndarray:
    """``f(d) = t_max * max(c, 0) / sqrt(d^2 + c^2)``: the largest upward pull of a cable
    whose exit is ``c`` above and ``d`` horizontally away from its attachment point (N).
    Broadcasts; 0 where the exit is not above the attachment point."""
    cp = np.maximum(c, 0.0)
    den = np.sqrt(d * d + cp * cp)
    return np.where(cp > 0, t_max * cp / np.where(cp > 0, den, 1.0), 0.0)


def upward_force_bound(robot: CableRobot, points: ArrayLike) -> np.ndarray:
    """Upper bound ``sum_i f_i(d_i)`` on the upward cable force at level platform positions,
    for the robot as placed, (B,) N (a float for one point).

    ``f_i(d) = t_max,i max(h_i - z_ai, 0) / sqrt(d^2 + (h_i - z_ai)^2)`` with ``h_i`` the
    exit height, ``z_ai`` the attachment height and ``d_i`` their horizontal distance:
    cable ``i`` pulls with at most ``t_max,i`` along its unit vector, whose vertical
    component is ``(h_i - z_ai) / L_i``. See :func:`lift_bound`.

    Parameters
    ----------
    robot : CableRobot
    points : (B, 3) or (3,)
        Platform positions (orientation zero), m. Not checked against the frame box.
    """
    require_instance(robot, CableRobot, "robot")
    P = as_array(points, "points")
    single = P.ndim == 1
    P = P[None, :] if single else P
    if P.ndim != 2 or P.shape[1] != 3:
        raise InvalidInputError("points", "must be (x, y, z) or a (B, 3) array")
    att = P[:, None, :] + robot.attach_local[None, :, :]           # level platform
    vec = robot.exits_world[None, :, :] - att                        # (B, m, 3)
    d = np.hypot(vec[..., 0], vec[..., 1])
    out = _lift_terms(robot.t_max, vec[..., 2], d).sum(axis=1)
    return out[0] if single else out


def _mean_lift(e: np.ndarray, q: np.ndarray, t: float, c: float, radius: float = 0.0,
               chunk: int = 2048) -> tuple[np.ndarray, np.ndarray]:
    """``g(e) = mean_k f(|e - q_k|)`` (f of :func:`_lift_terms`, ``c > 0``) at exit
    positions e (J, 2), and an upper bound of g over the disc of ``radius`` around each.

    The bound is the smaller of two valid ones: ``mean_k f(max(|e - q_k| - radius, 0))``
    (f decreases with the distance) and the Taylor bound
    ``g(e) + |grad g(e)| radius + radius^2 t / (2 c^2)`` (``t / c^2`` bounds the Hessian
    norm of every term: its eigenvalues are ``f''(d)`` and ``f'(d) / d``)."""
    val = np.empty(len(e))
    ub = np.empty(len(e))
    for s0 in range(0, len(e), chunk):              # chunks of cells, samples vectorised
        diff = e[s0:s0 + chunk, None, :] - q[None, :, :]
        d2 = np.einsum("jkx,jkx->jk", diff, diff)
        inv = 1.0 / np.sqrt(d2 + c * c)
        v = (t * c) * inv.mean(axis=1)
        val[s0:s0 + chunk] = v
        if radius > 0:
            grad = np.einsum("jk,jkx->jx", inv ** 3, diff) * (-t * c / q.shape[0])
            taylor = v + np.hypot(grad[:, 0], grad[:, 1]) * radius \
                + 0.5 * t * (radius / c) ** 2
            dr = np.maximum(np.sqrt(d2) - radius, 0.0)
            mono = (t * c) * (1.0 / np.sqrt(dr * dr + c * c)).mean(axis=1)
            ub[s0:s0 + chunk] = np.minimum(taylor, mono)
        else:
            ub[s0:s0 + chunk] = v
    return val, ub


def _max_mean_lift(q: np.ndarray, t: float, c: float, rtol: float = LIFT_RTOL,
                   max_cells: int = 100_000) -> tuple[float, float, np.ndarray]:
    """``max_{e in R^2} mean_k f(|e - q_k|)`` by branch and bound.

    The maximum lies in the convex hull of the ``q_k`` (projecting ``e`` onto it shortens
    every distance), hence in their bounding box. Cells of a uniform grid over that box
    are bounded from above by :func:`_mean_lift`; cells whose bound does not exceed the
    best value found (polished by L-BFGS-B) by ``rtol * t`` are dropped, the others split
    in four, until none is left.

    Returns ``(upper bound, best value attained, argmax e)``. The upper bound is rigorous
    (up to floating point) even if the refinement stops early at ``max_cells``.
    """
    if c <= 0:
        return 0.0, 0.0, q.mean(axis=0)
    lo, hi = q.min(axis=0), q.max(axis=0)
    span = hi - lo
    n = np.maximum(1, np.ceil(span / (0.5 * c))).astype(int)
    while n.prod() > max_cells // 4:
        n = np.maximum(1, n // 2)
    half = span / (2 * n)
    gx = lo[0] + half[0] * (2 * np.arange(n[0]) + 1)
    gy = lo[1] + half[1] * (2 * np.arange(n[1]) + 1)
    cells = np.stack(np.meshgrid(gx, gy, indexing="ij"), axis=-1).reshape(-1, 2)
    val, _ = _mean_lift(cells, q, t, c)
    k = int(np.argmax(val))
    best, arg = float(val[k]), cells[k].copy()

    def neg(e: np.ndarray) -> tuple[float, np.ndarray]:
        v, g = _value_grad(e)
        return -v, -g

    def _value_grad(e: np.ndarray) -> tuple[float, np.ndarray]:
        diff = e[None, :] - q
        inv = 1.0 / np.sqrt(np.einsum("kx,kx->k", diff, diff) + c * c)
        return float(t * c * inv.mean()), -(t * c) * (inv ** 3) @ diff / len(q)

    pol = minimize(neg, arg, jac=True, method="L-BFGS-B", bounds=list(zip(lo, hi)),
                   options={"ftol": LIFT_FTOL, "gtol": LIFT_GTOL})
    if -pol.fun > best:
        best, arg = float(-pol.fun), np.clip(pol.x, lo, hi)
    atol = rtol * t
    dropped = -np.inf                          # largest bound of the cells discarded so far
    for _ in range(64):
        val, ub = _mean_lift(cells, q, t, c, radius=float(np.hypot(*half)))
        k = int(np.argmax(val))
        if val[k] > best:
            best, arg = float(val[k]), cells[k].copy()
        keep = ub > best + atol
        if (~keep).any():
            dropped = max(dropped, float(ub[~keep].max()))
        if not keep.any() or 4 * keep.sum() > max_cells:
            break
        half = half / 2
        off = np.array([[-1.0, -1.0], [-1.0, 1.0], [1.0, -1.0], [1.0, 1.0]]) * half
        cells = (cells[keep][:, None, :] + off[None, :, :]).reshape(-1, 2)
    bound = max(best, dropped, float(ub[keep].max(initial=-np.inf)))
    return bound, best, arg


@dataclass(frozen=True, repr=False)
class LiftBound(CompactRepr):
    """Outcome of :func:`lift_bound`: can any placement of the mobile bases lift platform
    and payload everywhere on the top face of a workspace box?

    Attributes
    ----------
    bound : float
        Upper bound, valid for every placement, on the mean over :attr:`points` of the
        largest upward cable force at a level platform, N.
    required : float
        Upward force the cables must supply everywhere: platform and payload weight plus the
        largest downward disturbance force, N.
    weight : float
        Platform and payload weight ``-(m_p + m_l) g_z``, N.
    disturbance_down : float
        Largest downward ``fz`` of the disturbance vertices (0 without disturbance; negative
        when every vertex pushes up), N.
    refutes : bool
        ``bound < required`` (beyond a tolerance of 1e-6 of the weight): no placement can
        make the box wrench-feasible, with or without tipping.
    height : float
        ``zmax`` of the box, where the bound is evaluated, m.
    points : (K, 3)
        Sample points of the top face, m.
    per_cable : (m,)
        Contribution of each cable to ``bound``, N (they sum to it).
    exit_xy : (m, 2)
        Horizontal exit position attaining each contribution (the actual one for cables on
        fixed bases), m.
    movable : (m,) bool
        Whether the cable's exit moves with a mobile base (else it is fixed and used as is).
    """

    bound: float
    required: float
    weight: float
    disturbance_down: float
    refutes: bool
    height: float
    points: np.ndarray
    per_cable: np.ndarray
    exit_xy: np.ndarray
    movable: np.ndarray

    @property
    def success(self) -> bool:
        """True when the certificate does not refute (the box may be deployable); False
        when it proves that no placement exists."""
        return not self.refutes

    @property
    def status(self) -> str:
        """``"refuted"`` when the certificate proves infeasibility, else ``"ok"``."""
        return "refuted" if self.refutes else "ok"

    @property
    def message(self) -> str:
        """:meth:`explain`."""
        return self.explain()

    @property
    def shortfall(self) -> float:
        """``required - bound``, N (> 0 when the certificate refutes)."""
        return self.required - self.bound

    def explain(self) -> str:
        """One sentence with the numbers."""
        need = f"platform and payload weigh {self.weight:.1f} N"
        if self.disturbance_down != 0:
            need += (f" and the disturbance adds up to {self.disturbance_down:.1f} N "
                     "downward" if self.disturbance_down > 0 else
                     f" and the disturbance lifts at least {-self.disturbance_down:.1f} N")
        head = "no placement can work" if self.refutes else "the lift bound allows it"
        return (f"{head}: at z = {self.height:.4g} m the cables can lift at most "
                f"{self.bound:.1f} N on average over the top of the box, {need}")


def lift_bound(robot: CableRobot, workspace: ArrayLike, *,
               external_wrench: ArrayLike | None = None, samples: Sequence[int] = (41, 5),
               refute_tol: float = REFUTE_REL) -> LiftBound:
    """Placement-independent necessary condition for a wrench-feasible workspace box.

    This is our own certificate built on FASTKIT's statics (eq. 17 equilibrium
    ``W t + w_e = 0``, eq. 20 tension limits, eq. 24 available wrench set); the paper does
    not state it. If it refutes, **no** placement ``(x, y, theta)`` of the mobile bases
    makes the box wrench-feasible, even ignoring tipping (eqs. 21-23) and every wrench
    component but the vertical force.

    Parameters
    ----------
    robot : CableRobot
    workspace : (2, 3) or (6,)
        Box as for :func:`plan_deployment`; flat axes are allowed (e.g. the preset's
        ``desired_workspace`` slice).
    external_wrench : (V, n), optional
        Extra external wrenches (vertices), N and N m; only their ``fz`` is used.
    samples : (2,) ints
        Grid of sample points on the top face, along x and y (a flat axis gets one).
    refute_tol : float
        Refute only when the bound is below the required force by more than
        ``refute_tol`` times the weight (dimensionless; guards round-off at the boundary).

    Returns
    -------
    LiftBound

    Examples
    --------
    >>> from taut.io.cdpr_model import load_cdpr_model
    >>> lb = lift_bound(load_cdpr_model("fastkit"), [[-2.5, -0.05, 0.2], [2.5, 0.05, 2.2]])
    >>> lb.refutes, lb.status, round(lb.bound, 1), round(lb.required, 1)   # N
    (True, 'refuted', 64.2, 117.7)

    Notes
    -----
    The bound is for the level platform (zero orientation) that the workspace analyses and
    :func:`plan_deployment` use.

    Mobile bases only translate in the ground plane and rotate about the vertical, so
    every exit height ``h_i`` is independent of the placement. At platform position ``p``
    cable ``i`` pulls along ``(exit - attachment) / L_i``; with the attachment at height
    ``z_ai = p_z + b_iz`` and horizontal distance ``d_i`` from the exit, its upward pull
    is ``t_i (h_i - z_ai) / L_i`` with ``L_i = sqrt(d_i^2 + (h_i - z_ai)^2)`` and
    ``t_i <= t_max,i``. Hence the upward cable force is at most ``sum_i f_i(d_i)``,

        ``f_i(d) = t_max,i max(h_i - z_ai, 0) / sqrt(d^2 + (h_i - z_ai)^2)``,

    decreasing in ``d`` (:func:`upward_force_bound`). Equilibrium (eq. 17) needs an upward
    cable force of at least the weight ``-(m_p + m_l) g_z`` plus the largest downward
    disturbance at every pose of the box. Let ``C(p)`` be the largest upward force at
    ``p`` for a given placement and ``p_k`` (k = 1..K) the sample points of the top face
    ``z = zmax`` (where the exits are closest above the attachments, so the bound is
    smallest). With ``b_i,xy`` the horizontal attachment offset and ``e`` a free
    horizontal exit position,

        ``min_k C(p_k) <= mean_k C(p_k) <= sum_i max_e mean_k f_i(|e - (p_k,xy + b_i,xy)|)``.

    The right-hand side (:attr:`LiftBound.bound`) does not depend on the placement. Each
    inner maximum is a smooth 2-D problem, attained in the convex hull of the points
    ``p_k,xy + b_i,xy``; it is solved by branch and bound over that bounding box (cell
    bounds from the monotonicity of ``f_i`` and from its curvature, incumbent polished by
    L-BFGS-B), which keeps the result a rigorous upper bound, above the true maximum by at
    most ``1e-5 t_max,i`` per cable. Cables with the same ``t_max`` and exit height above
    their attachment share one maximisation (the attachment offset only shifts ``e``).
    Treating each exit as free is a relaxation (the exits of one base move together).
    Cables on fixed bases keep their actual exit.

    If the bound is below the required force, some top-face point is infeasible for every
    placement. The bound decreases as ``zmax`` rises (``f_i`` grows with
    ``h_i - z_ai``), so every taller box with the same x/y extent (it contains this top
    face as a slice) is refuted too. Tension lower limits, the other wrench components,
    tipping, the averaging and the free exits all leave the bound above the true capacity,
    so a bound above the required force proves nothing.
    """
    require_instance(robot, CableRobot, "robot")
    as_tolerance(refute_tol, "refute_tol")
    box = workspace_box(workspace, allow_flat=True)
    if isinstance(samples, (str, bytes)):
        raise InvalidInputError("samples", "must be two positive integers nx ny")
    sm = as_array(samples, "samples")
    if sm.shape != (2,) or np.any(sm < 1) or np.any(sm != np.round(sm)):
        raise InvalidInputError("samples", "must be two positive integers nx ny")
    if float(sm[0]) * float(sm[1]) > MAX_BATCH:
        raise InvalidInputError("samples", f"{float(sm[0]) * float(sm[1]):g} points exceed "
                                           f"the accepted range {MAX_BATCH:g} points")
    zt = float(box[1, 2])
    top = np.array([[box[0, 0], box[0, 1], zt], [box[1, 0], box[1, 1], zt]])
    pts, _ = grid_points(top, (int(sm[0]), int(sm[1]), 1))
    g_z = float(robot.gravity[2])
    weight = -robot.total_mass * g_z
    down = 0.0
    if external_wrench is not None:
        D = wrench_vertices(robot, external_wrench)
        down = float(np.max(-D[:, 2])) if len(D) else 0.0
    movable = np.array([robot.bases[k].mobile for k in robot.cable_base])
    per = np.zeros(robot.m)
    exy = robot.exits_world[:, :2].copy()
    solved: dict[tuple[float, float], tuple[float, np.ndarray]] = {}
    for i in range(robot.m):                            # a few cables; samples vectorised
        c = float(robot.exits_world[i, 2] - zt - robot.attach_local[i, 2])
        t = float(robot.t_max[i])
        if movable[i]:
            # max_e mean_k f(|e - (p_k + b_i)|) does not depend on b_i (shift e by b_i)
            if (t, c) not in solved:
                ub, _, arg = _max_mean_lift(pts[:, :2], t, c)
                solved[(t, c)] = (ub, arg)
            per[i] = solved[(t, c)][0]
            exy[i] = solved[(t, c)][1] + robot.attach_local[i, :2]
        elif c > 0:
            q = pts[:, :2] + robot.attach_local[i, :2]
            per[i] = float(_mean_lift(exy[i][None, :], q, t, c)[0][0])
    bound = float(per.sum())
    required = weight + down
    tol = refute_tol * max(abs(weight), 1.0)
    return LiftBound(bound, required, weight, down, bool(bound < required - tol), zt, pts,
                     per, exy, movable)
