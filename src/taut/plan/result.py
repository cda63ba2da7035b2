"""The plan result and the step shared by the roadmap planners: route a given formation,
time it (Algorithm 2 on crossings) and verify it with the quasi-static model."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from .._outcome import check_status
from ..errors import PlanningError
from .checks.certificate import Certificate
from .roadmap.crossing import CrossingRecord, _motion_from_legs
from .formations.optimal import Formation, _optimal_formation
from .roadmap.route import _find_route
from .checks.verify import Verification, _verify_motion
from .world import Scenario
from .._repr import CompactRepr

__all__ = ["PlanResult"]


@dataclass(frozen=True, eq=False, repr=False)
class PlanResult(CompactRepr):
    """A transport plan (or why there is none).

    Attributes
    ----------
    success : bool
        True only for a plan that passed :func:`~taut.plan.checks.verify.verify_motion`.
    status : {"ok", "refuted", "budget_exhausted", "no_route", "unverified"}
        ``refuted``: a certificate proves no plan exists (see ``certificate``);
        ``budget_exhausted``: none found within the search budget (no claim either way);
        ``no_route``: the roadmap planners' search space holds no route; ``unverified``:
        candidates were found but none passed verification.
    message : str
        What was found, or why not.
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
        Algorithm 2 / straight crossings of the roadmap planners (empty for SE(2) plans).
    planner : str
        ``"crossing"`` (the SE(2) planner with crossing), ``"se2-bypass"`` (its baseline),
        ``"disc"`` (the disc-model bypass baseline), ``"roadmap"``, ``"algorithm2"``.
    verification : Verification or None
    formations : tuple of Formation
        Every formation used, in order of first use.
    certificate : Certificate or None
        Why no plan exists, when that is proved.
    sheet_margin : float
        The margin every robot pair keeps inside its sheet distance, m.
    scenario : Scenario or None
        The problem planned (what :func:`~taut.plan.checks.profile.plan_profile` and
        :func:`~taut.plan.checks.robustness.plan_robustness` analyse the plan in).
    search : str or None
        Who found an SE(2) plan (``plan(..., search=...)``: ``"rrtconnect"`` or an OMPL
        planner); None for the roadmap planners and failures.
    """

    success: bool
    status: str
    message: str
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
    certificate: Certificate | None = None
    sheet_margin: float = 0.0
    scenario: Scenario | None = None
    search: str | None = None

    def __post_init__(self) -> None:
        check_status(self.status)


def failure(scenario: Scenario, message: str, planner: str, status: str = "no_route",
            certificate: Certificate | None = None) -> PlanResult:
    """A failed plan with empty trajectories."""
    n = scenario.team.n
    return PlanResult(False, status, message, np.zeros(0), np.zeros((0, n, 2)),
                      np.zeros((0, 3)), (), np.zeros(0), (),
                      tuple(o.id for o in scenario.world.obstacles), float("nan"),
                      float("nan"), None, (), planner, certificate=certificate,
                      scenario=scenario)


def compact_formation(scenario: Scenario, sheet_margin: float = 0.0) -> Formation:
    """The most compact stable all-taut formation (for bypassing).

    Raises
    ------
    PlanningError
        ``team``: no formation can hold the object at all.
    """
    team = scenario.team
    f = _optimal_formation(team, "compact", width=scenario.world.width,
                           sheet_margin=sheet_margin)
    if f is None:
        raise PlanningError("team", "cannot hold the object: no formation keeps every cable "
                            f"taut and the object stable at least {team.height_safety:g} m "
                            f"above the ground with robots of radius {team.robot_radius:g} m "
                            "not overlapping and the sheet not torn")
    return f


def attempt(scenario: Scenario, formation: Formation | Sequence[Formation], *,
            allow_crossing: bool, planner: str, straight_crossings: bool = True,
            sheet_margin: float = 0.0) -> PlanResult:
    """Route ``formation`` (or several, changing between them) on the disc-model roadmap,
    time the route and verify it; a failed plan carries the reason."""
    given = [formation] if isinstance(formation, Formation) else list(formation)
    route = _find_route(scenario, given, allow_crossing=allow_crossing,
                        straight_crossings=straight_crossings)
    if not route.success:
        return failure(scenario, route.message, planner)
    motion = _motion_from_legs(scenario, route.formations, route.legs, route.first)
    check = _verify_motion(scenario, motion.robots, motion.object, sheet_margin)
    if not check.success:
        return failure(scenario, f"plan rejected by verification: {check.message}", planner,
                       "unverified")
    crossed = tuple(dict.fromkeys(route.crossed))
    bypassed = tuple(o.id for o in scenario.world.obstacles if o.id not in crossed)
    used = tuple(dict.fromkeys([route.first] + [leg.formation for leg in route.legs]))
    forms = tuple(route.formations[k] for k in used)
    main = max(forms, key=lambda f: f.object_height)
    return PlanResult(True, "ok", _summary(motion.duration, motion.path_length, crossed),
                      motion.times, motion.robots, check.object, check.taut, motion.heading,
                      crossed, bypassed, motion.path_length, motion.duration, main,
                      motion.crossings, planner, check, forms, sheet_margin=sheet_margin,
                      scenario=scenario)


def _summary(duration: float, length: float, crossed: Sequence[str]) -> str:
    return (f"plan: {duration:.2f} s to the goal, path {length:.3f} m, crossed "
            f"[{', '.join(crossed)}]")


def relabel(result: PlanResult, planner: str) -> PlanResult:
    """The same result under another planner name."""
    return replace(result, planner=planner)
