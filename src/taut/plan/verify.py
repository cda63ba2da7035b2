"""Independent verification of a planned motion with the quasi-static model.

Checked at every sample (vectorised over samples):

1. the formation is feasible: the sheet does not tear (FK paper's FormationFeasible) and
   robot footprints do not overlap;
2. the object stays on the planned branch: the quasi-static simulation
   (:func:`taut.sheet.simulate.simulate`) started at the planned object state has no jump
   and no lost state, and its object is where the plan says (to 1e-6 of the sheet size);
3. the object is at least ``height_safety`` above the ground and above every obstacle
   whose footprint meets the robots' convex hull (the sheet's projection when every cable
   is taut);
4. every robot centre is inside the free space and at least ``robot_radius +
   lateral_safety`` from walls and obstacles.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely

from ..errors import TautError
from ..sheet.model import check_formations
from ..sheet.simulate import simulate
from .world import Scenario

__all__ = ["Verification", "verify_motion", "TOLERANCE"]

#: Absolute tolerance of the geometric checks, m.
TOLERANCE = 1e-6


@dataclass(frozen=True, eq=False)
class Verification:
    """Outcome of :func:`verify_motion`.

    Attributes
    ----------
    ok : bool
    reason : str or None
        First failed check.
    object : ndarray, shape (T, 3)
        Object position from the model (simulation or FK), m.
    taut : tuple of tuple of int
        Taut cables per sample (0-based).
    min_height_margin : float
        Least (object height - obstacle height) over samples with an obstacle beneath, m
        (inf when none).
    min_clearance : float
        Least robot-centre distance to a wall or obstacle, m.
    """

    ok: bool
    reason: str | None
    object: np.ndarray
    taut: tuple[tuple[int, ...], ...]
    min_height_margin: float
    min_clearance: float


def _model_states(scenario: Scenario, robots: np.ndarray, planned: np.ndarray
                  ) -> tuple[np.ndarray, tuple, str | None]:
    team = scenario.team
    sheet, zr = team.sheet, team.hold_height
    tol = 1e-6 * sheet.size
    sim = simulate(sheet, robots, zr, start=planned[0])
    obj, taut = sim.object, sim.taut
    bad = [e for e in sim.events if e.kind in ("jump", "lost")]
    if bad:
        e = bad[0]
        return obj, taut, f"object {e.kind}s at sample {e.step} (drop {e.drop:.3g} m)"
    err = np.linalg.norm(obj - planned, axis=1)
    err = np.where(np.isfinite(err), err, np.inf)
    if np.any(err > tol):
        t = int(np.argmax(err > tol))
        return obj, taut, (f"object left the planned branch at sample {t} "
                           f"(off by {err[t]:.3g} m)")
    return obj, taut, None


def verify_motion(scenario: Scenario, robots: np.ndarray, planned_object: np.ndarray
                  ) -> Verification:
    """Verify a sampled team motion (see module docstring).

    Parameters
    ----------
    scenario : Scenario
    robots : ndarray, shape (T, N, 2)
        Robot positions per sample, m.
    planned_object : ndarray, shape (T, 3)
        Where the plan expects the object, m.

    Returns
    -------
    Verification
    """
    team, world = scenario.team, scenario.world
    T, N = robots.shape[:2]
    empty = Verification(False, None, np.full((T, 3), np.nan), (), -np.inf, -np.inf)

    def fail(why: str, obj=None, taut=()) -> Verification:
        return Verification(False, why, empty.object if obj is None else obj, taut,
                            -np.inf, -np.inf)

    try:
        check_formations(team.sheet, robots)
    except TautError as exc:
        return fail(f"infeasible formation: {exc.problem}")
    iu, ju = np.triu_indices(N, 1)
    gap = np.linalg.norm(robots[:, iu] - robots[:, ju], axis=2).min()
    if gap < 2 * team.robot_radius - TOLERANCE:
        return fail(f"robots overlap (centres {gap:.3g} m apart)")
    try:
        obj, taut, why = _model_states(scenario, robots, planned_object)
    except TautError as exc:
        return fail(f"simulation failed: {exc}")
    if why is not None:
        return fail(why, obj, taut)
    if np.nanmin(obj[:, 2]) < team.height_safety - TOLERANCE:
        return fail("object closer to the ground than the height safety", obj, taut)
    # Robots clear of walls and obstacles.
    pts = shapely.points(robots.reshape(-1, 2))
    inside = shapely.contains(world.geometry, pts)
    if not inside.all():
        k = int(np.argmin(inside))
        return fail(f"robot {k % N + 1} leaves the free space at sample {k // N}", obj, taut)
    clear = shapely.distance(world.geometry.exterior, pts)
    margin = np.inf
    hulls = shapely.convex_hull(shapely.multipoints(robots))
    for o in world.obstacles:
        clear = np.minimum(clear, shapely.distance(o.geometry, pts))
        under = shapely.intersects(hulls, o.geometry)
        if under.any():
            m = obj[under, 2] - o.height
            margin = min(margin, float(m.min()))
            if m.min() < team.height_safety - TOLERANCE:
                t = int(np.flatnonzero(under)[np.argmin(m)])
                return fail(f"object only {m.min():.3g} m above obstacle {o.id!r} at sample "
                            f"{t} (height safety {team.height_safety:.3g} m)", obj, taut)
    need = team.clearance - TOLERANCE
    if clear.min() < need:
        k = int(np.argmin(clear))
        return fail(f"robot {k % N + 1} only {clear[k]:.3g} m from a wall or obstacle at "
                    f"sample {k // N}", obj, taut)
    return Verification(True, None, obj, tuple(taut), margin, float(clear.min()))
