"""Per-sample profile of a plan: what is beneath the sheet, how far the object keeps above
it, and how much sheet the robots leave unused (what the figures of :mod:`taut.viz.plan` and
the planner viewer of the web app plot).

"Beneath" is the tallest obstacle whose footprint meets the robots' convex hull (the
sheet's projection when every cable is taut), as in the planner's height rule
(:func:`taut.plan.checks.verify.verify_motion`, check 3). The sheet slack of a robot pair
is its sheet distance less its robot distance, :math:`|\\mathbf{v}_i - \\mathbf{v}_j| -
|\\mathbf{r}_i - \\mathbf{r}_j|` (negative: the sheet would tear). Lengths in metres,
times in seconds.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import InvalidInputError
from ..._validate import require_instance
from ..result import PlanResult
from ._geometry import beneath_height, pair_slack
from ..._repr import CompactRepr

__all__ = ["PlanProfile", "plan_profile"]


@dataclass(frozen=True, eq=False, repr=False)
class PlanProfile(CompactRepr):
    """Per-sample profile of a plan (:func:`plan_profile`); every array has shape (T,).

    Attributes
    ----------
    times_s : ndarray
        Sample times, s.
    object_height_m : ndarray
        Object height above the ground, m.
    beneath_height_m : ndarray
        Height of the tallest obstacle beneath the sheet, m (0 where there is none).
    height_over_obstacle_m : ndarray
        Object height above that obstacle, m (NaN where there is none).
    sheet_slack_m : ndarray
        Least sheet slack over robot pairs, m (>= the plan's ``sheet_margin`` for a
        verified plan; negative: the sheet would tear).
    """

    times_s: np.ndarray
    object_height_m: np.ndarray
    beneath_height_m: np.ndarray
    height_over_obstacle_m: np.ndarray
    sheet_slack_m: np.ndarray


def plan_profile(result: PlanResult) -> PlanProfile:
    """The per-sample profile of a plan (module docstring); empty arrays for a failed
    plan.

    Parameters
    ----------
    result : PlanResult
        A result of :func:`taut.plan.plan` (it carries its scenario).

    Returns
    -------
    PlanProfile

    Raises
    ------
    InvalidInputError
        ``result`` is not a plan or carries no scenario.
    """
    require_instance(result, PlanResult, "result")
    if result.scenario is None:
        raise InvalidInputError("result", "carries no scenario (not built by taut.plan.plan)")
    robots = np.asarray(result.robots, dtype=float)
    times = np.asarray(result.times, dtype=float)
    if len(times) == 0:
        empty = np.zeros(0)
        return PlanProfile(times, empty, empty, empty, empty)
    height = np.asarray(result.object, dtype=float)[:, 2]
    beneath = beneath_height(result.scenario, robots)
    over = np.where(beneath > 0, height - beneath, np.nan)
    slack = pair_slack(result.scenario, robots)[0].min(axis=1)
    return PlanProfile(times, height, beneath, over, slack)
