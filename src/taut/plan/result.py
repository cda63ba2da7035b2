"""The plan result and the step shared by both planners: route a given formation, time it
(Algorithm 2 on crossings) and verify it with the quasi-static model."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import PlanningError
from .crossing import CrossingRecord, motion_from_legs
from .formation import Formation, optimal_formation
from .route import find_route
from .verify import Verification, verify_motion
from .world import Scenario

__all__ = ["PlanResult", "attempt", "compact_formation", "failure"]


@dataclass(frozen=True, eq=False)
class PlanResult:
    """A transport plan (or why there is none).

    Attributes
    ----------
    success : bool
        True only for a plan that passed :func:`~taut.plan.verify.verify_motion`.
    reason : str or None
        Why planning failed (None on success).
    times : ndarray, shape (T,)
        Sample times, s.
    robots : ndarray, shape (T, N, 2)
        Robot positions, m.
    object : ndarray, shape (T, 3)
        Object position from the quasi-static model, m.
    taut : tuple of tuple of int
        Taut cables per sample (0-based).
    heading : ndarray, shape (T,)
        Formation rotation, rad.
    crossed, bypassed : tuple of str
        Ids of obstacles passed under the sheet / all others.
    path_length : float
        Planar length of the object's path, m.
    duration : float
        Time to the goal, s.
    formation : Formation or None
        The formation holding the object highest (the crossing one, if any).
    crossings : tuple of CrossingRecord
    planner : {"crossing", "baseline"}
    verification : Verification or None
    formations : tuple of Formation
        Every formation used, in order of first use (more than one when the team changes
        formation on the way).
    """

    success: bool
    reason: str | None
    times: np.ndarray
    robots: np.ndarray
    object: np.ndarray
    taut: tuple[tuple[int, ...], ...]
    heading: np.ndarray
    crossed: tuple[str, ...]
    bypassed: tuple[str, ...]
    path_length: float
    duration: float
    formation: Formation | None
    crossings: tuple[CrossingRecord, ...]
    planner: str
    verification: Verification | None = None
    formations: tuple[Formation, ...] = ()


def failure(scenario: Scenario, reason: str, planner: str) -> PlanResult:
    """A failed plan with empty trajectories."""
    n = scenario.team.n
    return PlanResult(False, reason, np.zeros(0), np.zeros((0, n, 2)), np.zeros((0, 3)), (),
                      np.zeros(0), (), tuple(o.id for o in scenario.world.obstacles),
                      float("nan"), float("nan"), None, (), planner)


def compact_formation(scenario: Scenario) -> Formation:
    """The most compact stable all-taut formation (for bypassing).

    Raises
    ------
    PlanningError
        ``team``: no formation can hold the object at all.
    """
    team = scenario.team
    f = optimal_formation(team, kind="compact", width=scenario.world.width)
    if f is None:
        raise PlanningError("team", "cannot hold the object: no formation keeps every cable "
                            f"taut and the object stable at least {team.height_safety:g} m "
                            f"above the ground with robots of radius {team.robot_radius:g} m "
                            "not overlapping and the sheet not torn")
    return f


def attempt(scenario: Scenario, formation: Formation | Sequence[Formation], *,
            allow_crossing: bool, planner: str, straight_crossings: bool = True
            ) -> PlanResult:
    """Route ``formation`` (or several, changing between them), time the route and verify
    it; a failed plan carries the reason."""
    route = find_route(scenario, formation, allow_crossing=allow_crossing,
                       straight_crossings=straight_crossings)
    if not route.found:
        return failure(scenario, route.reason or "no route", planner)
    motion = motion_from_legs(scenario, route)
    check = verify_motion(scenario, motion.robots, motion.object)
    if not check.ok:
        return failure(scenario, f"plan rejected by verification: {check.reason}", planner)
    crossed = tuple(dict.fromkeys(route.crossed))
    bypassed = tuple(o.id for o in scenario.world.obstacles if o.id not in crossed)
    used = tuple(dict.fromkeys([route.first] + [leg.formation for leg in route.legs]))
    forms = tuple(route.formations[k] for k in used)
    main = max(forms, key=lambda f: f.object_height)
    return PlanResult(True, None, motion.times, motion.robots, check.object, check.taut,
                      motion.heading, crossed, bypassed, motion.path_length, motion.duration,
                      main, motion.crossings, planner, check, forms)
