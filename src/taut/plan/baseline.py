"""Bypass-only baselines (2-D planning as in the planning paper's benchmark, ref. [21]).

* :func:`plan_baseline` (``"disc"``): the formation is a disc covering every heading, routed
  on the visibility roadmap, never crossing (the baseline of issue 4);
* ``plan(scenario, baseline="se2")``: the SE(2) search with crossing disabled (the crossing
  planner's own searches, formation library and budget).

The disc baseline uses the most compact stable all-taut formation (the most room to pass
beside obstacles); both use the same timing and verification as the crossing planner.
"""

from __future__ import annotations

from . import _tol
from .result import PlanResult, attempt, compact_formation
from .world import Scenario
from .._validate import MAX_SHEET_LENGTH, as_bounded, require_instance

__all__ = ["plan_baseline"]


def plan_baseline(scenario: Scenario, *, sheet_margin: float = _tol.SHEET_MARGIN
                  ) -> PlanResult:
    """Disc-model bypass-only plan of ``scenario``.

    Raises
    ------
    PlanningError
        The team cannot hold the object at all.
    """
    require_instance(scenario, Scenario, "scenario")
    as_bounded(sheet_margin, "sheet_margin", MAX_SHEET_LENGTH, "m", positive=False)
    return attempt(scenario, compact_formation(scenario, sheet_margin), allow_crossing=False,
                   planner="disc", sheet_margin=sheet_margin)
