"""Bypass-only baseline: the formation never crosses an obstacle (2-D planning as in the
planning paper's benchmark, ref. [21]). It uses the most compact stable all-taut formation
(the one with the most room to pass beside obstacles) and the same route search, timing
and verification as the crossing planner."""

from __future__ import annotations

from .result import PlanResult, attempt, compact_formation
from .world import Scenario

__all__ = ["plan_baseline"]


def plan_baseline(scenario: Scenario) -> PlanResult:
    """Bypass-only plan of ``scenario``.

    Raises
    ------
    PlanningError
        The team cannot hold the object at all.
    """
    return attempt(scenario, compact_formation(scenario), allow_crossing=False,
                   planner="baseline")
