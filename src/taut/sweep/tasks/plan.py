"""``plan_suite`` and ``plan_robustness``: the planner over generated corridors, and one
plan under robot position noise.

``plan_robustness`` plans the base scenario once per worker process (the planner is
deterministic), then for each point adds seeded normal noise of standard deviation
``sigma`` (m, per robot coordinate, drawn every second of the plan and linear in time in
between, modelling drifting position error; :func:`taut.plan.checks.robustness.position_error`)
and replays the noisy formations (:func:`taut.plan.checks.robustness.replay`): ``torn`` when some
robot pair stands farther apart than its sheet vertices (the sheet would tear or a robot
slip), else the quasi-static simulation runs and ``jumped`` says whether the object
dropped.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ...errors import SweepError, TautError
from ..task import Columns, Task

__all__ = ["PLAN_SUITE", "PLAN_ROBUSTNESS"]


def _run_suite(ctx: Any, cols: Columns, seeds: np.ndarray) -> Columns:
    from ...plan import generate_scenario, plan

    b = len(seeds)
    out: Columns = {"success": np.zeros(b, dtype=bool), "status": np.full(b, "", dtype=object),
                    "path_length": np.full(b, np.nan), "duration": np.full(b, np.nan),
                    "crossed": np.zeros(b, dtype=np.int64), "n_robots_used": np.zeros(b, np.int64),
                    "message": np.full(b, "", dtype=object)}
    for k in range(b):
        n = int(cols["n_robots"][k])
        try:
            sc = generate_scenario(int(cols["scenario_seed"][k]), n if n > 0 else None)
            res = plan(sc, baseline="se2" if cols["baseline"][k] else None)
        except TautError as exc:
            out["message"][k] = str(exc)
            continue
        ok = bool(res.success)
        out["success"][k], out["status"][k], out["message"][k] = ok, res.status, res.message
        out["n_robots_used"][k] = sc.team.n
        if ok:
            out["path_length"][k] = float(res.path_length)
            out["duration"][k] = float(res.duration)
            out["crossed"][k] = len(res.crossed)
    return out


@dataclass(frozen=True, eq=False)
class _PlanContext:
    scenario: Any
    times: np.ndarray        # (T,) s
    robots: np.ndarray       # (T, N, 2) m
    object: np.ndarray       # (T, 3) m


def _prepare_robustness(spec: Any, sc: Any) -> _PlanContext:
    from ...plan import plan

    res = plan(sc)
    if not res.success:
        raise SweepError("base", f"the base scenario has no plan to perturb ({res.message})")
    return _PlanContext(sc, np.asarray(res.times, float), np.asarray(res.robots, float),
                        np.asarray(res.object, float))


def _run_robustness(ctx: _PlanContext, cols: Columns, seeds: np.ndarray) -> Columns:
    from ...plan.checks.robustness import position_error, replay

    b = len(seeds)
    out: Columns = {"torn": np.zeros(b, dtype=bool), "max_extension": np.full(b, np.nan),
                    "jumped": np.zeros(b, dtype=bool), "max_deviation": np.full(b, np.nan),
                    "contact": np.zeros(b, dtype=bool), "collision": np.zeros(b, dtype=bool)}
    for k in range(b):
        rng = np.random.default_rng(int(seeds[k]))
        noisy = ctx.robots + position_error(rng, ctx.times, ctx.robots.shape[1],
                                            float(cols["sigma"][k]), "gaussian", 1.0)
        t = replay(ctx.scenario, noisy, ctx.object)
        out["torn"][k], out["max_extension"][k] = t.torn, t.extension
        out["jumped"][k], out["max_deviation"][k] = t.dropped, t.deviation
        out["contact"][k], out["collision"][k] = t.contact, t.collision
    return out


PLAN_SUITE = Task(
    name="plan_suite",
    summary="the planner (or the baseline) over seeded generated corridors",
    parameters={"scenario_seed": "seed of taut.plan.generate_scenario",
                "n_robots": "team size 3..8 (0: drawn from the seed)",
                "baseline": "1 for the bypass-only baseline, 0 for the crossing planner"},
    outputs={"success": "a verified plan was found", "status": "the plan's status",
             "path_length": "planar length of the object's path, m",
             "duration": "time to the goal, s", "crossed": "obstacles crossed under the sheet",
             "n_robots_used": "team size of the scenario", "message": "the plan's message"},
    defaults=lambda ctx: {"scenario_seed": 0.0, "n_robots": 0.0, "baseline": 0.0},
    default_chunk=1,
    needs_base="",
    prepare=lambda spec, base: None,
    run=_run_suite,
)

PLAN_ROBUSTNESS = Task(
    name="plan_robustness",
    summary="one plan replayed under seeded robot position noise",
    parameters={"sigma": "standard deviation of the position noise per coordinate (drawn "
                         "every second, linear in time in between), m",
                "trial": "trial number (only distinguishes points; seeds derive from it)"},
    outputs={"torn": "some robot pair exceeded its sheet distance",
             "max_extension": "largest pair distance beyond its sheet distance, m (< 0: slack)",
             "jumped": "the object dropped: its rest state ended and it fell more than 5 mm, "
                       "or it was lost, in the simulation",
             "max_deviation": "largest distance of the object from its planned position, m",
             "contact": "the object touched an obstacle beneath the sheet or the ground",
             "collision": "a robot's footprint touched a wall or an obstacle"},
    defaults=lambda ctx: {"sigma": 0.005, "trial": 0.0},
    default_chunk=25,
    needs_base="plan scenario",
    prepare=_prepare_robustness,
    run=_run_robustness,
)
