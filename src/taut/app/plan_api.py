"""JSON endpoints of the planner viewer: load a planning scenario, run the planner and its
SE(2) bypass baseline (the same search with crossing disabled) as the steps of a job that
:mod:`taut.app.jobs` queues (the page polls its progress), and return both plans with the
series the page plots.

Planning is :func:`taut.plan.plan` (``baseline="se2"`` for the baseline) and the series
are :func:`taut.plan.plan_profile`; this module computes nothing itself, it only reshapes
their results for drawing. The page's planner settings (``options``: the keyword
arguments of :func:`taut.plan.plan` in :data:`SETTINGS`, and ``baseline``, the bypass
planner compared with) are passed to the library as they are, and validated by it. A
finished plan also comes as the JSON file ``taut plan --out`` writes (``plan_json``) and
as the ROS 2 recording :func:`taut.io.write_mcap` writes (``plan_mcap``, base64; null
with the reason in ``plan_mcap_note`` when the ``mcap`` extra is missing).
Lengths m, times s.
"""

from __future__ import annotations

import base64
import inspect
import tempfile
import typing
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from ..errors import InvalidInputError
from ..io.serialize import json_ready, plan_to_dict, to_json
from ..io import plan_scenario_from_mapping, plan_scenario_to_mapping
from ..plan import PlanResult, Scenario, plan, plan_profile
from .catalog import Catalog
from .payload import field, mapping_from_upload

__all__ = ["PlanAPI", "plan_series", "world_to_dict", "settings", "PLAN_TIME_CAP_S",
           "SETTINGS"]

#: Wall-clock cap of one planning job, s: the app stays interactive (the planner's own
#: budget is counted in samples; a failing plan could otherwise search for minutes).
PLAN_TIME_CAP_S = 30.0
#: Keyword arguments of :func:`taut.plan.plan` the page's settings may give.
SETTINGS = ("method", "search", "sheet_margin", "spacing", "iterations", "seed")
#: The bypass planner compared with unless the page says otherwise.
BASELINE = "se2"


def settings() -> dict[str, Any]:
    """The planner settings the page offers, read from :func:`taut.plan.plan` itself (so
    each default and choice is defined once, in the library): ``{name: {"default": value,
    "choices": [...] or None}}`` for :data:`SETTINGS` and ``baseline`` (the bypass
    planner compared with; its default is "se2")."""
    hints = typing.get_type_hints(plan)
    params = inspect.signature(plan).parameters
    out: dict[str, Any] = {}
    for name in SETTINGS + ("baseline",):
        choices = _choices(hints[name])
        default = params[name].default
        out[name] = {"default": BASELINE if name == "baseline" else default,
                     "choices": choices}
    return out


def _choices(kind: Any) -> list[str] | None:
    """The strings of ``Literal[...]`` or ``Literal[...] | None``; None for a number."""
    args = [a for a in typing.get_args(kind) if a is not type(None)]
    if len(args) == 1 and typing.get_args(args[0]):
        args = list(typing.get_args(args[0]))
    return [a for a in args if isinstance(a, str)] or None


def _mcap(r: PlanResult) -> tuple[str | None, str]:
    """The plan as a ROS 2 MCAP file (:func:`taut.io.write_mcap`), base64, or None and
    the reason (the extra is missing, or there is no plan to record)."""
    from ..io import write_mcap

    with tempfile.TemporaryDirectory(prefix="taut-app-") as tmp:
        try:
            path = write_mcap(r, Path(tmp) / "plan.mcap")
        except InvalidInputError as exc:
            return None, str(exc)
        return base64.b64encode(path.read_bytes()).decode("ascii"), ""


def _options(body: dict[str, Any]) -> tuple[dict[str, Any], Any]:
    """The planner's keyword arguments from ``options`` and the comparison baseline (as
    given: :func:`taut.plan.plan` validates both)."""
    opts = dict(field(body, "options", dict, default={}))
    for name in opts:
        if name not in SETTINGS + ("baseline",):
            raise InvalidInputError(f"options.{str(name)[:40]}", "unknown setting; one of "
                                    + ", ".join(SETTINGS + ("baseline",)))
    baseline = opts.pop("baseline", BASELINE)
    return opts, baseline


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
        "settings": settings(),
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
        """Validate ``scenario`` and the names in ``options`` before a job is queued
        (their errors are the request's; a bad value is the job's error, from
        :func:`taut.plan.plan`)."""
        self._scenario(field(body, "scenario", dict))
        _options(body)
        return {}

    def baseline(self, body: dict[str, Any]) -> dict[str, Any]:
        """The bypass baseline: :func:`taut.plan.plan` with ``baseline`` from ``options``
        (default :data:`BASELINE`) and the same settings."""
        sc = self._scenario(field(body, "scenario", dict))
        opts, baseline = _options(body)
        opts.pop("method", None)                 # a baseline has no crossing method
        return {"baseline": _summary(plan(sc, baseline=baseline, time_budget=PLAN_TIME_CAP_S,
                                          **opts))}

    def crossing(self, body: dict[str, Any]) -> dict[str, Any]:
        """The planner with obstacle crossing, and the world it plans in."""
        sc = self._scenario(field(body, "scenario", dict))
        opts, _ = _options(body)
        r = plan(sc, time_budget=PLAN_TIME_CAP_S, **opts)
        mcap, note = _mcap(r) if r.success else (None, "no plan to record")
        return {"plan": _summary(r), "world": world_to_dict(sc),
                "plan_json": to_json(plan_to_dict(r), indent=None) + "\n",
                "plan_mcap": mcap, "plan_mcap_note": note}
