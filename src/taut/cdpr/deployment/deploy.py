"""Deployment planning of mobile CDPRs: where to park the mobile bases so that a desired
platform workspace is wrench-feasible without tipping a base and a required twist is
available everywhere in it (FASTKIT §2: "the system calculates the required mobile base
position from the desired workspace"; §3.2 twist sets, §4 wrench sets with eqs. 21-24).

Decision variables: ``(x, y, theta)`` of every mobile base (fixed frames stay put).

Deployment margin (maximised): the worst capacity margin of the required wrench set over a
grid of sample points of the workspace box, with tipping constraints
(:func:`taut.cdpr.capacity_margin`: distance, in mixed N / N m units, from the required
set to the available-wrench-set boundary; negative when infeasible). Constraints, handled
by penalties: every sample point inside the deployed frame box, the required twist inside
the available twist set (task mode) at every sample point, and no base footprint
overlapping the workspace box seen from above. Optimiser: scipy's seeded
``differential_evolution`` started from the model's placement, then a Nelder-Mead polish.
The winner is re-verified on a finer grid with the exact feasibility test
(:func:`taut.cdpr.wrench_feasible`, tipping on).

Before searching, :func:`plan_deployment` checks a placement-independent necessary
condition (:func:`taut.cdpr.lift_bound`): if even the best conceivable exit positions
cannot lift platform and payload on average over the top face of the box, no placement
exists and the optimiser is not run (status ``"refuted"``). Box validation and placement
live in :mod:`taut.cdpr.deployment.placement`, the certificate in :mod:`taut.cdpr.deployment.lift`, the
tallest-box bisection in :mod:`taut.cdpr.deployment.tallest`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import differential_evolution, minimize

from ..._outcome import check_status
from ..._validate import MAX_SPEED, as_array, check_range
from ...errors import InvalidInputError, TautError
from ..statics._common import wrench_vertices
from .._tol import DEPLOY_DE_TOL, DEPLOY_NM_FATOL, DEPLOY_NM_XATOL, FIXED_COORD_WIDTH
from .lift import LiftBound, lift_bound
from ..model.robot import CableRobot
from ..kinematics.cables import as_poses
from ..kinematics.modes import MotionLimits, fastkit_motion_limits
from .placement import footprint_overlap, place_bases, workspace_box
from ..sets.twist import ats_blocks
from ..workspace.wrench_feasible import grid_points
from ..sets.wrench import capacity_margin, wrench_feasible
from ..._validate import require_instance
from ..._repr import CompactRepr

__all__ = ["DeploymentOptions", "DeploymentResult", "plan_deployment", "evaluate_deployment"]

#: Penalty weight (per metre outside the frame, per m/s of twist shortfall, per metre of
#: footprint overlap) added to the negative capacity margin; large against margins of a
#: few N so that any constraint violation ranks below every admissible placement.
_PENALTY = 1e3


@dataclass(frozen=True)
class DeploymentOptions:
    """Search settings of :func:`plan_deployment`.

    Attributes
    ----------
    grid : (3,) ints
        Sample points per axis used during the search.
    verify_grid : (3,) ints
        Finer grid for the final verification.
    search : (dx, dy, dtheta)
        Half-widths of the search region around the model's placement, m, m, rad.
    maxiter, popsize, seed : int
        Differential-evolution settings (seeded: the result is reproducible).
    """

    grid: Sequence[int] = (6, 2, 4)
    verify_grid: Sequence[int] = (21, 3, 9)
    search: Any = (1.0, 0.5, 0.4)
    maxiter: int = 12
    popsize: int = 6
    seed: int = 0

    def __post_init__(self) -> None:
        sr = as_array(self.search, "search", shape=(3,))
        if np.any(sr < 0):
            raise InvalidInputError("search", "half-widths must be non-negative")
        object.__setattr__(self, "search", sr)
        for name, low in (("maxiter", 0), ("popsize", 1), ("seed", 0)):
            value = getattr(self, name)
            integer = isinstance(value, (int, np.integer)) and not isinstance(value, bool)
            if not (integer and low <= value < 2 ** 32):
                raise InvalidInputError(name, f"must be an integer from {low} to 2**32 - 1, "
                                              f"got {value!r}")


@dataclass(frozen=True, repr=False)
class DeploymentResult(CompactRepr):
    """Outcome of :func:`plan_deployment`.

    When the placement-independent certificate refutes the box (``lift_bound.refutes``)
    the search is skipped: ``success`` is False, ``status`` is ``"refuted"``,
    ``base_poses`` and ``robot`` are the input placement (meaningless for the answer),
    ``margin`` is NaN, ``twist_margin`` None, ``points``/``point_margin``/
    ``point_feasible`` are empty, ``evaluations`` is 0 and ``message`` is
    :meth:`LiftBound.explain`.

    Attributes
    ----------
    success : bool
        Verified: every verification point wrench-feasible with tipping, the required twist
        available there, no footprint over the workspace.
    status : str
        ``"ok"``; ``"refuted"`` (the lift certificate proves that no placement exists);
        ``"budget_exhausted"`` (the seeded search found no verified placement: no proof
        either way).
    message : str
        What was found, or why not.
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
    evaluations : int
        Candidate placements evaluated.
    lift_bound : LiftBound or None
        The placement-independent certificate checked first (:func:`lift_bound`).
    """

    success: bool
    status: str
    message: str
    base_poses: dict
    robot: CableRobot
    margin: float
    twist_margin: float | None
    points: np.ndarray
    point_margin: np.ndarray
    point_feasible: np.ndarray
    workspace: np.ndarray
    evaluations: int
    lift_bound: LiftBound | None = None

    def __post_init__(self) -> None:
        check_status(self.status)

    @property
    def refuted(self) -> bool:
        """True when the certificate proved that no placement exists (no search was run)."""
        return self.status == "refuted"


def evaluate_deployment(robot: CableRobot, points: np.ndarray,
                        external_wrench: np.ndarray | None, twists: np.ndarray | None,
                        limits: MotionLimits, moving: Sequence[str] | None
                        ) -> tuple[float, np.ndarray, float | None]:
    """Score one placement: (worst wrench margin, per-point margins, worst twist margin).

    ``twists`` (T, n) or None: required twists, the worst ATS margin over points and
    twists is returned (None without twists). Raises :class:`TautError` (e.g. a sample
    point outside the frame box)."""
    require_instance(robot, CableRobot, "robot")
    points = as_array(points, "points", shape=(None, 3))
    pm = capacity_margin(robot, points, external_wrench=external_wrench, tipping=True)
    tm = None
    if twists is not None:
        twists = check_range(twists, "twists", MAX_SPEED, "m/s or rad/s")
        if twists.ndim not in (1, 2) or twists.shape[-1] != robot.dof or not twists.size:
            raise InvalidInputError("twists", f"must be (T, {robot.dof}) required twists")
        twists = twists.reshape(-1, robot.dof)
        tm = np.inf
        poses = as_poses(robot, points, "points", check_bounds=False)  # checked above
        for _, ats in ats_blocks(robot, poses, limits, "task", moving):    # one block's
            tm = min(tm, *(float(ats.margin(t).min()) for t in twists))  # facets at a time
            del ats                     # before the next block is built, not after
    return float(pm.min()), pm, tm


@dataclass
class _PlacementScore:
    """The penalised objective of the search (to be maximised), counting its calls."""

    robot: CableRobot
    box: np.ndarray
    points: np.ndarray
    external_wrench: np.ndarray | None
    twists: np.ndarray | None
    limits: MotionLimits
    moving: Sequence[str] | None
    calls: int = field(default=0)

    def score(self, x: np.ndarray) -> float:
        self.calls += 1
        try:
            rr = place_bases(self.robot, x.reshape(-1, 3))
        except TautError:
            return -_PENALTY * 10
        lo, hi = rr.bounds
        out = np.maximum(lo - self.box[0], 0).sum() + np.maximum(self.box[1] - hi, 0).sum()
        if out > 0:
            return -_PENALTY * (1 + out)
        try:
            wm, _, tm = evaluate_deployment(rr, self.points, self.external_wrench, self.twists,
                                            self.limits, self.moving)
        except TautError:
            return -_PENALTY * 5
        val = wm
        if tm is not None and tm < 0:
            val -= _PENALTY * (-tm) + 1.0
        ov = footprint_overlap(rr, self.box)
        if ov > 0:
            val -= _PENALTY * ov + 1.0
        return val

    def __call__(self, x: np.ndarray) -> float:
        return -self.score(x)


def _search(objective: _PlacementScore, x0: np.ndarray, half: np.ndarray,
            opts: DeploymentOptions) -> np.ndarray:
    """Seeded differential evolution from the model's placement, then Nelder-Mead."""
    bounds = [(a - h, a + h) if h > 0 else (a, a + FIXED_COORD_WIDTH) for a, h in zip(x0, half)]
    de = differential_evolution(objective, bounds, x0=x0, seed=opts.seed,
                                maxiter=opts.maxiter, popsize=opts.popsize, polish=False,
                                tol=DEPLOY_DE_TOL, init="sobol")
    loc = minimize(objective, de.x, method="Nelder-Mead",
                   options={"maxfev": 60 * len(x0), "xatol": DEPLOY_NM_XATOL,
                            "fatol": DEPLOY_NM_FATOL})
    best = loc.x if loc.fun <= de.fun else de.x
    return np.clip(best, [b[0] for b in bounds], [b[1] for b in bounds])


def _failure_message(pf: np.ndarray, pm: np.ndarray, vpts: np.ndarray, tm: float | None,
                     ov: float) -> str:
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
    return "best placement found: " + "; ".join(why)


def _required_twists(robot: CableRobot, required_twist: ArrayLike | None) -> np.ndarray | None:
    if required_twist is None:
        return None
    tw = as_array(required_twist, "required_twist")
    if tw.shape[-1] != robot.dof or tw.ndim > 2:
        raise InvalidInputError("required_twist", f"must have {robot.dof} components")
    return tw.reshape(-1, robot.dof)


def plan_deployment(robot: CableRobot, workspace: ArrayLike, *,
                    external_wrench: ArrayLike | None = None,
                    required_twist: ArrayLike | None = None,
                    limits: MotionLimits | None = None, moving: Sequence[str] | None = None,
                    options: DeploymentOptions | None = None, **settings: Any
                    ) -> DeploymentResult:
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
    external_wrench : (V, n), optional
        Extra external wrenches on top of platform and payload weight (vertices, e.g.
        :func:`taut.cdpr.external_wrench_box`), N and N m.
    required_twist : (n,) or (T, n), optional
        Twists (m/s, rad/s) that must be available everywhere (task mode).
    limits : MotionLimits, optional
        Default :func:`taut.cdpr.fastkit_motion_limits`.
    moving : sequence of str, optional
        Bases moving in task mode (default the first mobile base).
    options : DeploymentOptions, optional
        Search settings; the same fields may be given as keywords (``grid=``,
        ``verify_grid=``, ``search=``, ``maxiter=``, ``popsize=``, ``seed=``).

    Returns
    -------
    DeploymentResult
        Checked first: when :func:`lift_bound` refutes the box (no placement can lift
        platform and payload over the top of the box) it is returned at once with
        ``success=False``, ``status="refuted"``, the certificate's sentence as ``message``
        and empty verification arrays.
    """
    require_instance(robot, CableRobot, "robot")
    box = workspace_box(workspace)
    mobile = [b for b in robot.bases if b.mobile]
    if not mobile:
        raise InvalidInputError("robot", "has no mobile base to deploy")
    opts = _options(options, settings)
    limits = fastkit_motion_limits() if limits is None else limits
    D = None if external_wrench is None else wrench_vertices(robot, external_wrench)
    tw = _required_twists(robot, required_twist)
    cert = lift_bound(robot, box, external_wrench=D)
    if cert.refutes:
        return DeploymentResult(False, "refuted", cert.explain(),
                                {b.name: b.pose.copy() for b in mobile}, robot, np.nan, None,
                                np.zeros((0, 3)), np.zeros(0), np.zeros(0, bool), box, 0, cert)
    pts, _ = grid_points(box, opts.grid)
    objective = _PlacementScore(robot, box, pts, D, tw, limits, moving)
    best = _search(objective, np.concatenate([b.pose for b in mobile]),
                   np.tile(opts.search, len(mobile)), opts)
    return _verify(robot, best, box, [b.name for b in mobile], D, tw, limits, moving, opts,
                   objective.calls, cert)


def _options(options: DeploymentOptions | None, settings: dict[str, Any]) -> DeploymentOptions:
    if options is not None and settings:
        raise InvalidInputError("options", "give a DeploymentOptions or keyword settings, "
                                           "not both")
    if options is not None:
        return options
    unknown = set(settings) - {"grid", "verify_grid", "search", "maxiter", "popsize", "seed"}
    if unknown:
        raise TypeError(f"plan_deployment() got unexpected keyword(s) {sorted(unknown)}")
    return DeploymentOptions(**settings)


def _verify(robot: CableRobot, best: np.ndarray, box: np.ndarray, names: list[str],
            D: np.ndarray | None, tw: np.ndarray | None, limits: MotionLimits,
            moving: Sequence[str] | None, opts: DeploymentOptions, calls: int,
            cert: LiftBound) -> DeploymentResult:
    """Re-check the winner on the finer grid with the exact test."""
    rr = place_bases(robot, best.reshape(-1, 3))
    vpts, _ = grid_points(box, opts.verify_grid)
    poses = {n: best[3 * i:3 * i + 3].copy() for i, n in enumerate(names)}
    try:
        wm, pm, tm = evaluate_deployment(rr, vpts, D, tw, limits, moving)
        pf = wrench_feasible(rr, vpts, tipping=True, external_wrench=D)
    except TautError as exc:
        return DeploymentResult(False, "budget_exhausted",
                                f"no placement keeps the workspace inside the frame: {exc}",
                                poses, rr, -np.inf, None, vpts, np.full(len(vpts), -np.inf),
                                np.zeros(len(vpts), bool), box, calls, cert)
    ov = footprint_overlap(rr, box)
    ok = bool(pf.all()) and (tm is None or tm >= 0) and ov == 0
    message = (f"verified on {len(vpts)} points: worst capacity margin {wm:.3g}" if ok else
               _failure_message(pf, pm, vpts, tm, ov))
    return DeploymentResult(ok, "ok" if ok else "budget_exhausted", message, poses, rr, wm, tm,
                            vpts, pm, pf, box, calls, cert)
