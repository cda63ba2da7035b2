"""Top-level planner with obstacle crossing (planning paper Sec. IV, Fig. 4).

1. Formations: the compact one (bypassing) and, for each obstacle-height class (the
   distinct obstacle heights, at most ``MAX_CLASSES`` of them), the optimal crossing
   formation of eqs. (11)-(15) for every obstacle up to that height.
2. Each formation is routed with crossing allowed (obstacles it can cross may lie on the
   route, the rest are bypassed), and so is each crossing formation paired with the
   compact one (the team changes formation in place where needed: compact to squeeze past
   obstacles, high to cross them); every candidate is timed with Algorithm 2 and
   verified; the bypass-only baseline plan is one more candidate.
   Crossings are the paper's Algorithm 2 and, unless ``straight_crossings=False``, also
   straight offset crossings (no turn over the obstacle; see
   :func:`~taut.plan.formation.offset_crossings`).
3. The fastest verified candidate wins; among equally fast ones a crossing plan is
   preferred, as in the paper. Because the baseline is a candidate, the planner succeeds
   whenever the baseline does and is never slower to the goal.

If nothing verifies, the result is a failure whose reason says why bypassing and each
crossing attempt failed.
"""

from __future__ import annotations

import numpy as np

from ..errors import InvalidInputError
from .baseline import plan_baseline
from .formation import MIN_DEPTH_FRACTION, Formation, optimal_formation
from .result import PlanResult, attempt, compact_formation, failure
from .route import crossable
from .world import Scenario

__all__ = ["plan", "MAX_CLASSES"]

#: Most obstacle-height classes for which a crossing formation is optimised.
MAX_CLASSES = 4


def _height_classes(scenario: Scenario) -> list[float]:
    heights = sorted({o.height for o in scenario.world.obstacles})
    if len(heights) > MAX_CLASSES:
        idx = np.unique(np.linspace(0, len(heights) - 1, MAX_CLASSES).round().astype(int))
        heights = [heights[i] for i in idx]
    return heights


def plan(scenario: Scenario, *, baseline: bool = False, straight_crossings: bool = True
         ) -> PlanResult:
    """Plan the transport of the object from ``scenario.start`` to ``scenario.goal``.

    Parameters
    ----------
    scenario : Scenario
    baseline : bool
        Plan with the bypass-only baseline instead.
    straight_crossings : bool
        Allow straight offset crossings besides the paper's Algorithm 2 (False: crossings
        are Algorithm 2 only, every crossed obstacle passes under the object).

    Returns
    -------
    PlanResult
        ``success`` is True only for a plan that passed verification.

    Raises
    ------
    PlanningError
        The team cannot hold the object at all.
    """
    if not isinstance(scenario, Scenario):
        raise InvalidInputError("scenario", "must be a taut.plan.Scenario")
    if baseline:
        return plan_baseline(scenario)
    world, team = scenario.world, scenario.team
    compact = compact_formation(scenario)
    best = plan_baseline(scenario)
    reasons = [] if best.success else [f"bypassing: {best.reason}"]
    candidates = []
    if any(crossable(scenario, compact, o, straight=straight_crossings) is None
           for o in world.obstacles):
        candidates.append(compact)
    for h in _height_classes(scenario):
        group = [o for o in world.obstacles if o.height <= h]
        diameter = max(o.diameter for o in group)
        # Prefer a formation that fits the widest passage (eq. 13 as a constraint).
        f = optimal_formation(team, kind="crossing", height=h, diameter=diameter,
                              width=world.width, max_reach=0.49 * world.width)
        if f is None:
            f = optimal_formation(team, kind="crossing", height=h, diameter=diameter,
                                  width=world.width)
        if f is None:
            ids = ", ".join(repr(o.id) for o in group if o.height == h)
            if h + team.height_safety >= (1 - MIN_DEPTH_FRACTION) * team.hold_height:
                why = (f"the object hangs below the hands ({team.hold_height:.3g} m), so it "
                       f"cannot clear {h:.3g} m plus the height safety")
            else:
                why = ("no stable all-taut formation lifts the object that high with room "
                       "between the robots")
            reasons.append(f"obstacle {ids} ({h:.3g} m tall) cannot be crossed: {why}")
            continue
        candidates.append(f)
    # Single formations, then the compact one together with the crossing formations (the
    # team may change formation where a crossing one does not fit).
    mixes = [f for f in candidates if f is not compact]
    combos: list = list(candidates)
    if mixes:
        combos.append([compact, *mixes])
    for f in combos:
        r = attempt(scenario, f, allow_crossing=True, planner="crossing",
                    straight_crossings=straight_crossings)
        if r.success and any(c.kind == "straight" for c in r.crossings):
            # The route search does not cost the turn into a straight crossing's heading;
            # Algorithm 2 alone (a subset of the edges) may be faster in time.
            r2 = attempt(scenario, f, allow_crossing=True, planner="crossing",
                         straight_crossings=False)
            if r2.success and r2.duration < r.duration:
                r = r2
        if not r.success:
            if isinstance(f, Formation):
                reasons.append(f"crossing with the object at {f.object_height:.3g} m: "
                               f"{r.reason}")
            continue
        if not best.success or r.duration <= best.duration * (1 + 1e-9):
            if not best.success or r.duration < best.duration * (1 - 1e-9) or r.crossed:
                best = r
    if best.success:
        if best.planner == "baseline":
            best = PlanResult(**{**best.__dict__, "planner": "crossing"})
        return best
    return failure(scenario, "; ".join(dict.fromkeys(reasons)) or "no plan", "crossing")
