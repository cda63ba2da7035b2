"""Deployment with the active base moving during the task (FASTKIT §2: in task mode the
active base moves while the passive one stays put): a piecewise-constant base schedule.

Policy (documented choice; the paper gives none): the workspace box is cut along x into
``stages`` equal slices. The bases that do not move in task mode stay at one placement
for the whole task; each moving base has one placement ``(x, y, theta)`` per slice and
is parked there while the platform works in that slice. Between slices the platform
waits on the face the two slices share while the moving base drives from one placement
to the next (quasi-statically, along the straight line in ``(x, y, theta)``).

Verification, exact (:func:`taut.cdpr.wrench_feasible` with tipping): every point of
each slice's grid with the bases of that stage, the required twist there (task mode),
no base footprint over *that slice* seen from above (the base may enter the part of the
box the platform is not working in), and every point of each shared face at
``transitions`` base poses interpolated between the two stages.

Search: the fixed bases first get the placement of :func:`taut.cdpr.plan_deployment` on
the whole box (its best candidate even when that is not verified), then each stage's
moving-base placement is searched alone on its slice by the same seeded optimiser.

Certificate: a slice is deployed with one placement, so :func:`taut.cdpr.lift_bound` of a
slice refuting it refutes the staged plan for every placement (``lift_bound`` of the
whole box is *not* valid for a moving base: it bounds one placement for all points).
Units: m, rad, N.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence, cast

import numpy as np
from numpy.typing import ArrayLike

from ..._outcome import check_status
from ..._validate import as_count, require_instance
from ...errors import InvalidInputError, TautError
from ..statics._common import wrench_vertices
from .deploy import (DeploymentResult, _options, _PlacementScore, _required_twists, _search,
    _verify, plan_deployment)
from .lift import LiftBound, lift_bound
from ..model.robot import CableRobot
from ..kinematics.modes import MotionLimits, fastkit_motion_limits, resolve_mode
from .placement import place_bases, workspace_box
from ..workspace.wrench_feasible import grid_points
from ..sets.wrench import wrench_feasible

#: Most stages (placements of the moving base) a deployment may use: each adds a full
#: placement search, and the per-slice certificate already stops refuting at 5 (FASTKIT).
MAX_STAGES = 50
#: Most interpolated base poses checked per change of stage.
MAX_TRANSITIONS = 100

__all__ = ["MovingDeploymentResult", "plan_moving_deployment", "staged_lift_bound"]


def slice_box(box: np.ndarray, stages: int) -> np.ndarray:
    """The ``stages`` slices (k, 2, 3) of ``box`` (2, 3) along x, equal widths, m."""
    edges = np.linspace(box[0, 0], box[1, 0], stages + 1)
    out = np.repeat(box[None], stages, axis=0)
    out[:, 0, 0], out[:, 1, 0] = edges[:-1], edges[1:]
    return out


def staged_lift_bound(robot: CableRobot, workspace: ArrayLike, stages: int, *,
                      external_wrench: ArrayLike | None = None,
                      samples: Sequence[int] = (41, 5)) -> LiftBound:
    """The lift certificate of a staged deployment: :func:`lift_bound` of every slice; the
    one with the least slack (bound minus required force) is returned, and it refutes the
    staged plan when it refutes its slice. Samples along x are split over the slices."""
    require_instance(robot, CableRobot, "robot")
    stages = as_count(stages, "stages", minimum=1, maximum=MAX_STAGES)
    if isinstance(samples, (str, bytes)) or np.ndim(samples) != 1 or len(samples) != 2:
        raise InvalidInputError("samples", "must be two counts (along x, along z)")
    samples = tuple(as_count(s, "samples", minimum=2, maximum=100_000) for s in samples)
    box = workspace_box(workspace, allow_flat=True)
    nx = int(samples[0]) if stages == 1 else max(2, int(np.ceil(samples[0] / stages)) + 1)
    certs = [lift_bound(robot, b, external_wrench=external_wrench, samples=(nx, samples[1]))
             for b in slice_box(box, stages)]
    return min(certs, key=lambda c: c.bound - c.required)


@dataclass(frozen=True)
class MovingDeploymentResult:
    """Outcome of :func:`plan_moving_deployment`.

    Attributes
    ----------
    success : bool
        Every stage verified (see :class:`DeploymentResult`) and every transition feasible.
    status : str
        ``"ok"``, ``"refuted"`` (a slice is refuted by the lift certificate: no schedule of
        this policy exists) or ``"budget_exhausted"`` (none verified; no proof).
    message : str
    stages : tuple of DeploymentResult
        Per slice: its verified (or best) placement, points, margins (empty when refuted).
    slices : (k, 2, 3)
        The slice boxes, m.
    base_poses : tuple of dict
        ``(x, y, theta)`` of every mobile base at each stage, m and rad.
    transition_feasible : (k - 1,) bool
        Platform on the shared face held at every interpolated base pose.
    margin : float
        Worst capacity margin over every stage (N / N m; NaN when refuted).
    workspace : (2, 3)
    robot : CableRobot
        The robot of the first stage (fixed bases at their placement).
    evaluations : int
        Candidate placements evaluated (the fixed plan and every stage).
    lift_bound : LiftBound
        :func:`staged_lift_bound`.
    """

    success: bool
    status: str
    message: str
    stages: tuple[DeploymentResult, ...]
    slices: np.ndarray
    base_poses: tuple[dict, ...]
    transition_feasible: np.ndarray
    margin: float
    workspace: np.ndarray
    robot: CableRobot
    evaluations: int
    lift_bound: LiftBound

    def __post_init__(self) -> None:
        check_status(self.status)

    @property
    def refuted(self) -> bool:
        """True when the certificate proved that no schedule of this policy exists."""
        return self.status == "refuted"


class _StageScore:
    """The placement objective with only the moving bases' coordinates free."""

    def __init__(self, inner: _PlacementScore, full: np.ndarray, free: np.ndarray) -> None:
        self.inner, self.full, self.free = inner, full, free

    def __call__(self, x: np.ndarray) -> float:
        v = self.full.copy()
        v[self.free] = x
        return self.inner(v)


def _transition_ok(robot: CableRobot, a: np.ndarray, b: np.ndarray, face: np.ndarray,
                   n: int, D: np.ndarray | None) -> bool:
    """Face points (F, 3) held with tipping at ``n`` base poses between placements a, b."""
    for s in np.linspace(0.0, 1.0, n + 2)[1:-1]:
        try:
            rr = place_bases(robot, ((1 - s) * a + s * b).reshape(-1, 3))
            if not wrench_feasible(rr, face, tipping=True, external_wrench=D).all():
                return False
        except TautError:
            return False
    return True


def plan_moving_deployment(robot: CableRobot, workspace: ArrayLike, *, stages: int = 2,
                           external_wrench: ArrayLike | None = None,
                           required_twist: ArrayLike | None = None,
                           limits: MotionLimits | None = None,
                           moving: Sequence[str] | None = None, transitions: int = 4,
                           **settings: Any) -> MovingDeploymentResult:
    """Deploy a mobile CDPR whose moving (active) base changes place during the task.

    Parameters
    ----------
    robot, workspace, external_wrench, required_twist, limits
        As for :func:`taut.cdpr.plan_deployment`.
    stages : int
        Number of slices along x, one moving-base placement each (1: a fixed placement
        with the footprint rule of this module).
    moving : sequence of str, optional
        Bases that move between stages (default: the first mobile base, as in task mode).
    transitions : int
        Interpolated base poses checked per change of stage.
    **settings
        Search settings of :class:`taut.cdpr.DeploymentOptions` (``grid`` and
        ``verify_grid`` apply to each slice).

    Returns
    -------
    MovingDeploymentResult
    """
    require_instance(robot, CableRobot, "robot")
    box = workspace_box(workspace)
    stages = as_count(stages, "stages", minimum=1, maximum=MAX_STAGES)
    transitions = as_count(transitions, "transitions", minimum=0, maximum=MAX_TRANSITIONS)
    mobile = [b.name for b in robot.bases if b.mobile]
    if not mobile:
        raise InvalidInputError("robot", "has no mobile base to deploy")
    opts = _options(None, settings)
    limits = fastkit_motion_limits() if limits is None else limits
    movers = [robot.bases[k].name for k in resolve_mode(robot, "task", moving).moving]
    D = None if external_wrench is None else wrench_vertices(robot, external_wrench)
    tw = _required_twists(robot, required_twist)
    cert = staged_lift_bound(robot, box, stages, external_wrench=D)
    slices = slice_box(box, stages)
    if cert.refutes:
        return MovingDeploymentResult(False, "refuted", cert.explain(), (), slices, (),
                                      np.zeros(0, bool), np.nan, box, robot, 0, cert)
    fixed = plan_deployment(robot, box, external_wrench=D, required_twist=tw, limits=limits,
                            moving=moving, options=opts)
    full = np.concatenate([fixed.base_poses[n] for n in mobile])
    free = np.concatenate([np.arange(3 * i, 3 * i + 3) for i, n in enumerate(mobile)
                           if n in movers])
    half = np.tile(opts.search, len(free) // 3)
    results, poses, calls = [], [], fixed.evaluations
    for sb in slices:
        pts, _ = grid_points(sb, opts.grid)
        inner = _PlacementScore(robot, sb, pts, D, tw, limits, moving)
        best = full.copy()
        best[free] = _search(cast(Any, _StageScore(inner, full, free)), full[free], half, opts)
        res = _verify(robot, best, sb, mobile, D, tw, limits, moving, opts, inner.calls,
                      lift_bound(robot, sb, external_wrench=D))
        calls += inner.calls
        results.append(res)
        poses.append(best)
    ny, nz = opts.verify_grid[1], opts.verify_grid[2]
    trans = np.array([_transition_ok(robot, poses[k], poses[k + 1],
                                     grid_points(np.stack([[sb[1, 0], *box[0, 1:]],
                                                           [sb[1, 0], *box[1, 1:]]]),
                                                 (1, ny, nz))[0], transitions, D)
                      for k, sb in enumerate(slices[:-1])], dtype=bool)
    ok = all(r.success for r in results) and bool(trans.all())
    margin = float(min(r.margin for r in results))
    bad = [k for k, r in enumerate(results) if not r.success]
    message = (f"verified {stages} stages: worst capacity margin {margin:.3g}" if ok else
               "; ".join([f"stage {k}: {results[k].message}" for k in bad]
                         + [f"transition {k} -> {k + 1} not held"
                            for k in np.nonzero(~trans)[0]]))
    return MovingDeploymentResult(ok, "ok" if ok else "budget_exhausted", message,
                                  tuple(results), slices,
                                  tuple(r.base_poses for r in results), trans, margin, box,
                                  results[0].robot, calls, cert)
