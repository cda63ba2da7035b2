"""Deployment planning of mobile CDPRs: where to park the mobile bases so that a desired
platform workspace is wrench-feasible without tipping a base and a required twist is
available everywhere in it (FASTKIT §2: "the system calculates the required mobile base
position from the desired workspace"; §3.2 twist sets, §4 wrench sets with eqs. 21-24).

Decision variables: ``(x, y, theta)`` of every mobile base (fixed frames stay put).

Deployment margin (maximised): the worst capacity margin of the required wrench set over a
grid of sample points of the workspace box, with tipping constraints
(:func:`taut.cdpr.wrench_set.capacity_margin`: distance, in mixed N / N m units, from the
required set to the available-wrench-set boundary; negative when infeasible). Constraints,
handled by penalties: every sample point inside the deployed frame box, the required twist
inside the available twist set (task mode) at every sample point, and no base footprint
overlapping the workspace box seen from above. Optimiser: scipy's seeded
``differential_evolution`` started from the model's placement, then a Nelder-Mead polish.
The winner is re-verified on a finer grid with the exact feasibility test
(:func:`taut.cdpr.wrench_set.wrench_feasible`, tipping on).

Before searching, :func:`plan_deployment` checks a placement-independent necessary
condition (:func:`lift_bound`): if even the best conceivable exit positions cannot lift
platform and payload on average over the top face of the box, no placement exists and the
optimiser is not run. :func:`tallest_workspace` bisects on the box height between that
certified limit and verified deployments.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any, Mapping, Sequence

import numpy as np
from scipy.optimize import differential_evolution, minimize

from .._validate import as_array
from ..errors import InvalidInputError, TautError
from .model import CableRobot
from .twist import MotionLimits, available_twist_set, fastkit_motion_limits
from .workspace import grid_points
from .wrench_set import capacity_margin, wrench_feasible

__all__ = ["place_bases", "workspace_box", "DeploymentResult", "plan_deployment",
           "evaluate_deployment", "LiftBound", "lift_bound", "upward_force_bound",
           "TallestWorkspace", "tallest_workspace"]

_PENALTY = 1e3


def workspace_box(box: Any, field: str = "workspace", *, allow_flat: bool = False
                  ) -> np.ndarray:
    """Validate a workspace box ``[[xmin, ymin, zmin], [xmax, ymax, zmax]]`` (m) -> (2, 3).

    Raises :class:`InvalidInputError` on NaN/inf, a wrong shape, or a box with no volume
    (some ``max <= min``; with ``allow_flat`` only ``max < min``, so slices such as the
    FASTKIT preset's ``desired_workspace`` pass)."""
    b = as_array(box, field)
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


def _footprint_overlap(robot: CableRobot, box: np.ndarray) -> float:
    """Largest penetration depth (m) of a base footprint into the workspace rectangle seen
    from above (separating-axis test; 0 when clear)."""
    rect = np.array([[box[0, 0], box[0, 1]], [box[1, 0], box[0, 1]],
                     [box[1, 0], box[1, 1]], [box[0, 0], box[1, 1]]])
    worst = 0.0
    for b in robot.bases:
        if not b.mobile:
            continue
        poly = b.to_world(np.column_stack([b.support_polygon, np.zeros(len(b.support_polygon))]))
        poly = poly[:, :2]
        depth = np.inf
        for P, Q in ((poly, rect), (rect, poly)):
            e = np.roll(P, -1, axis=0) - P
            nrm = np.column_stack([e[:, 1], -e[:, 0]])
            nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
            a, c = P @ nrm.T, Q @ nrm.T
            depth = min(depth, float(np.min(np.minimum(a.max(0) - c.min(0),
                                                       c.max(0) - a.min(0)))))
        worst = max(worst, depth)
    return max(worst, 0.0)


# --------------------------------------------------------------------------------------
# Placement-independent certificate: can any placement lift the platform at the top?
# --------------------------------------------------------------------------------------

def _lift_terms(t_max: np.ndarray, c: np.ndarray, d: np.ndarray) -> np.ndarray:
    """``f(d) = t_max * max(c, 0) / sqrt(d^2 + c^2)``: the largest upward pull of a cable
    whose exit is ``c`` above and ``d`` horizontally away from its attachment point (N).
    Broadcasts; 0 where the exit is not above the attachment point."""
    cp = np.maximum(c, 0.0)
    den = np.sqrt(d * d + cp * cp)
    return np.where(cp > 0, t_max * cp / np.where(cp > 0, den, 1.0), 0.0)


def upward_force_bound(robot: CableRobot, points: Any) -> np.ndarray:
    """Upper bound ``sum_i f_i(d_i)`` on the upward cable force at level platform positions,
    for the robot as placed, (B,) N.

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
    P = as_array(points, "points")
    P = P[None, :] if P.ndim == 1 else P
    if P.ndim != 2 or P.shape[1] != 3:
        raise InvalidInputError("points", "must be (x, y, z) or a (B, 3) array")
    att = P[:, None, :] + robot.attach_local[None, :, :]           # level platform
    vec = robot.exits_world[None, :, :] - att                        # (B, m, 3)
    d = np.hypot(vec[..., 0], vec[..., 1])
    return _lift_terms(robot.t_max, vec[..., 2], d).sum(axis=1)


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


def _max_mean_lift(q: np.ndarray, t: float, c: float, rtol: float = 1e-5,
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
                   options={"ftol": 1e-15, "gtol": 1e-12})
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


@dataclass(frozen=True)
class LiftBound:
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


def lift_bound(robot: CableRobot, workspace: Any, *, disturbance: Any = None,
               samples: Sequence[int] = (41, 5)) -> LiftBound:
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
    disturbance : (V, n), optional
        Extra external wrenches (vertices), N and N m; only their ``fz`` is used.
    samples : (2,) ints
        Grid of sample points on the top face, along x and y (a flat axis gets one).

    Returns
    -------
    LiftBound

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
    box = workspace_box(workspace, allow_flat=True)
    sm = np.asarray(samples, dtype=float)
    if sm.shape != (2,) or np.any(sm < 1) or np.any(sm != np.round(sm)):
        raise InvalidInputError("samples", "must be two positive integers nx ny")
    zt = float(box[1, 2])
    top = np.array([[box[0, 0], box[0, 1], zt], [box[1, 0], box[1, 1], zt]])
    pts, _ = grid_points(top, (int(sm[0]), int(sm[1]), 1))
    g_z = float(robot.gravity[2])
    weight = -robot.total_mass * g_z
    down = 0.0
    if disturbance is not None:
        D = as_array(disturbance, "disturbance", shape=(None, robot.dof))
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
    tol = 1e-6 * max(abs(weight), 1.0)
    return LiftBound(bound, required, weight, down, bool(bound < required - tol), zt, pts,
                     per, exy, movable)


@dataclass(frozen=True)
class DeploymentResult:
    """Outcome of :func:`plan_deployment`.

    When the placement-independent certificate refutes the box (``lift_bound.refutes``)
    the search is skipped: ``feasible`` is False, ``base_poses`` and ``robot`` are the
    input placement (meaningless for the answer), ``margin`` is NaN, ``twist_margin`` None,
    ``points``/``point_margin``/``point_feasible`` are empty, ``evaluations`` is 0 and
    ``reason`` is :meth:`LiftBound.explain`.

    Attributes
    ----------
    feasible : bool
        Verified: every verification point wrench-feasible with tipping, the required twist
        available there, no footprint over the workspace.
    base_poses : dict str -> (3,)
        ``(x, y, theta)`` of every mobile base, m and rad.
    robot : CableRobot
        The deployed robot.
    margin : float
        Worst capacity margin over the verification points (N / N m, > 0 when feasible;
        NaN when not evaluated).
    twist_margin : float or None
        Worst ATS margin of the required twist (m/s, rad/s), None without a required twist.
    points : (P, 3)
        Verification points, m (P = 0 when refuted by the certificate).
    point_margin : (P,)
    point_feasible : (P,) bool
        Exact wrench feasibility with tipping at each point.
    workspace : (2, 3)
    reason : str
        Empty when feasible; otherwise why no deployment was found.
    evaluations : int
        Candidate placements evaluated.
    lift_bound : LiftBound or None
        The placement-independent certificate checked first (:func:`lift_bound`).
    """

    feasible: bool
    base_poses: dict
    robot: CableRobot
    margin: float
    twist_margin: float | None
    points: np.ndarray
    point_margin: np.ndarray
    point_feasible: np.ndarray
    workspace: np.ndarray
    reason: str
    evaluations: int
    lift_bound: LiftBound | None = None

    @property
    def refuted(self) -> bool:
        """True when the certificate proved that no placement exists (no search was run)."""
        return self.lift_bound is not None and self.lift_bound.refutes


def evaluate_deployment(robot: CableRobot, points: np.ndarray, disturbance, twists, limits,
                        moving) -> tuple[float, np.ndarray, float | None]:
    """Score one placement: (worst wrench margin, per-point margins, worst twist margin).

    ``twists`` (T, n) or None: required twists, the worst ATS margin over points and
    twists is returned (None without twists). Raises :class:`TautError` (e.g. a sample
    point outside the frame box)."""
    pm = capacity_margin(robot, points, disturbance=disturbance, tipping=True)
    tm = None
    if twists is not None:
        ats = available_twist_set(robot, points, limits, "task", moving)
        tm = min(float(ats.margin(t).min()) for t in twists)
    return float(pm.min()), pm, tm


def plan_deployment(robot: CableRobot, workspace: Any, *, disturbance: Any = None,
                    required_twist: Any = None, limits: MotionLimits | None = None,
                    moving: Sequence[str] | None = None, grid: Sequence[int] = (6, 2, 4),
                    verify_grid: Sequence[int] = (21, 3, 9),
                    search: Sequence[float] = (1.0, 0.5, 0.4), maxiter: int = 12,
                    popsize: int = 6, seed: int = 0) -> DeploymentResult:
    """Find mobile-base placements for a desired workspace box.

    Parameters
    ----------
    robot : CableRobot
        Its mobile bases are moved; its payload, tension limits and stabiliser state are
        used as given (deploy the stabilisers first with
        :func:`taut.cdpr.with_stabilisers` if they are part of the plan).
    workspace : (2, 3) or (6,)
        Box ``[[xmin, ymin, zmin], [xmax, ymax, zmax]]`` or ``xmin xmax ymin ymax zmin
        zmax``, m, with positive volume.
    disturbance : (V, n), optional
        Extra external wrenches on top of platform and payload weight (vertices, e.g.
        :func:`taut.cdpr.disturbance_box`), N and N m.
    required_twist : (n,) or (T, n), optional
        Twists (m/s, rad/s) that must be available everywhere (task mode).
    limits : MotionLimits, optional
        Default :func:`fastkit_motion_limits`.
    moving : sequence of str, optional
        Bases moving in task mode (default the first mobile base).
    grid : (3,) ints
        Sample points per axis used during the search.
    verify_grid : (3,) ints
        Finer grid for the final verification.
    search : (dx, dy, dtheta)
        Half-widths of the search region around the model's placement, m, m, rad.
    maxiter, popsize, seed
        Differential-evolution settings (seeded: the result is reproducible).

    Returns
    -------
    DeploymentResult
        Checked first: when :func:`lift_bound` refutes the box (no placement can lift
        platform and payload over the top of the box) it is returned at once with
        ``feasible=False``, the certificate's sentence as ``reason`` and empty verification
        arrays; see :class:`DeploymentResult`.
    """
    box = workspace_box(workspace)
    mobile = [b for b in robot.bases if b.mobile]
    if not mobile:
        raise InvalidInputError("robot", "has no mobile base to deploy")
    limits = fastkit_motion_limits() if limits is None else limits
    D = None if disturbance is None else as_array(disturbance, "disturbance",
                                                  shape=(None, robot.dof))
    tw = None
    if required_twist is not None:
        tw = as_array(required_twist, "required_twist")
        if tw.shape[-1] != robot.dof or tw.ndim > 2:
            raise InvalidInputError("required_twist", f"must have {robot.dof} components")
        tw = tw.reshape(-1, robot.dof)
    sr = as_array(search, "search", shape=(3,))
    if np.any(sr < 0):
        raise InvalidInputError("search", "half-widths must be non-negative")
    for name, value, low in (("maxiter", maxiter, 0), ("popsize", popsize, 1), ("seed", seed, 0)):
        integer = isinstance(value, (int, np.integer)) and not isinstance(value, bool)
        if not (integer and low <= value < 2 ** 32):
            raise InvalidInputError(name, f"must be an integer from {low} to 2**32 - 1, "
                                          f"got {value!r}")
    cert = lift_bound(robot, box, disturbance=D)
    names = [b.name for b in mobile]
    if cert.refutes:
        return DeploymentResult(False, {b.name: b.pose.copy() for b in mobile}, robot, np.nan,
                                None, np.zeros((0, 3)), np.zeros(0), np.zeros(0, bool), box,
                                cert.explain(), 0, cert)
    pts, _ = grid_points(box, grid)
    x0 = np.concatenate([b.pose for b in mobile])
    half = np.tile(sr, len(mobile))
    bounds = [(a - h, a + h) if h > 0 else (a, a + 1e-12) for a, h in zip(x0, half)]
    count = [0]

    def score(x: np.ndarray, P: np.ndarray) -> tuple[float, Any]:
        count[0] += 1
        try:
            rr = place_bases(robot, x.reshape(-1, 3))
        except TautError:
            return -_PENALTY * 10, None
        lo, hi = rr.bounds
        out = np.maximum(lo - box[0], 0).sum() + np.maximum(box[1] - hi, 0).sum()
        if out > 0:
            return -_PENALTY * (1 + out), None
        try:
            wm, pm, tm = evaluate_deployment(rr, P, D, tw, limits, moving)
        except TautError:
            return -_PENALTY * 5, None
        val = wm
        if tm is not None and tm < 0:
            val -= _PENALTY * (-tm) + 1.0
        ov = _footprint_overlap(rr, box)
        if ov > 0:
            val -= _PENALTY * ov + 1.0
        return val, rr

    def f(x: np.ndarray) -> float:
        return -score(x, pts)[0]

    de = differential_evolution(f, bounds, x0=x0, seed=seed, maxiter=maxiter,
                                popsize=popsize, polish=False, tol=1e-6, init="sobol")
    loc = minimize(f, de.x, method="Nelder-Mead",
                   options={"maxfev": 60 * len(x0), "xatol": 1e-4, "fatol": 1e-6})
    best = loc.x if loc.fun <= de.fun else de.x
    best = np.clip(best, [b[0] for b in bounds], [b[1] for b in bounds])
    rr = place_bases(robot, best.reshape(-1, 3))
    vpts, _ = grid_points(box, verify_grid)
    poses = {n: best[3 * i:3 * i + 3].copy() for i, n in enumerate(names)}
    try:
        wm, pm, tm = evaluate_deployment(rr, vpts, D, tw, limits, moving)
        pf = wrench_feasible(rr, vpts, tipping=True, disturbance=D)
    except TautError as exc:
        return DeploymentResult(False, poses, rr, -np.inf, None, vpts, np.full(len(vpts),
                                -np.inf), np.zeros(len(vpts), bool), box,
                                f"no placement keeps the workspace inside the frame: {exc}",
                                count[0], cert)
    ov = _footprint_overlap(rr, box)
    ok = bool(pf.all()) and (tm is None or tm >= 0) and ov == 0
    reason = ""
    if not ok:
        why = []
        if not pf.all():
            k = int(np.argmin(pm))
            why.append(f"{int((~pf).sum())} of {len(pf)} sample points are not "
                       f"wrench-feasible with tipping (worst at "
                       f"{np.round(vpts[k], 3).tolist()} m, capacity margin {pm[k]:.3g})")
        if tm is not None and tm < 0:
            why.append(f"the required twist exceeds the available twist set by {-tm:.3g}")
        if ov > 0:
            why.append(f"a base footprint overlaps the workspace by {ov:.3g} m")
        reason = "best placement found: " + "; ".join(why)
    return DeploymentResult(ok, poses, rr, wm, tm, vpts, pm, pf, box, reason, count[0], cert)


# --------------------------------------------------------------------------------------
# Tallest deployable box
# --------------------------------------------------------------------------------------

@dataclass(frozen=True)
class TallestWorkspace:
    """Outcome of :func:`tallest_workspace`.

    Attributes
    ----------
    height : float
        ``zmax`` of the tallest box with a verified deployment, m (NaN if none was found).
    workspace : (2, 3) or None
        That box.
    deployment : DeploymentResult or None
        Its verified deployment (``deployment.feasible`` is True).
    certified_limit : float
        Lowest ``zmax`` at which :func:`lift_bound` refutes the box, m: every box reaching
        this high is proved infeasible for every placement. ``inf`` when the certificate
        does not refute even the requested ``zmax``.
    certificate : LiftBound
        The certificate at ``certified_limit`` (or at the requested ``zmax`` when it does
        not refute there).
    failed_below : float
        Lowest ``zmax`` at which the planner found no placement, m (NaN if none): the true
        tallest height lies between ``height`` and ``certified_limit``, most likely below
        this (the optimiser is not exhaustive).
    tried : tuple of (float, bool)
        ``(zmax, verified feasible)`` of every :func:`plan_deployment` call, in order.
    """

    height: float
    workspace: np.ndarray | None
    deployment: DeploymentResult | None
    certified_limit: float
    certificate: LiftBound
    failed_below: float
    tried: tuple[tuple[float, bool], ...]


def tallest_workspace(robot: CableRobot, workspace: Any, *, disturbance: Any = None,
                      tol: float = 0.05, certificate_tol: float = 1e-3,
                      samples: Sequence[int] = (41, 5), warm_start: bool = True,
                      **plan_options: Any) -> TallestWorkspace:
    """Tallest box with a verified deployment, by bisection on ``zmax``.

    Parameters
    ----------
    robot : CableRobot
    workspace : (2, 3) or (6,)
        Box whose x/y extent and ``zmin`` are kept; its ``zmax`` is the highest height
        tried.
    disturbance : (V, n), optional
        As for :func:`plan_deployment` (also used by the certificate).
    tol : float
        Stop when the bracket ``[verified, failed]`` of ``zmax`` is narrower, m.
    certificate_tol : float
        Resolution of the certified limit, m.
    samples : (2,) ints
        Top-face grid of the certificate (:func:`lift_bound`).
    warm_start : bool
        Centre each search on the last verified placement (the previous box is a slice of
        the taller one, so that placement is a good start).
    **plan_options
        Passed to :func:`plan_deployment` (``required_twist``, ``grid``, ``maxiter``, ...).

    Returns
    -------
    TallestWorkspace

    Notes
    -----
    1. The certificate's bound decreases as ``zmax`` rises (the exits get closer above
       the attachment points), so bisection on :func:`lift_bound` gives the certified limit
       ``z_c``: at ``z_c`` no placement exists, nor for any taller box (it contains the
       refuted slice).
    2. ``plan_deployment`` is bisected on ``zmax`` in ``(zmin, min(zmax, z_c))``: a
       verified answer raises the lower end, a failure lowers the upper end. The requested
       ``zmax`` is tried first when the certificate does not refute it. Each call costs one
       planner run (about ``log2(height range / tol)`` calls).

    The planner is a seeded heuristic: a failure does not prove infeasibility, so the
    returned height is a verified lower bound of the true tallest height and
    ``certified_limit`` a proved upper bound.
    """
    box = workspace_box(workspace)
    if not (np.isfinite(tol) and tol > 0):
        raise InvalidInputError("tol", "must be a positive number of metres")
    if not (np.isfinite(certificate_tol) and certificate_tol > 0):
        raise InvalidInputError("certificate_tol", "must be a positive number of metres")
    D = None if disturbance is None else as_array(disturbance, "disturbance",
                                                  shape=(None, robot.dof))
    zmin, ztop = float(box[0, 2]), float(box[1, 2])

    def at(z: float) -> np.ndarray:
        b = box.copy()
        b[1, 2] = z
        return b

    def certify(z: float) -> LiftBound:
        return lift_bound(robot, at(z), disturbance=D, samples=samples)

    cert = certify(ztop)
    limit = np.inf
    if cert.refutes:
        lo, hi, hi_cert = zmin, ztop, cert        # lo: not refuted (or the floor)
        while hi - lo > certificate_tol:
            mid = 0.5 * (lo + hi)
            c = certify(mid)
            if c.refutes:
                hi, hi_cert = mid, c
            else:
                lo = mid
        limit, cert = hi, hi_cert
    best: DeploymentResult | None = None
    height = np.nan
    tried: list[tuple[float, bool]] = []
    start = robot
    lo = zmin                                    # no verified box yet
    hi = min(ztop, limit)                        # infeasible when refuted
    z = ztop if not cert.refutes else 0.5 * (lo + hi)
    while True:
        res = plan_deployment(start, at(z), disturbance=D, **plan_options)
        tried.append((z, bool(res.feasible)))
        if res.feasible:
            best, height, lo = res, z, z
            if warm_start:
                start = res.robot
            if z >= hi:                          # the requested box itself
                hi = z
        else:
            hi = z
        if hi - lo <= tol:
            break
        z = 0.5 * (lo + hi)
    fails = [zz for zz, ok in tried if not ok]
    return TallestWorkspace(height, None if best is None else at(height), best, limit, cert,
                            min(fails) if fails else np.nan, tuple(tried))
