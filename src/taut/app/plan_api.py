"""JSON endpoints of the planner viewer: load a planning scenario, run the planner and its
SE(2) bypass baseline (the same search with crossing disabled) as the steps of a job that
:mod:`taut.app.jobs` queues (the page polls its progress), and return both plans with the
series the page plots.

Planning is :func:`taut.plan.plan` (``baseline="se2"`` for the baseline) and the series
are :func:`taut.plan.plan_profile`; this module computes nothing itself, it only reshapes
their results for drawing. Lengths m, times s.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import yaml

from ..io.serialize import json_ready, plan_to_dict
from ..io import plan_scenario_from_mapping, plan_scenario_to_mapping
from ..plan import PlanResult, Scenario, plan, plan_profile
from .catalog import Catalog
from .payload import field, mapping_from_upload

__all__ = ["PlanAPI", "plan_series", "world_to_dict", "PLAN_TIME_CAP_S"]

#: Wall-clock cap of one planning job, s: the app stays interactive (the planner's own
#: budget is counted in samples; a failing plan could otherwise search for minutes).
PLAN_TIME_CAP_S = 30.0


def world_to_dict(sc: Scenario) -> dict[str, Any]:
    """Geometry for drawing: walls, obstacle footprints (circles as polygons) and heights,
    start, goal, the team's sheet, hold height and robot radius."""
    return {
        "free_space": np.asarray(sc.world.free_space).tolist(),
        "obstacles": [{"id": o.id, "height": float(o.height),
                       "polygon": np.asarray(o.geometry.exterior.coords)[:-1].tolist()}
                      for o in sc.world.obstacles],
        "start": [float(x) for x in sc.start], "goal": [float(x) for x in sc.goal],
        "sheet": np.asarray(sc.team.sheet.vertices).tolist(),
        "hold_height": float(sc.team.hold_height),
        "robot_radius": float(sc.team.robot_radius),
        "height_safety": float(sc.team.height_safety),
    }


def plan_series(r: PlanResult) -> dict[str, list[float | None]]:
    """Per-sample series of a plan for the viewer's plots: the fields of its
    :func:`taut.plan.plan_profile` (null where not finite): ``beneath_height_m``,
    ``height_over_obstacle_m`` and ``sheet_slack_m``."""
    p = plan_profile(r)
    return {"beneath_height_m": json_ready(p.beneath_height_m),
            "height_over_obstacle_m": json_ready(p.height_over_obstacle_m),
            "sheet_slack_m": json_ready(p.sheet_slack_m)}


def _summary(r: PlanResult) -> dict[str, Any]:
    out = plan_to_dict(r)
    out.update(plan_series(r), object_height=(None if r.formation is None
                                              else float(r.formation.object_height)))
    return out


class PlanAPI:
    """The planner viewer's endpoints. A planning job is three calls, each run by a
    worker process (:mod:`taut.app.jobs` queues them and reports progress): :meth:`check`
    the scenario, plan the :meth:`baseline`, plan with obstacle :meth:`crossing`."""

    def __init__(self, catalog: Catalog) -> None:
        self.catalog = catalog

    @staticmethod
    def _scenario(data: dict[str, Any]) -> Scenario:
        return plan_scenario_from_mapping(data)

    def load(self, body: dict[str, Any]) -> dict[str, Any]:
        """``{"example": name}``, an upload ``{"text", "filename"}`` or ``{"scenario":
        mapping}`` -> the validated scenario mapping and its geometry."""
        if "example" in body:
            data = self.catalog.mapping("plan", field(body, "example", str))
        elif "text" in body:
            data = mapping_from_upload(field(body, "text", str),
                                       field(body, "filename", str, default="upload.yaml"))
        else:
            data = field(body, "scenario", dict)
        sc = self._scenario(data)
        return {"scenario": plan_scenario_to_mapping(sc), "world": world_to_dict(sc)}

    def yaml(self, body: dict[str, Any]) -> dict[str, Any]:
        """The scenario as a YAML file that ``taut plan`` reads back."""
        sc = self._scenario(field(body, "scenario", dict))
        text = ("# planning scenario saved by `taut app`; read it back with: taut plan FILE\n"
                + yaml.safe_dump(plan_scenario_to_mapping(sc), sort_keys=False,
                                 default_flow_style=None))
        return {"yaml": text, "filename": "plan_scenario.yaml"}

    def check(self, body: dict[str, Any]) -> dict[str, Any]:
        """Validate ``scenario`` before a job is queued (its errors are the request's)."""
        self._scenario(field(body, "scenario", dict))
        return {}

    def baseline(self, body: dict[str, Any]) -> dict[str, Any]:
        """The SE(2) bypass baseline: :func:`taut.plan.plan` with ``baseline="se2"``."""
        sc = self._scenario(field(body, "scenario", dict))
        return {"baseline": _summary(plan(sc, baseline="se2", time_budget=PLAN_TIME_CAP_S))}

    def crossing(self, body: dict[str, Any]) -> dict[str, Any]:
        """The planner with obstacle crossing, and the world it plans in."""
        sc = self._scenario(field(body, "scenario", dict))
        return {"plan": _summary(plan(sc, time_budget=PLAN_TIME_CAP_S)),
                "world": world_to_dict(sc)}
