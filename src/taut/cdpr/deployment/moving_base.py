"""Deployment with the active base moving during the task (FASTKIT §2: in task mode the
active base moves while the passive one stays put): a piecewise-constant base schedule.

Policy (documented choice; the paper gives none): the workspace box is cut along x into
``stages`` equal slices. The bases that do not move in task mode stay at one placement
for the whole task; each moving base has one placement ``(x, y, theta)`` per slice and
is parked there while the platform works in that slice. Between slices the platform
waits at one point of the face the two slices share while the moving base drives from one
placement to the next (quasi-statically, along the straight line in ``(x, y, theta)``) on
its wheels: its stabilisers are retracted for the drive (tipping with the wheel footprint,
from the first placement to the second, both included) and deployed again once in place
(FASTKIT §2; :func:`plan_base_drive` checks one such drive over time). The waiting point is
the lowest point of the face's grid held all along the drive: the wheel footprint's
tipping margin grows as the platform comes down.

Verification, exact (:func:`taut.cdpr.wrench_feasible` with tipping): every point of
each slice's grid with the bases of that stage, the required twist there (task mode),
no base footprint over *that slice* seen from above (the base may enter the part of the
box the platform is not working in), and, per change of stage, one point of the shared
face held at both placements and ``transitions`` base poses interpolated between them, the
moving bases on their wheels.

Search: the fixed bases first get the placement of :func:`taut.cdpr.plan_deployment` on
the whole box (its best candidate even when that is not verified), then each stage's
moving-base placement is searched alone on its slice by the same seeded optimiser.

Certificate: a slice is deployed with one placement, so :func:`taut.cdpr.lift_bound` of a
slice refuting it refutes the staged plan for every placement (``lift_bound`` of the
whole box is *not* valid for a moving base: it bounds one placement for all points).
Units: m, rad, N.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any, Sequence, cast

import numpy as np
from numpy.typing import ArrayLike

from ..._outcome import check_status
from ..._validate import as_array, as_count, require_instance
from ...errors import InvalidInputError, TautError
from ..statics._common import wrench_vertices
from .deploy import (DeploymentResult, _options, _PlacementScore, _required_twists, _search,
    _verify, plan_deployment)
from .lift import LiftBound, lift_bound
from ..model.robot import CableRobot
from ..control._setup import DRIVE_TENSION_METHOD, BaseMotion, _robot_at, drive_tensions
from ..statics.tension import distribute_tensions
from ..kinematics._bases import as_base_poses
from ..kinematics.modes import MotionLimits, fastkit_motion_limits, resolve_mode
from .placement import place_bases, workspace_box
from ..workspace.wrench_feasible import grid_points
from ..sets.wrench import wrench_feasible
from ..._repr import CompactRepr

#: Most stages (placements of the moving base) a deployment may use: each adds a full
#: placement search, and the per-slice certificate already stops refuting at 5 (FASTKIT).
MAX_STAGES = 50
#: Most interpolated base poses checked per change of stage.
MAX_TRANSITIONS = 100

__all__ = ["MovingDeploymentResult", "plan_moving_deployment", "staged_lift_bound",
           "BaseDrivePlan", "plan_base_drive"]


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


@dataclass(frozen=True, repr=False)
class MovingDeploymentResult(CompactRepr):
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
        A point of the shared face holds the platform at every base pose of the drive
        (both placements and the interpolated poses), the moving bases on their wheels.
    transition_wait_m : (k - 1, 3)
        Where the platform waits during each drive (the lowest such point of the face's
        grid), m; NaN where none is held.
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
    transition_wait_m: np.ndarray
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


def _transition_wait(robot: CableRobot, a: np.ndarray, b: np.ndarray, face: np.ndarray,
                     n: int, D: np.ndarray | None) -> np.ndarray:
    """The lowest face point (of ``face``, (F, 3)) held with tipping at placements a, b and
    ``n`` base poses between them (``robot``: the moving bases on their wheels), m; NaN
    when no face point is held all along."""
    held = np.ones(len(face), dtype=bool)
    for s in np.linspace(0.0, 1.0, n + 2):
        try:
            rr = place_bases(robot, ((1 - s) * a + s * b).reshape(-1, 3))
            held[held] = wrench_feasible(rr, face[held], tipping=True, external_wrench=D)
        except TautError:
            held[:] = False
        if not held.any():
            return np.full(3, np.nan)
    return face[held][np.argmin(face[held, 2])]


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
                                      np.zeros(0, bool), np.zeros((0, 3)), np.nan, box,
                                      robot, 0, cert)
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
    wheels = _stabilisers(robot, [b.stabilisers_deployed and b.name not in movers
                                  for b in robot.bases])     # movers drive on their wheels
    wait = np.array([_transition_wait(wheels, poses[k], poses[k + 1],
                                      grid_points(np.stack([[sb[1, 0], *box[0, 1:]],
                                                            [sb[1, 0], *box[1, 1:]]]),
                                                  (1, ny, nz))[0], transitions, D)
                     for k, sb in enumerate(slices[:-1])]).reshape(-1, 3)
    trans = ~np.isnan(wait[:, 0])
    ok = all(r.success for r in results) and bool(trans.all())
    margin = float(min(r.margin for r in results))
    bad = [k for k, r in enumerate(results) if not r.success]
    message = (f"verified {stages} stages: worst capacity margin {margin:.3g}" if ok else
               "; ".join([f"stage {k}: {results[k].message}" for k in bad]
                         + [f"transition {k} -> {k + 1}: no point of the shared face holds "
                            "the platform while the base drives on its wheels"
                            for k in np.nonzero(~trans)[0]]))
    return MovingDeploymentResult(ok, "ok" if ok else "budget_exhausted", message,
                                  tuple(results), slices,
                                  tuple(r.base_poses for r in results), trans, wait, margin, box,
                                  results[0].robot, calls, cert)


@dataclass(frozen=True, repr=False)
class BaseDrivePlan(CompactRepr):
    """Outcome of :func:`plan_base_drive`: the platform held while bases drive on their
    wheels, then their stabilisers deployed in place.

    Attributes
    ----------
    success : bool
        Every sample of the drive and the final, deployed state hold the platform within
        the tension limits with every base upright.
    status : str
        ``"ok"`` or ``"infeasible"``.
    message : str
        Where it fails first: time, platform and base poses, the library's reason (a base
        tips, or the tension limits).
    times_s : (S,)
        Sample times, s (those of the base motion).
    base_poses_m_rad : (S, K, 3)
        ``(x, y, theta)`` of every base, m and rad.
    stabilisers_deployed : (S + 1, K) bool
        Stabiliser state of every base at each sample, then (last row) once in place: a
        base that drives has them retracted all along the drive and deployed in the last
        row (one switch); the others keep the state they have in ``robot``.
    tensions_N : (S, m)
        Tension distribution keeping the bases upright (FASTKIT eqs. 21-23 imposed), N;
        NaN where none exists. The reference tensions :func:`taut.cdpr.simulate` uses for
        the same drive.
    tipping_margins_Nm : (S, E)
        ``-m_C`` of every base edge (eqs. 21-23) under ``tensions_N``, N m; >= 0 upright.
    final_tensions_N : (m,)
        Tensions of the final state (stabilisers deployed), N.
    final_tipping_margins_Nm : (E,)
        Edge margins of the final state, N m.
    min_tipping_margin_Nm : float
        Smallest margin over the drive and the final state, N m (NaN when infeasible).
    failed_at_s : float
        Time of the first sample no distribution holds, s (the last sample's when only the
        deployed state fails; NaN on success).
    drive_robot : CableRobot
        The robot while driving: the moving bases on their wheels (stabilisers retracted),
        the others as given.
    final_robot : CableRobot
        The robot in place: bases at their final poses, the moving bases' stabilisers
        deployed.
    """

    success: bool
    status: str
    message: str
    times_s: np.ndarray
    base_poses_m_rad: np.ndarray
    stabilisers_deployed: np.ndarray
    tensions_N: np.ndarray
    tipping_margins_Nm: np.ndarray
    final_tensions_N: np.ndarray
    final_tipping_margins_Nm: np.ndarray
    min_tipping_margin_Nm: float
    failed_at_s: float
    drive_robot: CableRobot
    final_robot: CableRobot

    def __post_init__(self) -> None:
        check_status(self.status)


def _stabilisers(robot: CableRobot, deployed: Sequence[bool]) -> CableRobot:
    """``robot`` with the stabilisers of each base deployed or retracted (bases without
    stabilisers unchanged)."""
    bases = tuple(replace(b, exit_points=dict(b.exit_points),
                          stabilisers_deployed=bool(d and b.stabilisers is not None))
                  if b.mobile else b for b, d in zip(robot.bases, deployed))
    return replace(robot, bases=bases)


def _drive_robots(robot: CableRobot, base_poses: np.ndarray
                  ) -> tuple[CableRobot, CableRobot, np.ndarray]:
    """The robot while driving (bases that move in ``base_poses`` (S, K, 3) on their
    wheels), in place (at the last poses, those bases' stabilisers deployed) and the
    stabiliser states (S + 1, K)."""
    moves = np.any(np.abs(base_poses - base_poses[:1]) > 0.0, axis=(0, 2))
    before = [b.stabilisers_deployed and not mv for b, mv in zip(robot.bases, moves)]
    drive = _stabilisers(robot, before)
    final = _stabilisers(_robot_at(robot, base_poses[-1]),
                         [b.stabilisers_deployed or mv for b, mv in zip(robot.bases, moves)])
    states = np.array([[b.stabilisers_deployed for b in drive.bases]] * len(base_poses)
                      + [[b.stabilisers_deployed for b in final.bases]], dtype=bool)
    return drive, final, states


def plan_base_drive(robot: CableRobot, pose: ArrayLike, base_motion: BaseMotion
                    ) -> BaseDrivePlan:
    """Check a physical deployment drive (FASTKIT §2: a mobile base drives on its wheels
    with its stabilisers retracted and deploys them once in place) while the cables hold
    the platform at ``pose``.

    The bases that move in ``base_motion`` drive on their wheels: their tipping limits
    (FASTKIT eqs. 21-23) use the wheel footprint; the other bases stand as in ``robot``.
    At every sample of ``base_motion`` the tensions are distributed with the tipping limits
    imposed (the exact min-norm QP, :func:`taut.cdpr.distribute_tensions` with
    ``tipping=True``; the same tensions :func:`taut.cdpr.simulate` uses as reference for
    this drive); at the end the bases that drove deploy their stabilisers (the support
    polygon grows to the hull of wheels and feet) and the final state is checked the same
    way. Quasi-static: the bases' own accelerations (FASTKIT's 0.2 m/s drives) are not in
    the tipping moments.

    Parameters
    ----------
    robot : CableRobot
        Bases at their start poses.
    pose : (6,)
        Platform pose held during the drive, m and rad.
    base_motion : BaseMotion
        Poses of every base over time.

    Returns
    -------
    BaseDrivePlan
        ``success=False`` with the first time, base poses and the reason when no tension
        distribution keeps every base upright.

    Examples
    --------
    >>> from taut.io.cdpr_model import load_cdpr_model
    >>> from taut.cdpr import BaseMotion, with_stabilisers
    >>> robot = with_stabilisers(load_cdpr_model("fastkit"))
    >>> drive = BaseMotion.line(robot, "active", (0.5, 0.0, 0.0), duration=5.0, samples=11)
    >>> plan_base_drive(robot, [0.3, 0.0, 0.7, 0, 0, 0], drive).success
    True
    >>> bad = plan_base_drive(robot, [0.3, 0.0, 1.0, 0, 0, 0], drive)
    >>> bad.success, bad.failed_at_s, bad.message[:60]
    (False, 0.0, 'no tension distribution keeps the bases upright at t = 0.000')
    """
    require_instance(robot, CableRobot, "robot")
    require_instance(base_motion, BaseMotion, "base_motion")
    p = as_array(pose, "pose", shape=(6,))
    if not any(b.mobile for b in robot.bases):
        raise InvalidInputError("robot", "has no mobile base to drive")
    bp = as_base_poses(robot, base_motion.poses, "base_motion.poses")
    drive, final, states = _drive_robots(robot, bp)
    t, ok, mom = drive_tensions(drive, bp, np.repeat(p[None], len(bp), axis=0))
    tf, okf, momf = drive_tensions(final, bp[-1:], p[None])
    margins, final_margins = -mom.reshape(len(bp), -1), -momf.reshape(-1)
    times = base_motion.times
    if ok.all() and okf.all():
        low = float(min(margins.min(initial=np.inf), final_margins.min(initial=np.inf)))
        shown = round(low, 1) + 0.0                                # + 0.0: no "-0.0"
        return BaseDrivePlan(True, "ok", f"drive held with every base upright: smallest "
                             f"tipping margin {shown:.1f} N m", times, bp, states, t, margins,
                             tf[0], final_margins, low, np.nan, drive, final)
    i = int(np.argmin(ok)) if not ok.all() else len(bp) - 1
    at = _robot_at(drive, bp[i]) if not ok.all() else final
    why = distribute_tensions(at, p, DRIVE_TENSION_METHOD, tipping=True).message
    state = (f"at t = {times[i]:.3f} s" if not ok.all() else
             f"once the stabilisers are deployed (t = {times[i]:.3f} s)")
    msg = (f"no tension distribution keeps the bases upright {state}: platform at "
           f"{np.round(p, 4).tolist()}, base poses {np.round(bp[i], 4).tolist()} "
           f"(moving bases on their wheels): {why}")
    return BaseDrivePlan(False, "infeasible", msg, times, bp, states, t, margins, tf[0],
                         final_margins, np.nan, float(times[i]), drive, final)
