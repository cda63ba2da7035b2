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
           "evaluate_deployment"]

_PENALTY = 1e3


def workspace_box(box: Any, field: str = "workspace") -> np.ndarray:
    """Validate a workspace box ``[[xmin, ymin, zmin], [xmax, ymax, zmax]]`` (m) -> (2, 3).

    Raises :class:`InvalidInputError` on NaN/inf, a wrong shape, or a box with no volume
    (some ``max <= min``)."""
    b = as_array(box, field)
    if b.shape == (6,):                       # CLI order: xmin xmax ymin ymax zmin zmax
        b = b.reshape(3, 2).T
    if b.shape != (2, 3):
        raise InvalidInputError(field, "must be [[xmin, ymin, zmin], [xmax, ymax, zmax]] or "
                                       "xmin xmax ymin ymax zmin zmax")
    if np.any(b[1] <= b[0]):
        k = int(np.argmax(b[1] <= b[0]))
        raise InvalidInputError(field, f"box has no volume: {'xyz'[k]}max {b[1, k]:g} <= "
                                       f"{'xyz'[k]}min {b[0, k]:g}")
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


@dataclass(frozen=True)
class DeploymentResult:
    """Outcome of :func:`plan_deployment`.

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
        Worst capacity margin over the verification points (N / N m, > 0 when feasible).
    twist_margin : float or None
        Worst ATS margin of the required twist (m/s, rad/s), None without a required twist.
    points : (P, 3)
        Verification points, m.
    point_margin : (P,)
    point_feasible : (P,) bool
        Exact wrench feasibility with tipping at each point.
    workspace : (2, 3)
    reason : str
        Empty when feasible; otherwise why no deployment was found.
    evaluations : int
        Candidate placements evaluated.
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


def evaluate_deployment(robot: CableRobot, box: np.ndarray, points: np.ndarray, disturbance,
                        twist, limits, moving) -> tuple[float, np.ndarray, float | None]:
    """Score one placement: (worst wrench margin, per-point margins, worst twist margin).

    Raises :class:`TautError` (e.g. a sample point outside the frame box)."""
    pm = capacity_margin(robot, points, disturbance=disturbance, tipping=True)
    tm = None
    if twist is not None:
        ats = available_twist_set(robot, points, limits, "task", moving)
        tm = float(ats.margin(twist).min())
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
            wm, pm, _ = evaluate_deployment(rr, box, P, D, None, limits, moving)
        except TautError:
            return -_PENALTY * 5, None
        val = wm
        if tw is not None:
            ats = available_twist_set(rr, P, limits, "task", moving)
            tm = min(float(ats.margin(t).min()) for t in tw)
            if tm < 0:
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
    names = [b.name for b in mobile]
    poses = {n: best[3 * i:3 * i + 3].copy() for i, n in enumerate(names)}
    try:
        wm, pm, _ = evaluate_deployment(rr, box, vpts, D, None, limits, moving)
        pf = wrench_feasible(rr, vpts, tipping=True, disturbance=D)
    except TautError as exc:
        return DeploymentResult(False, poses, rr, -np.inf, None, vpts, np.full(len(vpts),
                                -np.inf), np.zeros(len(vpts), bool), box,
                                f"no placement keeps the workspace inside the frame: {exc}",
                                count[0])
    tm = None
    if tw is not None:
        ats = available_twist_set(rr, vpts, limits, "task", moving)
        tm = min(float(ats.margin(t).min()) for t in tw)
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
    return DeploymentResult(ok, poses, rr, wm, tm, vpts, pm, pf, box, reason, count[0])
