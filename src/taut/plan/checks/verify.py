"""Independent verification of a planned motion with the quasi-static model, of the
continuous motion and not only of its samples.

Checked (vectorised over samples):

1. the formation is feasible: the sheet does not tear (FK paper's FormationFeasible),
   every robot pair stays ``sheet_margin`` inside its sheet distance, robot footprints do
   not overlap, also between samples (rigid intervals keep every distance; on the others
   robots move straight, and a pair's least distance has a closed form);
2. the object's rest state, followed continuously. Between two samples related by a rigid
   motion of the whole team (a rotation and a translation, fitted; equal pair distances
   alone would admit a mirror image) the rest state is carried rigidly (the model is
   invariant under planar rigid motions), so it cannot jump there: this is the
   per-interval proof. Every
   other interval (formation changes) is simulated (:func:`taut.sheet.sim.simulate`) with
   samples added adaptively until the object moves at most ``max_object_step`` between
   two; a jump, a lost state, or an interval that cannot be refined below the bound fails
   the plan. The object must be where the plan says (to 1e-6 of the sheet size) wherever
   the plan says it (planned NaN: no claim);
3. the object is at least ``height_safety`` above the ground and above every obstacle
   whose footprint meets the robots' convex hull (the sheet's projection when every cable
   is taut);
4. every robot centre is inside the free space and at least ``robot_radius +
   lateral_safety`` from walls and obstacles, and the robots' hull stays in the free space
   (walls are tall). Checks 3 (obstacles beneath the hull) and 4 are proved for the
   continuous motion between samples too (:mod:`taut.plan.checks._geometry`): each rule is
   a slack, m, that moves no faster than the robots, and every robot's travel between two
   samples is bounded (rigid intervals: centroid step plus radius times turn; formation
   changes: the longest straight robot step), so an interval whose end slacks add up to
   its travel cannot break a rule; others are bisected (rigidly or linearly) until proved,
   until an inserted pose breaks a rule, or until a depth limit (then unproved: refused).
   Between samples the object is taken at its lowest height on the interval (carried
   rigidly; on a formation change, the lowest model sample less ``max_object_step``), and
   the model samples of formation changes keep the height safety above the ground. The
   reported least clearance is the continuous motion's (exact robot paths, to
   ``_tol.CLEARANCE_ACCURACY``), not the samples'.

:func:`resample_motion` refines a sampled motion (rigidly on rigid intervals) so that the
checks can be re-run at any multiple of a plan's sampling.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
import shapely

from ..._outcome import check_status
from ...errors import InvalidInputError, TautError
from ...sheet import check_formations, forward_kinematics
from ...sheet import simulate
from .. import _tol
from ._geometry import Shapes, pair_closest, pair_slack, prove_between, rigid_fits, shapes_of
from ..world import Scenario
from ..._validate import (MAX_SHEET_LENGTH, as_array, as_bounded, as_count, require_instance,
    require_nonempty)
from .._tol import MAX_SHEET_MARGIN_M
from ..._repr import CompactRepr

__all__ = ["Verification", "verify_motion", "resample_motion"]

#: Absolute tolerance of the geometric checks, m (see ``taut.plan._tol``).
TOLERANCE = _tol.GEOMETRY_TOL


@dataclass(frozen=True, eq=False, repr=False)
class Verification(CompactRepr):
    """Outcome of :func:`verify_motion`.

    Attributes
    ----------
    success : bool
    status : {"ok", "refuted"}
        ``refuted``: some check failed (the motion is proved bad).
    message : str
        The first failed check, or a summary.
    object : ndarray, shape (T, 3)
        Object position from the model, m.
    taut : tuple of tuple of int
        Taut cables per sample (0-based).
    min_height_margin : float
        Least (object height - obstacle height) over samples with an obstacle beneath, m
        (inf when none); samples inserted by the proof between samples count, with the
        interval's lowest object height.
    min_clearance : float
        Least robot-centre distance to a wall or obstacle over the continuous motion, m:
        a lower bound within ``_tol.CLEARANCE_ACCURACY`` of it (so it does not depend on
        how finely the motion is sampled).
    min_sheet_slack : float
        Least (sheet distance - robot distance) over samples and robot pairs, m.
    max_object_step : float
        Largest object step between consecutive model samples on non-rigid intervals
        (after refinement), m (0 when every interval is rigid).
    """

    success: bool
    status: str
    message: str
    object: np.ndarray
    taut: tuple[tuple[int, ...], ...]
    min_height_margin: float
    min_clearance: float
    min_sheet_slack: float = np.inf
    max_object_step: float = 0.0

    def __post_init__(self) -> None:
        check_status(self.status)


def _rigid_fit(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Rotation (2, 2) and translation (2,) best mapping points ``a`` onto ``b`` (Kabsch,
    no reflection) and the largest residual."""
    ca, cb = a.mean(axis=0), b.mean(axis=0)
    h = (a - ca).T @ (b - cb)
    ang = np.arctan2(h[0, 1] - h[1, 0], h[0, 0] + h[1, 1])
    rot = np.array([[np.cos(ang), -np.sin(ang)], [np.sin(ang), np.cos(ang)]])
    t = cb - ca @ rot.T
    return rot, t, float(np.abs(a @ rot.T + t - b).max())


def _rigid_mask(robots: np.ndarray, tol: float) -> np.ndarray:
    """Bool (T-1,): sample pairs related by a rigid motion of the plane (a rotation and a
    translation: the best such fit, Kabsch without reflection, leaves every robot within
    ``tol``; equal pair distances alone would also admit a mirror image)."""
    _, fit = rigid_fits(robots[:-1], robots[1:])
    return np.abs(fit - robots[1:]).max(axis=(1, 2)) <= tol


def _follow_rigid(obj: np.ndarray, robots: np.ndarray, t: int) -> np.ndarray:
    rot, tr, _ = _rigid_fit(robots[t], robots[t + 1])
    return np.array([*(obj[:2] @ rot.T + tr), obj[2]])


def _simulate_run(scenario: Scenario, robots: np.ndarray, start: np.ndarray,
                  max_step: float, depth: int = 8):
    """Simulate a non-rigid run, refining intervals where the object moves more than
    ``max_step``. Returns (object at the run's samples, taut sets, largest step, message,
    lowest object height per interval over the model samples)."""
    team = scenario.team
    s = np.arange(len(robots), dtype=float)          # sample parameter of each fine state
    for _ in range(depth + 1):
        lo = np.floor(s).astype(int).clip(0, len(robots) - 2)
        f = (s - lo)[:, None, None]
        fine = robots[lo] * (1 - f) + robots[np.minimum(lo + 1, len(robots) - 1)] * f
        sim = simulate(team.carrier, fine, start=start)
        bad = [e for e in sim.events if e.kind in ("jump", "lost")]
        if bad:
            e = bad[0]
            why = (f"object jumps during a formation change (drop {e.drop:.3g} m)"
                   if e.kind == "jump" else "object is lost (reaches the ground) during a "
                                            "formation change")
            return None, None, np.inf, why, None
        step = np.linalg.norm(np.diff(sim.object, axis=0), axis=1)
        big = np.flatnonzero(step > max_step)
        if not len(big):
            keep = np.flatnonzero(np.abs(s - np.round(s)) == 0)
            z = sim.object[:, 2]
            low = np.minimum(np.minimum.reduceat(z, keep[:-1]), z[keep[1:]])
            return (sim.object[keep], [sim.taut[k] for k in keep], float(step.max(initial=0)),
                    None, low)
        s = np.sort(np.concatenate([s, (s[big] + s[big + 1]) / 2]))
    return None, None, float(step.max()), (f"the object moves {step.max():.3g} m between "
                                           "samples however finely a formation change is "
                                           "sampled (a jump)"), None


def _model_states(scenario: Scenario, robots: np.ndarray, planned: np.ndarray,
                  max_step: float, rigid: np.ndarray):
    """Rest state along the motion (module docstring, check 2) with the rigid intervals
    ``rigid`` (T-1,) carried rigidly: (object, taut sets, largest object step, message or
    None, lowest object height per interval, m)."""
    team = scenario.team
    size = team.sheet.size
    T = len(robots)
    fk0 = forward_kinematics(team.carrier, robots[0])
    if not fk0.stable:
        return None, (), 0.0, "no stable rest state at the first sample", None
    lowest = fk0.lowest
    assert lowest is not None                     # fk0.stable is not empty
    guess = planned[0] if np.all(np.isfinite(planned[0])) else lowest.object
    e0 = min(fk0.stable, key=lambda e: float(np.linalg.norm(e.object - guess)))
    obj = np.full((T, 3), np.nan)
    taut: list[tuple[int, ...]] = [()] * T
    obj[0], taut[0] = e0.object, e0.taut
    low = np.full(T - 1, np.nan)
    worst = 0.0
    t = 0
    while t < T - 1:
        if rigid[t]:
            obj[t + 1], taut[t + 1] = _follow_rigid(obj[t], robots, t), taut[t]
            low[t] = obj[t, 2]                    # carried rigidly: the height is constant
            t += 1
            continue
        u = t
        while u < T - 1 and not rigid[u]:
            u += 1
        o, ts, step, why, z = _simulate_run(scenario, robots[t:u + 1], obj[t], max_step)
        if why is not None:
            return obj, tuple(taut), step, why, low
        obj[t:u + 1], taut[t:u + 1], low[t:u] = o, ts, z
        worst = max(worst, step)
        t = u
    err = np.linalg.norm(obj - planned, axis=1)
    claim = np.all(np.isfinite(planned), axis=1)
    off = claim & ~(err <= _tol.OBJECT_RTOL * size)
    if off.any():
        k = int(np.argmax(off))
        return obj, tuple(taut), worst, (f"object left the planned branch at sample {k} "
                                         f"(off by {err[k]:.3g} m)"), low
    return obj, tuple(taut), worst, None, low


def _geometry(scenario: Scenario, robots: np.ndarray, obj: np.ndarray,
              shapes: Shapes | None = None) -> tuple[float, float, str | None]:
    """Checks 3-4 at the samples: (height margin, clearance, message or None); ``shapes``:
    the samples' points and hulls (:func:`~taut.plan.checks._geometry.shapes_of`)."""
    team, world = scenario.team, scenario.world
    T, N = robots.shape[:2]
    if np.nanmin(obj[:, 2]) < team.height_safety - TOLERANCE:
        return -np.inf, -np.inf, "object closer to the ground than the height safety"
    pts, hulls = shapes if shapes is not None else shapes_of(robots)
    inside = shapely.contains(world.geometry, pts)
    if not inside.all():
        k = int(np.argmin(inside))
        return -np.inf, -np.inf, f"robot {k % N + 1} leaves the free space at sample {k // N}"
    out = ~shapely.covers(world.geometry.buffer(TOLERANCE), hulls)
    if out.any():
        return -np.inf, -np.inf, (f"the sheet crosses a wall at sample "
                                  f"{int(np.argmax(out))}")
    clear = shapely.distance(world.geometry.exterior, pts)
    margin = np.inf
    for o in world.obstacles:
        clear = np.minimum(clear, shapely.distance(o.geometry, pts))
        under = shapely.intersects(hulls, o.geometry)
        if under.any():
            m = obj[under, 2] - o.height
            margin = min(margin, float(m.min()))
            if m.min() < team.height_safety - TOLERANCE:
                t = int(np.flatnonzero(under)[np.argmin(m)])
                return margin, -np.inf, (f"object only {m.min():.3g} m above obstacle "
                                         f"{o.id!r} at sample {t} (height safety "
                                         f"{team.height_safety:.3g} m)")
    if clear.min() < team.clearance - TOLERANCE:
        k = int(np.argmin(clear))
        return margin, float(clear.min()), (f"robot {k % N + 1} only {clear[k]:.3g} m from a "
                                            f"wall or obstacle at sample {k // N}")
    return margin, float(clear.min()), None


def _least_gap(robots: np.ndarray, rigid: np.ndarray) -> float:
    """Least distance between two robot centres over the continuous motion, m: rigid
    intervals (``rigid``, (T-1,)) keep every distance; on the others robots move straight,
    so a pair's relative position is linear in time and its least distance has a closed
    form."""
    iu, ju = np.triu_indices(robots.shape[1], 1)
    kept = np.linalg.norm(robots[:, iu] - robots[:, ju], axis=2)     # (T, P)
    if len(robots) < 2:
        return float(kept.min())
    moving = pair_closest(robots[:-1], robots[1:])
    return float(np.where(rigid[:, None], kept[:-1], moving).min())


def _sheet_slack(scenario: Scenario, robots: np.ndarray) -> tuple[float, int, int, int]:
    """Least (sheet distance - robot distance), m, and where (sample, i, j)."""
    slack, iu, ju = pair_slack(scenario, robots)
    t, p = np.unravel_index(int(np.argmin(slack)), slack.shape)
    return float(slack[t, p]), int(t), int(iu[p]), int(ju[p])


def verify_motion(scenario: Scenario, robots: ArrayLike, planned_object: ArrayLike, *,
                  sheet_margin: float = 0.0,
                  max_object_step: float = _tol.MAX_OBJECT_STEP) -> Verification:
    """Verify a sampled team motion as a continuous motion (see module docstring).

    Parameters
    ----------
    scenario : Scenario
    robots : ndarray, shape (T, N, 2)
        Robot positions per sample, m.
    planned_object : ndarray, shape (T, 3)
        Where the plan expects the object, m (rows of NaN: no claim).
    sheet_margin : float
        Every robot pair must stay this far inside its sheet distance, m.
    max_object_step : float
        Largest object step between model samples on non-rigid intervals, m.

    Returns
    -------
    Verification
        ``success`` False with the first failed check in ``message``.
    """
    require_instance(scenario, Scenario, "scenario")
    sheet_margin = as_bounded(sheet_margin, "sheet_margin", MAX_SHEET_MARGIN_M, "m",
                              positive=False)
    max_object_step = as_bounded(max_object_step, "max_object_step", MAX_SHEET_LENGTH, "m",
                                 positive=False)
    robots = as_array(robots, "robots", shape=(None, scenario.team.sheet.n, 2))
    if _shape(planned_object) != (len(robots), 3):        # NaN marks unplanned samples
        raise InvalidInputError("planned_object", f"must have shape {len(robots)}x3")
    require_nonempty(robots, "robots")
    return _verify_motion(scenario, np.asarray(robots, dtype=float),
                          np.asarray(planned_object, dtype=float), sheet_margin,
                          max_object_step)


def _verify_motion(scenario: Scenario, robots: np.ndarray, planned: np.ndarray,
                   sheet_margin: float, max_object_step: float = _tol.MAX_OBJECT_STEP
                   ) -> Verification:
    """:func:`verify_motion` on validated inputs: ``robots`` (T, N, 2) and ``planned``
    (T, 3) float arrays, m."""
    team = scenario.team
    T, N = robots.shape[:2]

    def fail(why: str, obj=None, taut=(), slack=-np.inf) -> Verification:
        return Verification(False, "refuted", why, np.full((T, 3), np.nan) if obj is None
                            else obj, tuple(taut), -np.inf, -np.inf, slack)

    try:
        check_formations(team.sheet, robots)
    except TautError as exc:
        return fail(f"infeasible formation: {exc.problem}")
    slack, ts, i, j = _sheet_slack(scenario, robots)
    if slack < sheet_margin - TOLERANCE:
        return fail(f"robots {i + 1} and {j + 1} only {slack:.3g} m inside their sheet "
                    f"distance at sample {ts} (sheet margin {sheet_margin:.3g} m)", slack=slack)
    rigid = _rigid_mask(robots, _tol.RIGID_RTOL * team.sheet.size * 10)
    gap = _least_gap(robots, rigid)
    if gap < 2 * team.robot_radius - TOLERANCE:
        return fail(f"robots overlap (centres {gap:.3g} m apart)", slack=slack)
    try:
        obj, taut, step, why, low = _model_states(scenario, robots, planned,
                                                  max_object_step, rigid)
    except TautError as exc:
        return fail(f"simulation failed: {exc}", slack=slack)
    if why is not None:
        return fail(why, obj, taut, slack)
    shapes = shapes_of(robots)
    margin, clear, why = _geometry(scenario, robots, obj, shapes)
    if why is not None:
        return fail(why, obj, taut, slack)
    margin2, clear2, why = prove_between(scenario, robots, low, rigid, max_object_step, shapes)
    if why is not None:
        return fail(why, obj, taut, slack)
    margin, clear = min(margin, margin2), min(clear, clear2)
    return Verification(True, "ok", f"verified at {T} samples", obj, tuple(taut), margin,
                        clear, slack, step)


def resample_motion(robots: ArrayLike, planned_object: ArrayLike, factor: int
                    ) -> tuple[np.ndarray, np.ndarray]:
    """``factor`` times denser samples of a motion: rigid intervals are interpolated as
    rigid motions (the object carried along), others linearly (planned object NaN at the
    added samples: no claim).

    Returns
    -------
    robots : ndarray, shape ((T - 1) * factor + 1, N, 2)
    planned_object : ndarray, shape ((T - 1) * factor + 1, 3)
    """
    robots = require_nonempty(as_array(robots, "robots", shape=(None, None, 2)), "robots")
    if _shape(planned_object) != (len(robots), 3):
        raise InvalidInputError("planned_object", f"must have shape {len(robots)}x3")
    factor = as_count(factor, "factor", minimum=1, maximum=10_000)
    robots = np.asarray(robots, dtype=float)
    obj = np.asarray(planned_object, dtype=float)
    T = len(robots)
    rigid = _rigid_mask(robots, _tol.RIGID_RTOL * max(float(np.ptp(robots)), 1.0))
    out_r, out_o = [robots[0]], [obj[0]]
    s = np.arange(1, factor + 1) / factor
    for t in range(T - 1):
        a, b = robots[t], robots[t + 1]
        if rigid[t]:
            rot, _, _ = _rigid_fit(a, b)
            ang = np.arctan2(rot[1, 0], rot[0, 0])
            ca, cb = a.mean(axis=0), b.mean(axis=0)
            for k, sk in enumerate(s):
                c, si = np.cos(sk * ang), np.sin(sk * ang)
                R = np.array([[c, -si], [si, c]])
                move = ca + sk * (cb - ca)
                out_r.append((a - ca) @ R.T + move)
                p = obj[t]
                out_o.append(obj[t + 1] if k == factor - 1 else
                             np.array([*((p[:2] - ca) @ R.T + move), p[2]]))
        else:
            for k, sk in enumerate(s):
                out_r.append(a * (1 - sk) + b * sk)
                out_o.append(obj[t + 1] if k == factor - 1 else np.full(3, np.nan))
    return np.asarray(out_r), np.asarray(out_o)


def _shape(value: object) -> tuple[int, ...] | None:
    """Shape of an array-like, None when ragged or not numeric."""
    try:
        return np.asarray(value, dtype=float).shape
    except (TypeError, ValueError):
        return None
